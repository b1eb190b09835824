"""The per-call bookkeeping around the regular pass (issue 30, part F): result objects built
on first access, constraint copies without ``dataclasses.replace``, with the answers of
the eager code."""

from __future__ import annotations

import copy
import pickle
from dataclasses import fields

import numpy as np

import mechsyn as ms
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.kinematics.simulation import LazyPointMotion, PointMotion
from mechsyn.kinematics.system import build_system


def _eager_points(sim: ms.Simulation, names: list[str]) -> dict:
    """Each named point's arrays from the poses, point by point
    (:meth:`PlanarSystem.point_state`), NaN where not assembled or rates not defined."""
    S, sw = sim.system, sim.sweep
    out = {}
    rates_ok = np.isfinite(sw.qd).all(axis=1) & np.isfinite(sw.qdd).all(axis=1)
    for name in names:
        pm = sim.points[name]
        i = S.index(pm.link)
        m = S.mech
        at = np.asarray(m.points[name].at if name in m.points else m.joint(name).point, float)
        P, V, A = S.point_state(sw.q, sw.qd, sw.qdd, i, S.to_local(pm.link, at))
        P[~sim.assembled] = np.nan
        V[~rates_ok] = np.nan
        A[~rates_ok] = np.nan
        out[name] = (P, V, A)
    return out


def test_points_lazy_and_equal_to_point_state():
    m = ms.examples.load("crank_rocker")
    sim = ms.simulate(m, {"A": np.linspace(0.0, 360.0, 73)}, points=["B", "C", "M"])
    assert sim.engine == "regular pass" and sim.sweep.links is not None
    pms = [sim.points[n] for n in ("B", "C", "M")]
    assert all(isinstance(p, LazyPointMotion) for p in pms)
    assert all(p._pva is None for p in pms)  # nothing computed before it is read
    want = _eager_points(sim, ["B", "C", "M"])
    for name, p in zip(("B", "C", "M"), pms):
        for got, ref in zip((p.position, p.velocity, p.acceleration), want[name]):
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12 * sim.system.scale)
    assert all(p._pva is not None for p in pms)  # one batch for all of them


def test_lazy_point_pickles_copies_and_sets_as_a_plain_one():
    m = ms.examples.load("crank_rocker")
    sim = ms.simulate(m, {"A": np.linspace(0.0, 90.0, 7)}, points=["M"])
    p = sim.points["M"]
    for back in (pickle.loads(pickle.dumps(p)), copy.deepcopy(p)):
        assert type(back) is PointMotion and back.link == p.link
        assert np.array_equal(back.position, p.position) and np.array_equal(back.acceleration, p.acceleration)
    p.velocity = np.zeros((7, 2))
    assert not p.velocity.any() and p.position.shape == (7, 2)
    assert "PointMotion(position=array" in repr(p)
    assert sim.to_dict()["points"]["M"]["position"][0] == p.position[0].tolist()


def test_folded_sweep_points_nan_where_not_assembled():
    m = ms.examples.load("fourbar")
    sim = ms.simulate(m, {"A": np.arange(100.0, 261.0, 4.0)})
    assert not sim.assembled.all() and sim.sweep.links is None
    for name, p in sim.points.items():
        assert np.isnan(p.position[~sim.assembled]).all()
        assert np.isfinite(p.position[sim.assembled]).all()


def test_link_angles_in_degrees_of_the_poses():
    m = ms.examples.load("crank_rocker")
    sim = ms.simulate(m, {"A": np.linspace(0.0, 360.0, 37)})
    S, q = sim.system, sim.sweep.q
    for i, name in enumerate(S.links):
        assert np.array_equal(sim.link(name).angle, np.degrees(q[:, 3 * i + 2]))


def test_refilled_constraints_equal_replace():
    m = ms.examples.load("crank_rocker")
    kp = cached_plan(m, inputs=("A",))
    moved = m.with_joint_points({"D": (float(m.joint("D").point[0]) + 0.01, float(m.joint("D").point[1]))})
    S = kp.refilled(moved).system
    ref = build_system(moved)
    assert [d.assembled for d in S.drivers] == [d.assembled for d in ref.drivers]
    assert len(S.cons) == len(ref.cons)
    for a, b in zip(S.cons, ref.cons):
        for f in fields(a):
            x, y = getattr(a, f.name), getattr(b, f.name)
            assert (np.array_equal(x, y) if isinstance(x, np.ndarray) else x == y), f.name


def _shifted_start_loop(S, u0, u_first):
    """The per-driver loop :func:`tracking._shifted_start` replaced (the reference)."""
    import math

    out = np.array(u_first, float)
    for k, d in enumerate(S.drivers):
        if d.type == "R":
            out[k] -= 2 * math.pi * round((float(u_first[k]) - float(u0[k])) / (2 * math.pi))
    return out


def test_shifted_start_and_path_bitwise_equal_to_the_loop():
    from mechsyn.kinematics import tracking

    S = build_system(ms.examples.load("crank_rocker"))
    rng = np.random.default_rng(30)
    u0 = np.array([S.drivers[0].assembled])
    for u in rng.uniform(-40.0, 40.0, 500).tolist() + [np.pi, -np.pi, 3 * np.pi, 0.0]:
        first = np.array([u])
        got, want = tracking._shifted_start(S, u0, first), _shifted_start_loop(S, u0, first)
        assert got.tobytes() == want.tobytes()
        path, shift = tracking.tracking_path(S, first, u0)
        n = max(1, int(np.ceil(abs(first[0] - shift[0] - u0[0]) / np.radians(1.0))))
        assert path.shape == (n, 1) and path[0, 0] == u0[0]


def test_points_to_frames_floats_and_arrays_bitwise_equal():
    from mechsyn.kinematics import frames

    S = build_system(ms.examples.load("jansen_leg"))
    rng = np.random.default_rng(5)
    idx = rng.integers(-1, len(S.links), 200)
    pts = rng.normal(scale=S.scale, size=(200, 2))
    pts[:5] = [[-0.0, -1.0], [0.0, -0.0], [np.nan, 1.0], [1e300, -1e-300], [-0.0, 0.0]]
    many = frames.points_to_frames(S.frames(), idx, pts)  # over FEW: the array path
    assert len(idx) > frames.FEW
    few = np.concatenate([frames.points_to_frames(S.frames(), idx[k:k + 10], pts[k:k + 10]) for k in range(0, 200, 10)])
    assert few.tobytes() == many.tobytes()  # NaN, signed zeros and all
    for i, p, x in zip(idx[5:40], pts[5:40], few[5:40]):
        assert np.array_equal(x, S.to_local(S.mech.ground if i < 0 else S.links[i], p))


def test_link_angles_filled_on_first_read_equal_the_eager_pass():
    import pickle

    from mechsyn.kinematics.engines import drawn_row
    from mechsyn.kinematics.regular import regular_sweep
    from mechsyn.kinematics.sweep import LazyAnglesSweep, Sweep

    for name in ("crank_rocker", "jansen_leg"):
        m = ms.examples.load(name)
        drive = m.actuated_joints[0].id
        x = np.linspace(-170.0, 190.0, 91)  # the drawn input inside the sweep: outwards from it
        sim = ms.simulate(m, {drive: x})
        sw = sim.sweep
        assert isinstance(sw, LazyAnglesSweep) and sw._fill is not None  # nothing read yet
        kp = cached_plan(m, inputs=(drive,))
        q, *_ = regular_sweep(kp.system, kp.groups, sw.inputs, np.ones(1), drawn_row(kp.system, sw.inputs))
        for i, link in enumerate(kp.system.links):
            assert np.array_equal(sim.link(link).angle, np.degrees(q[:, 3 * i + 2]))
        assert sw._fill is None and np.array_equal(sw.q, q)
        back = pickle.loads(pickle.dumps(sw))
        assert type(back) is Sweep and np.array_equal(back.q, q) and back.engine == sw.engine
