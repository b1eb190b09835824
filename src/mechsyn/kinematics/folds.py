"""The fold search of a tracked sweep: where a group's assembly ends (a dead point, a
limit of the working range) and starts again, from the groups' normalised discriminants
(:func:`fold_events`; the regular pass's :func:`pass_fold_events`, by the kernel's
:func:`mechsyn.kinematics.kernel.fold_scan`), each fold refined
on its discriminant along the input segment (a closed form where the group closes a
four-bar, :func:`_four_bar_specs`; else secant steps) and the folds
hidden behind an upstream group's. The scan and the refinement are the kernel's, one
implementation: compiled on the regular pass's program, run as plain Python on the
generic group steps (:func:`mechsyn.kinematics.kernel.scan_sweep`). The branch tracking
(:mod:`mechsyn.kinematics.tracking`) and the regular pass
(:mod:`mechsyn.kinematics.regular`) call it.
"""

from __future__ import annotations

import math

import numpy as np

from mechsyn.kinematics import kernel
from mechsyn.kinematics.groups import Plan, geometry_memo
from mechsyn.kinematics.positions import PoseState, solve_step
from mechsyn.kinematics.sweep import Event
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["SINGULAR_DISC", "fold_events", "pass_fold_events", "touch_candidates"]


#: Normalised discriminant below which a group counts as folded (tangent circles,
#: collinear links): its rates there are not defined.
SINGULAR_DISC = 1e-12


#: Relative size of the negative discriminant still taken as zero (round-off).
_ZERO_DISC = 1e-12


#: What an event on a connecting path (:func:`~mechsyn.kinematics.sweep.tracking_path`) says first.
ON_THE_WAY = "between the drawn configuration and the first input: "


def disc_at(S: PlanarSystem, plan: Plan, k: int, sigmas: list, rows: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Normalised discriminant of step ``k`` at the inputs ``X`` (M, n_inputs), upstream
    steps solved with their modes of the sweep rows ``rows`` (M,)."""
    st = PoseState(S, X.shape[0])
    for j in range(k):
        s = sigmas[j]
        solve_step(S, st, plan.steps[j], X, s[rows] if isinstance(s, np.ndarray) else s)
    out = []

    def capture(disc: np.ndarray, s_file: float) -> float:
        out.append(disc)
        return 1.0

    with np.errstate(invalid="ignore", divide="ignore"):
        solve_step(S, st, plan.steps[k], X, capture)
    return out[0]


def _disc_line(S: PlanarSystem, plan: Plan, k: int, sigmas: list, xa: list, xb: list, i0: int):
    """Discriminant of step ``k`` on the segment of inputs from ``xa`` (t = 0, row ``i0``)
    to ``xb`` (t = 1), the upstream groups in their modes of row ``i0``: a scalar
    function (for a driver-R + RRR chain the kernel's, on the regular pass's program:
    the numbers of ``xa + t (xb - xa)``)."""
    dx = [b - a for a, b in zip(xa, xb)]
    if plan.closed_form_rates:
        prog = kernel.program(S, plan)
        sg = np.ones(len(plan.steps))
        for j, s in enumerate(sigmas[:k]):
            if s is not None:
                sg[j] = float(s[i0]) if isinstance(s, np.ndarray) else float(s)
        return lambda t: kernel.scalar_disc(prog, k, sg, np.array([a + t * d for a, d in zip(xa, dx)]))
    rows = np.array([i0])
    return lambda t: float(disc_at(S, plan, k, sigmas, rows, np.array([[a + t * d for a, d in zip(xa, dx)]]))[0])


def touch_candidates(disc: np.ndarray) -> np.ndarray:
    """Rows where a group's normalised discriminant ``disc`` (per row, in sweep order) may
    touch zero: its local minima under 0.05 among the rows where it is assembled (the
    candidates of a change or branch point, decided by :func:`_touch`); of several groups
    (rows of ``disc``): any candidate shows (the flat indices are not rows then)."""
    return np.flatnonzero(_low_minima(np.where(disc > -_ZERO_DISC, np.maximum(disc, 0.0), np.nan))) + 1


def _low_minima(d: np.ndarray) -> np.ndarray:
    """Where (the inner rows, ``d[..., 1:-1]``) the discriminants ``d`` (NaN where not
    assembled, else at least 0) have a local minimum under 0.05."""
    mid = d[..., 1:-1]
    out = mid < 0.05
    out &= mid <= d[..., :-2]
    out &= mid <= d[..., 2:]
    return out


def fold_events(S: PlanarSystem, plan: Plan, ks: list[int], sigmas: list, X: np.ndarray, D: np.ndarray,
                n0: int) -> tuple[list, np.ndarray, list]:
    """Folds and reassembly of the branched steps ``ks`` on one sweep's rows ``X`` (M,
    n_inputs; the first ``n0`` the connecting path) from their normalised discriminants
    ``D`` (len(ks), M), all groups at once (branch rules 2 and 4 of :func:`solve_tracked`).

    A fold (the group's own discriminant changes sign between two rows, both evaluated)
    is a dead point, its input found on the discriminant along the segment between the
    rows (the kernel's secant steps on :func:`_disc_line`, upstream groups in their modes
    ``sigmas`` of the earlier row; the ends' values are ``D``'s). A group assembled at
    one row and cut off at the next by an upstream group's fold may fold first between
    the same rows: its discriminant at the upstream fold decides, and the earlier fold is
    the limit of the working range (likewise where the assembly starts again). A row
    where the group assembles after rows where it (or an upstream group) did not is a
    reassembly. Returns the events (per group in the order of ``ks``: its folds, then its
    reassemblies, each by row), the singular rows (M,) (a group folded flat within
    :data:`SINGULAR_DISC`) and per group the rows where it reassembles. Every such row
    is one where the group's assembly changes (:func:`_fold_scan`)."""
    ok = D > -_ZERO_DISC
    singular = (ok & (D < SINGULAR_DISC)).any(axis=0)
    found = _fold_scan(S, plan, ks, sigmas, X, D, n0)
    _, names, messages = _fold_words(plan, ks)
    events = [Event(int(i), "reassembled" if kind == 2 else "dead point", messages[int(g)][int(kind)], u,
                    names[int(g)]) for _, i, kind, g, *u in found.tolist()]
    back = ok[:, 1:] & ~ok[:, :-1]  # the rows where each group assembles again
    return events, singular, [(np.flatnonzero(r) + 1).tolist() for r in back]


def _fold_scan(S: PlanarSystem, plan: Plan, ks: list[int], sigmas: list, X: np.ndarray, D: np.ndarray,
               n0: int) -> np.ndarray:
    """:func:`fold_events`' events as rows (sweep, row, kind, group, input): the kernel's
    scan of one sweep (:func:`mechsyn.kinematics.kernel.scan_sweep`) run as plain Python,
    each fold refined in closed form where the group closes a four-bar
    (:func:`_four_bar_specs`), else on the group's discriminant along the segment of
    inputs (:func:`_disc_line`, upstream groups in their modes ``sigmas`` of the earlier
    row)."""
    def line(g: int, i: int, xa: np.ndarray, xb: np.ndarray):
        return _disc_line(S, plan, ks[g], sigmas, xa.tolist(), xb.tolist(), i - 1)

    return kernel.scan_sweep(np.ascontiguousarray(D, float), np.ascontiguousarray(X, float), n0, _ZERO_DISC,
                             _four_bar_specs(S, plan, ks), line)


#: What a fold scan's events say: the assembly ends, starts again, reassembles (``{}``: the group).
_FOLD_MESSAGES = ("assembly ends: the group {} folds flat (its discriminant changes sign: a dead point / limit of "
                  "the working range)", "assembly starts again here: the other limit of a working range",
                  "assembles again after a gap, in the assembly mode of the drawn configuration for the group {} "
                  "(the mode nearest the drawn one)")


def pass_fold_events(S: PlanarSystem, plan: Plan, D: np.ndarray, U: np.ndarray, split: int | None,
                     paths: list, pass_rows: np.ndarray | None = None) -> list | None:
    """:func:`fold_events` of the tracked sweeps of one regular pass (the sweep ``U`` (N,
    n_inputs), then the connecting paths ``paths`` (``(path, shift)`` of
    :func:`~mechsyn.kinematics.sweep.tracking_path`) of the one sweep, or of the sweeps
    forwards from row ``split`` and backwards from row ``split - 1``), from the groups'
    normalised discriminants ``D`` (groups in the order of their steps, the pass's rows),
    every group in its drawn mode: per sweep its singular rows and events along it; None
    when a discriminant has a local minimum under 0.05 (:func:`touch_candidates`: a
    change point may be near).

    The pass's rows are read once, laid out so that each sweep's rows follow each other
    (the backward sweep from right to left, then the forward one), and the kernel scans
    them (:func:`mechsyn.kinematics.kernel.fold_scan`, the decisions of :func:`_fold_scan`;
    ``pass_rows``: the pass's input rows, ``U`` then the paths, when at hand).
    """
    N = U.shape[0]
    n0s = [path.shape[0] for path, _ in paths]
    perm, b = _pass_layout(N, split, n0s)
    program = kernel.program(S, plan)  # the pass's program (kept with S)
    ks, names, messages = S.topology.product("fold scan", lambda: _fold_words(plan, program[0][4]), plan)
    X = np.concatenate([U] + [path for path, _ in paths]) if pass_rows is None else pass_rows
    low, singular, found = kernel.fold_scan(program, D, perm, b, X, paths, ks, _four_bar_specs(S, plan, ks),
                                            _ZERO_DISC, SINGULAR_DISC)
    if low:
        return None
    out = [(singular[b + n0s[0]:], [])] + ([(singular[b - n0s[1] - 1::-1], [])] if len(paths) > 1 else [])
    for w, i, kind, g, *u in found.tolist():
        w, i, kind, g = int(w), int(i), int(kind), int(g)
        n0 = n0s[w]
        out[w][1].append(Event(max(0, i - n0), "reassembled" if kind == 2 else "dead point",
                               messages[g][kind] if i >= n0 else ON_THE_WAY + messages[g][kind], u, names[g],
                               before_sweep=True if i < n0 else None))
    return out


def _fold_words(plan: Plan, ks: list) -> tuple:
    """The groups' steps ``ks`` as an array, their names and their events' messages."""
    names = ["-".join(plan.steps[k].joints) for k in ks]
    return np.array(ks, np.int64), names, [[m.format(name) for m in _FOLD_MESSAGES] for name in names]


def _pass_layout(N: int, split: int | None, n0s: list) -> tuple[np.ndarray, int]:
    """The order of a pass's rows (the sweep's N, then the connecting paths of ``n0s``
    rows) in which each tracked sweep's rows follow each other: ``[U[:split], path 2
    reversed, path 1, U[split:]]`` (or ``[path, U]``), and where the forward sweep starts
    (a few microseconds: not kept)."""
    if split is None:
        return np.concatenate([np.arange(N, N + n0s[0]), np.arange(N)]), 0
    n1, n2 = n0s
    return np.concatenate([np.arange(split), np.arange(N + n1 + n2 - 1, N + n1 - 1, -1), np.arange(N, N + n1),
                           np.arange(split, N)]), split + n2


def _four_bar_specs(S: PlanarSystem, plan: Plan, ks: list) -> np.ndarray:
    """Where RRR steps ``ks`` fold, in closed form when a group closes a four-bar (one end
    joint on the frame, the other on a crank turned by the only input about a frame
    pivot, :func:`_four_bar_form`): it folds where ``|P(u) - C| = L1 + L2`` or ``|L1 -
    L2|``, ``P(u) = O + e^{i s u} w`` (``O`` the crank's pivot, ``w`` the joint's offset
    from it on the crank, ``s`` the input's sign), by the law of cosines: ``|v|^2 + |w|^2
    + 2 |v| |w| cos(s u + arg w - arg v) = (L1 +- L2)^2`` with ``v = O - C``. Per group the
    numbers :func:`mechsyn.kinematics._kernel_numba._four_bar_t` reads (a four-bar 1 or
    not 0, ``|v|``, ``|w|``, ``arg w - arg v``, ``s``, the two squared distances), read
    off the regular pass's program and kept with the system."""
    memo = geometry_memo(S)
    key = ("four-bar folds", id(plan), tuple(ks))
    hit = memo.get(key)
    if hit is not None and hit[0] is plan:
        return hit[1]
    forms = S.topology.product(("four-bar forms", tuple(ks)), lambda: [_four_bar_form(S, plan, k) for k in ks], plan)
    out = np.zeros((len(ks), 7))
    for r, (k, form) in enumerate(zip(ks, forms)):
        if form is not None:
            _, fp, anc_s = kernel.program(S, plan)
            c, on_frame, crank = form
            s1, s3 = fp[k, 5], fp[k, 6]
            v, w = fp[c, 1] - (s1 if on_frame == 1 else s3), (s3 if on_frame == 1 else s1) - anc_s[crank]
            L1, L2 = math.sqrt(fp[k, 0].real), math.sqrt(fp[k, 0].imag)
            out[r] = (1.0, abs(v), abs(w), math.atan2(w.imag, w.real) - math.atan2(v.imag, v.real), fp[c, 0].real,
                      (L1 + L2) ** 2, (L1 - L2) ** 2)
    memo[key] = (plan, out)
    return out


def _four_bar_form(S: PlanarSystem, plan: Plan, k: int) -> tuple | None:
    """Whether RRR step ``k`` closes a four-bar (:func:`_four_bar_specs`; the topology
    decides it): ``(the crank's drive step, 1 when the group's first end joint is on the
    frame else 3, the crank's link)``, or None."""
    if len(S.drivers) != 1 or not plan.closed_form_rates:
        return None
    cranks = {s.links[0]: c for c, s in enumerate(plan.steps) if s.kind == "drive_R" and s.known[0] < 0}
    k1, k3 = plan.steps[k].known
    if k1 == k3 or -1 not in (k1, k3):
        return None
    crank = k3 if k1 < 0 else k1
    return (cranks[crank], 1 if k1 < 0 else 3, crank) if crank in cranks else None
