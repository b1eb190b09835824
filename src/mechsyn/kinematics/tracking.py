"""Branch tracking of Assur groups over a sweep: every branched group's assembly mode
followed on its discriminant through folds (dead points), change and branch points and
gaps (reassembly in the drawn mode), with the events refined by root finding on the
discriminant (:func:`solve_tracked`, :func:`solve_tracked_rates`).

At a change or branch point (the discriminant touches zero) the motion keeps the branch
whose velocity is continuous (``change_points="keep"``) or takes the other one
(``"switch"``); see docs/kinematics.md.
"""

from __future__ import annotations


import numpy as np

from mechsyn.kinematics.chain import chain_poses, tracked_pass
from mechsyn.kinematics.groups import Plan, cons_of
from mechsyn.kinematics.positions import PoseState, TrackedPositions, pose_rows, solve_step
from mechsyn.kinematics.folds import ON_THE_WAY, SINGULAR_DISC, disc_at, fold_events, touch_candidates
from mechsyn.kinematics.sweep import Event, tracking_path
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["BRANCHED", "SINGULAR_DISC", "solve_tracked", "solve_tracked_rates"]


#: Kinds of group with two assembly modes (a sign ``sigma`` chooses one).
BRANCHED = ("RRR", "RRP", "PRR", "RPR")


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
    rows = _tracking_rows(S, inputs)
    X, n0, shift = rows
    M = X.shape[0]
    st = PoseState(S, M)
    sigmas: list = [None] * len(plan.steps)
    discs: dict = {}
    singular = np.zeros(M, bool)
    raw_events: list = []
    for k, step in enumerate(plan.steps):
        choose = _chooser(S, plan, k, sigmas, [rows], [slice(0, M)], switch, [raw_events], singular, discs) \
            if step.kind in BRANCHED else None
        sigmas[k] = solve_step(S, st, step, X, choose)
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
            sigmas[k] = _chooser(S, plan, k, sigmas, rows, segs, switch, raw_events, singular)
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


def _chooser(S: PlanarSystem, plan: Plan, k: int, sigmas: list, rows: list, segs: list, switch: bool,
             raw_events: list, singular: np.ndarray, discs: dict | None = None):
    """The sign chooser of branched step ``k`` over one or several sweeps' rows (``segs``
    of the pass, ``rows`` their :func:`_tracking_rows`): called with the step's
    normalised discriminant and the drawn mode, it applies the branch rules
    (:func:`_branch_signs`) to each sweep's rows alone, records the events (per sweep in
    ``raw_events``), the singular rows and the discriminant (in ``discs``, when given),
    puts the signs in ``sigmas[k]`` and returns them."""
    def choose(disc: np.ndarray, s_file: float) -> np.ndarray:
        sig = np.empty(len(disc))
        for (X, n0, _), seg, evs in zip(rows, segs, raw_events):
            up = [s[seg] if isinstance(s, np.ndarray) else s for s in sigmas[:k]]
            sig[seg], found, sing = _branch_signs(S, plan, k, up, X, disc[seg], s_file, n0, switch)
            evs.extend(found)
            singular[seg][sing] = True
        if discs is not None:
            discs[k] = disc
        sigmas[k] = sig
        return sig
    return choose


def _tracking_rows(S: PlanarSystem, inputs: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """The rows a tracked sweep evaluates: the connecting path from the drawn input
    values (``n0`` rows), then the sweep shifted by whole turns next to them."""
    U = np.atleast_2d(np.asarray(inputs, float))
    path, shift = tracking_path(S, U[0])
    return np.vstack([path, U - shift]), path.shape[0], shift


def _sweep_events(raw_events: list, n0: int, shift: np.ndarray) -> list:
    """Events of the tracked rows (the first ``n0`` the connecting path, the rest the
    sweep shifted by the whole turns ``shift``) as events of the sweep: their row along
    it, the connecting path's marked (``before_sweep``, their message says so), the
    sweep's inputs with the whole turns added back."""
    sh = shift.tolist()
    out = []
    for e in raw_events:
        message, before, u = e.message, e.before_sweep, e.input
        if e.index < n0:  # on the way from the drawn configuration to the sweep
            message, before = ON_THE_WAY + message, True
        if not before:
            u = [x + s for x, s in zip(u, sh)]
        out.append(e.with_(index=max(0, e.index - n0), message=message, input=u, before_sweep=before))
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
