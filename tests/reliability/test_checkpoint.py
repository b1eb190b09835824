"""Checkpoints and --resume of the multi-start searches (issue 18, item 1).

An interrupted run (Ctrl-C raised through the progress callback or by the optimiser)
leaves a checkpoint; the resumed run must give the design an uninterrupted run gives.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mechsyn.checkpoint import RestartCheckpoint, read_checkpoint
from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import INTERRUPT_EXIT_CODE
from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.optimize import OPTIMIZERS, random_search, synthesize_path
from mechsyn.synthesis.path import PathCase

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "examples" / "synthesis" / "path_cases_public.json"
OPTS = {"maxiter": 25}


@pytest.fixture(scope="module")
def case() -> PathCase:
    th = [0.0, 0.4, 0.8, 1.2, 1.6]
    C = fourbar_position(3.0, 1.0, 3.0, 2.5, np.array(th), branch=-1, rcx=1.0, rcy=1.0).C
    return PathCase.from_dict({
        "id": "known", "targets": C.tolist(), "timing": {"type": "prescribed", "theta2": th},
        "fixed": {"x0": 0.0, "y0": 0.0, "theta0": 0.0},
        "variables": [{"name": n, "lower": lo, "upper": 6.0} for n, lo in
                      (("r1", 0.1), ("r2", 0.1), ("r3", 0.1), ("r4", 0.1), ("rcx", -6.0), ("rcy", -6.0))]})


@pytest.fixture(scope="module")
def uninterrupted(case):
    return synthesize_path(case, seed=3, restarts=3, time_limit=120, options=OPTS)


def _run(case, path, resume=False, progress=None):
    return synthesize_path(case, seed=3, restarts=3, time_limit=120, options=OPTS, progress=progress,
                           checkpoint=path, resume=resume)


def test_interrupt_after_a_restart_then_resume_gives_the_uninterrupted_design(case, uninterrupted, tmp_path):
    ck = tmp_path / "run.ckpt.json"

    def stop_after_first(state):
        if state.done >= 1:
            raise KeyboardInterrupt

    first = _run(case, ck, progress=stop_after_first)
    assert first.interrupted and first.restarts == 1
    assert list(read_checkpoint(ck)["finished"]) == ["0"]
    resumed = _run(case, ck, resume=True)
    assert not resumed.interrupted and resumed.resumed == 1
    assert resumed.design == uninterrupted.design
    assert resumed.restart_errors == uninterrupted.restart_errors
    # everything finished: resuming again runs nothing and gives the same answer
    again = _run(case, ck, resume=True)
    assert again.resumed == 3 and again.design == uninterrupted.design and again.nfev == resumed.nfev


def test_interrupt_inside_a_restart_keeps_its_best_in_the_checkpoint(case, uninterrupted, tmp_path, monkeypatch):
    ck = tmp_path / "run.ckpt.json"
    calls = [0]

    def stop_inside_second(state):
        calls[0] += state.done >= 1
        if calls[0] >= 4:  # a few generations into restart 2
            raise KeyboardInterrupt

    first = _run(case, ck, progress=stop_inside_second)
    data = read_checkpoint(ck)
    assert first.interrupted and list(data["finished"]) == ["0"]
    assert data["partial"]["index"] == 1 and np.isfinite(data["partial"]["fitness"])
    # the kept partial best competes: the result is no worse than restart 0 alone
    assert first.error <= uninterrupted.restart_errors[0] * (1 + 1e-9)
    # interrupted again at once: the checkpoint's partial best is kept, not lost
    monkeypatch.setitem(OPTIMIZERS, "de", _interrupt_at_once)
    second = _run(case, ck, resume=True)
    assert second.interrupted and second.restarts == 2
    monkeypatch.undo()
    resumed = _run(case, ck, resume=True)
    assert resumed.design == uninterrupted.design and read_checkpoint(ck)["partial"] is None


def _interrupt_at_once(fitness, lower, upper, **kw):
    raise KeyboardInterrupt


@pytest.fixture(scope="module")
def saved(case, tmp_path_factory) -> Path:
    """A checkpoint of a run interrupted after its first restart."""
    ck = tmp_path_factory.mktemp("ck") / "run.ckpt.json"
    _run(case, ck, progress=_stop_after_first)
    return ck


def _stop_after_first(state):
    if state.done >= 1:
        raise KeyboardInterrupt


@pytest.mark.parametrize("change, field", [({"seed": 4}, "key.seed"), ({"restarts": 4}, "key.restarts"),
                                           ({"options": {"maxiter": 26}}, "key.options"),
                                           ({"target_error": 1e-9}, "key.target_error")])
def test_resume_with_other_settings_is_refused_naming_the_setting(case, saved, change, field):
    args = {"seed": 3, "restarts": 3, "options": OPTS, "time_limit": 120, **change}
    with pytest.raises(MechsynInputError) as err:
        synthesize_path(case, checkpoint=saved, resume=True, **args)
    assert err.value.field == field and "start afresh" in err.value.hint


def test_resume_of_another_case_is_refused(case, saved):
    from dataclasses import replace

    other = replace(case, targets=case.targets + 0.1)
    with pytest.raises(MechsynInputError, match="another case") as err:
        _run(other, saved, resume=True)
    assert err.value.field == "key.case"


@pytest.mark.parametrize("text", ["{}", "[1, 2]", "not json", '{"format": "mechsyn-checkpoint", "version": 1, '
                                  '"kind": "synth path", "key": KEY, "finished": {"0": {"seed": "x"}}}'])
def test_damaged_or_foreign_checkpoint_is_one_clear_error(case, saved, tmp_path, text):
    bad = tmp_path / "bad.json"
    bad.write_text(text.replace("KEY", json.dumps(read_checkpoint(saved)["key"])))
    with pytest.raises(MechsynInputError) as err:
        _run(case, bad, resume=True)
    assert str(bad) in str(err.value) and err.value.hint


def test_a_new_checkpoint_never_replaces_a_file_it_did_not_write(case, tmp_path):
    mine = tmp_path / "notes.json"
    mine.write_text('{"my": "notes"}')
    with pytest.raises(MechsynInputError, match="not a mechsyn checkpoint; not overwritten"):
        _run(case, mine)
    assert mine.read_text() == '{"my": "notes"}'


def test_cli_checkpoint_then_resume(run_cli, tmp_path, monkeypatch):
    """`synth path --checkpoint` interrupted in its second restart exits 130 naming the file;
    `--resume` finishes with the answer of an uninterrupted run."""
    calls = [0]

    def flaky(fitness, lower, upper, **kw):
        calls[0] += 1
        if calls[0] == 2:
            fitness(np.random.default_rng(0).uniform(lower, upper, size=(8, len(lower))))
            raise KeyboardInterrupt
        return random_search(fitness, lower, upper, **kw)

    monkeypatch.setitem(OPTIMIZERS, "flaky", flaky)
    ck = tmp_path / "ck.json"
    base = ["synth", "path", CASES, "--case", "P2_kk5_timing", "--optimizer", "flaky", "--restarts", "3",
            "--target-error", "0", "--time-limit", "60", "--json"]
    code, out, err = run_cli(*base, "--checkpoint", ck)
    assert code == INTERRUPT_EXIT_CODE and json.loads(out)["interrupted"] is True
    assert f"continue with --resume {ck}" in " ".join(err.split())
    code, out, err = run_cli(*base, "--resume", ck)
    assert code == 0, err
    resumed = json.loads(out)
    calls[0] = 10  # no more interrupts
    code, out, _ = run_cli(*base)
    assert code == 0 and json.loads(out)["design"] == resumed["design"]
    assert resumed["resumed_restarts"] == 1


@pytest.mark.parametrize("args, message", [
    (["--checkpoint", "a.json", "--resume", "b.json"], "not both"),
    (["--resume", "missing.json"], "no such checkpoint file"),
])
def test_cli_checkpoint_options_checked_before_work(run_cli, tmp_path, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli("synth", "path", CASES, "--case", "P2_kk5_timing", *args)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1


def test_mechanism_search_interrupted_then_resumed_gives_the_uninterrupted_design(tmp_path):
    from mechsyn.synthesis.general import load_mechanism_case, synthesize_mechanism

    case = load_mechanism_case(ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml")
    args = {"seed": 1, "restarts": 2, "time_limit": 120, "n_polish": 1,
            "options": {"maxiter": 5, "popsize": 4, "init_oversample": 1}}
    full = synthesize_mechanism(case, **args)
    ck = tmp_path / "m.ckpt.json"
    first = synthesize_mechanism(case, checkpoint=ck, progress=_stop_after_first, **args)
    assert first.interrupted and list(read_checkpoint(ck)["finished"]) == ["0"]
    resumed = synthesize_mechanism(case, checkpoint=ck, resume=True, **args)
    assert not resumed.interrupted and resumed.design == full.design and resumed.error == full.error
    with pytest.raises(MechsynInputError, match="synth mechanism"):
        synthesize_path(load_cases_p2(), checkpoint=ck, resume=True)


def load_cases_p2():
    from mechsyn.synthesis.path import load_cases

    return load_cases(CASES)[0]
