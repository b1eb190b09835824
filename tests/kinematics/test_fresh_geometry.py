"""A fresh geometry of a known topology (issue 30, the fixed cost before the sweep): the
system refilled on floats, the regular program's numbers, the drawn-configuration
checks from the topology's shared part, each the same numbers and verdicts as a system
built anew for that geometry, bit for bit where the arithmetic is the same."""

from __future__ import annotations

import zlib
from dataclasses import replace

import numpy as np
import pytest

from kinematics_helpers import driven_planar_examples, fourbar
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import refill, regular
from mechsyn.kinematics.analysis import compile_plan, simulate
from mechsyn.kinematics.solve import assemble, drawn_checks, singular_configuration
from mechsyn.kinematics.system import Con, PlanarSystem, build_system, frame_points
from mechsyn.model.mechanism import Mechanism, fields_replaced


def _size(m: Mechanism) -> float:
    return float(np.ptp(np.array([j.point for j in m.joints], float), axis=0).max())


def _moved(m: Mechanism, rng: np.random.Generator, frac: float = 0.02) -> Mechanism:
    size = _size(m)
    return m.with_joint_points({j.id: j.point + rng.uniform(-frac, frac, 2) * size for j in m.joints})


def _built(m: Mechanism) -> PlanarSystem | None:
    try:
        return build_system(m)
    except MechsynInputError:
        return None


EXAMPLES = [(n, m) for n, m in driven_planar_examples() if _built(m) is not None]


def _same_array(x, y) -> None:
    assert (x is None) == (y is None)
    if x is not None:
        assert np.asarray(x).tolist() == np.asarray(y).tolist()  # bit for bit (and no NaN here)


@pytest.mark.parametrize("name,mech", EXAMPLES, ids=[n for n, _ in EXAMPLES])
def test_refilled_system_is_bitwise_the_built_one(name, mech):
    """Every number a refilled system holds (frames, drawn pose, scales, constraint
    blocks, drivers' drawn values) equals build_system's to the last bit."""
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    T = build_system(mech)
    for _ in range(2):
        moved = _moved(mech, rng)
        S = refill.with_geometry(T, moved)
        if S is None:  # cams, gears, belts: built anew
            assert any(c.kind not in ("R", "angle", "line") for c in T.cons)
            return
        ref = build_system(moved)
        assert S.mech is moved and S.scale == ref.scale
        assert (S.n, S.m, S.links, S.notes, S.vll) == (ref.n, ref.m, ref.links, ref.notes, ref.vll)
        for x, y in ((S.q0, ref.q0), (S.origin0, ref.origin0), (S.angle0, ref.angle0),
                     (S.row_scale, ref.row_scale), (S.col_scale, ref.col_scale)):
            _same_array(x, y)
        assert S.frames() == ref.frames()
        assert S.drivers == ref.drivers
        assert len(S.cons) == len(ref.cons)
        for c, r in zip(S.cons, ref.cons):
            assert (c.kind, c.joint, c.rows, c.a, c.b, c.driver, c.role, c.c0) == \
                (r.kind, r.joint, r.rows, r.a, r.b, r.driver, r.role, r.c0)
            for x, y in ((c.sa, r.sa), (c.sb, r.sb), (c.w, r.w)):
                _same_array(x, y)
        assert refill.joint_points(S)[:len(moved.joints)] == refill.joint_points(ref)


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
        assert regular._program(new.system, new.groups) == regular._program(ref, new.groups), name
    assert compared >= 4


def _folded(m: Mechanism) -> Mechanism:
    B, D = m.joint("B").point, m.joint("D").point
    return m.with_joint_points({"C": D + 0.4 * (D - B) / np.linalg.norm(D - B)})


def test_drawn_checks_fire_on_each_fresh_geometry_of_one_topology(monkeypatch):
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
        assert new.groups is kp.groups and new.system.cache["programs"] is kp.system.cache["programs"], label
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
