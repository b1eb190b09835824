"""The fresh-geometry fast path (issue 30): a mechanism of a known topology with moved
joints is simulated from the compiled template of that topology (the constraint system
refilled, the decomposition kept, the drawn-configuration checks from the groups), with
the answers, events, notes and refusals of the general path."""

from __future__ import annotations

import dataclasses
import zlib
from dataclasses import fields, replace

import numpy as np
import pytest

from kinematics_helpers import driven_planar_examples, fourbar
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import analysis
from mechsyn.kinematics import kernel, refill
from mechsyn.kinematics.analysis import compile_plan, simulate
from mechsyn.kinematics.solve import assemble, drawn_checks, singular_configuration
from mechsyn.kinematics.topology import CACHE, LRUCache, topology_key, topology_of
from mechsyn.kinematics.system import Con, build_system, frame_points
from mechsyn.model.mechanism import Mechanism, PointSpec, fields_replaced

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
        mp.setattr(analysis, "CACHE", LRUCache(CACHE.maxsize))
        mp.setattr(analysis, "drawn_checks", lambda S, plan: False)
        return _run(m, inputs)


def _fast(template: Mechanism, m: Mechanism, inputs: dict, monkeypatch: pytest.MonkeyPatch) -> tuple:
    """``m`` simulated from the template compiled for ``template`` (same topology)."""
    with monkeypatch.context() as mp:
        mp.setattr(analysis, "CACHE", LRUCache(CACHE.maxsize))
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


def _same_numbers(x, y) -> None:
    assert (x is None) == (y is None)
    if x is not None:
        assert np.asarray(x).tolist() == np.asarray(y).tolist()  # bit for bit


def test_refilled_system_equals_a_built_one():
    """Every number a refilled system holds (frames, drawn pose, scales, constraint
    blocks, drivers' drawn values, the points it keeps) is build_system's to the last
    bit: the fill on floats does the same products, sums and arctan2."""
    rng = np.random.default_rng(3)
    for _name, m in EXAMPLES:
        try:
            T = build_system(m)
        except MechsynInputError:
            continue
        for _ in range(2):
            moved = _moved(m, rng)
            S = refill.with_geometry(T, moved)
            if S is None:  # cams, gears, belts: built anew
                assert any(c.kind not in ("R", "angle", "line") for c in T.cons)
                break
            ref = build_system(moved)
            assert S.mech is moved and S.scale == ref.scale
            assert (S.n, S.m, S.links, S.notes, S.vll) == (ref.n, ref.m, ref.links, ref.notes, ref.vll)
            for x, y in ((S.q0, ref.q0), (S.origin0, ref.origin0), (S.angle0, ref.angle0),
                         (S.row_scale, ref.row_scale), (S.col_scale, ref.col_scale)):
                _same_numbers(x, y)
            assert S.frames() == ref.frames() and S.drivers == ref.drivers and len(S.cons) == len(ref.cons)
            for c, r in zip(S.cons, ref.cons):
                assert (c.kind, c.joint, c.rows, c.a, c.b, c.driver, c.role, c.c0) == \
                    (r.kind, r.joint, r.rows, r.a, r.b, r.driver, r.role, r.c0)
                for x, y in ((c.sa, r.sa), (c.sb, r.sb), (c.w, r.w)):
                    _same_numbers(x, y)
            assert refill.joint_points(S)[:len(moved.joints)] == refill.joint_points(ref)


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


# ------------------------------------------------------------------ the fill on floats
def test_frame_points_are_to_local_bit_for_bit():
    S = build_system(fourbar())
    rng = np.random.default_rng(5)
    idx = rng.integers(-1, len(S.links), 50)
    pts = rng.normal(size=(50, 2)) * 3.0
    got = frame_points(S.frames(), idx.tolist(), pts.tolist())
    names = [S.mech.ground if i < 0 else S.links[i] for i in idx.tolist()]
    assert [list(p) for p in got] == [S.to_local(n, p).tolist() for n, p in zip(names, pts)]
    assert S.to_locals(idx, pts).tolist() == [list(p) for p in got]


def test_regular_program_of_a_refilled_system_is_the_built_ones():
    """The program's numbers filled from the topology's shape on floats are those of the
    program of a system built for the moved geometry (which builds its own shape)."""
    rng = np.random.default_rng(9)
    compared = 0
    for name, m in EXAMPLES:
        kp = compile_plan(m, inputs=tuple(j.id for j in m.joints if j.actuated))
        if kp.groups is None or not kp.groups.closed_form_rates:  # not a driver-R + RRR chain
            continue
        new = kp.refilled(_moved(m, rng, 0.005))
        if new.groups is None:  # a double joint pulled apart: no longer that chain
            continue
        compared += 1
        moved = new.mechanism
        ref = build_system(moved)
        got, want = kernel.program(new.system, new.groups), kernel.program(ref, new.groups)
        assert np.array_equal(got[1], want[1]) and np.array_equal(got[2], want[2]), name
    assert compared >= 4


def test_drawn_checks_fire_on_each_fresh_geometry_of_one_topology():
    """The checks' topology part is shared by the systems of one topology; each fresh
    geometry still gets its own verdict: settled regular, settled singular (the folded
    four-bar), or left to the general test (a zero-length coupler, a near fold) whose
    refusal or note is that of a system built anew."""
    m = fourbar()
    kp = compile_plan(m, inputs=("A",))
    B, C, D = (m.joint(j).point for j in "BCD")
    near = _folded(m).joint("C").point + 1e-7 * np.array([0.0, 1.0])
    cases = [("regular", m.with_joint_points({"C": C + [0.03, -0.01]}), True, False),
             ("folded", _folded(m), True, True),
             ("zero-length coupler", m.with_joint_points({"C": B}), False, None),
             ("near the fold", m.with_joint_points({"C": near}), False, None),
             ("regular again", m.with_joint_points({"C": C + [-0.02, 0.01]}), True, False)]
    for label, moved, settled, singular in cases:
        new = kp.refilled(moved)
        assert new.groups is kp.groups and new.topology is kp.topology, label
        assert drawn_checks(new.system, new.groups) is settled, label
        fresh = build_system(moved)
        if settled:
            assert new.system.cache["singular_drawn"] is singular is singular_configuration(fresh), label
            continue
        try:  # the general test decides as for a system built anew
            want = ("ok", assemble(fresh).tolist(), singular_configuration(fresh))
        except MechsynInputError as e:
            want = ("error", str(e), None)
        try:
            got = ("ok", assemble(new.system).tolist(), singular_configuration(new.system))
        except MechsynInputError as e:
            got = ("error", str(e), None)
        assert got[0] == want[0] and got[2] == want[2], label
        if got[0] == "error":
            assert got[1] == want[1], label
        else:
            np.testing.assert_allclose(got[1], want[1], rtol=0, atol=1e-12 * 4.0)


def test_a_plan_the_checks_do_not_cover_goes_to_the_general_test():
    """A mechanism with a P pair: the group test does not apply on any geometry."""
    name, m = next((n, mm) for n, mm in EXAMPLES if any(j.type == "P" for j in mm.joints) and
                   compile_plan(mm, inputs=tuple(j.id for j in mm.joints if j.actuated)).groups is not None)
    kp = compile_plan(m, inputs=tuple(j.id for j in m.joints if j.actuated))
    new = kp.refilled(_moved(m, np.random.default_rng(2), 0.005))
    assert not drawn_checks(kp.system, kp.groups) and not drawn_checks(new.system, new.groups), name


def test_a_point_that_is_not_finite_is_refused_not_refilled():
    """A mechanism whose point is NaN (not through with_joint_points, which refuses it)
    is not refilled: the general path refuses it with its one line."""
    m = fourbar()
    T = build_system(m)
    bad = m.with_joints(tuple(replace(j, point=np.array([np.nan, 1.0])) if j.id == "C" else j for j in m.joints))
    assert refill.with_geometry(T, bad) is None
    compile_plan(m, inputs=("A",))
    with pytest.raises(MechsynInputError, match="do not assemble"):
        simulate(bad, {"A": np.linspace(0.0, 360.0, 5)})


def test_a_refilled_r_pair_reads_as_a_built_one():
    """A refilled R pair's local points (made arrays when first read) read, copy, pickle
    and replace as build_system's constraint does."""
    import copy
    import pickle

    m = fourbar()
    moved = m.with_joint_points({"C": m.joint("C").point + [0.02, -0.01]})
    S, ref = refill.with_geometry(build_system(m), moved), build_system(moved)
    for c, r in zip(S.cons, ref.cons):
        if c.kind != "R":
            continue
        for other in (copy.deepcopy(c), pickle.loads(pickle.dumps(c)), c, replace(c, c0=0.0)):
            assert other.sa.tolist() == r.sa.tolist() and other.sb.tolist() == r.sb.tolist()
        swapped = replace(c, sa=r.sb)
        assert swapped.sa.tolist() == r.sb.tolist() and swapped.sb.tolist() == r.sb.tolist()


def test_a_refilled_system_reads_as_a_built_one_before_and_after_its_lazy_fields():
    """The fields a refilled system makes when first read (its constraint blocks, its
    link origins) read, copy, pickle and replace as build_system's, whether or not they
    were read before; a system refilled from a refilled one too."""
    import copy
    import pickle

    m = fourbar()
    moved = m.with_joint_points({"C": m.joint("C").point + [0.02, -0.01]})
    ref = build_system(moved)

    def same(S) -> None:
        _same_numbers(S.origin0, ref.origin0)
        assert [(c.kind, c.joint, c.a, c.b, c.sa.tolist() if c.sa is not None else None,
                 c.sb.tolist() if c.sb is not None else None) for c in S.cons] == \
            [(c.kind, c.joint, c.a, c.b, c.sa.tolist() if c.sa is not None else None,
              c.sb.tolist() if c.sb is not None else None) for c in ref.cons]
        _same_numbers(S.row_scale, ref.row_scale)
        _same_numbers(S.col_scale, ref.col_scale)

    for read_first in (False, True):
        S = refill.with_geometry(build_system(m), moved)
        assert "cons" not in S.__dict__  # not made until read
        if read_first:
            same(S)
        for other in (copy.deepcopy(S), pickle.loads(pickle.dumps(S)), copy.copy(S), replace(S, notes=("x",)), S,
                      fields_replaced(S, scale=S.scale)):
            same(other)
    again = refill.with_geometry(refill.with_geometry(build_system(m), m), moved)  # from a refilled template
    same(again)
    given = fields_replaced(refill.with_geometry(build_system(m), moved), cons=ref.cons)
    assert given.origin0.tolist() == ref.origin0.tolist() and given.cons is ref.cons  # a given field stays
    assert not hasattr(S, "no_such_field")


@pytest.mark.parametrize("name", ["fourbar", "watt_sixbar", "crank_rocker"])
def test_a_drag_builds_no_constraint_block(name):
    """The regular pass of a fresh geometry (through its dead points, events and all)
    reads no constraint block of the refilled system: they are made only when read
    (fails on a code that fills every R pair's block on each drag step)."""
    import mechsyn as ms

    m = ms.examples.load(name)
    inputs = {"A": np.linspace(0, 360, 73)}
    simulate(m, inputs)  # the topology's template, its programs' shapes built
    B = m.joint("B").point
    sim = simulate(m.with_joint_points({"B": B + 0.01 * (B - m.joint("A").point)}), inputs)
    assert sim.engine == "regular pass" and isinstance(sim.system, refill._Refilled)
    assert not {"cons", "origin0"} & set(sim.system.__dict__)
    assert [c.kind for c in sim.system.cons] == [c.kind for c in build_system(sim.system.mech).cons]


@pytest.mark.parametrize("name, joint", [("crank_rocker", "D"), ("watt_sixbar", "F")])
def test_a_drag_that_changes_the_size_makes_no_scales(name, joint):
    """A joint on the outline moved (the size changes on each drag step): the regular
    pass reads no row or column scale of the refilled system, made only when read, for
    the size it was refilled with, equal to build_system's (fails on a code that makes
    them on each step)."""
    import mechsyn as ms

    m = ms.examples.load(name)
    inputs = {"A": np.linspace(0, 360, 73)}
    simulate(m, inputs)
    P = np.asarray(m.joint(joint).point, float)
    moved = m.with_joint_points({joint: P + 0.01 * (P - m.joint("A").point)})
    sim = simulate(moved, inputs)
    S, ref = sim.system, build_system(moved)
    assert sim.engine == "regular pass" and isinstance(S, refill._Refilled) and S.scale != build_system(m).scale
    assert not {"row_scale", "col_scale", "_row_scale", "_col_scale"} & set(S.__dict__)
    S2 = fields_replaced(S, scale=2 * S.scale)  # (its scales stay those of the size refilled with)
    for s in (S, S2):
        _same_numbers(s.row_scale, ref.row_scale)
        _same_numbers(s.col_scale, ref.col_scale)


def test_topology_is_shared_only_by_mechanisms_of_the_same_topology():
    """Mechanisms with_joint_points makes of one (numbers only) have its Topology (equal,
    the same hash, one entry of the cache); a P pair for an R pair or a renamed link is
    another topology, and the frozen mechanism keeps nothing of it in its fields."""
    m = fourbar()
    T = topology_of(m)
    moved = m.with_joint_points({"C": m.joint("C").point + [0.05, 0.0]})
    assert topology_of(moved) == T and hash(topology_of(moved)) == hash(T) and topology_key(moved) == T.key
    assert set(moved.__dict__) == set(m.__dict__) == {f.name for f in fields(m)}
    slider = fields_replaced(m, joints=tuple(replace(j, type="P", axis=np.array([1.0, 0.0])) if j.id == "C" else j
                                            for j in m.joints))
    renamed = replace(m, links=m.links[:-1] + (replace(m.links[-1], name="arm"),),
                      joints=tuple(replace(j, links=tuple("arm" if x == m.links[-1].name else x for x in j.links))
                                   for j in m.joints))
    for other in (slider, renamed):
        assert topology_of(other) != T and topology_key(other) != T.key


def test_drawn_row_of_each_fresh_geometry_on_one_grid():
    """A drag simulates one grid with a new drawn input each time: the row found for each
    is the one computed from scratch (the rows are kept with the grid's bytes)."""
    from mechsyn.kinematics import engines

    m = fourbar()
    kp = compile_plan(m, inputs=("A",))
    U = np.radians(np.arange(-180.0, 541.0, 2.5))[:, None]
    rng = np.random.default_rng(4)
    engines.CACHE.clear()
    for _ in range(12):
        S = kp.refilled(m.with_joint_points({"B": m.joint("B").point + rng.uniform(-0.3, 0.3, 2)})).system
        want = engines._segment_row(S.drivers, U.copy())
        assert engines.drawn_row(S, U) == want and engines.drawn_row(S, U.copy()) == want
    assert len(engines.CACHE.get(("input grid", U.shape, U.dtype.str))[1]) == 12


def test_fields_replaced_is_dataclasses_replace():
    c = Con("R", "B", 2, 0, 1, sa=np.zeros(2), sb=np.ones(2), role="pair")
    new = fields_replaced(c, sb=np.full(2, 2.0), c0=0.5)
    ref = replace(c, sb=np.full(2, 2.0), c0=0.5)
    assert (new.kind, new.joint, new.rows, new.a, new.b, new.c0, new.role) == \
        (ref.kind, ref.joint, ref.rows, ref.a, ref.b, ref.c0, ref.role)
    assert new.sb.tolist() == [2.0, 2.0] and c.sb.tolist() == [1.0, 1.0] and new.sa is c.sa
    with pytest.raises(TypeError, match="no field 'sc'"):
        fields_replaced(c, sc=np.zeros(2))
    with pytest.raises(AttributeError):
        new.c0 = 1.0  # still frozen

    @dataclasses.dataclass(frozen=True)
    class Checked:
        x: float

        def __post_init__(self) -> None:
            if self.x < 0:
                raise ValueError("x < 0")

    with pytest.raises(TypeError, match="__post_init__"):  # its check would be skipped
        fields_replaced(Checked(1.0), x=-1.0)


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


@pytest.mark.parametrize("case", ["no point", "no axis"])
def test_a_missing_point_or_axis_is_not_refilled_and_reported(case):
    """A mechanism of a known topology with a joint's point (or a P joint's axis) missing
    is not refilled (the template's numbers would be read as NaN): the general path
    reports it with its one line, as it does without a template."""
    from kinematics_helpers import EX
    from mechsyn.io import load_mechanism

    m = fourbar() if case == "no point" else load_mechanism(EX / "textbook/slider_crank.yaml")
    T = build_system(m)
    k = 2 if case == "no point" else next(i for i, j in enumerate(m.joints) if j.type == "P")
    bad = m.with_joints(tuple(replace(j, **({"point": None} if case == "no point" else {"axis": None}))
                              if i == k else j for i, j in enumerate(m.joints)))
    assert refill.with_geometry(T, bad) is None
    drive = next(j.id for j in m.joints if j.actuated)
    compile_plan(m, inputs=(drive,))  # the topology's template
    with pytest.raises(MechsynInputError, match="has no point" if case == "no point" else "has no axis"):
        simulate(bad, {drive: np.linspace(0.0, 1.0, 5)})


def test_input_spec_without_numbers_is_the_topologys():
    """One driver given, no P joint: the inputs' spec holds no number of the geometry and
    is the topology's, one object for every geometry; with a driver not given (a five-bar
    swept on one input), the other keeps each geometry's own drawn value."""
    from kinematics_helpers import EX
    from mechsyn.io import load_mechanism

    m = fourbar()
    a = compile_plan(m, inputs=("A",))
    b = a.with_joint_points({"C": np.asarray(m.joint("C").point, float) + 0.01})
    assert analysis._input_spec(a, ("A",)) is analysis._input_spec(b, ("A",))
    five = load_mechanism(EX / "textbook/five_bar_5r.yaml")
    drives = [j.id for j in five.joints if j.actuated]
    assert len(drives) == 2
    kp = compile_plan(five, inputs=(drives[0],))
    moved = kp.refilled(_moved(five, np.random.default_rng(3), 0.01))
    for plan in (kp, moved):
        spec = analysis._input_spec(plan, (drives[0],))
        assert spec.u0 == tuple(float(d.assembled) for d in plan.system.drivers)
        assert spec.u0 == tuple(float(d.assembled) for d in build_system(plan.mechanism).drivers)


def test_named_points_of_a_refilled_system_are_the_built_ones():
    """The named points' local coordinates of a refilled system (read off its floats)
    are those of a system built for the moved geometry, bit for bit."""
    rng = np.random.default_rng(5)
    compared = 0
    for name, m in EXAMPLES:
        kp = compile_plan(m, inputs=tuple(j.id for j in m.joints if j.actuated))
        new = kp.refilled(_moved(m, rng, 0.005))
        for names in (None, [j.id for j in m.joints]):
            got = analysis._named_points(new.system, new.mechanism, names)
            ref = analysis._named_points(build_system(new.mechanism), new.mechanism, names)
            assert np.array_equal(got[3], ref[3]) and got[1] == ref[1], name
            assert [(r[0], r[1], r[2], None if r[3] is None else r[3].tolist()) for r in got[0]] == \
                [(r[0], r[1], r[2], None if r[3] is None else r[3].tolist()) for r in ref[0]], name
        compared += bool(m.points)
    assert compared >= 3
