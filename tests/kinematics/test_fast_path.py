"""The fresh-geometry fast path (issue 30): a mechanism of a known topology with moved
joints is simulated from the compiled template of that topology (the constraint system
refilled, the decomposition kept, the drawn-configuration checks from the groups), with
the answers, events, notes and refusals of the general path."""

from __future__ import annotations

import zlib
from dataclasses import replace

import numpy as np
import pytest

from kinematics_helpers import driven_planar_examples, fourbar
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import analysis
from mechsyn.kinematics import refill
from mechsyn.kinematics.analysis import compile_plan, simulate
from mechsyn.kinematics.solve import drawn_checks, singular_configuration
from mechsyn.kinematics.refill import topology_key
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism, PointSpec

SINGULAR_NOTE = "the file's configuration is singular"


def _inputs(m: Mechanism) -> dict[str, np.ndarray]:
    """Every driver swept about its drawn value (R: a full turn, P: +-20 % of the size)."""
    S = build_system(m)
    out = {}
    for d in S.drivers:
        if d.type == "R":
            out[d.joint] = np.degrees(d.assembled) + np.linspace(-180.0, 180.0, 73)
        else:
            out[d.joint] = d.assembled + S.scale * np.linspace(-0.2, 0.2, 73)
    return out


def _moved(m: Mechanism, rng: np.random.Generator, frac: float = 0.02) -> Mechanism:
    """Every joint moved by up to ``frac`` of the size (each link's dimensions come from
    its drawn joints, so the result is a consistent mechanism)."""
    pts = np.array([j.point for j in m.joints], float)
    size = float(np.ptp(pts, axis=0).max())
    return m.with_joint_points({j.id: j.point + rng.uniform(-frac, frac, 2) * size for j in m.joints})


def _run(m: Mechanism, inputs: dict) -> tuple:
    try:
        return "ok", simulate(m, inputs)
    except MechsynInputError as e:
        return "error", str(e)


def _slow(m: Mechanism, inputs: dict, monkeypatch: pytest.MonkeyPatch) -> tuple:
    """The general path: no template, the rank machinery for the drawn checks."""
    with monkeypatch.context() as mp:
        mp.setattr(analysis, "_TOPOLOGIES", type(analysis._TOPOLOGIES)())
        mp.setattr(analysis, "drawn_checks", lambda S, plan: False)
        return _run(m, inputs)


def _fast(template: Mechanism, m: Mechanism, inputs: dict, monkeypatch: pytest.MonkeyPatch) -> tuple:
    """``m`` simulated from the template compiled for ``template`` (same topology)."""
    with monkeypatch.context() as mp:
        mp.setattr(analysis, "_TOPOLOGIES", type(analysis._TOPOLOGIES)())
        try:
            compile_plan(template, inputs=tuple(inputs))
        except MechsynInputError:
            pass
        return _run(m, inputs)


def _same(a: tuple, b: tuple, scale: float) -> None:
    assert a[0] == b[0], (a[1] if a[0] == "error" else "", b[1] if b[0] == "error" else "")
    if a[0] == "error":
        assert a[1] == b[1]
        return
    sa, sb = a[1], b[1]
    assert (sa.method, sa.engine) == (sb.method, sb.engine)
    assert np.array_equal(sa.assembled, sb.assembled)
    assert sa.notes == sb.notes
    assert [(e.index, e.kind, e.message) for e in sa.events] == [(e.index, e.kind, e.message) for e in sb.events]
    tol = dict(rtol=1e-9, atol=1e-9 * scale, equal_nan=True)
    for name, pa in sa.points.items():
        pb = sb.points[name]
        for x, y in ((pa.position, pb.position), (pa.velocity, pb.velocity), (pa.acceleration, pb.acceleration)):
            np.testing.assert_allclose(x, y, **tol)
    for name, la in sa.links.items():
        lb = sb.links[name]
        np.testing.assert_allclose(la.angle, lb.angle, rtol=1e-9, atol=1e-9, equal_nan=True)
        np.testing.assert_allclose(la.angular_velocity, lb.angular_velocity, rtol=1e-9, atol=1e-9, equal_nan=True)


def _builds(m: Mechanism) -> bool:
    try:
        build_system(m)
    except MechsynInputError:  # no joint points (a structural example)
        return False
    return True


EXAMPLES = [(n, m) for n, m in driven_planar_examples() if _builds(m)]


@pytest.mark.parametrize("name,mech", EXAMPLES, ids=[n for n, _ in EXAMPLES])
def test_fast_path_equals_general_path_on_moved_joints(name, mech, monkeypatch):
    rng = np.random.default_rng(zlib.crc32(name.encode()))  # not hash(): salted per process
    inputs = _inputs(mech)
    scale = float(np.ptp(np.array([j.point for j in mech.joints]), axis=0).max())
    for _ in range(2):
        moved = _moved(mech, rng)
        _same(_fast(mech, moved, inputs, monkeypatch), _slow(moved, inputs, monkeypatch), scale)


def test_moved_geometry_takes_the_fast_path(monkeypatch):
    """No constraint system built, no rank test: the template is refilled (fails on a code
    without a topology cache)."""
    m = fourbar()
    kp = compile_plan(m, inputs=("A",))

    def refused(*a, **k):
        raise AssertionError("the general path was taken")

    monkeypatch.setattr(analysis, "build_system", refused)
    monkeypatch.setattr(analysis, "decompose", refused)
    monkeypatch.setattr(analysis, "assemble", refused)
    moved = m.with_joint_points({"C": m.joint("C").point + [0.05, -0.02]})
    sim = simulate(moved, {"A": np.linspace(0, 360, 37)})
    assert sim.assembled.all()
    assert kp.with_joint_points({"C": moved.joint("C").point}).system.q0.tolist() == \
        compile_plan(moved, inputs=("A",)).system.q0.tolist()


def test_refilled_system_equals_a_built_one():
    rng = np.random.default_rng(3)
    for _name, m in EXAMPLES:
        try:
            T = build_system(m)
        except MechsynInputError:
            continue
        moved = _moved(m, rng)
        S = refill.with_geometry(T, moved)
        if S is None:  # cams, gears, belts: built anew
            assert any(c.kind not in ("R", "angle", "line") for c in T.cons)
            continue
        ref = build_system(moved)
        assert (S.n, S.m, S.links, S.notes, S.vll) == (ref.n, ref.m, ref.links, ref.notes, ref.vll)
        np.testing.assert_allclose(S.q0, ref.q0, rtol=1e-14, atol=1e-14 * ref.scale)
        np.testing.assert_array_equal(S.row_scale, ref.row_scale)
        assert [(d.joint, d.type, d.role) for d in S.drivers] == [(d.joint, d.type, d.role) for d in ref.drivers]
        np.testing.assert_allclose([d.assembled for d in S.drivers], [d.assembled for d in ref.drivers],
                                   rtol=1e-14, atol=1e-14 * ref.scale)
        for c, r in zip(S.cons, ref.cons):
            assert (c.kind, c.joint, c.a, c.b, c.driver, c.role) == (r.kind, r.joint, r.a, r.b, r.driver, r.role)
            for x, y in ((c.sa, r.sa), (c.sb, r.sb), (c.w, r.w)):
                assert (x is None) == (y is None)
                if x is not None:
                    np.testing.assert_allclose(x, y, rtol=1e-14, atol=1e-14 * ref.scale)
            assert c.c0 == pytest.approx(r.c0, rel=1e-14, abs=1e-14 * ref.scale)


def _folded(m: Mechanism) -> Mechanism:
    """The four-bar with its coupler-rocker joint C moved onto the line B-D beyond D (the
    coupler and rocker stretched out: a dead centre of the rocker)."""
    B, D = m.joint("B").point, m.joint("D").point
    return m.with_joint_points({"C": D + 0.4 * (D - B) / np.linalg.norm(D - B)})


@pytest.mark.parametrize("case", ["folded", "coincident", "coupler on the rocker pivot"])
def test_singular_or_degenerate_moved_geometry_reported_as_on_the_general_path(case, monkeypatch):
    m = fourbar()
    if case == "folded":
        moved = _folded(m)
    elif case == "coincident":  # coupler of zero length
        moved = m.with_joint_points({"C": m.joint("B").point})
    else:
        moved = m.with_joint_points({"C": m.joint("D").point})
    inputs = {"A": np.linspace(0.0, 360.0, 73)}
    fast, slow = _fast(m, moved, inputs, monkeypatch), _slow(moved, inputs, monkeypatch)
    _same(fast, slow, 4.0)
    if case == "folded":
        assert any(SINGULAR_NOTE in n for n in fast[1].notes)


def test_drawn_checks_agree_with_the_rank_test():
    """Where the group test settles the drawn checks, its verdict is the rank test's."""
    rng = np.random.default_rng(7)
    settled = 0
    for name, m in EXAMPLES + [("folded", _folded(fourbar()))]:
        for mech in (m, _moved(m, rng)):
            try:
                kp = compile_plan(mech, inputs=tuple(_inputs(mech)))
            except MechsynInputError:
                continue
            if not drawn_checks(kp.system, kp.groups):
                continue
            settled += 1
            fresh = build_system(mech, vll=kp.vll, prescribed=kp.prescribed)
            assert kp.system.cache["singular_drawn"] == singular_configuration(fresh), name
    assert settled >= 10


def _scaled(m: Mechanism, k: float) -> Mechanism:
    pts = {j.id: j.point * k for j in m.joints}
    out = m.with_joint_points(pts)
    return replace(out, points={n: PointSpec(p.link, p.at * k) for n, p in m.points.items()})


@pytest.mark.parametrize("k", [1e-3, 1e4])
def test_fast_path_is_scale_invariant(k, monkeypatch):
    rng = np.random.default_rng(11)
    for m in (fourbar(), _folded(fourbar())):
        moved = _moved(m, rng, 0.01) if m.joint("C").point[1] != 0 else m
        inputs = {"A": np.linspace(0.0, 360.0, 73)}
        one = _fast(m, moved, inputs, monkeypatch)[1]
        big = _fast(_scaled(m, k), _scaled(moved, k), inputs, monkeypatch)[1]
        assert one.notes == big.notes
        assert [(e.index, e.kind) for e in one.events] == [(e.index, e.kind) for e in big.events]
        assert np.array_equal(one.assembled, big.assembled)
        for name in one.points:
            np.testing.assert_allclose(big.point(name), one.point(name) * k, rtol=1e-9, atol=1e-9 * k,
                                       equal_nan=True)


def test_a_topology_change_never_reuses_a_plan():
    m = fourbar()
    compile_plan(m, inputs=("A",))
    # another pair type: C becomes a slider (P) along the rocker
    C, D = m.joint("C").point, m.joint("D").point
    slider = m.with_joints(tuple(replace(j, type="P", axis=(D - C) / np.linalg.norm(D - C)) if j.id == "C" else j
                                 for j in m.joints))
    # another link: the rocker's pivot D on a new link pinned to the frame at E (and driven)
    links = m.links + (replace(m.links[-1], name="arm"),)
    E = D + [0.5, 0.0]
    joints = tuple(replace(j, links=("rocker", "arm")) if j.id == "D" else j for j in m.joints)
    joints += (replace(m.joint("A"), id="E", links=("frame", "arm"), point=E, actuated=True),)
    other = replace(m, links=links, joints=joints)
    for mech in (slider, other):
        assert topology_key(mech) != topology_key(m)
        kp = compile_plan(mech, inputs=tuple(j.id for j in mech.joints if j.actuated))
        ref = build_system(mech)
        assert [(c.kind, c.joint, c.a, c.b, c.role) for c in kp.system.cons] == \
            [(c.kind, c.joint, c.a, c.b, c.role) for c in ref.cons]
        assert kp.system.mech is mech


def test_with_joint_points_checks_its_numbers():
    m = fourbar()
    with pytest.raises(MechsynInputError, match="no joint 'Z'"):
        m.with_joint_points({"Z": (0, 0)})
    with pytest.raises(MechsynInputError, match="finite") as e:
        m.with_joint_points({"C": (np.nan, 1.0)})
    assert e.value.field == "joints.C.point"
    with pytest.raises(MechsynInputError, match="2 finite numbers"):
        m.with_joint_points({"C": (1.0, 2.0, 3.0)})
    moved = m.with_joint_points({"C": [3.0, 2.5]})
    assert moved.joint("C").point.tolist() == [3.0, 2.5] and m.joint("C").point.tolist() != [3.0, 2.5]
    assert topology_key(moved) == topology_key(m)


# ------------------------------------------------------------------ the studio's drag
def _drag_request(name: str = "watt_sixbar") -> dict:
    import json

    from mechsyn.io import load_mechanism, mechanism_to_dict
    from mechsyn.web._service import example_path

    return json.loads(json.dumps(mechanism_to_dict(load_mechanism(example_path(name)))))


def _with_point(data: dict, jid: str, dx: float) -> dict:
    import copy

    out = copy.deepcopy(data)
    j = next(j for j in out["joints"] if j["id"] == jid)
    j["point"] = [j["point"][0] + dx, j["point"][1]]
    return out


def test_drag_request_skips_parsing_and_answers_as_the_worker(monkeypatch):
    from mechsyn.web import _service

    data = _drag_request()
    first = _service.quick_simulate(data, 90, None, False)
    assert first == _service.simulate(data, 90, None, False)
    calls = []
    real = _service.build
    monkeypatch.setattr(_service, "build", lambda d: calls.append(1) or real(d))
    for k in range(1, 4):
        moved = _with_point(data, "E", 0.01 * k)
        got = _service.quick_simulate(moved, 90, None, k % 2 == 0)
        assert got == _service.simulate(moved, 90, None, k % 2 == 0)
    assert len(calls) == 3  # the three reference simulate() calls: the quick path parsed nothing


@pytest.mark.parametrize("case", ["boolean", "null", "zero-length link", "steps", "topology"])
def test_drag_request_refusals_go_to_the_worker(case):
    from mechsyn.web import _service

    data = _drag_request("fourbar")
    assert _service.quick_simulate(data, 36) is not None  # the topology is known
    bad, steps = _with_point(data, "C", 0.0), 36
    joint = next(j for j in bad["joints"] if j["id"] == "C")
    if case == "boolean":
        joint["point"] = [True, 1.0]
    elif case == "null":
        joint["point"] = None
    elif case == "zero-length link":  # the coupler's joints B and C at one point
        joint["point"] = next(j for j in bad["joints"] if j["id"] == "B")["point"]
    elif case == "steps":
        steps = 10 ** 6
    else:  # another pair type: parsed anew, answered in-process when it has a plan
        joint["type"] = "P"
        joint["axis"] = [1.0, 0.0]
    got = _service.quick_simulate(bad, steps)
    if case == "topology":
        assert got is None or got == _service.simulate(bad, steps)
        return
    assert got is None
    with pytest.raises(MechsynInputError):
        _service.simulate(bad, steps)
