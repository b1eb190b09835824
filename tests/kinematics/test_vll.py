"""Variable-length links (paper 000): locked, free (passive) and active modes in one file."""

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.kinematics.solve import check_mobility
from mechsyn.kinematics.system import build_system

from kinematics_helpers import ex, point_state  # noqa: F401


def vll_length(sim, joint="S"):
    return sim.system.coordinate(np.nan_to_num(sim.sweep.q), joint)


def test_locked_mode_is_fully_actuated(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    S = build_system(m)
    assert check_mobility(S)["free"] == 0
    sim = simulate(m, {"E": input_grid(-10, 40, 5)}, points=["tip", "K", "L"])
    assert sim.assembled.all()
    L0 = np.linalg.norm(np.array([4, 22]) - [20, -2])
    assert np.allclose(vll_length(sim), L0, atol=1e-10)
    K, L = sim.points["K"].position, sim.points["L"].position
    assert np.allclose(np.linalg.norm(K - L, axis=1), L0, atol=1e-10)


def test_free_mode_is_underactuated(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    S = build_system(m, vll={"S": "free"})
    assert check_mobility(S)["free"] == 1  # one coordinate beyond the single motor
    with pytest.raises(MechsynInputError, match="free coordinate"):
        simulate(m, {"E": input_grid(0, 10, 5)}, vll={"S": "free"})


def test_free_mode_with_prescribed_length(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    lengths = np.linspace(28.8, 26.0, 8)
    sim = simulate(m, {"E": np.full(8, 10.0), "S": lengths}, vll={"S": "free"}, points=["tip"])
    assert sim.assembled.all()
    assert np.allclose(vll_length(sim), lengths, atol=1e-10)
    # the crank stays, the fingertip moves: the adaptive (underactuated) motion
    tip = sim.points["tip"].position
    assert np.linalg.norm(tip[-1] - tip[0]) > 1.0


def test_active_mode_drives_the_length(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    sim = simulate(m, {"E": np.full(5, 0.0), "S": np.linspace(25, 30, 5)}, vll={"S": "active"})
    assert np.allclose(vll_length(sim), np.linspace(25, 30, 5), atol=1e-10)
    assert sim.vll == {"S": "active"}


def test_limits(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    with pytest.raises(MechsynInputError, match="limits"):
        simulate(m, {"E": np.zeros(3), "S": np.array([20.0, 25, 30])}, vll={"S": "active"})


def test_three_phalanx_modes(ex):
    m = ex("fingers/three_phalanx_vll_000.yaml")
    assert check_mobility(build_system(m))["free"] == 0
    assert check_mobility(build_system(m, vll={"S1": "free", "S2": "free"}))["free"] == 2
    sim = simulate(m, {"F": np.linspace(0, 20, 5), "S1": np.linspace(28.8, 27, 5), "S2": np.full(5, 32.0)},
                   vll={"S1": "free", "S2": "free"})
    assert sim.assembled.all()


def test_bad_vll_options(ex):
    m = ex("fingers/two_phalanx_vll_000.yaml")
    with pytest.raises(MechsynInputError, match="P pair"):
        build_system(m, vll={"A": "locked"})
    with pytest.raises(MechsynInputError, match="unknown VLL mode"):
        build_system(m, vll={"S": "floppy"})
    with pytest.raises(MechsynInputError, match="no joint"):
        build_system(m, vll={"Z": "locked"})


def test_three_phalanx_forces_both_modes(ex):
    """Virtual power balance of the three-phalanx finger, locked and free (prescribed)."""
    from mechsyn.io import mechanism_to_dict, mechanism_from_dict
    from mechsyn.kinetostatics import forces

    d = mechanism_to_dict(ex("fingers/three_phalanx_vll_000.yaml"))
    d["loads"] = [{"link": "distal", "force": [-2.0, 0.5], "at": [0, 95]}]
    m = mechanism_from_dict(d, "three")
    locked = forces(m, {"F": np.linspace(0, 20, 5)}, static=True)
    free = forces(m, {"F": np.linspace(0, 20, 5), "S1": np.linspace(28.8, 27, 5), "S2": np.full(5, 32.0)},
                  vll={"S1": "free", "S2": "free"}, static=True)
    for fa in (locked, free):
        sim = fa.simulation
        S, sw = sim.system, sim.sweep
        tip = point_state(S, sw.q, sw.qd, sw.qdd, S.index("distal"), S.to_local("distal", np.array([0.0, 95.0])))
        power = tip[1] @ np.array([-2.0, 0.5])
        for k, dr in enumerate(S.drivers):
            power = power + fa.reactions.effort[dr.joint] * sw.speeds[k]
        assert np.abs(power).max() < 1e-9 * np.abs(tip[1]).max() * 2
    # locked: the VLLs carry axial force; free: their "drive" force is what a spring must give
    assert set(free.reactions.effort) == {"F", "S1", "S2"}
    assert np.abs(locked.reactions.force["S1"]).max() > 0


def test_limits_are_each_mechanisms_own_within_one_topology(ex):
    """The limits of a P joint are numbers, not topology: mechanisms of one topology (each
    compiled from the first's plan) with other limits each check their own."""
    from dataclasses import replace

    from mechsyn.kinematics.topology import topology_key

    m = ex("fingers/two_phalanx_vll_000.yaml")
    inputs = {"E": np.zeros(3), "S": np.array([25.0, 27.0, 33.0])}
    assert simulate(m, inputs, vll={"S": "active"}).assembled.any()  # within [24, 34]
    narrow = m.with_joints(tuple(replace(j, limits=(26.0, 30.0)) if j.id == "S" else j for j in m.joints))
    free = narrow.with_joint_points({"K": np.asarray(m.joint("K").point, float) + 0.01})
    free = free.with_joints(tuple(replace(j, limits=None) if j.id == "S" else j for j in free.joints))
    assert topology_key(narrow, {"S": "active"}) == topology_key(m, {"S": "active"}) == \
        topology_key(free, {"S": "active"})
    with pytest.raises(MechsynInputError, match=r"limits \[26, 30\]"):
        simulate(narrow, inputs, vll={"S": "active"})
    sim = simulate(free, {"E": np.zeros(2), "S": np.array([25.0, 35.0])}, vll={"S": "active"})
    assert not any(e.kind == "limit" for e in sim.events)  # no limits: none checked, none reported
    with pytest.raises(MechsynInputError, match=r"limits \[24, 34\]"):
        simulate(m, {"E": np.zeros(2), "S": np.array([25.0, 35.0])}, vll={"S": "active"})
