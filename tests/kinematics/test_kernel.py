"""The kernel of the regular pass (mechsyn.kinematics.kernel, issues 30 and 37) against the
generic group steps and the constraints' linear solves for the rates: the same states,
rates and discriminants on every planar example (and a moved copy of each) whose plan
the regular pass takes, and the same simulations as the tracked chain.
CI runs these tests under NUMBA_DISABLE_JIT=1 with coverage (.ci/steps/25-kernel.sh)."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics import kernel, regular
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.model.mechanism import Mechanism

def _scale(m: Mechanism) -> float:
    pts = np.array([j.point for j in m.joints if j.point is not None and len(j.point) == 2], float)
    return float(np.ptp(pts, axis=0).max())


def _is_chain(m: Mechanism) -> bool:
    try:
        kp = cached_plan(m)
    except Exception:  # noqa: BLE001  (no plan: Newton's)
        return False
    return kp.groups is not None and kp.groups.closed_form_rates and kp.system.n == 3 * len(kp.system.links)


def _chains() -> list[tuple[str, Mechanism]]:
    """Every planar example with drivers whose plan is a driver-R + RRR chain, and a copy
    with its R joints moved by up to 2 % of its size (where that is still such a chain)."""
    out = []
    for name in ms.examples.names():
        try:
            m = ms.examples.load(name)
        except Exception:  # noqa: BLE001  (not a mechanism)
            continue
        if not isinstance(m, Mechanism) or m.kind != "planar" or not any(j.actuated for j in m.joints):
            continue
        rng = np.random.default_rng(len(out))
        moved = {j.id: np.asarray(j.point, float) + rng.uniform(-0.02, 0.02, 2) * _scale(m) for j in m.joints
                 if j.type == "R" and j.point is not None and len(j.point) == 2}
        copy = m.with_joints(tuple(replace(j, point=moved[j.id]) if j.id in moved else j for j in m.joints))
        out += [(n, x) for n, x in ((name, m), (name + "~moved", copy)) if _is_chain(x)]
    return out


CHAINS = _chains()


def test_the_examples_have_chains_with_folds_and_several_drivers():
    """The comparison below covers four-bars, six-bars, several drivers and folds."""
    names = {n for n, _ in CHAINS}
    assert {"crank_rocker", "watt_sixbar", "fourbar"} <= names
    assert any(len(cached_plan(m).system.drivers) > 1 for _, m in CHAINS)




@pytest.mark.parametrize("name,mech", CHAINS, ids=[n for n, _ in CHAINS])
def test_the_kernel_pass_equals_the_generic_steps(name, mech):
    """Every link's rotation, its origin's position, velocity and acceleration, its rates
    and every group's discriminant from the kernel, against the generic group steps
    (:func:`mechsyn.kinematics.positions.solve_positions`, every group in the kernel's
    drawn mode) with the rates of the constraints' linear solves
    (:meth:`mechsyn.kinematics.system.PlanarSystem.rates`), and the discriminant of
    :func:`mechsyn.kinematics.groups.circle_circle` on the generic steps' joints."""
    from mechsyn.kinematics.groups import circle_circle, local_point
    from mechsyn.kinematics.positions import solve_positions

    kp = cached_plan(mech)
    S, plan = kp.system, kp.groups
    k = len(S.drivers)
    u0 = np.array([d.assembled for d in S.drivers])
    rng = np.random.default_rng(7)
    wide = np.radians(np.arange(-180.0, 541.0, 2.5))  # a full turn and more: folds if the chain has any
    X = np.column_stack([wide if i == 0 else u0[i] + rng.uniform(-0.3, 0.3, wide.size) for i in range(k)])
    speeds = np.linspace(1.0, 2.0, k)
    prog = kernel.program(S, plan)
    fp = prog[1]
    C, W, AL, D, near = kernel.run(prog, X, speeds, regular.REGULAR_DISC)

    def joint(i: int, jid: str) -> np.ndarray:  # a joint's complex position on link i (-1: the frame)
        s = complex(*local_point(S, i, jid))
        return np.full(len(X), s) if i < 0 else q[:, 3 * i] + 1j * q[:, 3 * i + 1] + np.exp(1j * q[:, 3 * i + 2]) * s

    with np.errstate(invalid="ignore", divide="ignore"):
        q = solve_positions(S, plan, X, [fp[s, 2].real if st.kind == "RRR" else None
                                         for s, st in enumerate(plan.steps)])[0]
        D0 = []
        for s, st in enumerate(plan.steps):
            if st.kind == "RRR":
                d = joint(st.known[1], st.joints[2]) - joint(st.known[0], st.joints[0])
                D0.append(circle_circle(d.real, d.imag, fp[s, 0].real, fp[s, 0].imag)[2])
    D0 = np.array(D0)
    assert near == (not np.nanmin(D0) >= regular.REGULAR_DISC)
    fin = np.isfinite(D0)
    assert np.array_equal(fin, np.isfinite(D)) and np.allclose(D0[fin], D[fin], rtol=1e-9, atol=1e-9)
    # rounding grows as a group folds, as 1 / disc^2 for the accelerations: rows clear of
    # folds agree to 1e-11 relative times that, element by element
    clear = (D0 > 1e-3).all(axis=0)
    q = q[clear]
    qd, qdd = S.rates(q, speeds)
    grow = 1.0 / D0[:, clear].min(axis=0) ** 2
    size = _scale(mech)
    nl = len(S.links)
    x, y, a = (slice(c, 3 * nl, 3) for c in range(3))
    pairs = [(np.exp(1j * q[:, a].T), C[0], 1.0)]
    pairs += [((v[:, x] + 1j * v[:, y]).T, C[i], size) for i, v in ((1, q), (2, qd), (3, qdd))]
    pairs += [(qd[:, a].T, W, 1.0), (qdd[:, a].T, AL, 1.0)]
    for want, got, unit in pairs:
        got = got[:, clear]
        assert np.array_equal(np.isnan(want), np.isnan(got))
        ok = np.isfinite(want)
        tol = 1e-11 * (unit + np.abs(want)) * grow
        assert np.all(np.abs(want[ok] - got[ok]) <= tol[ok]), name


@pytest.mark.parametrize("name", ["crank_rocker", "watt_sixbar", "stephenson_sixbar", "fourbar", "jansen_leg"])
@pytest.mark.parametrize("grid", [(0, 360, 1), (-720, 720, 3), (400, 40, -2)])
def test_the_regular_pass_simulates_as_the_tracked_chain(name, grid):
    """Poses, rates, named points, link angles and events of ``simulate`` over several
    turns, forwards and backwards, from inside and outside the drawn input (the Watt
    six-bar and the textbook four-bar through their dead points): the kernel's regular
    pass and the tracked chain (the same branch rules on the kernel's program run with
    per-row signs)."""
    m = ms.examples.load(name)
    drive = next(j.id for j in m.joints if j.actuated)
    a, b = (ms.simulate(m, {drive: grid}, method=e) for e in ("tracked chain", "regular pass"))
    assert (a.engine, b.engine) == ("tracked chain", "regular pass")
    assert [(e.kind, e.index, e.message) for e in a.events] == [(e.kind, e.index, e.message) for e in b.events]
    for e, f in zip(a.events, b.events):
        assert np.allclose(list(e.input.values()), list(f.input.values()), rtol=1e-12, atol=1e-12)
    for key in a.points:
        for attr in ("position", "velocity", "acceleration"):
            x, y = getattr(a.points[key], attr), getattr(b.points[key], attr)
            assert np.allclose(x, y, rtol=1e-11, atol=1e-11 * _scale(m), equal_nan=True), (key, attr)
    for key in a.links:  # the angles continuous from the drawn ones (whole turns counted the same)
        for attr in ("angle", "angular_velocity", "angular_acceleration"):
            x, y = getattr(a.links[key], attr), getattr(b.links[key], attr)
            assert np.allclose(x, y, rtol=1e-11, atol=1e-11, equal_nan=True), (key, attr)
    assert np.array_equal(a.assembled, b.assembled)


def test_numba_is_imported_by_the_first_sweep_only():
    """Importing mechsyn (its kinematics, its command line) imports no Numba: a command
    that runs no sweep does not pay for it; the first sweep does."""
    code = ("import sys, mechsyn, mechsyn.kinematics, mechsyn.cli.main; assert 'numba' not in sys.modules; "
            "import mechsyn as ms; ms.examples.load('crank_rocker').simulate(A=(0, 360, 30)); "
            "assert 'numba' in sys.modules")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    subprocess.run([sys.executable, "-c", code], check=True, env=env, timeout=300)


def _numpy_fold_masks(discs: dict, ks: list, perm: np.ndarray, b: int) -> tuple:
    """The fold scan's masks in NumPy (the test's oracle): the discriminants laid out
    (groups, L), the singular rows, the (group, row) pairs after which a group's assembly
    changes, whether a change point may be near."""
    from mechsyn.kinematics import folds

    D = np.stack([discs[k][perm] for k in ks])
    ok = D > -folds._ZERO_DISC
    d = np.where(ok, np.maximum(D, 0.0), np.nan)
    low = folds._low_minima(d)
    low[:, max(b - 2, 0):b] = False  # the sweeps' first rows (Y[b - 1], Y[b]) are no inner rows
    with np.errstate(invalid="ignore"):
        singular = (d < folds.SINGULAR_DISC).any(axis=0)
    return D, singular, np.nonzero(ok[:, 1:] != ok[:, :-1]), bool(low.any())


@pytest.mark.parametrize("name", ["watt_sixbar", "fourbar", "stephenson_sixbar", "peaucellier", "crank_rocker"])
def test_the_kernels_fold_masks_equal_numpys(name):
    """The fold search's masks (layout, singular rows, assembly changes, a low minimum
    that sends the chain to the tracked engine) from the kernel and in NumPy, on passes
    through dead points, a cell whose change points the pass declines, and one without
    folds."""
    from mechsyn.kinematics import folds

    kp = cached_plan(ms.examples.load(name))
    S, plan = kp.system, kp.groups
    for grid in (np.arange(0.0, 361.0), np.arange(-400.0, 400.0, 3.0)):
        X = np.radians(grid)[:, None]
        st = regular._pass(S, plan, X, np.ones(1), folds=True)
        ks = kernel.program(S, plan)[0][4]
        discs = dict(zip(ks, st[3]))
        M = X.shape[0]
        for split, n0s in ((None, (7,)), (M // 3, (5, 9))):
            perm, b = folds._pass_layout(M - sum(n0s), split, n0s)
            want = _numpy_fold_masks(discs, ks, perm, b)
            ng, L = len(ks), perm.shape[0]
            Dl, singular, chg = np.empty((ng, L)), np.empty(L, np.bool_), np.empty((ng, L - 1), np.bool_)
            low = kernel._nb().fold_rows(st[3], perm, b, folds._ZERO_DISC,
                                         folds.SINGULAR_DISC, Dl, singular, chg)
            assert np.array_equal(want[0], Dl, equal_nan=True) and np.array_equal(want[1], singular)
            assert all(np.array_equal(x, y) for x, y in zip(want[2], np.nonzero(chg))) and want[3] == low



def test_trig_is_numpys_and_follows_the_inputs() -> None:
    """The inputs' cosines and sines the compiled pass turns its drivers by are NumPy's,
    block by block, whether kept or not; a block changed in place, or the same bytes in
    another shape, are other inputs (never the kept answer of the old ones)."""
    X = np.radians(np.linspace(-720.0, 720.0, 97)).reshape(-1, 1)
    path = np.radians([[10.0], [20.0]])
    for _ in range(2):  # the second time from what is kept
        c, s = kernel.trig([X, path])
        assert np.array_equal(c, np.vstack([np.cos(X), np.cos(path)]))
        assert np.array_equal(s, np.vstack([np.sin(X), np.sin(path)]))
    X[5, 0] += 0.25  # the same array object, other numbers
    c, s = kernel.trig([X, path])
    assert c[5, 0] == np.cos(X[5, 0]) and s[5, 0] == np.sin(X[5, 0])
    two = np.radians([[0.0, 90.0], [45.0, 30.0]])
    c1, _ = kernel.trig([two])
    c2, _ = kernel.trig([two.reshape(4, 1)])
    assert c1.shape == (2, 2) and c2.shape == (4, 1)
    ints = np.array([[1], [2]], np.int64)  # the bytes of two tiny floats: other numbers
    assert np.array_equal(kernel.trig([ints.view(float)])[0], np.cos(ints.view(float)))
    assert np.array_equal(kernel.trig([ints])[0], np.cos(ints))
    big = np.zeros((kernel._TRIG_ROWS + 1, 1))  # not kept: computed each time
    assert np.array_equal(kernel.trig([big, path])[0][-2:], np.cos(path))



@pytest.mark.parametrize("name, around", [("fourbar_folded", None), ("fourbar_dead_centre", 30.0),
                                          ("fourbar", None), ("watt_sixbar", None)])
def test_the_kernels_poses_blank_the_fold_scans_singular_rows(name, around):
    """Through folds the kernel's poses blank the rates of the rows the fold scan finds
    singular (a group folded flat on a row) and count them: the same rows, NaN rates and
    events as the tracked chain; the sweep's rows with rates are its finite ones and its
    singular rows (when it knows them) the assembled rows without rates."""
    m = ms.examples.load(name)
    kp = cached_plan(m)
    drive = kp.system.drivers[0]
    u0 = np.degrees(drive.assembled)
    grid = np.arange(0.0, 361.0, 1.0) if around is None else u0 + np.arange(-around, around + 0.25, 0.5)
    a, b = (ms.simulate(m, {drive.joint: grid}, method=e) for e in ("tracked chain", "regular pass"))
    assert (a.engine, b.engine) == ("tracked chain", "regular pass")
    assert [(e.kind, e.index) for e in a.events] == [(e.kind, e.index) for e in b.events]
    sw = b.sweep
    finite = np.isfinite(sw.qd).all(axis=1) & np.isfinite(sw.qdd).all(axis=1)
    assert np.array_equal(sw.rates_ok, finite)
    singular = np.flatnonzero(sw.assembled & ~finite).tolist()
    assert sw.singular_rows is None or sw.singular_rows == singular
    assert singular == [e.index for e in b.events if e.kind == "singular"] or name in ("fourbar", "watt_sixbar")
    for key in a.links:
        assert np.array_equal(np.isnan(a.links[key].angular_velocity), np.isnan(b.links[key].angular_velocity))
    for key in a.points:
        assert np.array_equal(np.isnan(a.points[key].acceleration), np.isnan(b.points[key].acceleration))


@pytest.mark.parametrize("name", ["fourbar", "watt_sixbar"])
def test_the_batch_runs_the_kernels_program(name):
    """The batch engine runs the regular pass's program (``batch_pass``, the kernel's
    circle intersection): over a sweep through dead points, its assembled rows are the rows
    where every group of the regular pass's program assembles, and its least
    transmission angle the least ``|sin|`` of the angle between each group's links over
    those rows, read off its joints (rows where a group's discriminant is within 1e-12
    of zero may go either way: the batch turns the crank from its drawn configuration,
    the regular pass from its frame, and the last bits differ)."""
    from mechsyn.kinematics.batch import compile_plan as batch_plan, simulate_batch

    m = ms.examples.load(name)
    kp = cached_plan(m)
    S, plan = kp.system, kp.groups
    bp = batch_plan(m, points=[j.id for j in m.joints])
    offs = np.arange(0.0, 360.0, 2.0)
    res = simulate_batch(bp, bp.parameters(m), offs, transmission=True)
    u = np.radians(res.motion(0).inputs[bp.input_joint])[:, None]  # the inputs as simulate measures them
    with np.errstate(invalid="ignore", divide="ignore"):
        C, W, AL, D, near = kernel.run(kernel.program(S, plan), u, np.ones(1), regular.REGULAR_DISC)
    ok, clear = (D >= 0).all(axis=0), ~(np.abs(D) <= 1e-12).any(axis=0)  # (NaN downstream of a fold)
    assert np.array_equal(res.assembled[0][clear], ok[clear]) and clear.sum() >= len(offs) - 4 and near
    ok = res.assembled[0]
    sin_mu = np.inf
    for st in plan.steps:
        if st.kind != "RRR":
            continue
        J1, J2, J3 = st.joints
        P = {j: res.paths[j][0][ok] for j in (J1, J2, J3)}
        e1, e2 = P[J2] - P[J1], P[J2] - P[J3]
        s = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / (np.hypot(*e1.T) * np.hypot(*e2.T))
        sin_mu = min(sin_mu, s.min())
    assert res.min_transmission_angle[0] == pytest.approx(np.degrees(np.arcsin(sin_mu)), abs=1e-5)
    assert np.isnan(res.paths[plan.steps[-1].joints[1]][0][~ok]).all()
