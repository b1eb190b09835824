"""The objective of curve synthesis: how far a linkage's path is from the target (the
chamfer distance both ways, :func:`curve_errors`), the sharp features of a target (cusps and
corners, :func:`sharp_features`), the designer's bounds (size, link ratio, transmission
angle) and the least-squares problem that the refinement of
:mod:`mechsyn.synthesis.curves.synthesis` solves for one topology.
"""

from __future__ import annotations

import importlib
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.kinematics.batch import simulate_batch
from mechsyn.synthesis.curves.descriptors import resample
from mechsyn.synthesis.curves.target import TargetCurve
from mechsyn.synthesis.curves.topologies import TRACER, CurveTopology


def now() -> float:
    """The search's clock, ``time.perf_counter()``: every deadline of the curve search is read
    from it (a test may replace :data:`CLOCK` with a clock of its own)."""
    return CLOCK[0]()


#: the clock :func:`now` reads, in a one-entry list
CLOCK = [time.perf_counter]

M_TARGET = 64          # target points for the residuals
N_TRACE = 96           # input samples along the range (refinement)
N_FINAL = 360          # input samples of the reported path and errors
PENALTY = 1.0          # residual (in target diagonals) of an unassembled design

DEFAULT_MAX_SIZE = 1.5            # every point inside this many diagonals of the target's centroid
DEFAULT_MAX_LINK_RATIO = 10.0     # longest / shortest link length
DEFAULT_MIN_TRANSMISSION = 30.0   # degrees, worst over the motion
DEFAULT_TOLERANCE = 5e-3          # chamfer / diagonal within which fewer links rank first
MARGIN = 0.97                     # the refinement aims this far inside each bound


# ----------------------------------------------------------------------------- distances


def _polyline(points: np.ndarray, closed: bool) -> tuple[np.ndarray, np.ndarray]:
    """Segment starts and vectors ``(S, 2)`` of a polyline."""
    P = points
    Q = np.roll(P, -1, axis=0) if closed else P[1:]
    P = P if closed else P[:-1]
    return P, Q - P


def _to_polyline(X: np.ndarray, starts: np.ndarray, vecs: np.ndarray,
                 k: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Vectors from points ``X (..., n, 2)`` to their nearest point on the polyline
    (``starts``, ``vecs`` ``(..., S, 2)``), and the index of that segment ``(..., n)``.
    With ``k`` given, the segments are those (fixed correspondences, for Jacobians)."""
    if k is not None:   # X (KX, n, 2), starts and vecs (KS, S, 2), k (K, n); KX and KS 1 or K
        return _compiled().toward(*(np.ascontiguousarray(a, float) for a in (X, starts, vecs)),
                             np.ascontiguousarray(k, np.int64)), k
    d = X[..., :, None, :] - starts[..., None, :, :]                   # (..., n, S, 2)
    L2 = np.sum(vecs ** 2, axis=-1)[..., None, :]
    t = np.clip(np.sum(d * vecs[..., None, :, :], axis=-1) / np.where(L2 > 0, L2, 1.0), 0.0, 1.0)
    diff = d - t[..., None] * vecs[..., None, :, :]
    dist2 = np.sum(diff ** 2, axis=-1)
    k = np.argmin(dist2, axis=-1)
    return -np.take_along_axis(diff, k[..., None, None], axis=-2)[..., 0, :], k


M_ERROR = 256          # points equally spaced in arc length along each curve for the reported error


def even_points(points: np.ndarray, closed: bool, m: int = M_ERROR) -> np.ndarray:
    """``m`` points ``(m, 2)`` equally spaced in arc length along a polyline (an open one
    from its first point to its last, both included)."""
    z = resample(points, m, closed=True) if closed else resample(points, 2 * m - 2, closed=False)[:m]
    return np.stack([z.real, z.imag], axis=-1)


M_ORDER = 64           # points along each curve for the error's monotone correspondence
ROLL_STEP = 4          # start points tried first (every 4th), then every one about the best two
FINE = 4               # polyline points per sample step for the distances (the curves, not their chords)


def chamfer_error(path: np.ndarray, target: TargetCurve, closed_path: bool, unit: float | None = None,
                  m: int = M_ORDER) -> float:
    """The error of a traced path against the target: the symmetric chamfer distance
    along the curves in order, over the target's diagonal.

    .. math::

        e = \\frac{1}{2D}\\min_{W}\\frac{1}{2m}\\sum_{(i, j) \\in W} w_{ij}
            \\left(d(a_i, B_j) + d(b_j, A_i)\\right)

    with ``a_i`` and ``b_j`` ``m`` points equally spaced in arc length along the target
    ``A`` and the path ``B`` (each a polyline, closed or open), ``A_i`` and ``B_j`` the
    stretch of the other curve beside point ``i`` or ``j`` (from the point before to the
    point after, resampled :data:`FINE` times finer), ``d`` the distance from a point to it, ``D`` the target's diagonal (:attr:`TargetCurve.diagonal`, or ``unit``)
    and ``W`` a correspondence that runs along both curves in order (a monotone path from
    ``(0, 0)`` to ``(m-1, m-1)``, steps weighted ``w = 2`` diagonally and 1 along one curve,
    so the weights sum to ``2m``), from any start point of a closed curve and in either
    sense. Each point is thus matched to the other curve near where the order puts it: a
    path lying on the target scores 0 up to the polylines' chords, whatever the sampling,
    and the value is at least the order-free :func:`nearest_chamfer`; a loop that cuts
    across a letter, its pieces near parts of the outline visited out of order, scores
    more than one that goes round it. Computed by dynamic time warping (H. Sakoe and S.
    Chiba, *IEEE Trans. Acoustics, Speech, and Signal Processing* 26(1), 1978; the row
    recursion as a prefix minimum), over every start point near the best of every
    :data:`ROLL_STEP`-th (:func:`_in_order`).

    >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> circle = TargetCurve(np.c_[np.cos(t), np.sin(t)], closed=True)
    >>> bool(chamfer_error(np.c_[np.cos(t + 1), np.sin(t + 1)][::3], circle, True) < 2e-4)   # chords only
    True
    >>> round(chamfer_error(1.1 * np.c_[np.cos(t), np.sin(t)], circle, True) * circle.diagonal, 3)
    0.1
    >>> eight = np.c_[np.cos(t), np.sin(t) * np.sign(np.cos(t / 2))]   # the halves in another order
    >>> bool(chamfer_error(eight, circle, True) > 3 * nearest_chamfer(eight, circle, True))
    True
    """
    unit = target.diagonal if unit is None else unit
    Af = _fine(target.points, target.closed, m)
    best = np.inf
    for Bf in (_fine(path, closed_path, m), _fine(path[::-1], closed_path, m)):
        c = 0.5 * (_beside(Af[::FINE], Bf, closed_path) + _beside(Bf[::FINE], Af, target.closed).T)
        best = min(best, _in_order(c, target.closed, closed_path)[0])
    return float(best / unit)


def _in_order(c: np.ndarray, rows_closed: bool, cols_closed: bool) -> tuple[float, int]:
    """The least weighted cost over correspondences in order of a cost matrix ``c (n, m)``
    (:func:`mechsyn.synthesis.curves._numba.costs`) and the start shift of the closed
    curve it is reached at (the rows' when they are closed, else the columns'; 0 when
    neither is): every :data:`ROLL_STEP`-th shift, then every one about the best two."""
    dtw = _compiled()
    c = np.ascontiguousarray(c, float)
    if not (rows_closed or cols_closed):
        return float(dtw.costs(c, np.zeros(1, np.int64), True)[0]), 0
    n = c.shape[0] if rows_closed else c.shape[1]
    coarse = np.arange(0, n, ROLL_STEP)
    e = dtw.costs(c, coarse, rows_closed)
    best2 = coarse[np.argsort(e, kind="stable")[:2]]
    near = sorted({(s + k) % n for s in best2 for k in range(1 - ROLL_STEP, ROLL_STEP)})
    f = dtw.costs(c, np.array(near, np.int64), rows_closed)
    i = int(np.argmin(f))
    return float(f[i]), int(near[i])


def _compiled() -> Any:
    """The compiled correspondence and distances (:mod:`mechsyn.synthesis.curves._numba`),
    imported on first use."""
    if not _COMPILED:
        _COMPILED.append(importlib.import_module("mechsyn.synthesis.curves._numba"))
    return _COMPILED[0]


_COMPILED: list[Any] = []   # the compiled module, once imported


def _beside(X: np.ndarray, F: np.ndarray, closed: bool, k: int = FINE) -> np.ndarray:
    """``(n, m)``: distance from each point of ``X`` to the stretch of polyline ``F`` (``k``
    segments per sample: the samples are ``F[::k]``) beside its sample ``j``, from sample
    ``j - 1`` to sample ``j + 1`` (one side at an open end)."""
    return _stretches(_seg_dist(X, F, closed), closed, k)


def _seg_dist(X: np.ndarray, F: np.ndarray, closed: bool) -> np.ndarray:
    """``(n, S)``: distance from each point of ``X`` to each segment of polyline ``F``."""
    return _compiled().seg_dist(np.ascontiguousarray(X, float), np.ascontiguousarray(F, float), closed)


def _stretches(seg: np.ndarray, closed: bool, k: int) -> np.ndarray:
    """Segment distances ``(n, S)`` (``k`` segments per sample step) reduced to the
    stretch beside each sample (see :func:`_beside`)."""
    return _compiled().stretches(np.ascontiguousarray(seg, float), closed, k)


def _fine(points: np.ndarray, closed: bool, m: int, k: int = FINE) -> np.ndarray:
    """Points equally spaced in arc length, ``k`` per step of ``m`` samples (``[::k]``)."""
    return even_points(points, closed, k * m if closed else k * (m - 1) + 1)


def correspondence(c: np.ndarray, rows_closed: bool, cols_closed: bool) -> tuple[np.ndarray, tuple[bool, int]]:
    """``(n, m)`` boolean: the pairs (row sample, column sample) matched by the least-cost
    correspondence in order of cost matrix ``c (n, m)`` (the rows a target's samples, the
    columns a path's), from any start point of a closed curve and in either sense of the
    columns: the correspondence :func:`chamfer_error` takes its value along; and its sense
    (columns reversed) and start shift.

    >>> t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    >>> a = np.c_[np.cos(t), np.sin(t)]
    >>> c = np.linalg.norm(a[:, None] - np.roll(a[::-1], 3, axis=0)[None], axis=-1)
    >>> W, (reversed_, shift) = correspondence(c, True, True)
    >>> bool(np.all(c[W] < 1e-12)), int(W.sum()), reversed_
    (True, 8, True)
    """
    n, m = c.shape
    (_, shift), rev = min(((_in_order(c[:, ::-1] if rev else c, rows_closed, cols_closed), rev)
                           for rev in (False, True)), key=lambda x: x[0][0])
    i, j = _compiled().pairs(np.ascontiguousarray(c[:, ::-1] if rev else c, float), shift, rows_closed)
    if rows_closed:
        i = (i + shift) % n
    elif cols_closed:
        j = (j + shift) % m
    W = np.zeros((n, m), bool)
    W[i, m - 1 - j if rev else j] = True
    return W, (rev, shift)


def nearest_chamfer(path: np.ndarray, target: TargetCurve, closed_path: bool, unit: float | None = None) -> float:
    """The order-free symmetric chamfer of a path against the target (a diagnostic: each
    point to the nearest point of the other curve, wherever it is along it), over the
    target's diagonal.

    .. math::

        e = \\frac{1}{2D}\\left(\\frac{1}{M}\\sum_{i=1}^{M} d(a_i, B)
            + \\frac{1}{M}\\sum_{j=1}^{M} d(b_j, A)\\right)

    with ``a_i`` and ``b_j`` :data:`M_ERROR` points equally spaced in arc length along the
    target ``A`` and the path ``B`` (each a polyline, closed or open), ``d(p, C)`` the
    distance from ``p`` to the nearest point of polyline ``C`` and ``D`` the target's
    diagonal (:attr:`TargetCurve.diagonal`, or ``unit``). Both terms are means over arc
    length, so the value does not depend on how either curve is sampled, and a path lying
    on the target scores 0 up to the polylines' chords. The first term is large where the
    path leaves part of the target out, the second where it strays from it (a loop
    cutting across a letter).

    >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> circle = TargetCurve(np.c_[np.cos(t), np.sin(t)], closed=True)
    >>> bool(nearest_chamfer(np.c_[np.cos(t), np.sin(t)][::3], circle, True) < 1e-4)   # chords only
    True
    >>> round(nearest_chamfer(1.1 * np.c_[np.cos(t), np.sin(t)], circle, True) * circle.diagonal, 3)
    0.1
    """
    unit = target.diagonal if unit is None else unit
    A = even_points(target.points, target.closed)
    B = even_points(path, closed_path)
    a = np.linalg.norm(_to_polyline(A, *_polyline(path, closed_path))[0], axis=-1).mean()
    b = np.linalg.norm(_to_polyline(B, *_polyline(target.points, target.closed))[0], axis=-1).mean()
    return float(0.5 * (a + b) / unit)


def curve_errors(path: np.ndarray, target: TargetCurve, closed_path: bool,
                 unit: float | None = None) -> tuple[float, float, float]:
    """``(chamfer, nearest, ordered)`` of a traced path against the target, in target
    diagonals (or in ``unit``): :func:`chamfer_error` (the error shown and ranked by), the
    order-free :func:`nearest_chamfer` and, as a diagnostic of the timing only, the RMS
    distance between 128 points equally spaced in arc length along both, best start and
    sense."""
    unit = target.diagonal if unit is None else unit
    chamfer = chamfer_error(path, target, closed_path, unit)
    nearest = nearest_chamfer(path, target, closed_path, unit)
    m = 128
    w = resample(target.points, m, closed=target.closed)
    z = resample(path, m, closed=closed_path)
    rolls = (np.arange(m)[None, :] - np.arange(m)[:, None]) % m      # row s: the start moved by s
    best = min(float(np.sqrt(np.mean(np.abs(zz[rolls] - w) ** 2, axis=1)).min()) for zz in (z, z[::-1]))
    return float(chamfer), float(nearest), best / unit


def departure(path: np.ndarray, target: TargetCurve, closed_path: bool, m: int = M_ORDER) -> tuple[int, float]:
    """Where the path departs most from the target, in order: the index of the target
    point farthest from the stretch of the path that the correspondence in order of
    :func:`chamfer_error` puts beside it, and that distance (target units). For a loop
    that cuts across a letter, the parts of the outline it passes near but out of order
    count as departed from.

    >>> t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    >>> circle = TargetCurve(np.c_[np.cos(t), np.sin(t)], closed=True)
    >>> upper = np.c_[np.cos(t), np.abs(np.sin(t))]      # the upper half twice: the lower is left out
    >>> i, d = departure(upper, circle, True)
    >>> bool(circle.points[i, 1] < -0.5), bool(d > 1.0)
    (True, True)
    """
    Af, Bf = _fine(target.points, target.closed, m), _fine(path, closed_path, m)
    c = 0.5 * (_beside(Af[::FINE], Bf, closed_path) + _beside(Bf[::FINE], Af, target.closed).T)
    W, _ = correspondence(c, target.closed, closed_path)
    P = np.asarray(target.points, float)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
    total = arc[-1] + (float(np.linalg.norm(P[0] - P[-1])) if target.closed else 0.0)
    at = np.rint(arc / (total / (m if target.closed else m - 1))).astype(int)   # each point's sample
    at = at % m if target.closed else np.minimum(at, m - 1)
    seg = _seg_dist(P, Bf, closed_path)
    D = seg[np.arange(len(P)), _compiled().nearest_beside(seg, np.ascontiguousarray(W[at]), closed_path, FINE)]
    i = int(np.argmax(D))
    return i, float(D[i])


# ---------------------------------------------------------------------------- evaluation


def input_offsets(start: float, stop: float, closed: bool, n: int = N_TRACE) -> np.ndarray:
    if closed:
        return start + np.arange(n) * (360.0 / n)
    return np.linspace(start, stop, n)


_FULL_PLANS: dict[str, Any] = {}


def full_plan(topo: CurveTopology):
    """The topology's batch plan with every joint (and the tracer) as an output."""
    plan = _FULL_PLANS.get(topo.key)
    if plan is None:
        from mechsyn.kinematics.batch import compile_plan

        plan = compile_plan(topo.model, points=list(topo.plan.names))
        if list(plan.names) != list(topo.plan.names):  # the parameters must mean the same
            raise RuntimeError(f"{topo.key}: the full plan orders its points differently")
        _FULL_PLANS[topo.key] = plan
    return plan


def path_sizes(paths: dict[str, np.ndarray], centre: tuple[float, float]) -> np.ndarray:
    """Largest distance ``(K,)`` of any point from ``centre`` over the motion; samples
    not placed are ignored (inf when none is)."""
    R = np.stack([np.hypot(P[..., 0] - centre[0], P[..., 1] - centre[1]) for P in paths.values()], axis=-1)
    m = np.max(np.where(np.isfinite(R), R, -np.inf), axis=(1, 2))
    return np.where(np.isfinite(m), m, np.inf)          # nothing placed: no size to speak of


@dataclass(frozen=True)
class Bounds:
    """Design bounds in the working frame: ``centre`` the target's bounding-box centre,
    ``unit`` its diagonal, ``radius`` the size bound (``None`` or 0 where lifted)."""

    centre: tuple[float, float]
    unit: float
    radius: float | None
    link_ratio: float | None
    transmission: float
    region: tuple[float, float, float, float] | None

    def excess(self, size: np.ndarray, ratio: np.ndarray, mu: np.ndarray, margin: float = 1.0) -> np.ndarray:
        """Relative violations ``(K, 3)`` (size, link ratio, transmission), 0 inside the
        bounds each scaled by ``margin`` (the transmission bound divided by it)."""
        out = np.zeros((len(size), 3))
        if self.radius is not None:
            out[:, 0] = np.maximum(0.0, np.nan_to_num(size, nan=np.inf) / (margin * self.radius) - 1.0)
        if self.link_ratio is not None:
            out[:, 1] = np.maximum(0.0, ratio / (margin * self.link_ratio) - 1.0)
        if self.transmission > 0:
            need = min(89.0, self.transmission / margin)
            out[:, 2] = np.maximum(0.0, 1.0 - np.nan_to_num(mu, nan=0.0) / need)
        return np.minimum(out, 1e3)


@dataclass
class FitProblem:
    topo: CurveTopology
    target: TargetCurve
    closed_path: bool
    start: float
    stop: float
    bounds: Bounds

    def __post_init__(self) -> None:
        self.off = input_offsets(self.start, self.stop, self.closed_path)
        self.Af = _fine(self.target.points, self.target.closed, M_TARGET)   # the target, as the error sees it
        self.T = self.Af[::FINE]
        self.ts, self.tv = _polyline(self.Af, self.target.closed)
        self.features = sharp_features(self.target.points, self.target.closed)
        self.feature_at = np.argmin(np.linalg.norm(self.features[:, None] - self.T[None], axis=-1), axis=1) \
            if len(self.features) else np.zeros(0, int)
        self.diag = 1.0   # the working frame's length unit
        self.plan = full_plan(self.topo)
        names = self.topo.plan.names
        self.frame_pts = [i for i, n in enumerate(names) if n != TRACER and any(
            j["id"] == n and f"L{self.topo.frame}" in j["links"] for j in self.topo.template["joints"])]
        self.link_pairs = link_pairs(self.topo)
        self.nfev = 0
        self.deadline = float("inf")     # now() past which an evaluation raises OutOfTime
        self.best = (float("inf"), None)  # (cost, x) of the best design evaluated by fun
        self.last_match: tuple[np.ndarray, tuple] | None = None   # (path, its matched segments)

    def residuals(self, X: np.ndarray, keep: bool = False) -> np.ndarray:
        """Residual vectors ``(K, R)`` of designs ``X (K, P)``; with ``keep`` the nearest
        segments of the first design are used for all (the Jacobian's perturbations)."""
        X = np.atleast_2d(X)
        if now() > self.deadline:
            raise OutOfTime
        self.nfev += len(X)
        res = simulate_batch(self.plan, X, self.off, transmission=self.bounds.transmission > 0)
        P = res.paths[TRACER]
        bad = ~res.assembled.all(axis=1) | res.branch_jump
        P = np.where(np.isfinite(P), P, 0.0)
        starts = P if self.closed_path else P[:, :-1]
        vecs = (np.roll(P, -1, axis=1) if self.closed_path else P[:, 1:]) - starts
        F = self.features
        k1, k2, k3 = self.matched(P, bad, keep)    # segments matched in order (keep: the first design's)
        r1 = _to_polyline(self.T[None], starts, vecs, k1)[0]        # target -> path
        r2 = _to_polyline(P, self.ts[None], self.tv[None], k2)[0]   # path -> target
        r3 = _to_polyline(F[None], starts, vecs, k3)[0] if len(F) else np.zeros((len(X), 0, 2))
        r1 = r1 / np.sqrt(len(self.T))
        r2 = r2 * np.sqrt(_arc_weights(P, self.closed_path))[..., None]   # a mean over arc length, as reported
        r3 = r3 * (FEATURE_WEIGHT / np.sqrt(max(len(F), 1)))
        r = np.concatenate([r1.reshape(len(X), -1), r2.reshape(len(X), -1), r3.reshape(len(X), -1)],
                           axis=1) / self.diag
        r[bad] = PENALTY                 # off its branch or not assembled: never accepted
        size = path_sizes(res.paths, self.bounds.centre)
        mu = res.min_transmission_angle if res.min_transmission_angle is not None else np.full(len(X), 90.0)
        pen = [self.bounds.excess(size, link_ratio(X, self.link_pairs), mu, MARGIN) * BOUND_WEIGHT]
        if self.bounds.region is not None:
            x0, y0, x1, y1 = self.bounds.region
            G = X.reshape(len(X), -1, 2)[:, self.frame_pts]
            out = (np.maximum(0, x0 - G[..., 0]) + np.maximum(0, G[..., 0] - x1)
                   + np.maximum(0, y0 - G[..., 1]) + np.maximum(0, G[..., 1] - y1)) / self.diag
            pen.append(out * 10.0)
        self.last_bad = bad
        return np.concatenate([r] + pen, axis=1)

    def matched(self, P: np.ndarray, bad: np.ndarray, keep: bool) -> tuple[np.ndarray, ...]:
        """The segments each residual is measured to, for paths ``P (K, N, 2)``: ``(K, M)``
        path segments for the target's samples, ``(K, N)`` target segments for the path's
        samples, ``(K, F)`` path segments for the sharp features; each the nearest among
        those beside the samples a correspondence in order matches it to
        (:func:`correspondence`, the one :func:`chamfer_error` is taken along), so that a
        loop cutting across a letter is drawn to the parts of the outline its order puts it
        beside, not to the nearest stroke. With ``keep`` the first design's, for all (the
        Jacobian's perturbations)."""
        K = 1 if keep else len(P)
        last = self.last_match
        if K == 1 and last is not None and np.array_equal(last[0], P[0]):   # the Jacobian at fun's design
            ks = list(last[1])
        else:
            ks = self._match(P, bad, K)
            if K == 1:
                self.last_match = (P[0].copy(), tuple(ks))
        if keep:
            ks = [np.broadcast_to(k, (len(P),) + k.shape[1:]) for k in ks]
        return tuple(ks)

    def _match(self, P: np.ndarray, bad: np.ndarray, K: int) -> list[np.ndarray]:
        """The matched segments of :meth:`matched` for the first ``K`` paths."""
        ks = [np.zeros((K, len(self.T)), int), np.zeros((K, P.shape[1]), int),
              np.zeros((K, len(self.features)), int)]
        for d in range(K):
            if bad[d]:
                continue
            D1 = _seg_dist(self.T, P[d], self.closed_path)                  # (M, S1)
            D2 = _seg_dist(P[d], self.Af, self.target.closed)               # (N, S2)
            c = 0.5 * (_stretches(D1, self.closed_path, 1) + _stretches(D2, self.target.closed, FINE).T)
            W, _ = correspondence(c, self.target.closed, self.closed_path)   # (M, N): over every start and
            # sense, as the error is taken (one sought about the previous one can stay in a worse start)
            near = _compiled().nearest_beside
            ks[0][d] = near(D1, W, self.closed_path, 1)
            ks[1][d] = near(D2, np.ascontiguousarray(W.T), self.target.closed, FINE)
            if len(self.features):
                D3 = _seg_dist(self.features, P[d], self.closed_path)
                ks[2][d] = near(D3, W[self.feature_at], self.closed_path, 1)
        return ks

    def fun(self, x: np.ndarray) -> np.ndarray:
        r = self.residuals(x[None])[0]
        cost = float(r @ r)
        if cost < self.best[0] and not self.last_bad[0]:
            self.best = (cost, np.array(x, float))
        return r

    def jac(self, x: np.ndarray) -> np.ndarray:
        h = 1e-7 * self.diag
        X = np.vstack([x, x + h * np.eye(len(x))])
        R = self.residuals(X, keep=True)
        return (R[1:] - R[0]).T / h


def _arc_weights(P: np.ndarray, closed: bool) -> np.ndarray:
    """Weights ``(K, N)`` of path samples ``P (K, N, 2)`` summing to 1: each sample's share
    of the path's length (half its two neighbouring segments), so that sums over the
    samples are means over arc length whatever the crank's speed (uniform for a path
    without length)."""
    seg = np.hypot(*(np.diff(P, axis=1, append=P[:, :1] if closed else P[:, -1:])).transpose(2, 0, 1))
    before = np.roll(seg, 1, axis=1) if closed else np.concatenate([np.zeros_like(seg[:, :1]), seg[:, :-1]], axis=1)
    w = 0.5 * (seg + before)
    total = w.sum(axis=1, keepdims=True)
    return np.where(total > 0, w / np.where(total > 0, total, 1.0), 1.0 / P.shape[1])


class OutOfTime(Exception):
    """An evaluation asked for after :attr:`FitProblem.deadline` (the refinement keeps
    the best design it has evaluated)."""


FEATURE_WEIGHT = 0.25  # the sharp-feature residuals against the chamfer's (both /sqrt(count))
BOUND_WEIGHT = 1.0     # residual per unit of relative bound violation (aimed at MARGIN inside)


def sharp_features(points: np.ndarray, closed: bool, angle: float = 50.0) -> np.ndarray:
    """Corners, cusps and sharp bends of a curve ``(n, 2)``: the points where the
    direction turns by more than ``angle`` degrees within 2 % of the curve's length
    either side (local maxima of that turn), as ``(k, 2)``; an open curve's ends are
    features too. They are fitted point to path in the refinement beside the chamfer,
    so a corner is not rounded off for the sake of the mean distance.

    >>> sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])
    >>> sharp_features(sq, closed=True).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    """
    m = 200
    z = resample(points, m, closed=True) if closed else resample(points, 2 * m - 2, closed=False)[:m]
    k = max(2, int(round(0.02 * m)))
    if closed:
        d_in, d_out = z - np.roll(z, k), np.roll(z, -k) - z
    else:
        zi = np.arange(m)
        d_in = z - z[np.maximum(zi - k, 0)]
        d_out = z[np.minimum(zi + k, m - 1)] - z
    turn = np.degrees(np.abs(np.angle(d_out * np.conj(d_in))))
    turn = np.where((np.abs(d_in) > 0) & (np.abs(d_out) > 0), turn, 0.0)
    nb = [np.roll(turn, s) for s in range(-k, k + 1) if s]
    peak = (turn > angle) & np.all([turn >= b for b in nb], axis=0)
    if not closed:
        peak[:k + 1] = peak[-k - 1:] = False
        peak[0] = peak[-1] = True
    idx = np.flatnonzero(peak)
    keep = [i for j, i in enumerate(idx) if j == 0 or i - idx[j - 1] > k]   # one per plateau
    # the exact corner: the input point nearest the resampled peak
    P = np.asarray(points, float)
    pz = P[:, 0] + 1j * P[:, 1]
    near = [int(np.argmin(np.abs(pz - z[i]))) for i in keep]
    return P[sorted(set(near))] if near else np.zeros((0, 2))


def link_pairs(topo: CurveTopology) -> list[tuple[int, int]]:
    """Index pairs of joints (and tracer) on the same link: the link lengths."""
    names = topo.plan.names
    idx = {n: i for i, n in enumerate(names)}
    pairs = []
    for link, pts in topo.links_of().items():
        pts = [p for p in pts if p != TRACER]
        for a in range(len(pts)):
            for b in range(a + 1, len(pts)):
                pairs.append((idx[pts[a]], idx[pts[b]]))
    return pairs


def link_ratio(X: np.ndarray, pairs: list[tuple[int, int]]) -> np.ndarray:
    P = np.atleast_2d(X).reshape(len(np.atleast_2d(X)), -1, 2)
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    L = np.linalg.norm(P[:, a] - P[:, b], axis=-1)
    return L.max(axis=1) / np.maximum(L.min(axis=1), 1e-300)
