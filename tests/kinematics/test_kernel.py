"""The compiled regular pass (mechsyn.kinematics.kernel, issue 30) against the NumPy pass it
compiles: the same states, discriminants and fold flags on every planar example (and a
moved copy of each) whose plan the regular pass takes, and the same simulations."""

from __future__ import annotations

import importlib.util
from dataclasses import replace

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics import kernel, regular
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.model.mechanism import Mechanism

#: the tests that run the compiled pass (Numba: the fast extra; CI's .ci/steps/25-kernel.sh)
needs_numba = pytest.mark.skipif(importlib.util.find_spec("numba") is None,
                                 reason="Numba not installed (pip install 'mechsyn[fast]')")


@pytest.fixture(autouse=True)
def _kernel_on():
    """These tests compare the compiled pass with the NumPy one: the kernel in its
    default mode, whatever the environment said."""
    with kernel.use("auto"):
        yield


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


@needs_numba
@pytest.mark.parametrize("name,mech", CHAINS, ids=[n for n, _ in CHAINS])
def test_compiled_pass_equals_the_numpy_pass(name, mech):
    kp = cached_plan(mech)
    S, plan = kp.system, kp.groups
    k = len(S.drivers)
    u0 = np.array([d.assembled for d in S.drivers])
    rng = np.random.default_rng(7)
    wide = np.radians(np.arange(-180.0, 541.0, 0.5))  # a full turn and more: folds if the chain has any
    X = np.column_stack([wide if i == 0 else u0[i] + rng.uniform(-0.3, 0.3, wide.size) for i in range(k)])
    speeds = np.linspace(1.0, 2.0, k)
    steps, anchor, origin = regular._program(S, plan)
    st = regular._run(steps, anchor, X, speeds, folds=True)
    C0 = regular._states(st, origin, X.shape[0], len(S.links))
    C, W, AL, D, near = kernel.run(kernel.program_arrays(steps, anchor, origin), X, speeds, regular.REGULAR_DISC)
    assert near == st.near
    groups = sorted(st.discs)
    D0 = np.stack([st.discs[g] for g in groups])
    assert np.array_equal(np.isnan(D0), np.isnan(D))
    assert np.allclose(D0, D, rtol=1e-12, atol=1e-12, equal_nan=True)
    # rounding (NumPy's and libm's sines differ in the last place) grows as a group
    # folds, as 1 / disc^2 for the accelerations: rows clear of folds agree to 1e-14
    # relative times that, element by element
    clear = (D0 > 1e-3).all(axis=0)
    grow = 1.0 / D0[:, clear].min(axis=0) ** 2
    size = _scale(mech)
    pairs = [(C0[0], C[0], 1.0)] + [(C0[i], C[i], size) for i in (1, 2, 3)]
    pairs += [(np.stack([np.broadcast_to(st.link[i][j], arr[i].shape) for i in range(len(S.links))]), arr, 1.0)
              for arr, j in ((W, 1), (AL, 2))]
    for a, b, unit in pairs:
        assert np.array_equal(np.isnan(a[:, clear]), np.isnan(b[:, clear]))
        a, b = a[:, clear], b[:, clear]
        ok = np.isfinite(a)
        tol = 1e-14 * (unit + np.abs(a)) * grow
        assert np.all(np.abs(a[ok] - b[ok]) <= tol[ok])


@needs_numba
@pytest.mark.parametrize("name", ["crank_rocker", "watt_sixbar", "stephenson_sixbar", "fourbar", "jansen_leg"])
@pytest.mark.parametrize("grid", [(0, 360, 1), (-720, 720, 3), (400, 40, -2)])
def test_simulations_are_the_same_with_and_without_the_kernel(name, grid):
    """Poses, rates, named points, link angles and events of ``simulate`` over several
    turns, forwards and backwards, from inside and outside the drawn input (the Watt
    six-bar and the textbook four-bar through their dead points)."""
    m = ms.examples.load(name)
    drive = next(j.id for j in m.joints if j.actuated)
    sims = {}
    for mode in ("numpy", "auto"):
        with kernel.use(mode):
            assert kernel.active() == (mode == "auto")
            sims[mode] = m.simulate(**{drive: grid})
    a, b = sims["numpy"], sims["auto"]
    assert a.engine == b.engine == "regular pass"
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


def test_numpy_mode_turns_the_kernel_off():
    with kernel.use("numpy"):
        assert not kernel.active()
        kp = cached_plan(ms.examples.load("crank_rocker"))
        steps, anchor, origin = regular._program(kp.system, kp.groups)
        prog = kernel.program_arrays(steps, anchor, origin)
        assert kernel.run(prog, np.zeros((3, 1)), np.ones(1), 0.05) is None
        assert isinstance(regular._pass(kp.system, kp.groups, np.zeros((3, 1)), np.ones(1), True), regular._Pass)


def test_the_environment_is_read_once_and_a_wrong_mode_is_one_clear_error(monkeypatch):
    from mechsyn.errors import MechsynInputError

    monkeypatch.setattr(kernel, "_MODE", None)  # as in a new process
    monkeypatch.setenv("MECHSYN_KERNEL", "fastest")
    with pytest.raises(MechsynInputError, match="MECHSYN_KERNEL='fastest' is not one of auto, numba, numpy"):
        kernel.active()
    with pytest.raises(MechsynInputError, match="is not one of"):
        kernel.use("fastest").__enter__()
    monkeypatch.setenv("MECHSYN_KERNEL", " NumPy ")
    assert not kernel.active() and kernel._MODE == "numpy"
    monkeypatch.setenv("MECHSYN_KERNEL", "auto")  # read once: the first use decided
    assert not kernel.active()


def test_numba_asked_for_without_numba_names_the_extra(monkeypatch):
    monkeypatch.setattr(kernel, "_MODULE", False)  # as after a failed import of Numba
    with kernel.use("numba"), pytest.raises(ImportError, match=r'pip install "mechsyn\[fast\]"'):
        kernel.active()


def test_one_shot_commands_keep_the_numpy_pass(monkeypatch):
    """``mechsyn simulate`` runs one sweep: Numba's load would cost it more than it saves;
    the setting is the command's only (the caller's mode is as it was)."""
    from mechsyn.cli.main import ONE_SHOT, main

    monkeypatch.delenv("MECHSYN_KERNEL", raising=False)
    seen = []
    import mechsyn.kinematics.regular as reg

    real = reg._pass

    def spy(*a, **k):
        seen.append(kernel.active())
        return real(*a, **k)

    monkeypatch.setattr(reg, "_pass", spy)
    assert "simulate" in ONE_SHOT and "serve" not in ONE_SHOT and "synth" not in ONE_SHOT
    assert main(["simulate", "examples/kinematics/crank_rocker.yaml", "-i", "A=0:360:10"]) == 0
    assert seen and not any(seen)
    assert kernel.active() == (importlib.util.find_spec("numba") is not None)  # the caller's setting again


@needs_numba
@pytest.mark.parametrize("name", ["watt_sixbar", "fourbar", "stephenson_sixbar", "peaucellier", "crank_rocker"])
def test_fold_masks_compiled_equal_numpy(name):
    """The fold search's masks (layout, singular rows, assembly changes, a low minimum
    that sends the chain to the tracked engine) compiled and in NumPy, on passes through
    dead points, a cell whose change points the pass declines, and one without folds."""
    from mechsyn.kinematics import folds

    m = ms.examples.load(name)
    kp = cached_plan(m)
    S, plan = kp.system, kp.groups
    steps, anchor, origin = regular._program(S, plan)
    for grid in (np.arange(0.0, 361.0), np.arange(-400.0, 400.0, 3.0)):
        X = np.radians(grid)[:, None]
        st = regular._run(steps, anchor, X, np.ones(1), folds=True)
        ks = sorted(st.discs)
        M = X.shape[0]
        for split, n0s in ((None, (7,)), (M // 3, (5, 9))):
            rows = M - sum(n0s)
            perm, b = folds._pass_layout(rows, split, n0s)
            a = folds._fold_rows(st.discs, ks, perm, b)
            c = kernel.fold_rows([st.discs[k] for k in ks], perm, b, folds._ZERO_DISC, folds.SINGULAR_DISC)
            assert np.array_equal(a[0], c[0], equal_nan=True) and np.array_equal(a[1], c[1])
            assert all(np.array_equal(x, y) for x, y in zip(a[2], c[2])) and a[3] == c[3]


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


@needs_numba
@pytest.mark.parametrize("name, around", [("fourbar_folded", None), ("fourbar_dead_centre", 30.0),
                                          ("fourbar", None), ("watt_sixbar", None)])
def test_compiled_poses_blank_the_fold_scans_singular_rows(name, around):
    """Through folds the compiled poses blank the rates of the rows the fold scan finds
    singular (a group folded flat on a row) and count them: the same rows, NaN rates and
    events as the NumPy pass, which blanks them after its poses; the sweep's rows with
    rates are its finite ones and its singular rows (when it knows them) the assembled
    rows without rates."""
    m = ms.examples.load(name)
    kp = cached_plan(m)
    drive = kp.system.drivers[0]
    u0 = np.degrees(drive.assembled)
    grid = np.arange(0.0, 361.0, 1.0) if around is None else u0 + np.arange(-around, around + 0.25, 0.5)
    sims = {}
    for mode in ("numpy", "auto"):
        with kernel.use(mode):
            sims[mode] = ms.simulate(m, {drive.joint: grid})
    a, b = sims["numpy"], sims["auto"]
    assert a.engine == b.engine == "regular pass"
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
