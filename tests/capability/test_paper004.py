"""Paper 004 (velocity capability of a redundant planar 3R arm): Tables 1 and 2.

Reference numbers: spec/velocity-capability.md and spec/data/paper004_results.json.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm import ik_planar_3r
from mechsyn.capability.arm_file import load_arm
from mechsyn.capability.maps import capability_map, continuous_best, self_motion
from mechsyn.capability.measures import (
    exact_limit, exact_limit_lp, min_norm_limit, stepped_limit,
)

ROOT = Path(__file__).resolve().parents[2]
ARM_FILE = ROOT / "examples" / "capability" / "paper004_3r.yaml"
# a copy of spec/data/paper004_results.json (the spec's reference values)
REF_FILE = Path(__file__).parent / "data" / "paper004_results.json"

X = [1300, 1500, 1700, 1900, 2100]
Y = [900, 700, 500, 300, 100]
Q1_TABLE1 = [20, 40, 60, 80, 100, 120]
DIRS = {"Vx": (1.0, 0.0), "Vy": (0.0, 1.0)}


@pytest.fixture(scope="module")
def ref():
    return json.loads(REF_FILE.read_text())


@pytest.fixture(scope="module")
def arm():
    return load_arm(ARM_FILE)


def test_arm_file_is_the_papers(arm):
    assert arm.kind == "planar" and arm.n == 3
    np.testing.assert_allclose(arm.link_lengths, [900, 900, 900])
    np.testing.assert_allclose(np.degrees(arm.qd_max), [4, 4, 4])
    np.testing.assert_allclose(np.degrees(arm.lower), [0, -120, -120])
    np.testing.assert_allclose(np.degrees(arm.upper), [120, 120, 120])


def test_table1_configurations_from_exact_ik(arm, ref):
    q, ok = ik_planar_3r(arm, (1300, 900), np.radians(Q1_TABLE1), branch=-1)
    assert ok.all()
    np.testing.assert_allclose(arm.fk(q), [[1300, 900]] * 6, atol=1e-9)
    q_deg = np.degrees(q)
    expected = np.array([r["q_ik"] for r in ref["table1"]])  # rounded to 0.01 deg
    np.testing.assert_allclose(q_deg, expected, atol=0.0051)
    assert (q_deg[:, 2] < 0).all()  # the paper's elbow
    # the paper's printed angles are approximate: their end point is 15-25 mm off
    qp = np.radians([r["q_paper"] for r in ref["table1"]])
    np.testing.assert_allclose(arm.fk(qp), [r["fk_paper"] for r in ref["table1"]], atol=0.06)
    off = np.linalg.norm(arm.fk(qp) - [1300, 900], axis=1)
    assert ((off > 10) & (off < 35)).all()  # 12.7 to 31.1 mm (the spec says "15-25")


def test_table1_limits_reject_three_configurations(arm):
    """q3 >= -120 deg rejects q1 = 20, 40, 60 (the paper's "six and three" needs ~ -135)."""
    q, valid = self_motion(arm, (1300, 900), np.radians(Q1_TABLE1), "negative")
    assert valid.tolist() == [False, False, False, True, True, True]
    q, valid = self_motion(arm, (1300, 900), np.radians(Q1_TABLE1), "negative",
                           respect_limits=False)
    assert valid.all()


@pytest.mark.parametrize("which,key", [("q_ik", "ikq"), ("q_paper", "paperq")])
def test_table1_exact_min_norm_and_stepped(arm, ref, which, key):
    for r in ref["table1"]:
        q = np.radians(r[which]) if which == "q_paper" else ik_planar_3r(
            arm, (1300, 900), np.radians([r["q_ik"][0]]), -1)[0][0]
        J = arm.jacobian(q)
        for name, d in DIRS.items():
            exact = exact_limit(J, arm.qd_max, d)[0]
            mn = min_norm_limit(J, arm.qd_max, d)[0]
            assert exact == pytest.approx(r[key][f"{name}_lp"], rel=1e-6)
            assert mn == pytest.approx(r[key][f"{name}_mn"], rel=1e-6)
            assert exact_limit_lp(J, arm.qd_max, d)[0] == pytest.approx(exact, rel=1e-9)
            # stepped values: exactly
            assert float(stepped_limit(mn)) == r[key][f"{name}_step_mn"]
            assert float(stepped_limit(exact)) == r[key][f"{name}_step"]


def test_table1_vx_column_by_min_norm_stepping(arm, ref):
    """The paper's Vx column follows minimum-norm rates raised in 5 mm/s steps.

    Within one step everywhere except q1 = 80 deg, where the paper prints 80 and any
    consistent model gives 90 (the spec's 65, 70, 80, 90, 95, 60 against the paper's 65, 75,
    75, 80, 95, 60); the best configuration, q1 = 100 deg, gives the paper's 95 mm/s.
    The exact limit is higher (best q1 = 80, 110.3 mm/s): the paper's null-space term was
    not used to full effect. The Vy column is not reproducible (a factor-2 slip in the
    paper), so it is not tested against the paper.
    """
    q, _ = ik_planar_3r(arm, (1300, 900), np.radians(Q1_TABLE1), -1)
    J = arm.jacobian(q)
    stepped = stepped_limit(min_norm_limit(J, arm.qd_max, (1, 0)))
    paper = np.array([r["Vx_paper"] for r in ref["table1"]], float)
    np.testing.assert_array_equal(stepped, [65, 70, 80, 90, 95, 60])
    diff = np.abs(stepped - paper)
    assert (diff[[0, 1, 2, 4, 5]] <= 5).all()
    assert diff[3] == 10  # the paper's outlier at q1 = 80
    assert Q1_TABLE1[int(np.argmax(stepped))] == 100 and stepped.max() == 95
    exact = exact_limit(J, arm.qd_max, (1, 0))
    assert Q1_TABLE1[int(np.argmax(exact))] == 80
    assert exact.max() == pytest.approx(ref["table1"][3]["ikq"]["Vx_lp"], rel=1e-9)


@pytest.mark.parametrize("measure,tag", [("exact", "lp"), ("min_norm", "mn"),
                                         ("stepped_min_norm", "step_mn"), ("stepped", "step")])
@pytest.mark.parametrize("branch,bkey", [("negative", "-1"), ("both", "-1+1")])
def test_table2_grid(arm, ref, measure, tag, branch, bkey):
    """Paper's 5x5 grid, q1 in 20 deg steps over its limits, joint limits respected."""
    cmap = capability_map(arm, X, Y, (1, 0), measure=measure, branch=branch)
    expected = np.array(ref["table2"][f"{bkey}|all|{tag}"])
    if tag == "step":
        # Two cells of the reference's null-space stepping are one step low: there the
        # exact limit exceeds the next step by only 0.028 mm/s (1500, 500) and 0.011 mm/s
        # (2100, 100) and the reference's search missed the feasible rates. Stepping with
        # the exact feasibility test gives 110 and 90; shown feasible by explicit rates.
        low = [(1, 2), (4, 4)]
        for i, j in low:
            assert cmap.value[i, j] == expected[i, j] + 5
            expected[i, j] += 5
            q = cmap.q[i, j]
            _assert_feasible(arm, q, cmap.value[i, j], (1, 0))
        np.testing.assert_array_equal(cmap.value, expected)
    elif tag == "step_mn":
        np.testing.assert_array_equal(cmap.value, expected)
    else:
        np.testing.assert_allclose(cmap.value, expected, rtol=1e-6)
    # the optimal configurations reach their points inside the limits
    q = cmap.q.reshape(-1, 3)
    pts = np.stack(np.meshgrid(X, Y, indexing="ij"), -1).reshape(-1, 2)
    np.testing.assert_allclose(arm.fk(q), pts, atol=1e-8)
    assert arm.within_limits(q).all()


def _assert_feasible(arm, q, speed, d):
    """Explicit joint rates within the limits that move the end point at ``speed`` along d."""
    from scipy.optimize import linprog

    J = arm.jacobian(q)[0]
    n = J.shape[1]
    res = linprog(np.zeros(n), A_eq=J, b_eq=speed * np.asarray(d, float),
                  bounds=[(-w, w) for w in arm.qd_max], method="highs")
    assert res.status == 0
    assert np.all(np.abs(res.x) <= arm.qd_max * (1 + 1e-9))
    np.testing.assert_allclose(J @ res.x, speed * np.asarray(d, float), atol=1e-9)


def test_table2_paper_values_against_the_model(arm, ref):
    """Rows X = 1300, 1500 agree with min-norm stepping within 5 mm/s except the 145 at
    (1300, 100) (the spec's finding, recomputed). Physically impossible values: the 145
    and the whole row X = 2100 exceed the largest speed of *any* configuration (both
    elbows, no position limits). The spec says "rows X >= 1900", but row X = 1900 stays
    below that absolute bound; with the paper's own model (limits, q3 < 0) only its cell
    (1900, 900) exceeds the bound."""
    step_mn = capability_map(arm, X, Y, (1, 0), measure="stepped_min_norm").value
    paper = np.array(ref["table2_paper"])
    ok = np.abs(step_mn[:2] - paper[:2]) <= 5
    assert not ok[0, 4] and ok.sum() == 9
    pts = np.stack(np.meshgrid(X, Y, indexing="ij"), -1).reshape(-1, 2)
    _, bound = continuous_best(arm, pts, (1, 0), branch="both", respect_limits=False)
    bound = bound.reshape(5, 5)
    impossible = paper > bound
    expected = np.zeros((5, 5), bool)
    expected[4, :] = True
    expected[0, 4] = True
    np.testing.assert_array_equal(impossible, expected)
    _, model = continuous_best(arm, pts, (1, 0), branch="negative", respect_limits=True)
    over = paper > model.reshape(5, 5)
    assert over[3].tolist() == [True, False, False, False, False]


def test_upper_bound_by_continuous_search(arm, ref):
    """Largest exact speed over all configurations (both elbows, no position limits)."""
    pts = np.stack(np.meshgrid(X, Y, indexing="ij"), -1).reshape(-1, 2)
    q, v = continuous_best(arm, pts, (1, 0), branch="both", respect_limits=False)
    bound = np.array(ref["table2_upper_bound"]).ravel()
    # the reference is a sampled maximum; the refined search may only find more
    assert (v >= bound - 1e-9).all() and (v <= bound + 0.01).all()
    np.testing.assert_allclose(exact_limit(arm.jacobian(q), arm.qd_max, (1, 0)), v, rtol=1e-12)
    np.testing.assert_allclose(arm.fk(q), pts, atol=1e-8)


def test_continuous_search_beats_the_samples(arm):
    sampled = capability_map(arm, X, Y, (1, 0)).value
    cont = capability_map(arm, X, Y, (1, 0), continuous=True)
    assert (cont.value >= sampled - 1e-12).all()
    assert cont.value[0, 0] == pytest.approx(110.835, abs=1e-3)
    assert arm.within_limits(cont.q.reshape(-1, 3)).all()
