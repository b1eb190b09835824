"""The fold search of a tracked sweep: where a group's assembly ends (a dead point, a
limit of the working range) and starts again, from the groups' normalised discriminants
(:func:`fold_events`; the regular pass's :func:`pass_fold_events`, by the kernel's
:func:`mechsyn.kinematics.kernel.fold_scan`), each fold refined
on its discriminant along the input segment (a closed form where the group closes a
four-bar, :func:`_four_bar_fold`; else secant steps, :func:`_hidden_fold`) and the folds
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
_ON_THE_WAY = "between the drawn configuration and the first input: "


def swept(i: int, message: str, u: list, n0: int, shift: list, before: bool | None = None) -> tuple:
    """An event's row, message, input and ``before_sweep`` along the sweep from its row
    ``i`` of the tracked rows (the first ``n0`` the connecting path, the rest the sweep
    shifted by the whole turns ``shift``): :func:`_sweep_events` of one event."""
    if i < n0:  # on the way from the drawn configuration to the sweep
        message, before = _ON_THE_WAY + message, True
    if not before:
        u = [x + s for x, s in zip(u, shift)]
    return max(0, i - n0), message, u, before


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
    rows (:func:`_hidden_fold` on :func:`_disc_line`, upstream groups in their modes
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
    names = ["-".join(plan.steps[k].joints) for k in ks]
    events = [Event(int(i), "reassembled" if kind == 2 else "dead point", _FOLD_MESSAGES[int(kind)].format(names[int(g)]),
                    u, names[int(g)]) for _, i, kind, g, *u in found.tolist()]
    back = ok[:, 1:] & ~ok[:, :-1]  # the rows where each group assembles again
    return events, singular, [(np.flatnonzero(r) + 1).tolist() for r in back]


def _fold_scan(S: PlanarSystem, plan: Plan, ks: list[int], sigmas: list, X: np.ndarray, D: np.ndarray,
               n0: int) -> np.ndarray:
    """:func:`fold_events`' events as rows (sweep, row, kind, group, input): the kernel's
    scan of one sweep (:func:`mechsyn.kinematics.kernel.scan_sweep`) run as plain Python,
    each fold refined in closed form where the group closes a four-bar
    (:func:`_four_bar_fold`), else on the group's discriminant along the segment of inputs
    (:func:`_disc_line`, upstream groups in their modes ``sigmas`` of the earlier row;
    :func:`_hidden_fold`)."""
    return kernel.scan_sweep(np.ascontiguousarray(D, float), np.ascontiguousarray(X, float), n0, _ZERO_DISC,
                             _refine, (S, plan, ks, sigmas))


def _refine(c: tuple, g: int, i: int, hidden: int, xa: np.ndarray, xb: np.ndarray, fa: float, fb: float,
            ends: np.ndarray, starts: np.ndarray) -> float:
    """Where (t) group ``g`` of the scan folds between rows ``i - 1`` and ``i`` (inputs
    ``xa``, ``xb``), NaN when it does not (:func:`_fold_scan`'s refinement)."""
    S, plan, ks, sigmas = c
    t = _four_bar_fold(S, plan, ks[g], xa, xb) if not hidden else None
    if t is None:
        t = _hidden_fold(_disc_line(S, plan, ks[g], sigmas, xa.tolist(), xb.tolist(), i - 1), fa, fb, ends, starts,
                         i, hidden)
    return math.nan if t is None else t


#: What a fold scan's events say: the assembly ends, starts again, reassembles (``{}``: the group).
_FOLD_MESSAGES = ("assembly ends: the group {} folds flat (its discriminant changes sign: a dead point / limit of "
                  "the working range)", "assembly starts again here: the other limit of a working range",
                  "assembles again after a gap, in the assembly mode of the drawn configuration for the group {} "
                  "(the mode nearest the drawn one)")


def pass_fold_events(S: PlanarSystem, plan: Plan, discs: dict, sigmas: list, U: np.ndarray, split: int | None,
                     paths: list, pass_rows: np.ndarray | None = None, block: np.ndarray | None = None) -> list | None:
    """:func:`fold_events` of the tracked sweeps of one regular pass (the sweep ``U`` (N,
    n_inputs), then the connecting paths ``paths`` (``(path, shift)`` of
    :func:`~mechsyn.kinematics.sweep.tracking_path`) of the one sweep, or of the sweeps forwards from row ``split``
    and backwards from row ``split - 1``), from the groups' normalised discriminants
    ``discs`` (step -> its values on the pass's rows), every group in its mode
    ``sigmas``: per sweep its singular rows and events along it (:func:`_sweep_events`);
    None when a discriminant has a local minimum under 0.05 (:func:`touch_candidates`:
    a change point may be near).

    The pass's rows are read once, laid out so that each sweep's rows follow each other
    (the backward sweep from right to left, then the forward one), and the kernel scans
    them (:func:`mechsyn.kinematics.kernel.fold_scan`, the decisions of :func:`_fold_scan`;
    ``pass_rows``: the pass's input rows, ``U`` then the paths, when at hand; ``block``:
    the discriminants as rows of one array, in the order of their steps, when at hand).
    """
    N = U.shape[0]
    n0s = tuple(path.shape[0] for path, _ in paths)
    perm, b = _pass_layout(N, split, n0s)
    ks = sorted(discs)
    program = kernel.program(S, plan)  # the pass's program (kept with S)
    X = np.concatenate([U] + [path for path, _ in paths]) if pass_rows is None else pass_rows
    return _compiled_fold_events(S, plan, program, [discs[k] for k in ks] if block is None else block, ks,
                                 perm, b, X, paths)


def _compiled_fold_events(S: PlanarSystem, plan: Plan, program: tuple, discs: list, ks: list, perm: np.ndarray,
                          b: int, X: np.ndarray, paths: list) -> list | None:
    """:func:`pass_fold_events` by the kernel (``program``: the pass's arrays, ``X``: its
    input rows; :func:`mechsyn.kinematics.kernel.fold_scan`)."""
    steps, names, messages = S.topology.product("fold scan", lambda: _fold_words(plan, ks), plan)
    memo = geometry_memo(S)
    specs = memo.get(("four-bar folds", id(plan)))  # this geometry's closed-form fold numbers per group
    if specs is None or specs[0] is not plan:
        specs = memo[("four-bar folds", id(plan))] = (plan, np.array([_four_bar_numbers(_four_bar_spec(S, plan, k))
                                                                      for k in ks]))
    low, singular, found = kernel.fold_scan(program, discs, perm, b, X, paths, steps, specs[1], _ZERO_DISC,
                                            SINGULAR_DISC)
    if low:
        return None
    n0s = [path.shape[0] for path, _ in paths]
    out = [(singular[b + n0s[0]:], [])] + ([(singular[b - n0s[1] - 1::-1], [])] if len(paths) > 1 else [])
    for w, i, kind, g, *u in found.tolist():
        w, i, kind, g = int(w), int(i), int(kind), int(g)
        n0 = n0s[w]
        out[w][1].append(Event(max(0, i - n0), "reassembled" if kind == 2 else "dead point",
                               messages[g][kind] if i >= n0 else _ON_THE_WAY + messages[g][kind], u, names[g],
                               before_sweep=True if i < n0 else None))
    return out


def _fold_words(plan: Plan, ks: list) -> tuple:
    """The groups' steps ``ks`` as an array, their names and their events' messages."""
    names = ["-".join(plan.steps[k].joints) for k in ks]
    return np.array(ks, np.int64), names, [[m.format(name) for m in _FOLD_MESSAGES] for name in names]


def _four_bar_numbers(spec: tuple | None) -> tuple:
    """The numbers :func:`_four_bar_fold` reads off :func:`_four_bar_spec`'s ``spec``: a
    four-bar (1) or not (0), ``|v|``, ``|w|``, ``arg w - arg v``, the input's sign, the
    two squared distances of its folds."""
    if spec is None:
        return (0.0,) * 7
    v, w, sgn, targets = spec
    return (1.0, abs(v), abs(w), math.atan2(w.imag, w.real) - math.atan2(v.imag, v.real), sgn, *targets)


def _pass_layout(N: int, split: int | None, n0s: tuple) -> tuple[np.ndarray, int]:
    """The order of a pass's rows (the sweep's N, then the connecting paths of ``n0s``
    rows) in which each tracked sweep's rows follow each other: ``[U[:split], path 2
    reversed, path 1, U[split:]]`` (or ``[path, U]``), and where the forward sweep starts
    (a few microseconds: not kept)."""
    if split is None:
        perm = np.concatenate([np.arange(N, N + n0s[0]), np.arange(N)])
        b = 0
    else:
        n1, n2 = n0s
        perm = np.concatenate([np.arange(split), np.arange(N + n1 + n2 - 1, N + n1 - 1, -1), np.arange(N, N + n1),
                               np.arange(split, N)])
        b = split + n2
    return perm, b


def _four_bar_fold(S: PlanarSystem, plan: Plan, k: int, xa: list, xb: list) -> float | None:
    """Where (t in [0, 1]) RRR step ``k`` folds on the segment of inputs from ``xa`` to
    ``xb``, in closed form when the group closes a four-bar: one end joint on the frame,
    the other on a crank turned by the only input about a frame pivot. The group folds
    where ``|P(u) - C| = L1 + L2`` or ``|L1 - L2|``, ``P(u) = O + e^{i s u} w`` (``O``
    the crank's pivot, ``w`` the joint's offset from it on the crank, ``s`` the input's
    sign), by the law of cosines: ``|v|^2 + |w|^2 + 2 |v| |w| cos(s u + arg w - arg v) =
    (L1 +- L2)^2`` with ``v = O - C``. None when the group is not such a four-bar or the
    segment holds not exactly one such angle (the numerical search decides)."""
    t = kernel.four_bar_fold(np.array(_four_bar_numbers(_four_bar_spec(S, plan, k))), float(xa[0]), float(xb[0]))
    return None if math.isnan(t) else float(t)


def _four_bar_spec(S: PlanarSystem, plan: Plan, k: int) -> tuple | None:
    """``(v, w, s, ((L1 + L2)^2, (L1 - L2)^2))`` of :func:`_four_bar_fold` for RRR step
    ``k``, or None (kept with the system). Whether the group closes a four-bar is the
    topology's (:func:`_four_bar_form`); the numbers are read off the regular pass's
    program."""
    memo = geometry_memo(S)
    key = ("four-bar fold", id(plan), k)
    if key in memo:
        return memo[key]
    out = None
    form = S.topology.product(("four-bar form", k), lambda: _four_bar_form(S, plan, k), plan)
    if form is not None:
        kernel.program(S, plan)  # the regular program (steps, anchors, origin: complex local points) kept with S
        c, on_frame, crank = form
        steps, cx, _ = memo[("regular", id(plan))][1]
        O, sgn, pivot = steps[c][6], steps[c][5], cx[crank][1]
        _, _, _, _, L1s, L2s, _, _, _, s1, s3 = steps[k]
        frame_end, crank_end = (s1, s3) if on_frame == 1 else (s3, s1)
        L1, L2 = math.sqrt(L1s), math.sqrt(L2s)
        out = (O - frame_end, crank_end - pivot, sgn, ((L1 + L2) ** 2, (L1 - L2) ** 2))
    memo[key] = out
    return out


def _four_bar_form(S: PlanarSystem, plan: Plan, k: int) -> tuple | None:
    """Whether RRR step ``k`` closes a four-bar (:func:`_four_bar_fold`; the topology
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


def _hidden_fold(f, fa: float, fb: float, ends: np.ndarray, starts: np.ndarray, i: int,
                 hidden: int) -> float | None:
    """Where (t) a group folds between rows ``i - 1`` and ``i`` (``f`` its discriminant
    along the segment, ``fa``, ``fb`` its values at the rows), by the kernel's refinement
    (:func:`mechsyn.kinematics.kernel.hidden_fold`). ``hidden`` 0: its own
    discriminant changes sign between the rows (t at the ends when the change is round-off
    only); 1: it is assembled at row i - 1 and an upstream group ends the assembly at
    ``ends[i]``: the group's own fold before that point, if its discriminant is negative
    there (else None); -1: likewise after an upstream start at ``starts[i]``."""
    tc = 0.0 if not hidden else float(ends[i] if hidden > 0 else starts[i])
    t = kernel.hidden_fold(f, fa, fb, tc, hidden, _ZERO_DISC)
    return None if math.isnan(t) else float(t)
