"""Branch tracking of Assur groups over a sweep: every branched group's assembly mode
followed on its discriminant through folds (dead points), change and branch points and
gaps (reassembly in the drawn mode), with the events refined by root finding on the
discriminant (:func:`solve_tracked`, :func:`solve_tracked_rates`).

At a change or branch point (the discriminant touches zero) the motion keeps the branch
whose velocity is continuous (``change_points="keep"``) or takes the other one
(``"switch"``); see docs/kinematics.md.
"""

from __future__ import annotations

import math

import numpy as np

from mechsyn.kinematics.chain import chain_poses, tracked_pass
from mechsyn.kinematics.groups import Plan, cons_of
from mechsyn.kinematics.positions import PoseState, TrackedPositions, pose_rows, solve_step
from mechsyn.kinematics.folds import SINGULAR_DISC, disc_at, swept, fold_events, touch_candidates
from mechsyn.kinematics.sweep import Event
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["BRANCHED", "REGULAR_DISC", "SINGULAR_DISC", "solve_tracked", "solve_tracked_rates", "tracking_path"]


#: Kinds of group with two assembly modes (a sign ``sigma`` chooses one).
BRANCHED = ("RRR", "RRP", "PRR", "RPR")


#: The longest step of a connecting path's R inputs.
_DEGREE = math.radians(1.0)


def _turned(kinds: tuple, u0: list, first: list) -> list:
    """The first input values ``first`` moved by whole turns (R inputs, ``kinds`` the
    drivers' types) to the values nearest the drawn ones ``u0`` (lists of floats)."""
    return [b - 2 * math.pi * round((b - a) / (2 * math.pi)) if kind == "R" else b
            for a, b, kind in zip(u0, first, kinds)]


def _connecting_path(kinds: tuple, scale: float, u0: list, u1: list, max_rows: int = 4000) -> np.ndarray:
    """Inputs from the drawn values ``u0`` towards ``u1`` (excluded; lists of floats) in
    steps of at most 1 degree (R) or 1 % of the mechanism's size ``scale`` (P)."""
    most = max(abs(b - a) / (_DEGREE if kind == "R" else 0.01 * scale) for a, b, kind in zip(u0, u1, kinds))
    n = int(min(max_rows, max(1, math.ceil(most))))
    if n == 1:  # the drawn values themselves (t = 0)
        return np.array([u0])
    t = np.arange(n) / n
    out = np.empty((n, len(u0)))
    for k, (a, b) in enumerate(zip(u0, u1)):  # u0 + t (u1 - u0), column by column
        np.multiply(t, b - a, out=out[:, k])
        out[:, k] += a
    return out


def _kinds(S: PlanarSystem) -> tuple[tuple, float]:
    """The drivers' types and the size the connecting paths' P steps are measured by."""
    kinds = tuple(d.type for d in S.drivers)
    return kinds, (S.scale if "P" in kinds else 1.0)


def regular_rows(S: PlanarSystem, U: np.ndarray, split: int | None) -> np.ndarray:
    """The rows ``U`` followed by the connecting paths from the drawn input values to the
    sweep (to rows ``split`` and ``split - 1`` when the drawn values lie between them,
    else to row 0), for :func:`mechsyn.kinematics.regular.regular_sweep`."""
    kinds, scale = _kinds(S)
    u0 = [float(d.assembled) for d in S.drivers]
    ends = [0] if split is None else [split, split - 1]
    return np.concatenate([U] + [_connecting_path(kinds, scale, u0, _turned(kinds, u0, U[e].tolist())) for e in ends])


#: Smallest normalised discriminant of every group over a sweep for which
#: :func:`mechsyn.kinematics.regular.regular_sweep` answers (below it :func:`solve_tracked` looks for folds and
#: change points: its candidates are local minima under 0.05).
REGULAR_DISC = 0.05 + 1e-9


def solve_tracked(S: PlanarSystem, plan: Plan, inputs: np.ndarray, switch: bool = False) -> TrackedPositions:
    """Poses for all inputs on the branch of the drawn configuration, with branch events.

    The branch rules (docs/kinematics.md, "Branches"):

    1. The drawn (file) configuration decides every group's assembly mode. The sweep is
       reached from the drawn input values along a straight path of inputs (backwards if
       the sweep starts below them), so the mode at the first input is the drawn mode
       continued, not the mode re-read there.
    2. A group's normalised discriminant ``Delta`` (RRR: ``h^2 / L1^2``; RRP: the
       circle-line discriminant over ``L1^2``; RPR: ``1 - (e/|AC|)^2``) crossing zero is a
       *fold* (dead point): the group cannot be assembled beyond it; the input is found by
       regula falsi (Illinois, :func:`_fold_root`) on ``Delta`` of that group alone
       (upstream groups re-evaluated at the trial input), to 1e-14 of the step.
    3. ``Delta`` touching zero without changing sign (a local minimum at zero, found by
       Brent's method on ``dDelta/du``) is a *bifurcation* (change point, flat rhombus):
       both modes meet, and the motion whose velocity is continuous is the one on which
       the signed height ``sigma sqrt(Delta)`` changes sign, so ``sigma`` flips there.
    4. After a gap the group reassembles in the drawn mode.

    ``inputs`` (N, n_inputs) in radians / length. ``switch``: at change / branch points
    take the other branch instead (``sigma`` kept: a parallelogram becomes an
    anti-parallelogram there); the events say so.
    """
    X, n0, shift = _tracking_rows(S, inputs)
    M = X.shape[0]
    st = PoseState(S, M)
    sigmas: list = []
    discs: dict = {}
    singular = np.zeros(M, bool)
    raw_events: list = []
    for k, step in enumerate(plan.steps):
        if step.kind not in BRANCHED:
            sigmas.append(solve_step(S, st, step, X, None))
            continue
        choose = _chooser(S, plan, k, sigmas, X, n0, switch, discs, raw_events, singular)
        sigmas.append(solve_step(S, st, step, X, choose))
    q = pose_rows(S, st, plan)
    for step in plan.steps:  # a link driven from the frame takes the input's own turn count
        if step.kind == "drive_R" and step.known[0] < 0:
            con = next(c for c in cons_of(S, step.joints[0]) if c.role == "drive")
            sgn = 1.0 if con.b == step.links[0] else -1.0
            q[n0:, 3 * step.links[0] + 2] += sgn * shift[con.driver]
    sig_out = [s[n0:] if isinstance(s, np.ndarray) else s for s in sigmas]
    return TrackedPositions(q[n0:], sig_out, {k: v[n0:] for k, v in discs.items()}, singular[n0:],
                            _sweep_events(raw_events, n0, shift))


def solve_tracked_rates(S: PlanarSystem, plan: Plan, parts: list, speeds: np.ndarray,
                        switch: bool = False) -> list[tuple]:
    """:func:`solve_tracked` and :func:`mechsyn.kinematics.chain.solve_all` of a driver-R + RRR chain for several
    sweeps (``parts``: arrays of input rows, each reached from the drawn configuration on
    its own) by the kernel's program (:func:`mechsyn.kinematics.chain.tracked_pass`):
    each group's signs are chosen by the branch rules on its discriminant, sweep by
    sweep, in the order of the steps.
    Returns per sweep ``q, qd, qdd`` (N, n), its singular rows and its events."""
    parts = [np.atleast_2d(np.asarray(p, float)) for p in parts]
    rows = [_tracking_rows(S, p) for p in parts]
    starts = np.cumsum([0] + [X.shape[0] for X, _, _ in rows])
    segs = [slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]
    sigmas: list = [1.0] * len(plan.steps)
    singular = np.zeros(int(starts[-1]), bool)
    raw_events: list = [[] for _ in parts]
    for k, step in enumerate(plan.steps):
        if step.kind in BRANCHED:
            sigmas[k] = _parts_chooser(S, plan, k, sigmas, rows, segs, switch, raw_events, singular)
    # the sweeps' own rows (not shifted by turns: the same numbers as an untracked pass);
    # the choosers' events and root searches use the shifted rows
    E = np.vstack([blk for (X, n0, _), U in zip(rows, parts) for blk in (X[:n0], U)])
    C, W, AL, _ = tracked_pass(S, plan, E, speeds, sigmas)
    out = []
    for (X, n0, shift), U, seg, evs in zip(rows, parts, segs, raw_events):
        sweep_rows = slice(seg.start + n0, seg.stop)
        q, qd, qdd = chain_poses(S, plan, U, C[:, :, sweep_rows], W[:, sweep_rows], AL[:, sweep_rows])
        out.append((q, qd, qdd, singular[sweep_rows], _sweep_events(evs, n0, shift)))
    return out


def _parts_chooser(S: PlanarSystem, plan: Plan, k: int, sigmas: list, rows: list, segs: list, switch: bool,
                   raw_events: list, singular: np.ndarray):
    """The sign chooser of branched step ``k`` over several sweeps' rows (``segs`` of the
    pass): the branch rules (:func:`_branch_signs`) applied to each sweep's rows alone;
    the signs are also put in ``sigmas[k]``."""
    def choose(disc: np.ndarray, s_file: float) -> np.ndarray:
        sig = np.empty(len(disc))
        for (X, n0, _), seg, evs in zip(rows, segs, raw_events):
            up = [s[seg] if isinstance(s, np.ndarray) else s for s in sigmas[:k]]
            sig[seg], found, sing = _branch_signs(S, plan, k, up, X, disc[seg], s_file, n0, switch)
            evs.extend(found)
            singular[seg][sing] = True
        sigmas[k] = sig
        return sig
    return choose


def _tracking_rows(S: PlanarSystem, inputs: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """The rows a tracked sweep evaluates: the connecting path from the drawn input
    values (``n0`` rows), then the sweep shifted by whole turns next to them."""
    U = np.atleast_2d(np.asarray(inputs, float))
    path, shift = tracking_path(S, U[0])
    return np.vstack([path, U - shift]), path.shape[0], shift


def tracking_path(S: PlanarSystem, first: np.ndarray, u0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The connecting path from the drawn input values to a tracked sweep whose first
    input values are ``first``, and the whole turns ``shift`` the sweep is tracked
    shifted by (R inputs a whole number of turns from the drawn values are the same
    configurations: the sweep is tracked next to the drawn values, so that its rows
    follow each other); ``u0``: the drawn input values when known. Both arrays are
    read-only: a sweep of the same first inputs from the same drawn values (a cached or
    a refilled geometry: the path does not depend on the links) takes them again."""
    a = tuple([float(d.assembled) for d in S.drivers] if u0 is None else u0.tolist())
    kinds, scale = _kinds(S)
    b = tuple(first.tolist())
    return S.topology.product(("tracking path", scale, a, b), lambda: _tracking_path(kinds, scale, a, b))


def _tracking_path(kinds: tuple, scale: float, u0: tuple, first: tuple) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tracking_path` of the drivers' types ``kinds`` (the topology's) and the
    size ``scale``, kept as the topology's product with the numbers it depends on."""
    shift = [b - c for b, c in zip(first, _turned(kinds, u0, first))]  # the numbers of first - (first - turns)
    path = _connecting_path(kinds, scale, list(u0), [b - c for b, c in zip(first, shift)])
    out = path, np.array(shift)
    for x in out:
        x.setflags(write=False)
    return out


def _chooser(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, n0: int, switch: bool,
             discs: dict, raw_events: list, singular: np.ndarray):
    """The sign chooser of branched step ``k``: called with the step's normalised
    discriminant and the drawn mode, it applies the branch rules (:func:`_branch_signs`),
    records the discriminant, events and singular rows, and returns the signs."""
    def choose(disc: np.ndarray, s_file: float) -> np.ndarray:
        sig, evs, sing = _branch_signs(S, plan, k, sigmas, X, disc, s_file, n0, switch)
        discs[k] = disc
        raw_events.extend(evs)
        singular[sing] = True
        return sig
    return choose


def _sweep_events(raw_events: list, n0: int, shift: np.ndarray) -> list:
    """Events of the tracked rows as events of the sweep (the connecting path's marked)."""
    sh = shift.tolist()
    out = []
    for e in raw_events:
        index, message, u, before = swept(e.index, e.message, e.input, n0, sh, e.before_sweep)
        out.append(e.with_(index=index, message=message, input=u, before_sweep=before))
    return out


def _branch_signs(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, disc: np.ndarray,
                  s_file: float, n0: int, switch: bool = False) -> tuple[np.ndarray, list, np.ndarray]:
    """Assembly sign per row of a branched step (rules of :func:`solve_tracked`)."""
    M = len(disc)
    step = plan.steps[k]
    group = "-".join(step.joints)
    size = np.array([1.0 if d.type == "R" else S.scale for d in S.drivers])  # inputs relative to the size
    events, singular, resets = fold_events(S, plan, [k], sigmas, X, disc[None], n0)
    breaks: list[tuple[int, str]] = [(i, "reset") for i in resets[0]]  # (row, "flip" | "reset")
    # bifurcations: local minima of the discriminant at zero
    touched: list = []
    for i in touch_candidates(disc).tolist():
        t_star, dmin = _touch(S, plan, k, sigmas, X, i)
        if dmin > 1e-10:
            continue  # a sharp but regular turn
        if dmin < -1e-10:  # the group folds and unfolds within one step: a short gap
            events.append(Event(i, "dead point", f"the group {group} cannot be assembled in a short interval near "
                                "this input (it folds and unfolds within one step): refine the input step",
                                X[i].tolist(), group))
            breaks.append((i + 1, "reset"))
            continue
        # where the crossing lies: at row i (|t| tiny), or between i and a neighbour
        if abs(t_star) < 1e-7:
            row, at = i + 1, i
            singular[i] = True
        elif t_star > 0:
            row, at = i + 1, i + 1
        else:
            row, at = i, i
        u = X[i] + t_star * (X[i + 1] - X[i]) if t_star >= 0 else X[i] + t_star * (X[i] - X[i - 1])
        if any(abs(i - j) <= 2 and np.abs((u - v) / size).max() < 1e-8 for j, v in touched):
            continue  # the same crossing seen from the neighbouring sample
        touched.append((i, u))
        if not switch:
            breaks.append((row, "flip"))
        events.append(Event(at, "singular", input=u.tolist(), group=group, crossed=bool(not singular[i]),
                       message=f"change / branch point: the group {group} is folded flat here (its two "
                                  "assembly modes meet); "
                                  + ("the motion switches to the other branch (change_points='switch')" if switch
                                     else "the motion continues on the branch whose velocity is continuous "
                                          "(the drawn branch)")
                                  + ("; velocities and accelerations are not defined at this input (null)"
                                     if singular[i] else "")))
    sig = np.full(M, s_file)
    cur = s_file
    last = 0
    for row, kind in sorted(breaks):
        sig[last:row] = cur
        cur = -cur if kind == "flip" else s_file
        last = row
    sig[last:] = cur
    return sig, events, singular


def _touch(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, i: int) -> tuple[float, float]:
    """Where the discriminant of step ``k`` is least near row ``i``: (t, value), with ``t``
    in [-1, 1] (``t < 0`` towards row i-1, ``t > 0`` towards row i+1), by Brent's method on
    the central difference of the discriminant."""
    from scipy.optimize import brentq

    da, db = X[i] - X[i - 1], X[i + 1] - X[i]

    def at(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        P = X[i] + np.where(t[:, None] >= 0, t[:, None] * db, t[:, None] * da)
        return disc_at(S, plan, k, sigmas, np.full(len(t), i), P)

    h = 1e-6

    def slope(t: float) -> float:
        v = at(np.array([t - h, t + h]))
        return float(v[1] - v[0])

    ts = np.linspace(-1, 1, 9)
    vals = at(ts)
    j = int(np.nanargmin(vals))
    lo, hi = ts[max(0, j - 1)], ts[min(8, j + 1)]
    try:
        t = brentq(slope, lo + h, hi - h, xtol=1e-12)
    except ValueError:
        t = float(ts[j])
    dmin = float(at(np.array([t]))[0])
    if abs(dmin) <= 1e-10:
        # the minimum of a quadratic is found by its slope only to about sqrt(eps): at a
        # tangency the signed height sqrt(Delta) is linear on each side, so the secants
        # of sqrt(Delta) from both sides, extrapolated to zero spacing (Richardson),
        # give its zero to round-off
        def secant_roots(dt: float) -> float:
            ts_ = t + np.array([-2 * dt, -dt, dt, 2 * dt])
            f = np.sqrt(np.maximum(at(ts_), 0.0))
            left = ts_[1] - f[1] * (ts_[1] - ts_[0]) / (f[1] - f[0])
            right = ts_[2] - f[2] * (ts_[3] - ts_[2]) / (f[3] - f[2])
            return 0.5 * (left + right)

        with np.errstate(invalid="ignore", divide="ignore"):
            r1, r2 = secant_roots(1e-2), secant_roots(2e-2)
        t_fine = (4 * r1 - r2) / 3
        if np.isfinite(t_fine) and abs(t_fine - t) < 0.1:
            t = float(t_fine)
    return t, dmin
