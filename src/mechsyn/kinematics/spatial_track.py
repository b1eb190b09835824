"""Continuation of a spatial mechanism's poses over a sweep (used by
:mod:`mechsyn.kinematics.spatial`; the equations are :mod:`mechsyn.kinematics.spatial_model`).

The walk goes outwards from the drawn assembly along the sweep's rows, by *blocks* of rows.
Every row of a block is predicted from the block's first pose by a second-order predictor
(the twists' first and second derivatives along the row's input step, through the
exponential of a twist; the derivatives are solved once per block, for the unit step of
each moving drive, and are linear and quadratic in the step), and all rows are corrected
at once: chord steps ``δξ = -J⁺ g`` with the Jacobian of the block's first pose (one
product per block for all rows), a fresh Jacobian of the current iterate wherever those do
not shrink the residual tenfold per step (the pseudo-inverse at the regular rank ``r``:
least-squares for redundant constraints, minimum-norm for idle motions). A row is accepted
when its residual is under ``NEWTON_TOL`` without the corrector moving it further than half
its predictor's step (else it may have jumped to another branch); the block's longest
accepted run of rows from its first on is kept, and the next block starts from its last
row. Blocks are cut where the predictor's step exceeds ``MAX_STEP`` (radians, or lengths in
units of the length scale), so the Taylor predictor stays accurate, and are at most
``MAX_STRIDE`` rows; after trouble the next block is half as long, down to one row, which is
then reached by the single-pose predictor-corrector halving its step down to ``1/4096``
of a row (and a dead point where even that fails). ``MAX_STRIDE = 1`` gives the per-row
path (every row its own block), the reference of the tests.

References
----------
.. [1] E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*, SIAM,
   2003, ch. 2 and 6 (predictor-corrector continuation, step-length control).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.kinematics.spatial_model import SpatialModel, helix_angles, move, numba_kernel, pair_error

__all__ = ["Tracker", "State", "RANK_TOL", "NEWTON_TOL", "MAX_STEP"]

#: A singular value below this fraction of the largest is a lost direction (rank decisions).
RANK_TOL = 1e-8
#: Residual (in units of the length scale) at which the corrector accepts a pose; the
#: floor of :func:`newton_tol` (which also stays ``ULPS`` units in the last place of the
#: file's coordinates above their rounding).
NEWTON_TOL = 1e-12
ULPS = 64
#: Largest entry of a pair's relative rotation minus the rotation of its joint value
#: (:func:`~mechsyn.kinematics.spatial_model.pair_error`) on an accepted pose: a true
#: assembly has the residual's size there, a reversed axis about 2.
PAIR_TOL = 1e-6


def newton_tol(M: SpatialModel) -> float:
    """The corrector's tolerance for ``M``: ``NEWTON_TOL`` of the length scale, or ``ULPS``
    units in the last place of the file's largest coordinate (in model units) when that is
    more (a mechanism far from the origin, or with its points clustered, cannot close better
    than its coordinates are written)."""
    return max(NEWTON_TOL, ULPS * M.ulp)


def singular_tol(M: SpatialModel) -> float:
    """``σ_r / σ_1`` under which a row is singular: the accuracy Newton reaches at a singular
    point (the square root of its tolerance, as it converges only linearly there), at least
    ``RANK_TOL``."""
    return max(RANK_TOL, 10 * np.sqrt(newton_tol(M)))
#: Largest predictor step in a block (radians; lengths in units of the length scale): the
#: second-order predictor's error is then about ``MAX_STEP³ / 6`` of the twists' scale,
#: well inside Newton's reach; every row is still checked on its own (residual and branch
#: guard). Measured: 0.35 / 0.5 / 0.75 / 1.0 give Bennett sweeps of 52 / 48 / 41 / 39 ms.
MAX_STEP = 0.75
MAX_HALVINGS = 12
#: Events and working-range limits are refined to this fraction of the row step.
REFINE = 1e-6
MAX_STRIDE = 64


@dataclass
class Lin:
    """Jacobians ``Jc`` (B, m, 6 n) at B poses, in twists taken at the links' centres ``C``
    (B, n, 3) (see :meth:`Tracker.state`), and their minimum-norm least-squares solutions.

    The solutions use the smaller Gram matrix (``Jc^T Jc`` or ``Jc Jc^T``, ``rows``) with a
    damping ``μ = 1e-14`` of its largest diagonal entry, through its inverse ``Gi``, then
    steps of iterative refinement (iterated Tikhonov: each step multiplies the damping's
    error by ``μ / (σ² + μ)``), so the answer is the pseudo-inverse's to rounding wherever
    ``σ_r / σ_1`` is above about ``1e-5``; the solution stays in the row space of ``Jc``
    (no idle component) by construction. ``bound``: ``1 / √(‖G‖_F ‖G⁻¹‖_F)`` per pose.
    """

    Jc: np.ndarray
    Gi: np.ndarray
    bound: np.ndarray
    rows: bool
    r: int
    C: np.ndarray

    @functools.cached_property
    def ratio(self) -> np.ndarray:
        """``σ_r / σ_1`` per pose, 0 where the rank has dropped: exact (an SVD) where it is
        under ``1e-3``; elsewhere a lower bound within a factor ``√k`` (``bound``, for a
        Gram matrix of rank ``k = r``), which is enough to tell a regular pose."""
        B, k = len(self.Jc), min(self.Jc.shape[1:])
        if self.r == 0:
            return np.ones(B)
        out = self.bound.copy() if k == self.r else np.zeros(B)
        exact = out < 1e-3
        if exact.any():
            out[exact] = svd_ratio(self.Jc[exact], self.r)
        return out

    def twists(self, y: np.ndarray) -> np.ndarray:
        """Twists ``(ω, u)`` at the centres (B, 6 n, ...) -> ``(ω, v)`` at the origin: ``v = u + c × ω``."""
        B = len(y)
        Y = y.reshape(B, self.C.shape[1], 6, -1)
        X = Y.copy()
        X[:, :, 3:] += np.cross(self.C[:, :, :, None], Y[:, :, :3], axisa=2, axisb=2, axisc=2)
        return X.reshape(y.shape)


def svd_ratio(Jc: np.ndarray, r: int) -> np.ndarray:
    """``σ_r / σ_1`` of each of the matrices ``Jc`` (B, m, k) by an SVD (0 where ``σ_1 = 0``)."""
    sv = np.linalg.svd(Jc, compute_uv=False)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.nan_to_num(sv[:, r - 1] / sv[:, 0])


@dataclass
class State:
    """B assembled poses: link poses, unwrapped H angles, the pairs' angles and slides,
    linearisation, residuals."""

    R: np.ndarray
    p: np.ndarray
    href: np.ndarray
    theta: np.ndarray
    s: np.ndarray
    lin: Lin
    g: np.ndarray
    x: tuple | None = None


class Tracker:
    """Predictor-corrector continuation of one model (see the module doc)."""

    def __init__(self, M: SpatialModel) -> None:
        self.M = M
        self.m_c = M.n_constraints
        self.m = self.m_c + len(M.drives)
        self.rows = self.m < 6 * M.n  # the Gram matrix J Jᵀ (else Jᵀ J)
        self.rank: int | None = None
        self.drawn_singular: int | None = None  # the drawn assembly's rank when below the sweep's
        self.halvings = 0
        self.tol = newton_tol(M)
        self.rank_tol = max(RANK_TOL, 100 * self.tol)
        self.rejected = 0  # converged poses refused by the pair check (another root of the equations)
        self.last_pair: dict[int, str] = {}  # the poses of the last correction refused: their pair
        self._left: tuple | None = None

    def state(self, R: np.ndarray, p: np.ndarray, href: np.ndarray, target: np.ndarray,
              rates: tuple | None = None, refine: int = 2) -> State:
        """The residuals, the pairs' angles and slides and the linearisation at B poses:
        the Jacobian in twists ``(ω, u)`` with ``u`` the velocity of each link's centre ``c``
        (``v = u + c × ω``) and the inverse of its Gram matrix.

        A minimum-norm solution in these coordinates is orthogonal to the idle motions,
        and an idle spin of a link about a line through its centre is ``(a, 0)`` there
        (a rod between two ball joints has its centre on its line), so minimum-norm rates
        and steps give the spin no component: idle spins stay at rest, whichever point the
        file measures from. The regular rank is the drawn assembly's (the first state's),
        by an SVD. With ``rates`` (the drives' rates and their derivatives, each (B,
        drives)) the state keeps no inverse Gram matrices but the rates ``x`` (first and
        second derivatives, ``J ξ' = u̇``, ``J ξ'' = ü - γ(ξ')``) with ``refine`` steps of
        iterative refinement."""
        M, B, n, m = self.M, len(R), self.M.n, self.m
        R, p = np.ascontiguousarray(R, float), np.ascontiguousarray(p, float)
        q = m if self.rows else 6 * n
        g, J, Gi = np.empty((B, m)), np.empty((B, m, 6 * n)), np.empty((B, 0, 0) if rates else (B, q, q))
        C, bound, x1, x2 = np.empty((B, n, 3)), np.empty(B), np.empty((B, 6 * n)), np.empty((B, 6 * n))
        th, s = np.empty((B, len(M.angle_joints))), np.empty((B, len(M.slide_joints)))
        du, ddu = (np.ascontiguousarray(r, float) for r in rates) if rates else (np.empty((0, len(M.drives))),) * 2
        numba_kernel().states(M.tables, R, p, np.ascontiguousarray(href, float), np.ascontiguousarray(target, float),
                              self.rows, g, J, Gi, C, bound, th, s, du, ddu, refine, x1, x2)
        if self.rank is None:
            s0 = np.linalg.svd(J[0], compute_uv=False)
            self.rank = int(np.count_nonzero(s0 > self.rank_tol * s0[0])) if s0.size and s0[0] > 0 else 0
        if M.helix:
            href = helix_angles(M, th, href)
        return State(R, p, href, th, s, Lin(J, Gi, bound, self.rows, self.rank, C), g, (x1, x2) if rates else None)

    def rates(self, st: State, du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Twists (B, 6 n) of the links per input step ``du`` (B, drives) at the poses of
        ``st`` (one, or B) for a predictor: first and second derivatives (``J ξ' = du``,
        ``J ξ'' = -γ(ξ')``), without refinement."""
        z = np.zeros(len(du), int) if len(st.R) == 1 else slice(None)
        return self.state(st.R[z], st.p[z], st.href[z], np.zeros(du.shape), (du, np.zeros(du.shape)), 0).x

    def correct(self, R: np.ndarray, p: np.ndarray, href: np.ndarray, target: np.ndarray, limit: np.ndarray,
                iters: int = 8, anchor: Lin | None = None, first: bool = False, tol: float | None = None) -> tuple:
        """Newton corrections of B poses to the inputs ``target``: the poses, a mask of
        those that converged without moving further than ``limit`` and are true assemblies
        (:meth:`true_pairs`), and the pairs' angles at the last iterate. ``first``: stop at
        the first pose that fails (a block keeps its rows up to there); ``tol``: the residual
        to reach (default the tracker's; 0 polishes ``iters`` steps).

        Chord steps: each pose keeps its linearisation (``anchor``'s, the first pose of
        ``anchor`` serving all, when given) while its residual falls at least tenfold per
        step (the predictor lands close, so that is most steps); else it takes the Jacobian
        of its current iterate (:func:`mechsyn.kinematics._spatial_numba.correct`)."""
        B, M = len(R), self.M
        R, p = np.array(R, float, order="C"), np.array(p, float, order="C")
        q = self.m if self.rows else 6 * M.n
        Ja, Ga, Ca = (np.empty((0, 6 * M.n)), np.empty((q, q)), np.empty((M.n, 3))) if anchor is None else (
            anchor.Jc[0], anchor.Gi[0], anchor.C[0])
        ok, th, s = np.zeros(B, bool), np.zeros((B, len(M.angle_joints))), np.zeros((B, len(M.slide_joints)))
        numba_kernel().correct(M.tables, R, p, np.ascontiguousarray(href, float), np.ascontiguousarray(target, float),
                               np.broadcast_to(np.asarray(limit, float), (B,)).copy(), iters,
                               self.tol if tol is None else tol, Ja, Ga, Ca, self.rows, first, ok, th, s)
        return R, p, self.true_pairs(R, ok), th

    def true_pairs(self, R: np.ndarray, ok: np.ndarray) -> np.ndarray:
        """``ok`` without the poses whose pairs are not the file's (a reversed R axis, a
        half-turned P pair: :func:`~mechsyn.kinematics.spatial_model.pair_error`), whose
        pair ``last_pair`` names."""
        self.last_pair = {}
        if ok.any() and len(self.M.pairs.ids):
            err = pair_error(self.M, R[ok])
            bad = err.max(axis=1) > PAIR_TOL
            self.last_pair = {int(b): self.M.pairs.ids[int(np.argmax(e))]
                              for b, e in zip(np.flatnonzero(ok)[bad], err[bad])}
            self.rejected += len(self.last_pair)
        true = ok.copy()
        true[list(self.last_pair)] = False
        return true

    def block(self, st: State, u0: np.ndarray, Ub: np.ndarray) -> tuple[int, np.ndarray, Any, Any]:
        """The rows ``Ub`` (K, drives) after the pose ``st`` (at inputs ``u0``), predicted
        from its tangents (:func:`taylor`) and corrected in one call, first by chord steps
        with the linearisation of ``st``. Returns the number ``n`` of rows accepted from the
        first on (each converged without moving further than half its predictor's step,
        which is at most ``MAX_STEP``), the predictor's step size of every row, the accepted
        poses ``(R, p, href)`` and the state of the last of them."""
        x1, x2 = taylor(self, st, Ub - u0)
        size = np.abs(x1).max(axis=1)
        K = int(np.argmin(np.append(size <= MAX_STEP, False)))  # the rows the predictor reaches
        if K == 0:
            return 0, size, None, None
        zero = np.zeros(K, int)
        R, p = move(st.R[zero], st.p[zero], x1[:K] + 0.5 * x2[:K])
        href = st.href[zero]
        R, p, ok, th = self.correct(R, p, href, Ub[:K], 0.5 * size[:K] + 1e-9, anchor=st.lin, first=True)
        n = int(np.argmin(np.append(ok, False)))
        if n == 0:
            return 0, size, None, None
        if self.M.helix:
            href = helix_angles(self.M, th, href)
        return n, size, (R[:n], p[:n], href[:n]), self.state(R[n - 1:n], p[n - 1:n], href[n - 1:n], Ub[n - 1:n])

    def advance(self, st: State, u0: np.ndarray, u1: np.ndarray) -> State | None:
        """From ``st`` at inputs ``u0`` to ``u1`` by blocks of one row (:meth:`block`), halving
        the step at trouble down to ``2^-MAX_HALVINGS`` of it; None when it cannot get there."""
        t, h = 0.0, 1.0
        while t < 1.0:
            h = min(h, 1.0 - t)
            _, size, _, nxt = self.block(st, u0 + t * (u1 - u0), (u0 + (t + h) * (u1 - u0))[None])
            size = float(size[0])
            if nxt is None:
                if h < 0.5 ** MAX_HALVINGS:
                    return None
                h *= 0.5
                self.halvings += size <= MAX_STEP  # trouble, not a long step
                continue
            st, t = nxt, t + h
            h = min(1.0, 2 * h)
        return st

    def reassemble(self, st: State, U: np.ndarray, rows: np.ndarray) -> tuple[list, tuple[int, State] | None]:
        """The first of ``rows`` (after a gap) where Newton from the pose ``st`` converges to
        a true assembly, and its state (None: none does); all rows tried in one batch. First
        the rows before it (row, pair) where Newton converged to another root of a pair's
        equations (:meth:`true_pairs`)."""
        B = len(rows)
        rep = np.zeros(B, int)
        R, p, ok, _ = self.correct(st.R[rep], st.p[rep], st.href[rep], U[rows], np.full(B, np.inf), iters=30)
        j = int(np.argmax(ok)) if ok.any() else B
        refused = [(int(rows[b]), pair) for b, pair in sorted(self.last_pair.items()) if b < j]
        if not ok.any():
            return refused, None
        return refused, (int(rows[j]), self.state(R[j:j + 1], p[j:j + 1], st.href, U[rows[j]][None]))


# --------------------------------------------------------------------------- leaving a singular pose
def point_speeds(M: SpatialModel, st: State, X: np.ndarray, extra: tuple = ()) -> np.ndarray:
    """The largest speed of a joint point, or of a point ``extra`` (link index, local point),
    in each of the motions ``X`` (k, 6 n) (twists at the origin) at the first pose of ``st``."""
    X = X.reshape(len(X), M.n, 6)
    out = np.zeros(len(X))
    for i, x0 in [(M.index(link), M.local(j.point)) for j in M.mech.joints if j.point is not None
                  for link in j.links] + list(extra):
        if i < M.n:
            y = st.R[0, i] @ x0 + st.p[0, i]
            out = np.maximum(out, np.abs(X[:, i, 3:] + np.cross(X[:, i, :3], y)).max(axis=1))
    return out


def free_motions(tr: Tracker, st: State, tol: float, extra: tuple = ()) -> np.ndarray:
    """The motions (k, 6 n) at the first pose of ``st`` with every drive at rest (the null
    space of the Jacobian: its singular values under ``tol`` of the largest, as twists at the
    origin) that move a joint point or a point ``extra`` (link index, local point), not idle
    spins; each signed so that its largest entry is positive."""
    _, s, Vt = np.linalg.svd(st.lin.Jc[0], full_matrices=True)
    s = np.concatenate([s, np.zeros(Vt.shape[0] - len(s))])
    x = st.lin.twists(Vt[s <= tol * s[0]].T[None])[0].T
    x = x[point_speeds(tr.M, st, x, extra) > 1e-6]
    return x * np.sign(x[np.arange(len(x)), np.argmax(np.abs(x), axis=1)])[:, None]


def leave(tr: Tracker, st: State, u0: np.ndarray, u1: np.ndarray) -> State | None:
    """From a singular pose ``st`` (at inputs ``u0``) to ``u1``, or None: Newton from the pose moved by
    the tangent and ``±σ`` along each null direction that moves a joint point (see
    :mod:`mechsyn.kinematics.spatial_singular`)."""
    du = u1 - u0
    size = float(np.abs(du).max(initial=0.0))
    if size == 0.0:
        return st
    N = free_motions(tr, st, singular_tol(tr.M))
    if not len(N):
        return None
    x1, x2 = tr.rates(st, du[None])
    base = x1[0] + 0.5 * x2[0]
    sig = np.concatenate([np.array([1.0, 3.0, 0.3]) * np.sqrt(size), [size, 3 * size]])
    guesses = [base] + [base + sign * g * v for v in N for g in sig for sign in (1.0, -1.0)]
    same = tr._left is not None and tr._left[0] is st  # the other way from the same pose: the same branch
    if same:
        guesses.insert(0, -tr._left[2] * (size / tr._left[1]))
    X = np.array(guesses)
    B = len(X)
    rep = np.zeros(B, int)
    R, p = move(st.R[rep], st.p[rep], X)
    R, p, ok, _ = tr.correct(R, p, st.href[rep], np.broadcast_to(u1, (B, len(u1))), np.full(B, np.inf), iters=30)
    if not ok.any():
        return None
    if same and ok[0]:
        j = 0
    else:
        dist = np.abs(R - st.R[rep]).max(axis=(1, 2, 3)) + np.abs(p - st.p[rep]).max(axis=(1, 2))
        dist = np.where(ok, dist, np.inf)
        j = int(np.argmax(dist <= dist.min() * (1 + 1e-6) + 1e-12))
    tr._left = (st, size, X[j])
    return tr.state(R[j:j + 1], p[j:j + 1], st.href, u1[None])


# --------------------------------------------------------------------------- the walk
@dataclass
class Walk:
    """Poses of every row (NaN where not reached), how each was reached (``how``: 0 not, 1
    by moving from the drawn assembly, 2 the same going the other way round with the R input
    taken modulo 360, 3 by re-assembly in another assembly) and the events met on the way."""

    R: np.ndarray
    p: np.ndarray
    href: np.ndarray
    ok: np.ndarray
    events: list
    how: np.ndarray
    #: then, of the rows reported (NaN elsewhere: :func:`mechsyn.kinematics.spatial._sweep_rows`),
    #: the rates (twists), the closure residual, ``σ_r / σ_1`` and the pairs' angles and slides
    xi: np.ndarray | None = None
    xid: np.ndarray | None = None
    res: np.ndarray | None = None
    ratio: np.ndarray | None = None
    theta: np.ndarray | None = None
    slide: np.ndarray | None = None

    def put(self, k: int | np.ndarray, R: np.ndarray, p: np.ndarray, href: np.ndarray, how: int = 1) -> None:
        """Rows ``k`` reached (``how``) at the poses ``R``, ``p`` (H angles ``href``)."""
        self.R[k], self.p[k], self.href[k] = R, p, href
        self.ok[k] = True
        self.how[k] = how

    def at(self, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.R[k:k + 1], self.p[k:k + 1], self.href[k:k + 1]


def walk(tr: Tracker, start: State, U: np.ndarray, event: Any) -> Walk:
    """Every row of the inputs ``U`` (N, drives) from the drawn assembly ``start`` (at zero
    inputs): to the row nearest it, then outwards both ways by blocks of rows
    (:func:`_blocks_along`) as far as the mechanism moves. Then, by one rule, the rows left:

    1. a sweep of one R (or H) input that reached one end goes on past it with the rows left
       taken modulo 360 degrees (the other way round from the drawn assembly: the rows a
       full-turn sweep could not reach forwards are reached backwards, on the drawn circuit);
    2. rows still left are re-assembled by Newton from the pose next to each gap (the row
       before it, then the row after it): another assembly than the drawn one (no motion
       from the drawn assembly reaches them), each such stretch an event ``reassembled``.

    ``event(index, kind, detail)`` makes the event dicts. From a singular pose (a file
    drawn at a dead or change point) the first row each way is reached by :func:`leave`."""
    M = tr.M
    N = len(U)
    w = Walk(np.full((N, M.n + 1, 3, 3), np.nan), np.full((N, M.n + 1, 3), np.nan),
             np.zeros((N, len(M.helix))), np.zeros(N, bool), [], np.zeros(N, np.int8))
    k0 = int(np.argmin(np.abs(U).max(axis=1)))
    z = np.zeros(U.shape[1])
    st = tr.advance(start, z, U[k0]) or leave(tr, start, z, U[k0])
    if st is None:
        w.events.append(event(k0, "not assembled", None))
    else:
        w.put(k0, st.R, st.p, st.href)
    ends = [None if st is None else _blocks_along(tr, w, st, U, k0, order, event)
            for order in (np.arange(k0 + 1, N), np.arange(k0 - 1, -1, -1))]
    _round(tr, w, U, ends, event)
    _reassemble_rest(tr, w, U, event)
    w.events.sort(key=lambda e: e["index"])
    return w


def turning_column(M: SpatialModel, U: np.ndarray) -> int | None:
    """The column of ``U`` of the sweep's one moving input when it is an angle, else None."""
    moving = np.flatnonzero(np.ptp(U, axis=0) > 0) if len(U) else []
    if len(moving) != 1 or M.drives[moving[0]][1] != "angle":
        return None
    return int(moving[0])


def _round(tr: Tracker, w: Walk, U: np.ndarray, ends: list, event: Any) -> None:
    """Rule 1 of :func:`walk`: past an end the walk reached, on to the rows left with the
    input taken modulo 2π (beyond the last row upwards, or below the first downwards)."""
    col = turning_column(tr.M, U)
    if col is None or w.ok.all():
        return
    N = len(U)
    up = U[-1, col] >= U[0, col]
    for st, end, sign in ((ends[0], N - 1, 1.0), (ends[1], 0, -1.0)):
        left = np.flatnonzero(~w.ok)
        if st is None or not w.ok[end] or not len(left) or (w.how[end] != 1):
            continue
        d = sign * (1 if up else -1)  # +1: inputs grow past this end
        V = U.copy()
        shift = np.mod(d * (U[left, col] - U[end, col]), 2 * np.pi)
        shift[shift < 1e-12] = 2 * np.pi  # the end's own input: a full turn on
        V[left, col] = U[end, col] + d * shift
        order = left[np.argsort(shift, kind="stable")]
        before = w.ok.copy()
        _blocks_along(tr, w, st, V, end, order, event, how=2)
        got = np.flatnonzero(w.ok & ~before)
        if len(got):
            w.events.append(event(int(got[0]), "other way round", None))
    _same_angle(w, U, col)


def _same_angle(w: Walk, U: np.ndarray, col: int) -> None:
    """Rows left whose input equals, modulo 2π, that of a row reached by moving from the
    drawn assembly take its pose (an R input is an angle: 360 is 0)."""
    key = np.round(np.mod(U[:, col], 2 * np.pi) / (2 * np.pi) * 1e9).astype(np.int64) % 1_000_000_000
    seen = {int(key[k]): k for k in np.flatnonzero(w.ok & (w.how == 1))}
    for k in np.flatnonzero(~w.ok):
        src = seen.get(int(key[k]))
        if src is not None:
            w.put(k, *w.at(src), how=2)


def _reassemble_rest(tr: Tracker, w: Walk, U: np.ndarray, event: Any) -> None:
    """Rule 2 of :func:`walk`: each gap left re-assembled by Newton from the pose of the row
    next to it, first from the row before it (gaps in row order), then from the row after it
    (gaps in reverse order: a gap before the first row reached has no row before it); the
    first row of the gap, counted from that side, where Newton converges to a true assembly,
    then walked on both ways as far as the mechanism moves."""
    N = len(U)
    for side in (-1, 1):
        for i in (range(1, N) if side < 0 else range(N - 2, -1, -1)):
            if w.ok[i] or not w.ok[i + side]:
                continue
            rows = np.arange(i, N) if side < 0 else np.arange(i, -1, -1)
            rows = rows[:int(np.argmax(np.append(w.ok[rows], True)))]  # up to the next assembled row
            refused, got = tr.reassemble(tr.state(*w.at(i + side), U[i + side][None]), U, rows)
            for k, jid in refused:
                w.events.append(event(k, "refused", jid))
            if got is None:
                continue
            k, st = got
            w.put(k, st.R, st.p, st.href, how=3)
            _blocks_along(tr, w, st, U, k, np.sort(rows[rows > k]), event, how=3)
            _blocks_along(tr, w, st, U, k, np.sort(rows[rows < k])[::-1], event, how=3)
            w.events.append(event(int(rows[np.argmax(w.ok[rows])]), "reassembled", None))


def _blocks_along(tr: Tracker, w: Walk, st: State, U: np.ndarray, k0: int, order: np.ndarray, event: Any,
                  how: int = 1) -> State | None:
    """Walk along ``order`` by blocks of rows of adaptive length (:meth:`Tracker.block`),
    each from the last row of the one before, until the first row it cannot reach (a
    ``dead point`` event there); the rows reached go into ``w``. Returns the state of the
    last row when it reached the end of ``order``, else None."""
    prev, i, stride = k0, 0, MAX_STRIDE
    while i < len(order):
        j = min(i + stride, len(order)) - 1
        rows = order[i:j + 1]
        n, size, poses, nxt = tr.block(st, U[prev], U[rows])
        if n == 0 and j > i:  # not even the next row: from it on, one row at a time
            stride = 1
            continue
        if n == 0:  # a single row: halve within it
            k = int(rows[0])
            nxt = tr.advance(st, U[prev], U[k]) or leave(tr, st, U[prev], U[k])
            if nxt is None:
                if not w.ok[k]:
                    lim = limit(tr, st, U[prev], U[k])
                    w.events.append(event(k, "dead point", st.lin.ratio[0], at=lim - U[k], last=prev))
                return None
            n, poses, size = 1, (nxt.R, nxt.p, nxt.href), np.zeros(1)
        w.put(rows[:n], *poses, how)
        st, prev, i = nxt, int(rows[n - 1]), i + n
        reach = int(np.argmin(np.append(size <= MAX_STEP, False)))  # the rows the predictor reaches
        stride = max(1, stride // 2) if n < reach else min(2 * stride, MAX_STRIDE)  # trouble: shorter blocks
    return st


def limit(tr: Tracker, st: State, u0: np.ndarray, u1: np.ndarray) -> np.ndarray:
    """The input where the motion from ``st`` (at ``u0``, assembled) towards ``u1`` (not
    reached) stops: bisection on whether Newton from the nearest pose reached converges to
    a true assembly (on either branch that meets there), to ``REFINE`` of the step, then the
    fold itself from the poses before it (:func:`_fold`)."""
    lo, hi = 0.0, 1.0
    R, p, href = st.R, st.p, st.href
    inf = np.array([np.inf])
    while hi - lo > REFINE:
        t = 0.5 * (lo + hi)
        R1, p1, ok, _ = tr.correct(R, p, href, (u0 + t * (u1 - u0))[None], inf, iters=12)
        if ok[0]:
            R, p, lo = R1, p1, t
        else:
            hi = t
    return u0 + _fold(tr, (R, p, href), u0, u1, lo) * (u1 - u0)


def _fold(tr: Tracker, pose: tuple, u0: np.ndarray, u1: np.ndarray, lo: float) -> float:
    """The fold (turning point of the input) next to ``lo``, the last fraction of the step
    from ``u0`` to ``u1`` where Newton converged (from the pose ``pose`` there). Near the
    fold the branch turns back: the input is ``t* - c s²`` and ``σ_r/σ_1`` is ``a |s|`` in
    a parameter ``s`` along it, so the input is a series ``t* + q2 ρ² + q3 ρ³`` in the ratio
    ``ρ``; it is fitted to polished poses at ``lo - 4^j REFINE`` whose ratio is clean
    (``>= √tol``, where Newton's blur is below ``1e-4`` of it: see
    :func:`~mechsyn.kinematics.spatial_singular._apex`). Bisection alone stops early by up
    to ``REFINE``, as Newton converges only linearly there. ``lo`` when the fit does not
    land within ``4 REFINE`` past it."""
    ts = lo - REFINE * 4.0 ** np.arange(1, 7)
    ts = ts[ts > 0]
    if len(ts) < 2:
        return lo
    B = len(ts)
    z = np.zeros(B, int)
    rho = polished_ratio(tr, pose[0][z], pose[1][z], pose[2][z], u0 + ts[:, None] * (u1 - u0))
    clean = np.isfinite(rho) & (rho >= np.sqrt(tr.tol))
    if clean.sum() < 2:
        return lo
    r = rho[clean]
    A = np.stack([np.ones_like(r), r * r] + ([r ** 3] if clean.sum() > 2 else []), axis=1)
    t_star = float(np.linalg.lstsq(A, ts[clean], rcond=None)[0][0])
    return t_star if lo <= t_star <= lo + 4 * REFINE else lo


def polished_ratio(tr: Tracker, R: np.ndarray, p: np.ndarray, href: np.ndarray, u: np.ndarray,
                   iters: int = 40, polish: int = 8) -> np.ndarray:
    """``σ_r / σ_1`` (B,) at the poses Newton reaches from ``R``, ``p`` at the inputs ``u``
    (B, drives), inf where it does not converge: ``iters`` steps to the tolerance, then
    ``polish`` more past it (next to a singular point Newton converges only linearly and
    reaches a residual ε only within √ε of the pose, which blurs the ratio)."""
    B = len(u)
    inf = np.full(B, np.inf)
    R, p, ok, _ = tr.correct(R, p, href, u, inf, iters=iters)
    R, p, _, _ = tr.correct(R, p, href, u, inf, iters=polish, tol=0.0)
    out = np.full(B, np.inf)
    if ok.any():
        good = np.flatnonzero(ok)
        out[good] = svd_ratio(tr.state(R[good], p[good], href[good], u[good]).lin.Jc, tr.rank)
    return out


def taylor(tr: Tracker, st: State, du: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The predictor's twists (first and second derivative) of B rows from the pose ``st``
    along their input steps ``du`` (B, drives), without a solve per row: the first
    derivative is linear in ``du`` and the second quadratic, so the pose solves for the unit
    step of every drive that moves and for the sums of two of them (the cross terms by
    polarisation: ``x2(a + b) - x2(a) - x2(b)``)."""
    cols = np.flatnonzero(np.any(du != 0, axis=0))
    c = len(cols)
    pairs = [(a, b) for a in range(c) for b in range(a + 1, c)]
    D = np.zeros((c + len(pairs), du.shape[1]))
    D[np.arange(c), cols] = 1.0
    for q, (a, b) in enumerate(pairs):
        D[c + q, cols[a]] = D[c + q, cols[b]] = 1.0
    X1, X2 = tr.rates(st, D)
    d = du[:, cols]
    x1, x2 = d @ X1[:c], (d * d) @ X2[:c]
    for q, (a, b) in enumerate(pairs):
        x2 += np.outer(d[:, a] * d[:, b], X2[c + q] - X2[a] - X2[b])
    return x1, x2
