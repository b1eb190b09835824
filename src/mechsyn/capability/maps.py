"""Search over the self-motion of a redundant arm, and capability maps over a region.

Paper 004: at every point A_i of a working region, the configurations M_i reaching it are
sampled (q1 in 20 deg steps, the other joints by inverse kinematics); the best one gives
V_max(A_i); tables over the region give maps of V_max and of the optimal joint angles, to
be interpolated for motion planning. Here the search is also continuous (a dense q1 scan
refined by golden-section search), vectorised over all points of a grid at once.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn._result import Result
from mechsyn.capability.arm import SerialArm, ik_numeric, ik_planar_3r
from mechsyn.capability.measures import (
    MEASURES, component_limit, exact_limit, min_norm_limit, min_norm_rates, optimal_rates, stepped_limit,
)
from mechsyn.errors import MechsynInputError
from mechsyn.parallel import run_tasks
from mechsyn.progress import ProgressCallback, counter

BRANCHES = {"negative": (-1,), "positive": (1,), "both": (-1, 1)}


def measure_values(arm: SerialArm, q: np.ndarray, direction, measure: str = "exact",
                   step: float = 5.0) -> np.ndarray:
    """One directional measure (see :mod:`mechsyn.capability.measures`) at configurations
    ``q`` (N, n); NaN rows (unreachable) give ``-inf``."""
    if measure not in MEASURES:
        raise ValueError(f"unknown measure {measure!r}; one of {', '.join(MEASURES)}")
    q = np.atleast_2d(np.asarray(q, float))
    good = np.all(np.isfinite(q), axis=1)
    out = np.full(q.shape[0], -np.inf)
    if not good.any():
        return out
    J = arm.jacobian(q[good])
    w = arm.qd_max
    if measure == "exact":
        v = exact_limit(J, w, direction)
    elif measure == "component":
        v = component_limit(J, w, direction)
    elif measure == "min_norm":
        v = min_norm_limit(J, w, direction, arm.weights)
    elif measure == "stepped":
        v = stepped_limit(exact_limit(J, w, direction), step)
    else:
        v = stepped_limit(min_norm_limit(J, w, direction, arm.weights), step)
    out[good] = v
    return out


def is_closed_form(arm: SerialArm) -> bool:
    """Planar 3R arms have exact IK for given q1 (:func:`ik_planar_3r`)."""
    return arm.kind == "planar" and arm.n == 3 and bool(arm.is_revolute.all())


def q1_range(arm: SerialArm, respect_limits: bool = True) -> tuple[float, float]:
    """Interval of the redundancy parameter q1 (radians): its limits, else a full turn."""
    lo, hi = arm.lower[0], arm.upper[0]
    if not respect_limits or not np.isfinite(lo) or not np.isfinite(hi):
        return -math.pi, math.pi
    return float(lo), float(hi)


def self_motion(arm: SerialArm, point, q1: np.ndarray | None = None, branch: str = "negative",
                respect_limits: bool = True, seeds: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Configurations reaching ``point`` over the self-motion.

    Planar 3R: exact IK for each ``q1`` (radians) and each elbow of ``branch``
    (``negative``: q3 < 0, paper 004's table; ``positive``; ``both``). Other arms: damped
    least squares from ``seeds`` quasi-random starts (joint 1 fixed at each ``q1`` when
    given), duplicates removed (:func:`self_motions`). Returns ``q`` (K, n) and ``valid``
    (K,): reached and, when ``respect_limits``, inside the joint limits.
    """
    if branch not in BRANCHES:
        raise ValueError(f"branch must be one of {', '.join(BRANCHES)}")
    if not is_closed_form(arm):
        return self_motions(arm, np.atleast_2d(np.asarray(point, float)), q1,
                            respect_limits, seeds)[0]
    if q1 is None:
        lo, hi = q1_range(arm, respect_limits)
        q1 = np.arange(lo, hi + 1e-9, math.radians(20.0))
    qs, oks = [], []
    for b in BRANCHES[branch]:
        q, ok = ik_planar_3r(arm, point, q1, b)
        qs.append(q)
        oks.append(ok)
    q, ok = np.concatenate(qs), np.concatenate(oks)
    valid = ok & (arm.within_limits(np.nan_to_num(q)) if respect_limits else True)
    return q, valid


def halton(count: int, dim: int) -> np.ndarray:
    """Points 1..count of the unscrambled Halton sequence in ``[0, 1)^dim``.

    Coordinate j is the radical inverse of the index in the j-th prime base (Halton 1960);
    the same numbers as ``scipy.stats.qmc.Halton(d=dim, scramble=False).random(count +
    1)[1:]``, without the 0.9 s import of :mod:`scipy.stats`.

    References
    ----------
    J. H. Halton, "On the efficiency of certain quasi-random sequences of points in
    evaluating multi-dimensional integrals", Numerische Mathematik 2, 84-90, 1960.

    Examples
    --------
    >>> halton(3, 2).tolist()
    [[0.5, 0.3333333333333333], [0.25, 0.6666666666666666], [0.75, 0.1111111111111111]]
    """
    primes: list[int] = []
    k = 2
    while len(primes) < dim:
        if all(k % p for p in primes):
            primes.append(k)
        k += 1
    out = np.zeros((count, dim))
    for j, base in enumerate(primes):
        i = np.arange(1, count + 1)
        f = 1.0
        while i.any():
            f /= base
            out[:, j] += f * (i % base)
            i //= base
    return out


def self_motions(arm: SerialArm, points: np.ndarray, q1: np.ndarray | None = None,
                 respect_limits: bool = True, seeds: int = 64
                 ) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`self_motion` of a numerically solved arm at many ``points`` (P, task_dim).

    The ``seeds`` starts of every point run through one vectorised damped least squares
    (:func:`ik_numeric`, each seed stopping when it has converged); the answers are
    those of solving each point alone. Returns one ``(q, valid)`` per point.
    """
    points = np.atleast_2d(np.asarray(points, float))
    P = points.shape[0]
    lo = np.where(np.isfinite(arm.lower), arm.lower, -math.pi)
    hi = np.where(np.isfinite(arm.upper), arm.upper, math.pi)
    start = lo + halton(seeds, arm.n) * (hi - lo)
    if q1 is not None:
        q1 = np.atleast_1d(q1)
        start = np.repeat(start, q1.size, axis=0)
        start[:, 0] = np.tile(q1, seeds)
    S = start.shape[0]
    q, ok = ik_numeric(arm, np.repeat(points, S, axis=0), np.tile(start, (P, 1)),
                       fixed_first=q1 is not None, respect_limits=respect_limits)
    out = []
    for k in range(P):
        qk, okk = q[k * S:(k + 1) * S], ok[k * S:(k + 1) * S]
        qk, okk = qk[okk], okk[okk]
        if len(qk):  # the same configuration up to full turns of R joints counts once
            key = np.where(arm.is_revolute, (qk + math.pi) % (2 * math.pi) - math.pi, qk)
            _, keep = np.unique(np.round(key, 4), axis=0, return_index=True)
            qk, okk = qk[np.sort(keep)], okk[np.sort(keep)]
        valid = okk & (arm.within_limits(np.nan_to_num(qk)) if respect_limits else True)
        out.append((qk, valid))
    return out


def _golden_max(f: Callable[[np.ndarray], np.ndarray], a: np.ndarray, b: np.ndarray,
                iterations: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised golden-section search for a maximum of ``f`` on ``[a, b]`` (arrays)."""
    r = (math.sqrt(5) - 1) / 2
    c, d = b - r * (b - a), a + r * (b - a)
    fc, fd = f(c), f(d)
    for _ in range(iterations):
        left = fc >= fd  # the maximum lies in [a, d]; else in [c, b]
        a, b = np.where(left, a, c), np.where(left, d, b)
        nc = np.where(left, b - r * (b - a), d)
        nd = np.where(left, c, a + r * (b - a))
        fnew = f(np.where(left, nc, nd))
        fc, fd = np.where(left, fnew, fd), np.where(left, fc, fnew)
        c, d = nc, nd
    x = np.where(fc >= fd, c, d)
    return x, np.maximum(fc, fd)


def continuous_best(arm: SerialArm, points: np.ndarray, direction, measure: str = "exact",
                    branch: str = "negative", respect_limits: bool = True,
                    scan_step_deg: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Best configuration over a continuous q1 for each of ``points`` (P, 2), planar 3R.

    A q1 scan in ``scan_step_deg`` steps, then golden-section refinement within one step
    of the best sample (infeasible q1 count as -inf). Returns ``q`` (P, 3), NaN where no
    configuration reaches the point, and the measure (P,), -inf there.
    """
    if not is_closed_form(arm):
        raise ValueError("continuous self-motion search is implemented for planar 3R arms")
    points = np.atleast_2d(np.asarray(points, float))
    P = points.shape[0]
    lo, hi = q1_range(arm, respect_limits)
    K = max(int(math.ceil((hi - lo) / math.radians(scan_step_deg))), 1) + 1
    scan = np.linspace(lo, hi, K)
    h = (hi - lo) / (K - 1) if K > 1 else 0.0
    best_q = np.full((P, 3), np.nan)
    best_v = np.full(P, -np.inf)
    for b in BRANCHES[branch]:
        def f(q1: np.ndarray, pts: np.ndarray = points, b: int = b) -> np.ndarray:
            q, ok = ik_planar_3r(arm, pts, q1, b)
            v = measure_values(arm, q, direction, measure)
            if respect_limits:
                v = np.where(arm.within_limits(np.nan_to_num(q, nan=np.inf)), v, -np.inf)
            return np.where(ok, v, -np.inf)

        grid_pts = np.repeat(points, K, axis=0)
        vals = f(np.tile(scan, P), grid_pts).reshape(P, K)
        k = np.argmax(vals, axis=1)
        q1s, vs = scan[k], vals[np.arange(P), k]
        a = np.clip(q1s - h, lo, hi)
        c = np.clip(q1s + h, lo, hi)
        x, fx = _golden_max(f, a, c)
        better = fx > vs
        q1s, vs = np.where(better, x, q1s), np.where(better, fx, vs)
        q, ok = ik_planar_3r(arm, points, q1s, b)
        improve = vs > best_v
        best_v = np.where(improve, vs, best_v)
        best_q[improve] = q[improve]
    best_q[~np.isfinite(best_v)] = np.nan
    return best_q, best_v


#: the continuous measure whose ascent a stepped one follows (stepping is monotone)
_SMOOTH = {"stepped": "exact", "stepped_min_norm": "min_norm"}


def measure_gradient(arm: SerialArm, q: np.ndarray, direction, measure: str = "exact"
                     ) -> tuple[np.ndarray, np.ndarray]:
    """A measure at configurations ``q`` (N, n) and its gradient over the joints (N, n).

    Sensitivity of the optimum (the envelope theorem): the exact limit is
    ``y . J(q) u`` with the dual vector ``y`` and the optimal rates ``u``
    (:func:`~mechsyn.capability.measures.optimal_rates`), the component limit the same
    with ``y = d`` and ``u = w sign(J^T d)``, so their gradient is ``y . d(J u)/dq``
    (:meth:`SerialArm.jacobian_derivative`, linear in the number of joints). The
    minimum-norm limit ``w_i / |q_dot_i|`` of its worst joint i differentiates through
    ``q_dot = W^-1 J^T (J W^-1 J^T)^-1 d``. Where the measure is not smooth (ties between
    facets or joints) this is the gradient of the piece that is active. A stepped measure
    gives its continuous measure and that one's gradient (stepping is monotone).

    Examples
    --------
    >>> import mechsyn as ms
    >>> arm = ms.examples.load("paper004_3r")
    >>> q = np.radians([[80.0, 25.0, -70.0]])
    >>> v, g = measure_gradient(arm, q, [1.0, 0.0])
    >>> e = 1e-7 * np.eye(3)
    >>> fd = [(measure_values(arm, q + e[k], [1, 0]) - measure_values(arm, q - e[k], [1, 0]))[0] / 2e-7
    ...       for k in range(3)]
    >>> bool(np.allclose(g[0], fd, rtol=1e-5))
    True
    """
    base = _SMOOTH.get(measure, measure)
    if base not in MEASURES:
        raise ValueError(f"unknown measure {measure!r}; one of {', '.join(MEASURES)}")
    v, g, _ = _value_gradient(arm, np.atleast_2d(np.asarray(q, float)), direction, base)
    return v, g


def _value_gradient(arm: SerialArm, q: np.ndarray, direction, base: str
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`measure_gradient` of a continuous measure ``base``, and the Jacobians
    (N, task_dim, n), from one computation of the joint frames."""
    axes = arm.joint_axes(q)
    J, w = axes[0][:, :arm.task_dim], arm.qd_max
    d = np.broadcast_to(np.asarray(direction, float) / np.linalg.norm(direction), (q.shape[0], arm.task_dim))
    if base == "min_norm":
        return (*_min_norm_gradient(arm, q, axes, d), J)
    if base == "exact":
        v, y = exact_limit(J, w, d, dual=True)
        u = optimal_rates(J, w, d, v, y)
    else:
        y = d
        u = w * np.sign(np.einsum("nmk,nm->nk", J, d))
        v = component_limit(J, w, d)
    return v, np.einsum("nkm,nm->nk", arm.jacobian_derivative(q, u, axes), y), J


def _min_norm_gradient(arm: SerialArm, q: np.ndarray, axes: tuple[np.ndarray, np.ndarray], d: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`measure_gradient` of the minimum-norm limit ``w_i / |q_dot_i|`` (worst joint
    i). With ``lam = A^-1 d``, ``A = J W^-1 J^T``: ``dq_dot_i/dq_k = W^-1_i (dJ_i/dq_k . lam
    - J_i . A^-1 (dJ/dq_k q_dot + J W^-1 c_k))``, ``c_k[j] = dJ_j/dq_k . lam``; the sums
    over j are a suffix and a prefix sum of 3x3 matrices (as in
    :meth:`SerialArm.jacobian_derivative`)."""
    J3, Z = axes
    J = J3[:, :arm.task_dim]
    N, m, n = J.shape
    winv = 1.0 / np.asarray(arm.weights, float)
    qd, ok = min_norm_rates(J, d, arm.weights)
    v = min_norm_limit(J, arm.qd_max, d, arm.weights)
    Ainv = np.linalg.pinv((J * winv) @ np.swapaxes(J, 1, 2), hermitian=True)
    lam = np.einsum("nij,nj->ni", Ainv, d)
    rev = arm.is_revolute
    lam3 = np.concatenate([lam, np.zeros((N, 3 - m))], axis=1)
    i = np.argmax(np.abs(qd) / arm.qd_max, axis=1)  # the worst joint
    rows = np.arange(N)
    Ji, zi = J3[rows, :, i], Z[rows, :, i]
    k = np.arange(n)
    # a_k = dJ_i/dq_k . lam: z_k x J_i (R joint k <= i), z_i x J_k (k > i, R joint i)
    a = np.where(rev & (k <= i[:, None]), np.einsum("nmk,nm->nk", np.cross(Z, Ji[:, :, None], axis=1), lam3), 0.0)
    a += np.where((k > i[:, None]) & rev[i][:, None],
                  np.einsum("nmk,nm->nk", np.cross(zi[:, :, None], J3, axis=1), lam3), 0.0)
    b = arm.jacobian_derivative(q, qd, axes)  # (N, n, m)
    # e_k = sum_j winv_j J_j (dJ_j/dq_k . lam): [sum_{j>=k} winv_j J_j (J_j x lam)^T] z_k (R k)
    # + [sum_{j<k, R} winv_j J_j (lam x z_j)^T] J_k
    wJ = J3 * winv
    Mj = np.einsum("nak,nbk->nkab", wJ, np.cross(J3, lam3[:, :, None], axis=1))
    suffix = np.cumsum(Mj[:, ::-1], axis=1)[:, ::-1]
    Pj = np.where(rev[:, None, None], np.einsum("nak,nbk->nkab", wJ, np.cross(lam3[:, :, None], Z, axis=1)), 0.0)
    prefix = np.cumsum(Pj, axis=1) - Pj
    e = np.where(rev[:, None], np.einsum("nkab,nbk->nka", suffix, Z), 0.0) + np.einsum("nkab,nbk->nka", prefix, J3)
    dqd = winv[i][:, None] * (a - np.einsum("nm,nmj,nkj->nk", J[rows, :, i], Ainv, b + e[:, :, :m]))
    qdi = qd[rows, i]
    g = np.where((ok & (v > 0))[:, None], -v[:, None] * dqd / np.where(qdi != 0, qdi, 1.0)[:, None], 0.0)
    return v, g


def refine_over_self_motion(arm: SerialArm, point, q0: np.ndarray, direction,
                            measure: str = "exact", respect_limits: bool = True,
                            iterations: int = 40, step: float = 0.2
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Local ascent over the self-motion manifold from configurations ``q0`` (K, n).

    Each iteration moves along the measure's gradient (:func:`measure_gradient`)
    projected onto the null space of J (the tangent of the self-motion), by ``2h``, ``h``
    and ``h/2``, and by ``h`` and ``h/2`` along the shortest vector in the convex hull of
    that gradient and the gradients at the last iteration's trials (gradient sampling:
    the measure is a minimum of smooth pieces; where pieces meet in a ridge, their
    gradients point across it and that vector along it); each trial is pulled back onto
    the point with damped least squares (:func:`ik_numeric`); the best improving one
    (within the limits) is kept with its step as the next ``h``; where none improves,
    ``h`` is divided by 4, and a start whose ``h`` falls below 1e-6, or whose projected
    gradient vanishes, is done.
    Five trials per start and iteration, each linear in the number of joints (a search
    along every null direction cost a number of trials that grew with the joints, each
    of them growing too). A stepped measure ascends its continuous measure (stepping is
    monotone, so the same configurations are best). Vectorised over the K starts, each
    independent of the others; deterministic. ``point`` is one (task_dim,) or one per
    start (K, task_dim), so the starts of many grid points run together. Returns the
    refined ``q`` (K, n) and their measure (K,).
    """
    q = np.atleast_2d(np.asarray(q0, float)).copy()
    K, n = q.shape
    r = arm.task_dim
    base = _SMOOTH.get(measure, measure)
    target = np.broadcast_to(np.asarray(point, float), (K, r))
    good = np.all(np.isfinite(q), axis=1)  # a NaN row (not reached) stays as it is, at -inf
    val, grad, jac = np.full(K, -np.inf), np.zeros((K, n)), np.zeros((K, r, n))
    if good.any():  # at q; each trial's come with it
        val[good], grad[good], jac[good] = _value_gradient(arm, q[good], direction, base)
    h = np.full(K, step)
    sampled = np.repeat(grad[:, None, :], 5, axis=1)  # the gradients at the last trials (around q)
    active = np.flatnonzero(good) if n > r else np.arange(0)
    scale = np.array([2.0, 1.0, 0.5, 1.0, 0.5])  # along the gradient, then along the ridge
    for _ in range(iterations):
        if not active.size:
            break
        qa, J = q[active], jac[active]
        A = qa.shape[0]
        g = _null_part(J, grad[active])
        bundle = np.concatenate([g[:, None], _null_part(J[:, None], sampled[active])], axis=1)
        ridge = _min_norm_combination(bundle)
        moving = np.linalg.norm(g, axis=1) > 1e-12 * np.maximum(np.abs(val[active]), 1e-300)
        dirs = np.stack([_unit(g)] * 3 + [_unit(ridge)] * 2, axis=1)  # (A, 5, n)
        trial, ok = ik_numeric(arm, np.repeat(target[active], 5, axis=0),
                               (qa[:, None, :] + h[active][:, None, None] * scale[:, None] * dirs).reshape(-1, n),
                               respect_limits=respect_limits, iterations=30, tol=1e-9)
        tv, tg, tJ = (x.reshape(A, 5, *x.shape[1:]) for x in _value_gradient(arm, trial, direction, base))
        if respect_limits:
            ok &= arm.within_limits(trial)
        tv = np.where(ok.reshape(A, 5), tv, -np.inf)
        trial = trial.reshape(A, 5, n)
        sampled[active] = np.where(np.isfinite(tv)[:, :, None], tg, grad[active][:, None])
        k = np.argmax(tv, axis=1)
        pick = np.arange(A), k
        best = tv[pick]
        better = moving & (best > val[active] + 1e-12 * np.abs(val[active]))
        up = active[better]
        q[up], grad[up], jac[up] = trial[pick][better], tg[pick][better], tJ[pick][better]
        val[active] = np.where(better, best, val[active])
        h[active] = np.where(better, np.minimum(h[active] * scale[k], 16 * step), h[active] / 4)
        active = active[moving & (h[active] >= 1e-6)]
    return q, (val if base == measure else measure_values(arm, q, direction, measure))


def _null_part(J: np.ndarray, g: np.ndarray) -> np.ndarray:
    """``g`` (..., n) without its part in the row space of ``J`` (..., m, n): its
    projection on the tangent of the self-motion, ``g - J^T (J J^T)^+ J g``."""
    JJt = np.linalg.pinv(J @ np.swapaxes(J, -1, -2), hermitian=True)
    return g - np.einsum("...mk,...m->...k", J, np.einsum("...ij,...jk,...k->...i", JJt, J, g))


def _unit(v: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(v, axis=1, keepdims=True)
    return v / np.where(norm > 0, norm, 1.0)


def _min_norm_combination(V: np.ndarray, rounds: int = 50) -> np.ndarray:
    """The shortest vector in the convex hull of the rows of ``V`` (N, k, n) (Frank and
    Wolfe with exact line search, from ``V[:, 0]``): the steepest ascent of a minimum of
    smooth pieces whose gradients are the rows (gradient sampling, Burke, Lewis and
    Overton 2005); along a ridge where gradients from its two sides point across it."""
    x = V[:, 0].copy()
    for _ in range(rounds):
        j = np.argmin(np.einsum("nkj,nj->nk", V, x), axis=1)
        diff = x - V[np.arange(len(j)), j]
        dd = np.einsum("nj,nj->n", diff, diff)
        t = np.clip(np.einsum("nj,nj->n", diff, x) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
        x -= t[:, None] * diff
    return x


@dataclass(repr=False)
class CapabilityMap(Result):
    """V_max over a grid: ``value[i, j]`` at ``(xs[i], ys[j])`` with the optimal
    configuration ``q[i, j]`` (radians; NaN where no allowed configuration reaches).

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> arm = ms.examples.load("paper004_3r")
    >>> cmap = ms.capability_map(arm, np.array([900.0, 1000.0]), np.array([900.0, 1000.0]), [1, 0])
    >>> cmap.value.shape, cmap.q.shape
    ((2, 2), (2, 2, 3))
    """

    _plot = "capability:plot_capability_map"

    xs: np.ndarray
    ys: np.ndarray
    z: float | None
    direction: np.ndarray
    measure: str
    search: str
    value: np.ndarray
    q: np.ndarray
    joint_names: tuple[str, ...]
    joint_is_revolute: np.ndarray
    #: the optimal configuration interpolated at a point (see :func:`capability_grid`)
    interpolated: dict[str, Any] | None = field(default=None, repr=False)
    interrupted: bool = False          # Ctrl-C: only the points of ``computed`` were solved
    computed: np.ndarray | None = None  # (len(xs), len(ys)) bool; None: every point

    def done(self) -> np.ndarray:
        """Which grid points were solved (all, unless Ctrl-C interrupted the map)."""
        return np.ones(self.value.shape, bool) if self.computed is None else self.computed

    def q_user(self) -> np.ndarray:
        """Optimal joint values in file units (degrees for R joints)."""
        return np.where(self.joint_is_revolute, np.degrees(self.q), self.q)

    def to_dict(self) -> dict:
        v = np.where(np.isfinite(self.value), self.value, np.nan)
        return {"x": self.xs, "y": self.ys, "z": self.z, "direction": self.direction,
                "measure": self.measure, "search": self.search,
                "v_max": v, "q_opt": self.q_user(), "joints": list(self.joint_names),
                "interrupted": self.interrupted, "computed_points": int(self.done().sum()),
                **({"computed": self.done()} if self.interrupted else {}),
                **({} if self.interpolated is None else {"interpolated": self.interpolated})}

    def table(self) -> np.ndarray:
        """Rows ``x, y, v_max, q...`` (x outer, y inner), shape (P, 3 + n); NaN where no
        allowed configuration reaches. Points not solved (Ctrl-C) have no row."""
        X, Y = np.meshgrid(self.xs, self.ys, indexing="ij")
        v = np.where(np.isfinite(self.value), self.value, np.nan)
        n = self.q.shape[-1]
        rows = np.column_stack([X.ravel(), Y.ravel(), v.ravel(), self.q_user().reshape(-1, n)])
        return rows if self.computed is None else rows[self.computed.ravel()]

    def rows(self) -> list[list[float]]:
        """:meth:`table` as a list of rows."""
        return self.table().tolist()

    def to_csv(self) -> str:
        """CSV text: a header ``x, y, v_max_<measure>, <joint>_opt...`` and :meth:`table`,
        each number the shortest text that reads back to the same float (as ``repr``),
        empty where not reachable. Formatted from the arrays, no Python loop per value.

        Examples
        --------
        >>> m = CapabilityMap(np.array([0.0, 1.0]), np.array([2.0]), None, np.array([1.0, 0]),
        ...                   "exact", "sampled", np.array([[0.5], [-np.inf]]),
        ...                   np.array([[[0.1]], [[np.nan]]]), ("q1",), np.array([False]))
        >>> print(m.to_csv(), end="")
        x,y,v_max_exact,q1_opt
        0.0,2.0,0.5,0.1
        1.0,2.0,,
        """
        table = self.table()
        head = ["x", "y", f"v_max_{self.measure}", *[f"{n}_opt" for n in self.joint_names]]
        columns = [_csv_column(table[:, j]) for j in range(table.shape[1])]
        return "\n".join([",".join(head), *map(",".join, zip(*columns))]) + "\n"


def _csv_column(values: np.ndarray) -> list[str]:
    """A column's numbers as CSV cells: Python's shortest round-trip text of each float (the
    text NumPy's ``astype(str)`` gives, at less than half its cost), empty for NaN.

    >>> _csv_column(np.array([0.1, np.nan, 1e-05, 2600.0]))
    ['0.1', '', '1e-05', '2600.0']
    """
    cells = list(map(float.__repr__, values.tolist()))
    for i in np.flatnonzero(np.isnan(values)).tolist():
        cells[i] = ""
    return cells


def capability_map(arm: SerialArm, xs, ys, direction, *, z: float | None = None,
                   measure: str = "exact", q1: np.ndarray | None = None,
                   branch: str = "negative", respect_limits: bool = True,
                   continuous: bool = False, chunk: int = 2048,
                   progress: ProgressCallback | None = None,
                   workers: int = 1, scheduler=None) -> CapabilityMap:
    """Best configuration and V_max at every grid point (paper 004, Table 2).

    ``q1`` (radians) samples the self-motion (default: 20 deg steps over q1's limits, the
    paper's choice); ``continuous`` uses :func:`continuous_best` instead (planar 3R), or
    refines the best 8 IK solutions with :func:`refine_over_self_motion` (other arms).
    The grid is solved in chunks of ``chunk`` points; ``progress(state)``
    (:class:`mechsyn.progress.Progress`: points done of all) is called after each chunk. ``workers`` (local processes) or
    ``scheduler`` (a Dask cluster) solve the chunks in parallel
    (:func:`mechsyn.parallel.run_tasks`): every point's answer depends only on the point,
    so the map is the same. Spatial arms need ``z`` (the grid lies in the plane z = const).
    Ctrl-C (:class:`KeyboardInterrupt`, also raised by ``progress``) returns the chunks
    finished so far, ``interrupted=True`` and ``computed`` marking their points (NaN
    elsewhere); it propagates when no chunk had finished.

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> arm = ms.examples.load("paper004_3r")
    >>> cmap = ms.capability_map(arm, np.array([1000.0]), np.array([1000.0]), [1, 0])
    >>> bool(np.isfinite(cmap.value).all())
    True
    """
    xs, ys = np.asarray(xs, float), np.asarray(ys, float)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel()], 1)
    if arm.kind == "spatial":
        pts = np.hstack([pts, np.full((pts.shape[0], 1), 0.0 if z is None else z)])
    P = pts.shape[0]
    tasks = [(arm, pts[start:start + chunk], direction, measure, q1, branch, respect_limits,
              continuous) for start in range(0, P, chunk)]

    got: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    advance = counter(progress, P, "points")

    def finished(index: int, result) -> None:
        got[index] = result  # kept before the progress callback, which may raise Ctrl-C
        advance(len(result[0]))

    interrupted = False
    try:
        run_tasks(_map_chunk, tasks, workers=workers, scheduler=scheduler, on_result=finished)
    except KeyboardInterrupt:
        if not got:
            raise
        interrupted = True
    size = [len(t[1]) for t in tasks]
    value = np.concatenate([got[i][0] if i in got else np.full(k, np.nan) for i, k in enumerate(size)])
    qopt = np.concatenate([got[i][1] if i in got else np.full((k, arm.n), np.nan) for i, k in enumerate(size)])
    qopt[~np.isfinite(value)] = np.nan
    d = np.asarray(direction, float)
    computed = np.repeat([i in got for i in range(len(tasks))], size).reshape(X.shape) if interrupted else None
    return CapabilityMap(xs, ys, z, d / np.linalg.norm(d), measure,
                         "continuous" if continuous else "sampled",
                         value.reshape(X.shape), qopt.reshape(*X.shape, arm.n),
                         arm.joint_names, arm.is_revolute, interrupted=interrupted, computed=computed)


def _map_chunk(arm: SerialArm, pts: np.ndarray, direction, measure: str, q1, branch: str,
               respect_limits: bool, continuous: bool) -> tuple[np.ndarray, np.ndarray]:
    """V_max (P,) and the best configuration (P, n) at the points of one chunk."""
    if continuous and is_closed_form(arm):
        q, v = continuous_best(arm, pts, direction, measure, branch, respect_limits)
        return v, q
    if not is_closed_form(arm):
        return _numeric_best(arm, pts, direction, measure, q1, respect_limits, continuous)
    if q1 is None:
        lo, hi = q1_range(arm, respect_limits)
        q1s = np.arange(lo, hi + 1e-9, math.radians(20.0))
    else:
        q1s = np.atleast_1d(q1)
    K = q1s.size
    pp = np.repeat(pts, K, axis=0)
    bq, bv = [], []
    for b in BRANCHES[branch]:
        q, ok = ik_planar_3r(arm, pp, np.tile(q1s, len(pts)), b)
        v = measure_values(arm, q, direction, measure)
        if respect_limits:
            v = np.where(arm.within_limits(np.nan_to_num(q, nan=np.inf)), v, -np.inf)
        bq.append(q.reshape(-1, K, 3))
        bv.append(v.reshape(-1, K))
    qq, vv = np.concatenate(bq, 1), np.concatenate(bv, 1)
    k = np.argmax(vv, axis=1)
    rows = np.arange(vv.shape[0])
    return vv[rows, k], qq[rows, k]


def _numeric_best(arm: SerialArm, pts: np.ndarray, direction, measure: str, q1,
                  respect_limits: bool, continuous: bool) -> tuple[np.ndarray, np.ndarray]:
    """Best measure (P,) and configuration (P, n) at points of a numerically solved arm:
    all points' IK together (:func:`self_motions`), then, with ``continuous``, the best
    8 configurations of every point refined together (:func:`refine_over_self_motion`)."""
    P = pts.shape[0]
    value = np.full(P, -np.inf)
    qopt = np.full((P, arm.n), np.nan)
    found = [q[valid] for q, valid in self_motions(arm, pts, q1, respect_limits)]
    sizes = np.array([len(q) for q in found])
    if not sizes.any():
        return value, qopt
    owner = np.repeat(np.arange(P), sizes)
    q = np.concatenate(found)
    v = measure_values(arm, q, direction, measure)
    if continuous:  # the best 8 of each point, in the order of a stable sort
        order = np.lexsort((np.arange(len(v)), -v, owner))
        rank = np.arange(len(v)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        top = order[rank < 8]
        owner = owner[top]
        q, v = refine_over_self_motion(arm, pts[owner], q[top], direction, measure,
                                       respect_limits)
    for k in np.unique(owner):  # first maximum of each point, as np.argmax
        rows = np.flatnonzero(owner == k)
        best = rows[np.argmax(v[rows])]
        value[k], qopt[k] = v[best], q[best]
    return value, qopt


def interpolate_configuration(cmap: CapabilityMap, method: str = "cubic"
                              ) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """Interpolant ``(x, y) -> q`` (radians, shape (..., n)) of the optimal configuration
    over the map (paper 004 suggests Lagrange polynomials; here
    scipy's RegularGridInterpolator, ``linear``, ``cubic`` or ``quintic``). Points
    near unreachable cells give NaN; the optimum may jump between self-motion branches,
    so check the interpolated configuration with forward kinematics before use.
    """
    q = cmap.q
    from scipy.interpolate import RegularGridInterpolator  # lazy: 0.5 s of start-up

    interp = RegularGridInterpolator((cmap.xs, cmap.ys), q, method=method,
                                     bounds_error=False, fill_value=np.nan)

    def at(x, y):
        x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
        return interp(np.stack([x.ravel(), y.ravel()], -1)).reshape(*x.shape, q.shape[-1])

    return at


def _interpolated(arm: SerialArm, cmap: CapabilityMap, at: np.ndarray) -> dict[str, Any]:
    """The optimal configuration interpolated at ``at`` = (x, y), its tool error and measure."""
    xs, ys = cmap.xs, cmap.ys
    if not (xs.min() <= at[0] <= xs.max() and ys.min() <= at[1] <= ys.max()):
        raise MechsynInputError(f"({at[0]:g}, {at[1]:g}) lies outside the grid", field="interpolate",
                                hint=f"give a point with x in [{xs.min():g}, {xs.max():g}] and y in "
                                     f"[{ys.min():g}, {ys.max():g}]")
    method = "cubic" if xs.size >= 4 and ys.size >= 4 else "linear"
    qi = interpolate_configuration(cmap, method)(at[0], at[1])
    target = at if arm.kind == "planar" else np.array([at[0], at[1], cmap.z])
    out: dict[str, Any] = {"point": target, "method": method, "q_deg": None, "tool_error": None,
                           cmap.measure: None}
    if np.all(np.isfinite(qi)):
        out.update({"q_deg": arm.to_user(qi), "tool_error": float(np.linalg.norm(arm.fk(qi)[0] - target)),
                    cmap.measure: float(measure_values(arm, qi[None], cmap.direction, cmap.measure)[0])})
    return out


def capability_grid(arm: SerialArm, xs, ys, direction, *, z: float | None = None, measure: str = "exact",
                    q1: np.ndarray | None = None, branch: str = "negative", respect_limits: bool = True,
                    continuous: bool = False, interpolate: Any = None,
                    progress: ProgressCallback | None = None, workers: int = 1,
                    scheduler: Any = None) -> CapabilityMap:
    """:func:`capability_map` with its inputs checked, the chunk size fit to the inverse
    kinematics (closed form or numeric), and the optimal configuration interpolated at
    ``interpolate`` = (x, y) when given (``CapabilityMap.interpolated``).

    Parameters
    ----------
    arm : SerialArm
    xs, ys : array_like
        The grid (finite; at most 5,000,000 points).
    direction : array_like
        Direction of motion, finite and non-zero.
    z : float, optional
        The grid's plane z = const; required for spatial arms.
    measure, q1, branch, respect_limits, continuous, progress, workers, scheduler
        As for :func:`capability_map`.
    interpolate : array_like, optional
        A point (x, y) inside the grid.

    Returns
    -------
    CapabilityMap

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.capability.maps import capability_grid
    >>> arm = ms.examples.load("paper004_3r")
    >>> m = capability_grid(arm, [900.0, 1000.0], [900.0, 1000.0], [1, 0], interpolate=(950, 950))
    >>> m.interpolated["method"], m.interpolated["tool_error"] < 50
    ('linear', True)
    """
    xs, ys, d = (np.asarray(v, float) for v in (xs, ys, direction))
    if not (np.all(np.isfinite(xs)) and np.all(np.isfinite(ys))):
        raise MechsynInputError("values must be finite", field="grid")
    if xs.size * ys.size > 5_000_000:
        raise MechsynInputError(f"{xs.size * ys.size:,} grid points are more than 5,000,000", field="grid",
                                hint="use larger steps or a smaller area")
    if arm.kind == "spatial" and z is None:
        raise MechsynInputError("a spatial arm's grid needs its plane", field="z",
                                hint="give the plane of the grid, e.g. z = 400")
    if not np.all(np.isfinite(d)) or not np.linalg.norm(d) > 0:
        raise MechsynInputError("the direction must be a finite, non-zero vector", field="direction")
    if measure not in MEASURES:
        raise MechsynInputError(f"unknown measure {measure!r}", field="measure", hint=", ".join(MEASURES))
    cmap = capability_map(arm, xs, ys, d, z=z, measure=measure, q1=q1, branch=branch,
                          respect_limits=respect_limits, continuous=continuous,
                          chunk=2048 if is_closed_form(arm) else 64, progress=progress,
                          workers=workers, scheduler=scheduler)
    if interpolate is not None:
        cmap.interpolated = _interpolated(arm, cmap, np.asarray(interpolate, float))
    return cmap
