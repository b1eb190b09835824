"""Checkpoints and --resume of ``synth finger-design`` (issue 18): one record per
finished VLL variant; a resumed run searches only the others and gives the design an
uninterrupted run gives."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

from mechsyn.checkpoint import read_checkpoint
from mechsyn.errors import MechsynInputError
from mechsyn.interrupt import INTERRUPT_EXIT_CODE
from mechsyn.results import dumps
from mechsyn.synthesis.finger import design as fd
from mechsyn.synthesis.finger.cases import load_case

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "fingers" / "finger_design_three_phalanx.yaml"
TINY = {"maxiter": 4, "popsize": 5, "force_maxiter": 1, "vll_steps": 3, "candidates": 1}


@pytest.fixture(scope="module")
def case():
    return replace(load_case(CASE), **TINY)


@pytest.fixture(scope="module")
def uninterrupted(case):
    return fd.design_finger(case, seed=0)


def _same(a, b):
    da, db = json.loads(dumps(a)), json.loads(dumps(b))
    da.pop("seconds"), db.pop("seconds")
    return da == db


def _stop_in_second_variant(state):
    if state.stage == "VLL S2: stage 1" and state.message.startswith("generation 2/"):
        raise KeyboardInterrupt


@pytest.fixture
def saved(case, tmp_path):
    ck = tmp_path / "finger.ckpt.json"
    first = fd.design_finger(case, seed=0, progress=_stop_in_second_variant, checkpoint=ck)
    assert first.interrupted
    return ck


def test_interrupted_in_the_second_variant_then_resumed_gives_the_uninterrupted_design(
        case, uninterrupted, saved, monkeypatch):
    assert list(read_checkpoint(saved)["done"]) == ["S1"]      # the cut-short S2 is not kept as finished
    searched = []
    real = fd._design_variant
    monkeypatch.setattr(fd, "_design_variant", lambda run, combo: searched.append(combo) or real(run, combo))
    resumed = fd.design_finger(case, seed=0, checkpoint=saved, resume=True)
    assert searched == [("S2",), ("S1", "S2")]                  # S1 read back, not searched again
    assert not resumed.interrupted and _same(resumed, uninterrupted)
    assert list(read_checkpoint(saved)["done"]) == ["S1", "S2", "S1+S2"]
    again = fd.design_finger(case, seed=0, checkpoint=saved, resume=True)   # nothing left to search
    assert searched == [("S2",), ("S1", "S2")] and _same(again, uninterrupted)


def test_interrupt_before_a_variant_evaluated_anything_keeps_the_earlier_ones(case, uninterrupted, tmp_path):
    def stop(state):
        if state.message.startswith("VLL S2: stage 1 (targets"):
            raise KeyboardInterrupt

    ck = tmp_path / "ck.json"
    first = fd.design_finger(case, seed=0, progress=stop, checkpoint=ck)
    assert first.interrupted and [v.combination for v in first.variants] == [("S1",)]
    assert "VLL S2: not searched (interrupted)" in first.notes
    assert _same(fd.design_finger(case, seed=0, checkpoint=ck, resume=True), uninterrupted)


def test_read_back_variant_keeps_its_paths_and_mechanism(case, uninterrupted, saved):
    resumed = fd.design_finger(case, seed=0, checkpoint=saved, resume=True)
    a, b = uninterrupted.variants[0], resumed.variants[0]
    assert a.mechanism == b.mechanism and a.vll_ranges == b.vll_ranges
    for jid, u in a.underactuated.items():
        for p, P in u["paths"].items():
            assert (P == b.underactuated[jid]["paths"][p])[P == P].all()
            assert ((P != P) == (b.underactuated[jid]["paths"][p] != b.underactuated[jid]["paths"][p])).all()


def test_resume_with_another_seed_or_case_is_refused(case, saved):
    with pytest.raises(MechsynInputError, match="key.seed"):
        fd.design_finger(case, seed=1, checkpoint=saved, resume=True)
    with pytest.raises(MechsynInputError, match="key.case"):
        fd.design_finger(replace(case, maxiter=5), seed=0, checkpoint=saved, resume=True)


def test_resume_of_another_search_is_refused(case, tmp_path):
    from mechsyn.checkpoint import RestartCheckpoint

    ck = tmp_path / "path.ckpt.json"
    RestartCheckpoint.open(ck, "synth path", {"seed": 0}).save()
    with pytest.raises(MechsynInputError, match="resume it with mechsyn synth path"):
        fd.design_finger(case, seed=0, checkpoint=ck, resume=True)


def test_cli_checkpoint_then_resume(run_cli, case, uninterrupted, tmp_path, monkeypatch):
    """Ctrl-C in the second variant: exit 130 naming the checkpoint; --resume finishes it."""
    case_file = tmp_path / "case.yaml"
    import yaml

    data = yaml.safe_load(CASE.read_text())
    data["mechanism"] = str(CASE.parent / data["mechanism"])
    data["optimizer"] = TINY
    case_file.write_text(yaml.safe_dump(data))
    real = fd.stage1_population

    def flaky(case_, combo):
        f, calls = real(case_, combo), [0]

        def g(X):
            calls[0] += 1
            if combo == ("S2",) and calls[0] == 2:
                raise KeyboardInterrupt
            return f(X)
        return g

    monkeypatch.setattr(fd, "stage1_population", flaky)
    ck = tmp_path / "ck.json"
    base = ["synth", "finger-design", case_file, "--json"]
    code, out, err = run_cli(*base, "--checkpoint", ck)
    assert code == INTERRUPT_EXIT_CODE and json.loads(out)["interrupted"] is True
    assert f"continue with --resume {ck}" in " ".join(err.split())
    monkeypatch.setattr(fd, "stage1_population", real)
    code, out, err = run_cli(*base, "--resume", ck)
    assert code == 0, err
    resumed = json.loads(out)
    assert resumed["design"] == json.loads(dumps(uninterrupted))["design"]


@pytest.mark.parametrize("damage", ["no_notes", "design_text", "stopped_text", "variant_list"])
def test_a_damaged_variant_record_is_one_error_naming_it(case, saved, damage):
    """Issue 27: a damaged record gave a traceback (KeyError, TypeError) on --resume."""
    data = json.loads(saved.read_text())
    rec = data["done"]["S1"]
    if damage == "no_notes":
        del rec["notes"]
    elif damage == "design_text":
        rec["variant"]["design"] = "oops"
    elif damage == "stopped_text":
        rec["stopped"] = "no"
    else:
        rec["variant"] = [1, 2]
    saved.write_text(json.dumps(data))
    with pytest.raises(MechsynInputError, match="damaged record of VLL S1") as err:
        fd.design_finger(case, seed=0, checkpoint=saved, resume=True)
    assert err.value.field == "done.S1"


def test_a_forged_variant_record_is_not_believed(case, uninterrupted, saved):
    """Issue 27: forged results in a checkpoint were reported as feasible: now only the design
    vectors are read back and every claim is computed again from them."""
    data = json.loads(saved.read_text())
    rec = data["done"]["S1"]["variant"]
    rec.update(error_rms=0.0, error_max=0.0, assembled_at_all_targets=True,
               vll_ranges={j: [0.0, 1e9] for j in rec["vll_ranges"]})
    rec["forces"]["criterion"] = -1e9
    saved.write_text(json.dumps(data))
    resumed = fd.design_finger(case, seed=0, checkpoint=saved, resume=True)
    assert _same(resumed, uninterrupted)  # the forged numbers are gone
    rec["design"] = {k: 1e12 for k in rec["design"]}  # outside the bounds
    saved.write_text(json.dumps(data))
    with pytest.raises(MechsynInputError, match="outside the case's bounds"):
        fd.design_finger(case, seed=0, checkpoint=saved, resume=True)
