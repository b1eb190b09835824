"""The regular pass through folds: its fold search on the pass's rows, the link angles and
the connecting paths give what the per-sweep computations give, to the bit."""

import math
from dataclasses import replace

import numpy as np
import pytest

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.kinematics.engines import drawn_row

from kinematics_helpers import ex, fourbar_dict  # noqa: F401


def _per_sweep(S, plan, st, U, split, paths, sigmas):
    """The fold search sweep by sweep: each tracked sweep's rows gathered from the pass
    (its connecting path, then its inputs shifted by whole turns), then
    :func:`fold_events` on them (the computation ``pass_fold_events`` replaces)."""
    from mechsyn.kinematics.folds import fold_events, touch_candidates
    from mechsyn.kinematics.tracking import _sweep_events

    N = U.shape[0]
    parts = [U] if split is None else [U[split:], U[:split][::-1]]
    order = [np.arange(N)] if split is None else [np.arange(split, N), np.arange(split - 1, -1, -1)]
    from mechsyn.kinematics import kernel

    start, out, ks, D = N, [], list(kernel.program(S, plan)[0][4]), st[3]
    tracks = []
    for (path, shift), p, idx in zip(paths, parts, order):
        n0 = path.shape[0]
        tracks.append((np.concatenate([path, p - shift]), n0, shift, D[:, np.concatenate([np.arange(start, start + n0),
                                                                                            idx])]))
        start += n0
    if any(touch_candidates(P).size for *_, P in tracks):
        return None
    for X, n0, shift, P in tracks:
        events, singular, _ = fold_events(S, plan, ks, sigmas, X, P, n0)
        out.append((singular[n0:], _sweep_events(events, n0, shift)))
    return out


def _cases(ex):
    files = [ex("textbook/watt_sixbar.yaml"), ex("textbook/fourbar.yaml"), ex("textbook/stephenson_sixbar.yaml")]
    # four-bars whose crank cannot turn fully (two dead points each way), drawn on both branches
    files += [mechanism_from_dict(fourbar_dict(a=2.0, b=3.0, c=2.5, g=4.0, theta=th, branch=br))
              for th, br in ((40.0, 1), (-30.0, -1), (100.0, 1))]
    grids = [(0.0, 361.0, 1.0), (360.0, -1.0, -3.0), (-180.0, 541.0, 2.5), (100.0, 261.0, 4.0), (0.0, 361.0, 0.25),
             (-800.0, 100.0, 2.5), (500.0, -300.0, -2.5)]
    for m in files:
        j = next(jj.id for jj in m.joints if jj.actuated)
        kp = cached_plan(m, inputs=(j,))
        for g in grids:
            yield m.name, g, kp.system, kp.groups, np.radians(np.arange(*g))[:, None]


def test_tracking_path_is_kept_and_read_only():
    """A tracking path depends on the drivers' types, the drawn and the first input values
    only: a refilled geometry takes the same (read-only) arrays; the path steps at most 1
    degree towards the first inputs moved by whole turns next to the drawn ones."""
    from mechsyn.kinematics.sweep import tracking_path

    m = mechanism_from_dict(fourbar_dict(a=1.0, b=3.5, c=3.0, g=4.0, theta=60.0))
    S = cached_plan(m, inputs=("A",)).system
    u0 = math.radians(60.0)
    first = np.array([u0 + 4 * math.pi + 0.1])  # two turns on, 5.73 degrees beyond the drawn angle
    path, shift = tracking_path(S, first)
    assert shift.tolist() == [first[0] - (first[0] - 4 * math.pi)]
    drawn = float(S.drivers[0].assembled)  # atan2 of the drawn crank: 60 degrees to the last place or two
    assert path.shape == (6, 1) and path[0, 0] == drawn and abs(drawn - u0) < 1e-15
    assert np.all(np.diff(path[:, 0]) <= math.radians(1.0) + 1e-15)
    assert abs(path[-1, 0] + (path[1, 0] - path[0, 0]) - (first[0] - shift[0])) < 1e-14
    with pytest.raises(ValueError):
        path[0, 0] = 0.0
    moved = mechanism_from_dict(fourbar_dict(a=1.0, b=3.6, c=2.9, g=4.1, theta=60.0))
    again = tracking_path(cached_plan(moved, inputs=("A",)).system, first)
    assert again[0] is path and again[1] is shift
    assert tracking_path(S, np.array([u0]))[0].shape == (1, 1)  # at the drawn input: the drawn values


def _folding_cases(ex):
    """:func:`_cases` and the six-bars moved so that both their groups fold (the second
    one's folds found by the root search, some hidden by the first one's), over their
    grids."""
    yield from _cases(ex)
    for f, jid, point in (("textbook/watt_sixbar.yaml", "G", (3.5, 5.0)),
                          ("textbook/stephenson_sixbar.yaml", "F", (5.5, 3.0))):
        m = ex(f)
        m = m.with_joints(tuple(replace(j, point=np.array(point, float)) if j.id == jid else j for j in m.joints))
        kp = cached_plan(m, inputs=("A",))
        for g in ((-90.0, 270.0, 4.0), (-5.0, 115.0, 3.0), (0.0, 361.0, 1.0), (500.0, -300.0, -2.5),
                  (100.0, 261.0, 4.0)):
            yield m.name, g, kp.system, kp.groups, np.radians(np.arange(*g))[:, None]


def test_the_kernels_fold_scan_equals_the_sweeps_python_scan(ex, monkeypatch):
    """``pass_fold_events`` reads every tracked sweep's folds, reassembly, singular rows
    and change-point candidates off the pass's rows laid out once, by the kernel
    (``kernel.fold_scan``); the tracked engine's sweep-by-sweep search in Python
    (:func:`fold_events`) gives the same events (every field; inputs to 1e-12) and
    singular rows, forwards, backwards, over several turns, where the drawn input lies
    outside the sweep, and where an upstream group's fold hides a group's own."""
    from mechsyn.kinematics import kernel, regular, folds, tracking

    seen = {"hidden": 0, "root": 0}
    real = kernel._plain()["hidden_fold"]

    def spy(f, fa, fb, tc, hidden, zero):  # which refinements the Python scan made
        t = real(f, fa, fb, tc, hidden, zero)
        seen["hidden" if hidden else "root"] += not math.isnan(t)
        return t

    monkeypatch.setitem(kernel._plain(), "hidden_fold", spy)
    events = before = folded = backward = 0
    for name, g, S, plan, U in _folding_cases(ex):
        split = drawn_row(S, U)
        parts = [U] if split is None else [U[split:], U[:split][::-1]]
        paths = [tracking.tracking_path(S, p[0]) for p in parts]
        X = np.concatenate([U] + [p for p, _ in paths])
        st = regular._pass(S, plan, X, np.ones(1), folds=True)
        fp = kernel.program(S, plan)[1]
        sigmas = [1.0 if s.kind == "drive_R" else fp[k, 2].real for k, s in enumerate(plan.steps)]
        got = folds.pass_fold_events(S, plan, st[3], U, split, paths, X)
        want = _per_sweep(S, plan, st, U, split, paths, sigmas)
        assert (got is None) == (want is None), (name, g)
        if got is None:
            continue
        folded += bool(sum(len(ev) for _, ev in got))
        backward += split is not None and bool(got[1][1])
        assert len(got) == len(want) == (1 if split is None else 2)
        for (s1, e1), (s2, e2) in zip(got, want):
            assert np.array_equal(s1, s2), (name, g)
            assert [{**e.to_dict(), "input": None} for e in e1] == [{**e.to_dict(), "input": None} for e in e2]
            for a, b in zip(e1, e2):
                assert np.allclose(a.input, b.input, rtol=1e-12, atol=1e-12), (name, g, a, b)
            events += len(e1)
            before += sum(bool(e.before_sweep) for e in e1)
    assert folded >= 20 and backward >= 5, (folded, backward)  # most pass dead points, some backwards
    assert events >= 200 and before >= 1 and seen["root"] >= 20 and seen["hidden"] >= 2, (events, before, seen)


def test_the_regular_pass_scans_its_folds_in_the_kernel(ex, monkeypatch):
    """A simulation through dead points on the regular pass makes no Python fold scan
    (no row-by-row Python, no Python root search): its events come from
    ``kernel.fold_scan``, the same as the tracked chain's."""
    from mechsyn.kinematics import folds
    from mechsyn.kinematics.analysis import simulate

    m = ex("textbook/watt_sixbar.yaml")
    x = np.arange(0.0, 361.0)
    want = simulate(m, {"A": x}, method="tracked chain").events

    def no_scan(*a, **k):
        raise AssertionError("the Python fold scan ran after a compiled pass")

    monkeypatch.setattr(folds, "_fold_scan", no_scan)
    got = simulate(m, {"A": x}, method="regular pass").events
    assert len(got) == len(want) >= 3 and sum(e.kind == "dead point" for e in got) >= 2
    for a, b in zip(got, want):
        assert {**a.to_dict(), "input": None} == {**b.to_dict(), "input": None}
        assert abs(a.input["A"] - b.input["A"]) < 1e-9, (a, b)


def test_tracking_paths_kept_for_the_same_first_rows():
    """A sweep of the same grid again (a drag, a design loop) takes the connecting paths
    kept with its system; any other first rows (or drawn row) take their own, each
    :func:`tracking_path`'s."""
    from mechsyn.kinematics import regular
    from mechsyn.kinematics.sweep import tracking_path

    S = cached_plan(mechanism_from_dict(fourbar_dict(a=1.0, b=3.5, c=3.0, g=4.0, theta=60.0)), inputs=("A",)).system
    U = np.radians(np.arange(0.0, 361.0))[:, None]
    for V in (U, U + 0.01, U[100:], np.radians(np.arange(361.0, 0.0, -2.0))[:, None]):
        split = drawn_row(S, V)
        got = regular._tracking_paths(S, V, split)
        assert regular._tracking_paths(S, V.copy(), split) is got
        firsts = [V[0]] if split is None else [V[split], V[split - 1]]
        assert len(got) == len(firsts)
        for (path, shift), first in zip(got, firsts):
            want = tracking_path(S, first)
            assert path is want[0] and shift is want[1]
    regular._tracking_paths(S, U, drawn_row(S, U))
    assert regular._tracking_paths(S, U, None)[0][0] is tracking_path(S, U[0])[0]  # the same rows, another split
