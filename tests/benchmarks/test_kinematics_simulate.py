"""benchmarks/kinematics_simulate.py (issue 30): the pylinkage models read from the mechanisms,
the answer check against pylinkage, and the benchmark's reduced run with its checks passing."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict, mechanism_to_dict

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "benchmarks"))

import kinematics_simulate as ks  # noqa: E402
import pylinkage_models as pm  # noqa: E402

CASES = ("crank-rocker", "Watt, full turn", "Watt, no dead points", "Jansen leg", "crank-rocker, 2e+04")


def test_models_follow_the_files_dyads():
    cr = pm.model_of(load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml"))
    assert cr.crank == ("A", "B") and cr.ground == ("A", "D")
    assert cr.steps == (("rrr", "C", "B", "D"), ("fixed", "point:M", "B", "C"))
    watt = pm.model_of(load_mechanism(ROOT / "examples/textbook/watt_sixbar.yaml"))
    assert [s[:2] for s in watt.steps] == [("rrr", "C"), ("fixed", "E"), ("fixed", "F"), ("rrr", "G"),
                                            ("fixed", "point:P")]


def test_a_double_joint_is_one_pin():
    """The Jansen leg's knees are written as two joints at one point: one pylinkage joint each."""
    m = pm.model_of(load_mechanism(ROOT / "examples/kinematics/jansen_leg.yaml"))
    assert m.pins["P1"] == ["P1", "P1_2"] and m.pins["P2"] == ["P2", "P2_2"] and m.pins["P4"] == ["P4", "P4_2"]
    assert len(m.names) == 8  # P0, P2, P1, P3, P4, P5, P6 and the foot


def test_what_pylinkage_cannot_say_is_named():
    d = mechanism_to_dict(load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml"))
    d["joints"][3] = {**d["joints"][3], "actuated": True}
    with pytest.raises(pm.NotExpressible, match="one driven joint"):
        pm.model_of(mechanism_from_dict(d))


def _sim(pos, vel, acc, names):
    return SimpleNamespace(points={n: SimpleNamespace(position=pos[:, k], velocity=vel[:, k],
                                                      acceleration=acc[:, k]) for k, n in enumerate(names)})


def test_the_answer_check_sees_a_difference_and_a_different_row():
    rng = np.random.default_rng(3)
    pos, vel, acc = (rng.normal(size=(20, 3, 2)) for _ in range(3))
    sim = _sim(pos, vel, acc, ["a", "b", "c"])
    assert ks.compare(sim, ["a", "b", "c"], (pos, vel, acc), 2.0)["ok"]
    off = vel.copy()
    off[7, 2, 1] += 1e-8
    got = ks.compare(sim, ["a", "b", "c"], (pos, off, acc), 2.0)
    assert not got["ok"] and got["vel"] == pytest.approx(0.5e-8)
    blank = pos.copy()
    blank[4, 1] = np.nan  # pylinkage cannot place b on row 4, mechsyn answers it
    got = ks.compare(sim, ["a", "b", "c"], (blank, vel, acc), 2.0)
    assert not got["ok"] and got["differ"] == ["rows with positions: mechsyn 20, pylinkage 19"]


def _run(python: str) -> str:
    res = subprocess.run([python, str(ROOT / "benchmarks/kinematics_simulate.py"), "--repeats", "1",
                          "--big", "20000"], capture_output=True, text=True, cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": str(ROOT / "src")})
    assert res.returncode == 0, res.stdout + res.stderr
    assert "# checks: crank-rocker = bare NumPy to" in res.stdout
    return res.stdout


def _check_rows(out: str) -> None:
    """The answer checks' table (from its header to the blank line): every case, each 'ok'."""
    lines = out.splitlines()
    first = next(k for k, line in enumerate(lines) if line.startswith("case") and "answered" in line) + 1
    table = lines[first:lines.index("", first)]
    assert [line[:22].strip() for line in table] == list(CASES)
    for line in table:
        assert line.split()[-1] == "ok", line


@pytest.mark.slow
def test_reduced_run_checks_pass():
    """With pylinkage importable, every case's answers equal pylinkage's; without, one line says
    how to get the comparison."""
    out = _run(sys.executable)
    if importlib.util.find_spec("pylinkage") and importlib.util.find_spec("numba"):
        _check_rows(out)
    else:
        assert [line for line in out.splitlines() if "pylinkage" in line] == [
            "pylinkage: not importable, skipped (get it: pip install pylinkage numba)"]


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("PYLINKAGE_PYTHON"), reason="PYLINKAGE_PYTHON (a python with pylinkage) not set")
def test_reduced_run_against_pylinkage():
    _check_rows(_run(os.environ["PYLINKAGE_PYTHON"]))


def test_fresh_geometry_takes_with_joint_points_where_it_exists():
    m = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    calls = []
    fake = SimpleNamespace(joints=m.joints, joint=m.joint, with_joint_points=lambda pts: calls.append(pts) or m)
    make, path, where = ks.fresh_maker(fake, "D")
    assert path == "Mechanism.with_joint_points" and make(3) is m
    assert list(calls[0]) == ["D"] and np.array_equal(calls[0]["D"], where(3))


def test_fresh_geometry_otherwise_takes_the_studios_path():
    m = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    if hasattr(m, "with_joint_points"):
        pytest.skip("Mechanism.with_joint_points exists: the studio's path is not taken")
    make, path, where = ks.fresh_maker(m, "D")
    assert path.startswith("mechanism_from_dict")
    moved = make(1)
    assert np.allclose(moved.joint("D").point[:2], where(1)) and not np.allclose(where(1), m.joint("D").point[:2])
    assert [j.id for j in moved.joints] == [j.id for j in m.joints]
    assert all(np.array_equal(a.point, b.point) for a, b in zip(moved.joints, m.joints) if a.id != "D")
