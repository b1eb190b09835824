"""The compiled plan and incremental re-simulation (issue 14 §4)."""

from dataclasses import replace

import numpy as np
import pytest

from mechsyn.kinematics.analysis import compile_plan, input_grid, simulate

from kinematics_helpers import ex, point_state  # noqa: F401


def test_with_joint_points_equals_a_fresh_simulation(ex):
    m = ex("textbook/watt_sixbar.yaml")
    plan = compile_plan(m, inputs=("A",))
    moved = {"G": (5.2, 6.1), "C": (4.05, 3.02)}
    x = {"A": input_grid(-60, 300, 3)}
    again = plan.with_joint_points(moved)
    assert again.groups is plan.groups  # the solution plan is reused
    fresh_mech = m.with_joints(tuple(replace(j, point=np.asarray(moved[j.id], float)) if j.id in moved else j
                                     for j in m.joints))
    a, b = again.simulate(x), simulate(fresh_mech, x)
    assert np.array_equal(a.assembled, b.assembled) and (~a.assembled).any()
    for p in b.points:
        assert np.allclose(a.points[p].position, b.points[p].position, equal_nan=True, atol=1e-12)
    assert [(e["index"], e["kind"]) for e in a.events] == [(e["index"], e["kind"]) for e in b.events]
    for e, f in zip(a.events, b.events):  # the same inputs (dead points refined on the same discriminant)
        assert e.to_dict().keys() == f.to_dict().keys() and e.message == f.message
        if e.input is not None:
            assert all(abs(e.input[k] - f.input[k]) < 1e-9 for k in e.input), (e, f)
    # and the moved design really differs from the drawn one
    c = plan.simulate(x)
    assert not np.allclose(c.points["P"].position, a.points["P"].position, equal_nan=True)


def jansen(writing):
    """The Jansen leg of examples/kinematics/jansen_leg.yaml with its double joint at the
    knee (P4) written three ways: both pairs on the foot link (the file), a chain
    k-c, c-foot, or a star k-c, k-foot."""
    import yaml

    from mechsyn.io import mechanism_from_dict
    from kinematics_helpers import EX

    d = yaml.safe_load((EX / "kinematics/jansen_leg.yaml").read_text())
    J = {j["id"]: j for j in d["joints"]}
    if writing == "chain":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["c", "ghi"]
    elif writing == "star":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["k", "ghi"]
    return mechanism_from_dict(d, f"jansen-{writing}")


def test_double_joints_decompose_however_written():
    x = {"P0": input_grid(0, 360, 5)}
    ref = simulate(jansen("third"), x, method="newton")
    for writing in ("third", "chain", "star"):
        plan = compile_plan(jansen(writing), inputs=("P0",))
        assert plan.groups is not None and [s.kind for s in plan.groups.steps] == ["drive_R"] + ["RRR"] * 3
        sim = plan.simulate(x)
        assert sim.method == "assur" and sim.assembled.all() and not sim.events
        assert np.abs(sim.points["foot"].position - ref.points["foot"].position).max() < 1e-9
        assert np.abs(sim.points["foot"].velocity - ref.points["foot"].velocity).max() < 1e-8


def test_cached_plan_is_reused_and_recompiled_when_a_joint_moves(ex):
    from mechsyn.kinematics.analysis import cached_plan

    m = ex("kinematics/crank_rocker.yaml")
    first = cached_plan(m, inputs=("A",))
    assert cached_plan(m, inputs=("A",)) is first
    x = {"A": input_grid(0, 360, 30)}
    before = simulate(m, x).point("M").copy()
    m.joint("C").point[:] = (3.2, 3.0)  # moved in place: the plan must not be reused
    moved = cached_plan(m, inputs=("A",))
    assert moved is not first
    after = simulate(m, x).point("M")
    fresh = compile_plan(m, inputs=("A",)).simulate(x).point("M")
    assert np.allclose(after, fresh, equal_nan=True, atol=1e-12)
    assert not np.allclose(after, before, equal_nan=True)


def _same(a, b):
    assert np.array_equal(a.assembled, b.assembled)
    for p in b.points:
        for k in ("position", "velocity", "acceleration"):
            assert np.allclose(getattr(a.points[p], k), getattr(b.points[p], k), equal_nan=True, atol=1e-12), (p, k)
    for n in b.links:
        assert np.allclose(a.links[n].angle, b.links[n].angle, equal_nan=True, atol=1e-9), n
    assert [(e["index"], e["kind"]) for e in a.events] == [(e["index"], e["kind"]) for e in b.events]
    for e, f in zip(a.events, b.events):  # the same inputs (dead points refined on the same discriminant)
        assert e.to_dict().keys() == f.to_dict().keys() and e.message == f.message
        if e.input is not None:
            assert all(abs(e.input[k] - f.input[k]) < 1e-9 for k in e.input), (e, f)


def test_one_pass_equals_the_tracked_sweep(ex):
    """Where no group comes near a fold, the one array pass answers with the links'
    states; with dead points the regular pass goes on through them (a ``Folded``).
    Either way the engine gives what the tracked outward sweeps give."""
    from mechsyn.kinematics.analysis import cached_plan
    from mechsyn.kinematics.engines import drawn_row
    from mechsyn.kinematics.regular import Folded, sweep_through_folds

    cases = [("kinematics/crank_rocker.yaml", "A", True), ("kinematics/jansen_leg.yaml", "P0", True),
             ("textbook/fourbar.yaml", "A", False), ("textbook/watt_sixbar.yaml", "A", False)]
    for f, j, regular in cases:
        m = ex(f)
        kp = cached_plan(m, inputs=(j,))
        for grid in ((0, 360, 1), (-90, 500, 7), (200, 260, 0.5)):
            x = input_grid(*grid)
            U = np.radians(x)[:, None]
            got = sweep_through_folds(kp.system, kp.groups, U, np.ones(1), drawn_row(kp.system, U))
            got = None if isinstance(got, Folded) else got
            assert (got is not None) == regular or grid[1] - grid[0] < 360, (f, grid)
            if got is not None:
                q, qd, qdd, links = got
                assert np.allclose(links.z, np.exp(1j * q[:, 2::3].T), atol=1e-12)
                for i in range(len(kp.system.links)):  # a link's origin seen from its complex state
                    for k, arr in enumerate((q, qd, qdd)):
                        assert np.allclose(links.point(i, np.zeros(2))[k], arr[:, 3 * i:3 * i + 2], atol=1e-12)
            fast = simulate(m, {j: x})
            assert fast.engine == "regular pass", (f, grid, fast.engine)
            sw = fast.sweep
            if sw.links is not None and got is None:  # through folds (the compiled pass): NaN where the poses are
                assert sw.nan_rows
                for i in range(len(kp.system.links)):
                    for k, arr in enumerate((sw.q, sw.qd, sw.qdd)):
                        assert np.allclose(sw.links.point(i, np.zeros(2))[k], arr[:, 3 * i:3 * i + 2], atol=1e-12,
                                           equal_nan=True)
            tracked = simulate(m, {j: x}, method="tracked chain")  # the engine by its name
            assert tracked.engine == "tracked chain"
            _same(fast, tracked)


def test_scalar_discriminant_equals_the_array_pass(ex):
    """The one-input evaluation used by the dead-point root search gives the array pass's
    discriminant of every group."""
    from mechsyn.kinematics import dyads, folds, kernel
    from mechsyn.kinematics.analysis import cached_plan
    from mechsyn.kinematics.kernel import program as kernel_program

    for f in ("textbook/watt_sixbar.yaml", "textbook/stephenson_sixbar.yaml", "kinematics/peaucellier.yaml"):
        m = ex(f)
        j = next(jj.id for jj in m.joints if jj.actuated)
        kp = cached_plan(m, inputs=(j,))
        S, plan = kp.system, kp.groups
        X = np.radians(input_grid(0, 350, 10))[:, None]
        tp = dyads.solve_tracked(S, plan, X)
        prog = kernel_program(S, plan)
        for k, step in enumerate(plan.steps):
            if step.kind != "RRR":
                continue
            ref = folds.disc_at(S, plan, k, tp.sigmas, np.arange(len(X)), X)
            sig = [np.array([float(s[i]) if isinstance(s, np.ndarray) else float(s or 1.0) for s in tp.sigmas])
                   for i in range(len(X))]
            got = np.array([kernel.scalar_disc(prog, k, sig[i], X[i]) for i in range(len(X))])
            assert np.allclose(got, ref, atol=1e-12, equal_nan=True), (f, k)


def test_cached_plans_do_not_keep_mechanisms_alive(ex, monkeypatch):
    import gc
    import weakref

    from mechsyn.kinematics import analysis
    from mechsyn.kinematics.topology import LRUCache

    monkeypatch.setattr(analysis, "CACHE", LRUCache(8))
    m = ex("kinematics/crank_rocker.yaml")
    simulate(m, {"A": input_grid(0, 90, 30)})  # (the first of its topology: the template is a copy)
    ref = weakref.ref(m)
    for _ in range(analysis.CACHE.maxsize):  # later mechanisms push it out of the bounded cache
        simulate(ex("kinematics/crank_rocker.yaml"), {"A": input_grid(0, 90, 30)})
    del m
    gc.collect()
    assert ref() is None


def test_a_speed_that_is_not_a_number_is_refused(ex):
    """The one pass trusts every row to have finite rates: a NaN or infinite input speed is
    refused with the field named, never swept into NaN rates."""
    from mechsyn.errors import MechsynInputError

    m = ex("kinematics/crank_rocker.yaml")
    for bad in (float("nan"), float("inf")):
        with pytest.raises(MechsynInputError, match="finite") as err:
            simulate(m, {"A": input_grid(0, 90, 1)}, speeds={"A": bad})
        assert err.value.field == "speeds"


def test_one_pass_with_a_drive_between_moving_links_equals_the_tracked_sweep(ex):
    """A five-bar driven at the frame and between two moving links (B): the one pass turns
    the second link with the first and gives what the tracked sweep gives."""
    m = ex("textbook/five_bar_5r.yaml")
    m = m.with_joints(tuple(replace(j, actuated=j.id in ("A", "B")) for j in m.joints))
    x = input_grid(-5, 5, 1)
    inp, speeds = {"A": x, "B": 0.5 * x}, {"A": 1.0, "B": 0.7}
    fast = simulate(m, inp, speeds=speeds)
    assert fast.sweep.links is not None and not fast.events
    tracked = simulate(m, inp, speeds=speeds, method="tracked chain")
    _same(fast, tracked)


@pytest.mark.parametrize("f, j, grid", [("textbook/watt_sixbar.yaml", "A", (0, 360, 2)),     # through folds
                                        ("kinematics/crank_rocker.yaml", "A", (0, 360, 5)),  # regular pass
                                        ("textbook/watt_sixbar.yaml", "A", (100, 130, 0.5))])
def test_named_points_in_one_batch_equal_each_point_on_its_own(ex, f, j, grid):
    """Every named point (and joint) of a sweep, computed for all points at once, equals
    the state of that point alone (``kinematics_helpers.point_state``) with its rows not
    assembled (and its rates where they are not defined) NaN, bit for bit; with the regular
    pass's link states and without them (the tracked chain)."""
    from mechsyn.kinematics import analysis

    m = ex(f)
    names = list(m.points) + [jj.id for jj in m.joints]
    for method in ("regular pass", "tracked chain"):
        s = simulate(m, {j: input_grid(*grid)}, points=names, method=method)
        S, sw = s.system, s.sweep
        ok = s.assembled
        rates = ok & np.isfinite(sw.qd).all(axis=1) & np.isfinite(sw.qdd).all(axis=1)
        for name, (link, at) in analysis.resolve_points(m, names).items():
            want = point_state(S, sw.q, sw.qd, sw.qdd, S.index(link), S.to_local(link, at))
            for k, (got, ref) in enumerate(zip((s.points[name].position, s.points[name].velocity,
                                                s.points[name].acceleration), want)):
                ref = ref.copy()
                ref[~(ok if k == 0 else rates)] = np.nan
                if sw.links is not None:  # the links' complex states: the same motion to round-off
                    assert np.allclose(got, ref, rtol=1e-12, atol=1e-12 * S.scale * (1 + 10 * k), equal_nan=True)
                else:
                    assert np.array_equal(got, ref, equal_nan=True), (name, k)


@pytest.mark.parametrize("f, moved", [("textbook/watt_sixbar.yaml", {"E": (0.013, -0.021), "C": (-0.02, 0.01)}),
                                      ("kinematics/jansen_leg.yaml", {"P5": (0.31, -0.17)}),
                                      ("textbook/stephenson_sixbar.yaml", {})])
def test_regular_program_refilled_by_topology_equals_one_built_from_the_groups(ex, f, moved):
    """The regular pass's program of a refilled system (its topology's shape, the numbers
    of the moved geometry put in) equals the program written out from the groups of that
    system (local points, squared lengths, drawn modes, rotation vectors, anchors), to
    the last bits of its arithmetic."""
    from mechsyn.kinematics.analysis import cached_plan
    from mechsyn.kinematics.groups import cons_of, local_point
    from mechsyn.kinematics.kernel import program as _program

    m = ex(f)
    j = next(jj.id for jj in m.joints if jj.actuated)
    kp = cached_plan(m, inputs=(j,))
    _program(kp.system, kp.groups)  # the shape, kept for the topology
    pts = {k: np.asarray(m.joint(k).point, float) + np.asarray(v) for k, v in moved.items()}
    kp2 = compile_plan(m.with_joint_points(pts), inputs=(j,))
    S = kp2.system
    assert S.topology == kp.system.topology  # what the topology decides: kept by it
    _, fp, anc_s = _program(S, kp2.groups)
    want, anchor = [], {}

    def lp(i: int, jid: str) -> complex:
        return complex(*local_point(S, i, jid))

    for step in kp2.groups.steps:  # the program's numbers from the groups, written out here
        if step.kind == "drive_R":
            (new,), (k,), (jid,) = step.links, step.known, step.joints
            con = next(c for c in cons_of(S, jid) if c.role == "drive")
            want.append((1.0 if con.b == new else -1.0, lp(k, jid), 0, 0, 0, 0, 0))
            anchor[new] = lp(new, jid)
            continue
        (k1, k3), (b1, b2), (J1, J2, J3) = step.known, step.links, step.joints
        u, v = lp(b1, J2) - lp(b1, J1), lp(b2, J2) - lp(b2, J3)
        A0, B0, C0 = (complex(*m.with_joint_points(pts).joint(jj).point) for jj in (J1, J2, J3))
        sigma = 1.0 if ((C0 - A0).conjugate() * (B0 - A0)).imag >= 0 else -1.0
        want.append((abs(u) ** 2 + 1j * abs(v) ** 2, 0, sigma, (u / abs(u) ** 2).conjugate(),
                     (v / abs(v) ** 2).conjugate(), lp(k1, J1), lp(k3, J3)))
        anchor[b1], anchor[b2] = lp(b1, J1), lp(b2, J3)
    # the numbers, to the last bits of their arithmetic
    assert np.allclose(np.array(want, complex), fp, rtol=1e-14, atol=1e-14 * S.scale)
    assert np.allclose([anchor[i] for i in sorted(anchor)], anc_s[sorted(anchor)], rtol=1e-14, atol=1e-14 * S.scale)


@pytest.mark.parametrize("f, joint", [("textbook/watt_sixbar.yaml", "E"), ("textbook/fourbar.yaml", "C"),
                                      ("kinematics/crank_rocker.yaml", "C")])
def test_four_bar_fold_spec_of_a_refilled_geometry_equals_a_fresh_plans(ex, f, joint):
    """The closed-form four-bar fold's numbers, read off the regular pass's program of a
    drag's refilled geometry, equal those of a plan compiled afresh for the moved
    mechanism, group by group (None where the group closes no four-bar)."""
    from mechsyn.kinematics import folds
    from mechsyn.kinematics.analysis import cached_plan
    from mechsyn.kinematics.groups import geometry_memo

    m = ex(f)
    m = m.with_joint_points({joint: np.asarray(m.joint(joint).point, float) + 0.01})
    kp = cached_plan(m, inputs=("A",))
    simulate(m, {"A": input_grid(0, 360, 2)})  # the regular program kept with the system
    memo = geometry_memo(kp.system)
    assert memo[("kernel", id(kp.groups))][0] is kp.groups
    ks = [k for k, s in enumerate(kp.groups.steps) if s.kind == "RRR"]
    memo.pop(("four-bar folds", id(kp.groups), tuple(ks)), None)
    got = folds._four_bar_specs(kp.system, kp.groups, ks)
    fresh = compile_plan(m, inputs=("A",))
    assert fresh.system is not kp.system
    want = folds._four_bar_specs(fresh.system, fresh.groups, ks)
    assert np.array_equal(got[:, 0], want[:, 0]) and got[:, 0].any() and np.array_equal(got[:, 4], want[:, 4])
    assert np.allclose(got, want, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("gap", [0.0, 4.4e-16, 3e-13])
def test_coincident_circle_centres_are_indeterminate_in_both_forms(gap):
    """An RRR group whose circle centres are one point (within 1e-12 of its lengths) has no
    determinate middle joint: NaN in the array and the scalar forms alike, whatever the last
    bits of ``d`` (the Peaucellier cell's dead point gave 0 on one machine and 4.4e-16 on
    another, so NaN from one pass and a discriminant of 1 from the other)."""
    from mechsyn.kinematics.groups import circle_circle

    for scale in (1e-3, 1.0, 1e4):
        L1s = L2s = (2.0 * scale) ** 2
        d = gap * scale
        f, g2, disc = circle_circle(np.array([d, 2.0 * scale]), np.zeros(2), L1s, L2s)
        assert np.isnan(disc[0]) and disc[1] == pytest.approx(0.75)
        f_s, g2_s, disc_s = circle_circle(d, 0.0, L1s, L2s)
        assert np.isnan(f_s) and np.isnan(g2_s) and np.isnan(disc_s)


def test_separate_circle_centres_are_kept():
    """Just above the coincidence threshold (1e-10 of the lengths) the group is determinate."""
    from mechsyn.kinematics.groups import circle_circle

    f, g2, disc = circle_circle(np.array([1e-10]), np.zeros(1), 4.0, 4.0)
    assert np.isfinite(disc[0])
