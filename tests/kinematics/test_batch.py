"""The batch engine equals simulate on sampled designs, and flags what it cannot run through."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.io.load import load_mechanism, mechanism_from_dict, mechanism_to_dict
from mechsyn.kinematics import simulate
from mechsyn.kinematics.batch import compile_plan, simulate_batch

EX = Path(__file__).resolve().parents[2] / "examples"


def _with_params(mech, plan, x):
    base = mechanism_to_dict(mech)
    where = dict(zip(plan.names, np.asarray(x).reshape(-1, 2).tolist()))
    base["joints"] = [{**j, "point": where[j["id"]]} for j in base["joints"]]
    if "points" in base:
        base["points"] = {n: {**p, "at": where[n]} for n, p in base["points"].items()}
    return mechanism_from_dict(base)


@pytest.mark.parametrize("name", [
    "kinematics/crank_rocker",
    # dead points: simulate refines each one (about a second per design), so these are slow
    pytest.param("textbook/fourbar", marks=pytest.mark.slow),
    pytest.param("textbook/watt_sixbar", marks=pytest.mark.slow),
    pytest.param("textbook/stephenson_sixbar", marks=pytest.mark.slow)])
def test_batch_equals_simulate_on_perturbed_designs(name):
    mech = load_mechanism(EX / f"{name}.yaml")
    plan = compile_plan(mech)
    rng = np.random.default_rng(3)
    x0 = plan.parameters(mech)
    designs = np.vstack([x0, x0 + rng.normal(scale=0.15, size=(2, len(x0)))])
    off = np.arange(0.0, 360.0, 3.0)
    res = simulate_batch(plan, designs, off, transmission=True)
    for k, x in enumerate(designs):
        m = _with_params(mech, plan, x)
        sim = simulate(m, {plan.input_joint: compile_plan(m).reference_input + off})
        assert np.array_equal(res.assembled[k], sim.assembled)
        for n in plan.outputs:
            np.testing.assert_allclose(res.paths[n][k], sim.points[n].position, atol=1e-9)
        assert res.dead_point[k] == (not sim.assembled.all())


def test_full_rotation_and_dead_points_flagged():
    crank_rocker = load_mechanism(EX / "kinematics/crank_rocker.yaml")
    triple_rocker = load_mechanism(EX / "textbook/fourbar.yaml")
    off = np.arange(0.0, 361.0, 1.0)
    a = simulate_batch(compile_plan(crank_rocker), compile_plan(crank_rocker).parameters(crank_rocker), off,
                       transmission=True)
    b = simulate_batch(compile_plan(triple_rocker), compile_plan(triple_rocker).parameters(triple_rocker), off)
    assert a.full_cycle.tolist() == [True] and b.dead_point.tolist() == [True]
    assert 0 < a.min_transmission_angle[0] < 90


def _almost_crank_rocker(rocker: float):
    """Frame 4, crank 1, coupler 3.5: for rocker < 1.5 the crank stops near 180 deg."""
    B, D, L1 = np.array([1.0, 0.0]), np.array([4.0, 0.0]), 3.5
    a = (L1 ** 2 - rocker ** 2 + 9.0) / 6.0
    C = B + np.array([a, np.sqrt(L1 ** 2 - a ** 2)])
    return mechanism_from_dict({"name": "x", "kind": "planar", "ground": "f", "links": ["f", "c", "k", "r"],
                                "joints": [{"id": "A", "type": "R", "links": ["f", "c"], "point": [0, 0],
                                            "actuated": True},
                                           {"id": "B", "type": "R", "links": ["c", "k"], "point": B.tolist()},
                                           {"id": "C", "type": "R", "links": ["k", "r"], "point": C.tolist()},
                                           {"id": "D", "type": "R", "links": ["r", "f"], "point": D.tolist()}]})


def test_stepped_over_dead_point_is_a_branch_jump():
    mech = _almost_crank_rocker(1.499)   # not assembled for crank angles 177.1..182.9 deg
    plan = compile_plan(mech)
    fine = simulate_batch(plan, plan.parameters(mech), np.arange(0.0, 360.0, 0.5))
    assert fine.dead_point[0] and not fine.assembled[0, 360] and fine.assembled[0, 350]
    coarse = simulate_batch(plan, plan.parameters(mech), np.arange(5.0, 365.0, 10.0))
    assert coarse.assembled.all() and coarse.branch_jump[0] and not coarse.full_cycle[0]
    ok = simulate_batch(plan, plan.parameters(_almost_crank_rocker(1.6)), np.arange(5.0, 365.0, 10.0))
    assert ok.full_cycle[0]


def test_not_decomposable_or_not_R_is_refused():
    mech = load_mechanism(EX / "textbook/slider_crank.yaml")
    with pytest.raises(MechsynInputError):
        compile_plan(mech)


def test_reference_inputs_match_simulate_measure_and_2d_inputs():
    from mechsyn.synthesis.curves.database import sample_designs
    from mechsyn.synthesis.curves.topologies import curve_topologies

    rng = np.random.default_rng(5)
    topos = curve_topologies(6)
    for t in topos[:6]:
        X = sample_designs(t, 3, rng)
        got = t.plan.reference_inputs(X)
        for x, g in zip(X, got):
            want = compile_plan(mechanism_from_dict(t.mechanism(x)), points=["T"]).reference_input
            assert abs((g - want + 180) % 360 - 180) < 1e-9
        off = np.linspace(0, 90, 7)
        rows = np.vstack([off, off + 30, off - 10])
        two = simulate_batch(t.plan, X, rows).paths["T"]
        for k in range(3):
            one = simulate_batch(t.plan, X[k], rows[k]).paths["T"][0]
            np.testing.assert_array_equal(np.isnan(one), np.isnan(two[k]))
            np.testing.assert_allclose(one[np.isfinite(one)], two[k][np.isfinite(two[k])])
