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


def test_one_output_equals_every_output():
    """The outputs asked for do not change the answers (the program places every link;
    the outputs are read off it)."""
    watt = load_mechanism(EX / "textbook/watt_sixbar.yaml")
    one = compile_plan(watt, points=["P"])
    assert one.describe()[0] == "crank A" and len(one.describe()) == 1 + one.n_dyads == 3
    every = compile_plan(watt, points=[j.id for j in watt.joints] + ["P"])
    rng = np.random.default_rng(8)
    X = one.parameters(watt) + rng.normal(scale=0.1, size=(5, one.n_parameters))
    off = np.arange(0.0, 360.0, 2.0)
    a, b = simulate_batch(one, X, off), simulate_batch(every, X, off)
    np.testing.assert_array_equal(a.assembled, b.assembled)
    np.testing.assert_array_equal(a.paths["P"], b.paths["P"])


@pytest.mark.parametrize("name", ["watt_sixbar", "stephenson_sixbar"])
def test_every_joint_equals_simulate_where_some_dyad_fails(name):
    """Frame points and points upstream of the dyad that fails are NaN where the
    mechanism is not assembled, as in simulate (NaN does not reach them by itself)."""
    mech = load_mechanism(EX / f"textbook/{name}.yaml")
    names = [j.id for j in mech.joints] + list(mech.points)
    plan = compile_plan(mech, points=names)
    off = np.arange(0.0, 360.0, 3.0)
    res = simulate_batch(plan, plan.parameters(mech), off)
    sim = simulate(mech, {plan.input_joint: plan.reference_input + off}, points=names)
    assert 0 < res.assembled.sum() < len(off)              # the six-bar locks over part of the turn
    np.testing.assert_array_equal(res.assembled[0], sim.assembled)
    for n in names:
        np.testing.assert_allclose(res.paths[n][0], sim.points[n].position, atol=1e-9)


def test_transmission_angle_does_not_depend_on_the_assembly_mode():
    mech = load_mechanism(EX / "kinematics/crank_rocker.yaml")
    mirror = mechanism_to_dict(mech)                        # the same linkage reflected in the x axis
    mirror["joints"] = [{**j, "point": [j["point"][0], -j["point"][1]]} for j in mirror["joints"]]
    mirror["points"] = {n: {**p, "at": [p["at"][0], -p["at"][1]]} for n, p in mirror["points"].items()}
    off = np.arange(0.0, 360.0, 1.0)
    mu = []
    for m in (mech, mechanism_from_dict(mirror)):
        plan = compile_plan(m)
        res = simulate_batch(plan, plan.parameters(m), off, transmission=True)
        mu.append((res.sigmas[0, 0], res.min_transmission_angle[0]))
    assert mu[0][0] == -mu[1][0]
    # Norton's crank-rocker: mu_min = acos((b^2 + c^2 - (d - a)^2) / (2 b c)), coupler b, rocker c
    a, b, c, d = 1.0, 3.5, 3.0, 4.0
    want = np.degrees(np.arccos((b * b + c * c - (d - a) ** 2) / (2 * b * c)))
    assert abs(mu[0][1] - want) < 1e-6 and abs(mu[1][1] - want) < 1e-6


def test_a_designs_answers_do_not_depend_on_the_other_designs():
    """Designs run one after the other in one compiled pass (mixed assembly modes, one
    design on its own): each design's answers and flags are those it has alone, sample
    for sample."""
    mech = load_mechanism(EX / "textbook/watt_sixbar.yaml")
    plan = compile_plan(mech, points=["P", "E", "B", "D"])
    rng = np.random.default_rng(11)
    x0 = plan.parameters(mech)
    X = x0 + rng.normal(scale=0.1, size=(7, len(x0)))
    X[::3, 1::2] *= -1.0                     # mirrored designs: the other assembly mode of every dyad
    off = np.arange(0.0, 360.0, 5.0)
    many = simulate_batch(plan, X, off, transmission=True)
    assert len(np.unique(many.sigmas[:, 0])) == 2
    for k in (0, 1, 6):
        one = simulate_batch(plan, X[k], off, transmission=True)
        for n in plan.outputs:
            np.testing.assert_array_equal(one.paths[n][0], many.paths[n][k])
        for f in ("assembled", "dead_point", "branch_jump", "min_transmission_angle", "sigmas"):
            np.testing.assert_array_equal(getattr(one, f)[0], getattr(many, f)[k])


def test_an_eight_bar_equals_simulate():
    """An eight-bar of the curve topologies (three dyads)."""
    from mechsyn.synthesis.curves.database import sample_designs
    from mechsyn.synthesis.curves.topologies import curve_topologies

    topo = next(t for t in curve_topologies(8) if t.plan.n_dyads == 3)
    X = sample_designs(topo, 3, np.random.default_rng(4))
    off = np.arange(0.0, 360.0, 4.0)
    res = simulate_batch(topo.plan, X, off)
    for k, x in enumerate(X):
        m = mechanism_from_dict(topo.mechanism(x))
        ref = compile_plan(m, points=["T"]).reference_input
        sim = simulate(m, {topo.plan.input_joint: ref + off}, points=["T"])
        np.testing.assert_array_equal(res.assembled[k], sim.assembled)
        np.testing.assert_allclose(res.paths["T"][k], sim.points["T"].position, atol=1e-9)


def test_no_inputs_or_no_designs():
    mech = load_mechanism(EX / "textbook/watt_sixbar.yaml")
    plan = compile_plan(mech)
    none = simulate_batch(plan, np.zeros((0, plan.n_parameters)), np.arange(0.0, 360.0, 10.0))
    assert none.paths["P"].shape == (0, 36, 2) and none.sigmas.shape == (0, 2)
    empty = simulate_batch(plan, plan.parameters(mech), np.array([]), transmission=True)
    assert empty.paths["P"].shape == (1, 0, 2) and np.isnan(empty.min_transmission_angle[0])


@pytest.mark.parametrize("name", ["crank_rocker", "watt_sixbar"])
def test_one_designs_rows_are_a_motion_equal_to_simulate(name):
    """Asked for one design, the batch answers a Motion: the input joint's values as
    simulate measures them, the same assembled rows and point positions as simulate, no
    rates (NaN, said in the notes), and a dead point said in the notes."""
    import mechsyn as ms

    mech = ms.examples.load(name)
    names = [j.id for j in mech.joints] + list(mech.points)
    plan = compile_plan(mech, points=names)
    designs = np.stack([plan.parameters(mech), 1.5 * plan.parameters(mech)])
    off = np.arange(0.0, 360.0, 3.0)
    res = simulate_batch(plan, designs, off)
    m = res.motion(1)
    assert isinstance(m, ms.kinematics.Motion) and m.engine == "batch" and m.mechanism == mech.name
    one = res.motion(0)
    sim = simulate(mech, {plan.input_joint: plan.reference_input + off}, points=names)
    np.testing.assert_allclose(one.inputs[plan.input_joint], sim.inputs[plan.input_joint], atol=1e-9)
    np.testing.assert_array_equal(one.assembled, sim.assembled)
    for n in names:
        np.testing.assert_allclose(one.point(n), sim.points[n].position, atol=1e-9)
        np.testing.assert_allclose(m.point(n), 1.5 * one.point(n), atol=1e-9)  # the design scaled by 1.5
        assert np.isnan(one.points[n].velocity).all()
    assert any("velocities" in note for note in one.notes)
    assert any("dead point" in note for note in one.notes) == (not sim.assembled.all())
    assert one.to_dict()["engine"] == "batch"
    if sim.assembled.all():
        assert one.working_ranges() == sim.working_ranges()
