"""Ctrl-C keeps the best result so far (issue 18, item 1).

In-process: KeyboardInterrupt raised from a progress callback or an optimiser; one real
SIGINT sent to a ``python -m mechsyn`` subprocess.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.interrupt import INTERRUPT_EXIT_CODE, BestSoFar
from mechsyn.synthesis.optimize import OPTIMIZERS, synthesize_path
from mechsyn.synthesis.path import evaluate_design, load_cases

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json"
SLIDER_CASE = ROOT / "examples" / "synthesis" / "slider_crank_path_case.yaml"
FINGER_CASE = ROOT / "examples" / "fingers" / "finger_design_case.yaml"


def _interrupt_after(n: int):
    calls = [0]

    def progress(*args):
        calls[0] += 1
        if calls[0] >= n:
            raise KeyboardInterrupt

    return progress


def test_best_so_far_keeps_lowest_finite_row():
    best = BestSoFar()
    best.offer(np.array([[1.0], [2.0]]), np.array([np.nan, 3.0]))
    best.offer(np.array([[5.0]]), np.array([np.inf]))
    assert best.x.tolist() == [2.0] and best.f == 3.0


def test_path_search_interrupted_by_callback_returns_best_so_far():
    case = load_cases(CASES)[0]
    res = synthesize_path(case, seed=0, restarts=3, time_limit=60, options={"maxiter": 300},
                          progress=_interrupt_after(20))
    assert res.interrupted and res.restarts == 1
    assert res.feasible and np.isfinite(res.error)
    # the reported error belongs to the reported design
    assert evaluate_design(case, res.design)["error"] == pytest.approx(res.error, rel=1e-12)
    assert res.to_dict()["interrupted"] is True


def test_path_search_interrupted_before_any_evaluation_propagates(monkeypatch):
    def optimizer(fitness, lower, upper, **kw):
        raise KeyboardInterrupt

    monkeypatch.setitem(OPTIMIZERS, "_interrupt_at_once", optimizer)
    with pytest.raises(KeyboardInterrupt):
        synthesize_path(load_cases(CASES)[0], seed=0, restarts=1, time_limit=60,
                        optimizer="_interrupt_at_once")


def test_mechanism_search_interrupted_by_callback_returns_best_so_far():
    from mechsyn.synthesis.general import evaluate_mechanism_design as evaluate_mechanism
    from mechsyn.synthesis.general import load_mechanism_case, synthesize_mechanism

    case = load_mechanism_case(SLIDER_CASE)
    res = synthesize_mechanism(case, seed=0, time_limit=60, restarts=2, progress=_interrupt_after(5))
    assert res.interrupted and res.feasible
    x = np.array([res.design[n] for n in case.names])
    assert evaluate_mechanism(case, x).error == pytest.approx(res.error, rel=1e-9)
    assert res.error <= res.start_error
    assert "interrupted" in res.mechanism["name"]


def test_finger_design_interrupted_keeps_stage1_best():
    from mechsyn.synthesis.finger.cases import load_case
    from mechsyn.synthesis.finger.design import design_finger

    case = load_case(FINGER_CASE)
    case.maxiter, case.popsize, case.force_maxiter = 200, 8, 4

    def progress(state):
        if "generation 6/" in state.message:
            raise KeyboardInterrupt

    res = design_finger(case, seed=1, time_limit=120, progress=progress)
    assert res.interrupted and not res.stopped_by_time_limit
    assert len(res.variants) == 1 and np.isfinite(res.best_variant.error_rms)
    assert any("not searched (interrupted)" in n for n in res.notes) or len(case.combinations) == 1


def _interrupting_optimizer(fitness, lower, upper, *, seed, should_stop, options):
    rng = np.random.default_rng(seed)
    for _ in range(5):
        fitness(rng.uniform(lower, upper, size=(64, len(lower))))
    raise KeyboardInterrupt


@pytest.mark.parametrize("command", ["path", "mechanism"])
def test_cli_interrupted_search_writes_best_and_exits_130(command, run_cli, tmp_path, monkeypatch):
    monkeypatch.setitem(OPTIMIZERS, "interrupting", _interrupting_optimizer)
    out = tmp_path / "best.yaml"
    args = (["synth", "path", CASES, "--case", "P2_kk5_timing"] if command == "path"
            else ["synth", "mechanism", SLIDER_CASE])
    code, stdout, stderr = run_cli(*args, "--optimizer", "interrupting", "--out", out, "--time-limit", "30")
    assert code == INTERRUPT_EXIT_CODE
    assert stderr.strip().splitlines()[-1] == "interrupted"
    assert "interrupted" in stdout
    text = out.read_text()
    assert "interrupted" in text.lower()
    assert yaml.safe_load(text)["joints"]


def test_cli_interrupted_json_says_so(cli_json, run_cli, monkeypatch):
    monkeypatch.setitem(OPTIMIZERS, "interrupting", _interrupting_optimizer)
    code, stdout, _ = run_cli("synth", "mechanism", SLIDER_CASE, "--optimizer", "interrupting", "--json")
    import json

    assert code == INTERRUPT_EXIT_CODE and json.loads(stdout)["interrupted"] is True


def _catches(pid: int, sig: int) -> bool:
    """Whether process ``pid`` has installed a handler for ``sig`` (Linux: SigCgt)."""
    try:
        with open(f"/proc/{pid}/status") as fh:
            mask = next(int(ln.split()[1], 16) for ln in fh if ln.startswith("SigCgt:"))
    except (OSError, StopIteration):
        return False
    return bool(mask >> (sig - 1) & 1)


def _signal_subprocess(args: list[str], cwd: Path, ready: Path | None = None, delay: float = 0.0,
                       sig: int = signal.SIGINT) -> subprocess.CompletedProcess:
    """Run mechsyn, send ``sig`` once its ``main()`` runs (its SIGTERM handler is installed:
    a readiness signal, not a time; before it, even Ctrl-C could land in the interpreter's
    start or the package's import) and ``ready`` exists (then ``delay`` s more), collect."""
    if not Path("/proc/self/status").exists():
        pytest.skip("needs /proc to see when the process handles the signal")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    # a child of a non-interactive shell may inherit SIGINT ignored: restore the default so
    # Python installs its KeyboardInterrupt handler, as in a terminal
    p = subprocess.Popen([sys.executable, "-m", "mechsyn", *args], env=env, cwd=cwd, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    end = time.monotonic() + 240  # only ends a broken run
    while p.poll() is None and time.monotonic() < end and not (
            _catches(p.pid, signal.SIGTERM) and (ready is None or ready.exists())):
        time.sleep(0.02)
    time.sleep(delay)
    p.send_signal(sig)
    out, err = p.communicate(timeout=120)
    return subprocess.CompletedProcess(p.args, p.returncode, out, err)


@pytest.mark.slow
@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_real_signal_to_synth_path_keeps_best(tmp_path, sig, code, word):
    # the signal once the search has saved its first checkpoint (it has evaluated designs)
    r = _signal_subprocess(["synth", "path", str(CASES), "--case", "P5_ellipse10_notiming",
                            "--time-limit", "300", "--target-error", "0", "--out", "x.yaml",
                            "--checkpoint", "ck.json"], delay=0.5, cwd=tmp_path, ready=tmp_path / "ck.json", sig=sig)
    assert r.returncode == code, r.stderr
    assert "continue with --resume ck.json" in " ".join(r.stderr.split())
    assert r.stderr.strip().splitlines()[-1] == word
    assert "Traceback" not in r.stderr
    assert (tmp_path / "x.yaml").read_text().startswith("# INTERRUPTED")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ck.json", "x.yaml"]  # no temporary file left


@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_real_signal_during_a_plain_command(tmp_path, sig, code, word):
    """SIGINT exits 130, SIGTERM 143 (it killed the process before, leaving temporary files);
    the signal is sent once the process handles it, never after a time (under load the old
    test's fixed delay could hit the interpreter before its handler: -2 != 130)."""
    r = _signal_subprocess(["simulate", str(ROOT / "examples" / "kinematics" / "crank_rocker.yaml"),
                            "--input", "A=0:3600:0.005", "--json"], cwd=tmp_path, sig=sig)
    assert r.returncode == code, r.stderr
    assert r.stderr.strip().splitlines()[-1] == word
    assert "Traceback" not in r.stderr


def test_cli_interrupted_curve_synthesis_writes_best_and_exits_130(run_cli, tmp_path, monkeypatch):
    import json

    import mechsyn.synthesis.curves.synthesis as curves
    from mechsyn.synthesis.curves.database import build_database

    if run_cli("synth", "curve", "-h")[0] != 0:
        pytest.skip("synth curve is not registered on the command line yet")

    db = tmp_path / "db"
    build_database(db, max_links=4, per_topology=120)
    t = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    target = tmp_path / "t.json"
    target.write_text(json.dumps({"points": np.c_[2 + np.cos(t), 1 + 0.5 * np.sin(t)].tolist(), "closed": True}))
    refine = curves._refine
    calls = [0]

    def refine_then_interrupt(*args, **kwargs):
        calls[0] += 1
        if calls[0] > 2:
            raise KeyboardInterrupt
        return refine(*args, **kwargs)

    monkeypatch.setattr(curves, "_refine", refine_then_interrupt)
    code, out, err = run_cli("synth", "curve", target, "--max-links", "4", "--database", db, "--json",
                             "--time-limit", "60", "--refinements", "10")
    assert code == INTERRUPT_EXIT_CODE, err
    assert err.strip().splitlines()[-1] == "interrupted"
    res = json.loads(out)
    assert res["interrupted"] is True


CAPABILITY_ARM = ROOT / "examples" / "capability" / "paper004_3r.yaml"


def test_capability_map_interrupted_keeps_the_finished_chunks():
    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.maps import capability_map

    arm = load_arm(CAPABILITY_ARM)
    xs, ys = np.linspace(1300, 2100, 5), np.linspace(100, 900, 4)
    full = capability_map(arm, xs, ys, [1, 0])
    part = capability_map(arm, xs, ys, [1, 0], chunk=6, progress=_interrupt_after(2))
    assert part.interrupted and part.done().sum() == 12  # two chunks of 6 points (x outer)
    done = part.done()
    assert np.array_equal(part.value[done], full.value[done], equal_nan=True)
    assert np.isnan(part.value[~done]).all() and len(part.table()) == 12
    assert part.to_dict()["computed_points"] == 12 and not full.to_dict()["interrupted"]
    # the chunk whose progress call was interrupted is kept too
    assert capability_map(arm, xs, ys, [1, 0], chunk=6, progress=_interrupt_after(1)).done().sum() == 6


def test_cli_capability_map_interrupted_writes_solved_points_and_exits_130(run_cli, tmp_path, monkeypatch):
    import mechsyn.capability.maps as maps

    real, calls = maps._map_chunk, [0]

    def second_chunk_interrupts(*args):
        calls[0] += 1
        if calls[0] == 2:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(maps, "_map_chunk", second_chunk_interrupts)
    csv = tmp_path / "map.csv"
    code, out, err = run_cli("capability", CAPABILITY_ARM, "--grid", "1300:2100:10,100:900:10",
                             "--direction", "1,0", "--csv", csv)
    assert code == INTERRUPT_EXIT_CODE and err.strip().splitlines()[-1] == "interrupted"
    assert "interrupted: 2048 of 6561 points solved" in out
    lines = csv.read_text().splitlines()
    assert len(lines) == 1 + 2048 and lines[-1].count(",") == lines[0].count(",")
