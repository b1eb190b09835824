"""Finite (local) mobility at a configuration: a numerical local-dimension test.

The instantaneous mobility ``m = dim ker M`` counts the motions of first order. The
**finite** (local) mobility is the dimension of the configuration space ``V`` (all
assemblies of the loops, every drive free) near the drawn configuration ``θ0``; it is
at most ``m`` and smaller at

* a **singular** configuration (a c-space singularity): ``V`` is not a smooth manifold
  there, branches of the motion meet (a four-bar folded flat at its change point:
  instantaneous 2, finite 1), and
* a **shaky** one: ``V`` is smooth there, of a dimension below ``m`` (a taut four-bar:
  instantaneous 2, finite 0; Wohlhart's variant of Fayet's linkage, instantaneous 5,
  finite 3, Müller 2016/2025; an octahedron whose alternate faces' planes meet in a
  point [4]_: its bars spin, the platform is held at second order).

Method (shrinking scales; all lengths in units of the mechanism's length scale, angles
in radians):

1. **Regular test.** For a few random unit directions ``d`` of ``ker M(θ0)``, the points
   ``θ0 + ε d`` are projected onto ``V`` by Gauss-Newton (least-norm steps), at
   ``ε`` and ``ε/4``. If ``d`` is tangent to a smooth ``m``-dimensional ``V``, the
   projection moves the point by ``O(ε²)``: the relative correction
   ``ρ(ε) = |θ(ε) - θ0 - ε d| / ε`` shrinks with ``ε``. A direction that leaves ``V``
   at second or higher order is corrected by ``O(ε)``: ``ρ`` stays. If ``ρ(ε/4) ≤ 0.6 ρ(ε)``
   for every sampled direction, every instantaneous motion extends to a finite one:
   the configuration is regular and the finite mobility is ``m``. (A random direction
   of ``ker M`` lies on a lower-dimensional tangent cone with probability zero, so a
   few samples decide.) A step near which the projection finds no assembly (it fails:
   a cusp's other side) does not extend either.
2. Otherwise, ``m + 4`` directions are projected at ``ε/4``; those that stay away from
   ``θ0`` (``|θ - θ0| > 0.2 ε/4``) land on branches of ``V`` through ``θ0``. At up to three
   landing points ``θ_i`` with the most different directions (generic, smooth points of
   their branches), steps ``η d`` with ``η = |θ_i|/8`` and ``d`` from ``ker M(θ0)`` are
   projected again: the number of independent directions in which they land is the
   branch's dimension (a smooth point's tangent space; this also holds where the
   instantaneous mobility stays higher along the branch), capped at ``dim ker M(θ_i)`` (a
   landing near where two branches cross along a line would otherwise read both as one
   wider branch). Once every landing lies in the tangent space of a branch measured
   (within about 3°), no other is measured: one smooth branch. The finite mobility is
   the largest. No landing point at all: ``θ0`` is isolated in ``V`` (finite mobility
   0), or, where projections failed, the motion is "not followed". A projection landing
   farther than ``3 ε`` from its start jumped to a distant assembly (least-norm steps
   can spin a free bar by radians): it counts as failed, never as a landing.
3. **Smooth or singular.** The tangent directions found (landing directions from ``θ0``
   and the branches' tangent spaces) span a space of dimension equal to the finite
   mobility exactly when the tangent cone is one linear space, i.e. ``V`` is a smooth
   manifold at ``θ0``; a larger span (two branches crossing) is a singular
   configuration. Directions of ``ker M`` at more than about 17° from that span are
   probed too, to find a second branch the first samples missed. A tangent cone that is
   only half of its span (a step opposite a landing direction lands nowhere opposite: a
   cusp's half-line) is singular too. Branches crossing at less than about 17° can be
   taken for one.

Tolerances: the Gauss-Newton target is ``max(1e-14, min(10 tol ε, (ε/1000)²))`` with
``tol`` the rank tolerance (relative to the length scale, see
:mod:`mechsyn.structure.rank`): the closure error of coordinates rounded in the file is
accepted (an iteration that stalls below ``10 tol ε`` stops there), and a motion
obstructed at second order (error growing as the square of the step) is undone to a
thousandth of the step; ``ρ`` below ``max(1e-6, 100 tol)`` counts as zero.

References
----------
.. [1] A. Müller, "Local kinematic analysis of closed-loop linkages - mobility,
   singularities, and shakiness", *ASME J. Mechanisms Robotics* 8(4), 041013, 2016
   (ASME DETC 2015-47485). doi:10.1115/1.4032778
.. [2] A. Müller, "Wohlhart's three-loop mechanism: an overconstrained and shaky
   linkage", arXiv:2509.14698, 2025.
.. [3] A. J. Sommese, J. Verschelde and C. W. Wampler, "Numerical decomposition of
   the solution sets of polynomial systems into irreducible components", *SIAM J.
   Numer. Anal.* 38(6), 2022-2046, 2001 (local dimension by nearby witness points).
.. [4] W. Blaschke, "Wackelige Achtflache", *Math. Z.* 6, 85-93, 1920 (an octahedron is
   infinitesimally movable when the planes of four alternate faces meet in a point).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

__all__ = ["LocalMobility", "local_mobility"]

#: Largest step of the regular test (normalised units: radians, lengths / length scale).
STEP = 0.04
_SPAN_EIG = 0.01  # an eigenvalue of Σ v vᵀ above this times the largest is a direction
_MAX_ITER = 100
_JUMP = 3.0  # a projection from a step ε lands within about 2ε of the base; farther, it jumped
_MISSED = 0.3  # sine of the angle beyond which a direction of ker M is missed by the directions found
_OPPOSITE = 0.87  # cos 30°: a step opposite a landing lands opposite it on a smooth branch
_ON_BRANCH = 0.05  # a landing within about 3° of a measured branch's tangent space lies on that branch

Step = Callable[[np.ndarray], "tuple[np.ndarray, np.ndarray]"]
Null = Callable[[np.ndarray], "tuple[int, np.ndarray]"]


@dataclass(frozen=True)
class LocalMobility:
    """What :func:`local_mobility` found at the configuration.

    ``configuration`` is ``"regular"``, ``"singular"`` (branches of the motion meet),
    ``"shaky"`` (smooth, instantaneous mobility above the finite one) or
    ``"not followed"`` (the projection did not converge; ``finite`` is None).
    ``tangent_span``: dimension of the span of the finite motions' directions;
    ``rank_nearby``: rank of the loop-closure matrix at nearby assembled configurations
    (None when there are none).
    """

    instantaneous: int
    finite: int | None
    configuration: str
    tangent_span: int | None
    rank_nearby: int | None
    notes: list[str] = field(default_factory=list)


class _Projector:
    """Gauss-Newton projection onto the closure set, counting its iterations."""

    def __init__(self, step: Step, tol: float) -> None:
        self.step, self.tol, self.calls = step, tol, 0

    def __call__(self, theta: np.ndarray, eps: float) -> np.ndarray | None:
        loose = max(1e-13, 10.0 * self.tol * eps)  # what rounded coordinates leave
        target = max(1e-14, min(loose, 1e-6 * eps * eps))
        theta = theta.copy()
        seen: list[float] = []
        for _ in range(_MAX_ITER):
            self.calls += 1
            err, delta = self.step(theta)
            e = float(np.linalg.norm(err))
            if not np.isfinite(e):
                return None
            if e <= target or (e <= loose and len(seen) >= 3 and e > 0.9 * seen[-3]):
                return theta  # converged, or stalled at the rounding of the file's coordinates
            seen.append(e)
            theta = theta - delta
        return None


def _direction(Nb: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    d = Nb @ rng.standard_normal(Nb.shape[1])
    return d / np.linalg.norm(d)


def _extends(proj: _Projector, base: np.ndarray, Nb: np.ndarray, eps: float, rng: np.random.Generator,
             samples: int) -> bool:
    """Whether random tangent directions at ``base`` extend to finite motions (step 1). A
    projection that finds no assembly near the step (it fails) does not extend it: step 2
    then says where the motion goes, or that it cannot be followed."""
    floor = max(1e-6, 100.0 * proj.tol)
    for _ in range(samples):
        d = _direction(Nb, rng)
        rho = []
        for e in (eps, eps / 4):
            t = proj(base + e * d, e)
            if t is None:
                return False
            rho.append(float(np.linalg.norm(t - base - e * d)) / e)
        if rho[1] > max(0.6 * rho[0], floor):
            return False
    return True


def _span(vectors: list[np.ndarray], F: int) -> tuple[int, np.ndarray]:
    """Number of independent directions among ``vectors`` (length at most about 1: a
    landing's displacement over its step, or a unit tangent) and an orthonormal basis of
    them (``F × k``): eigenvalues of ``Σ v vᵀ`` above :data:`_SPAN_EIG` times the largest.
    A landing that barely left its base weighs little: its direction is the least sure."""
    if not vectors:
        return 0, np.zeros((F, 0))
    V = np.array(vectors)
    w, U = np.linalg.eigh(V.T @ V)
    keep = w > _SPAN_EIG * max(float(w[-1]), 1e-300)
    return int(keep.sum()), U[:, keep]


def _landings(proj: _Projector, base: np.ndarray, Nb: np.ndarray, eps: float, rng: np.random.Generator,
              samples: int) -> tuple[list[np.ndarray], int]:
    """Unit directions (from ``base``) of the projected points that stay away from it,
    and how many projections failed."""
    out, failed = [], 0
    for _ in range(samples):
        t = proj(base + eps * _direction(Nb, rng), eps)
        if t is None or np.linalg.norm(t - base) > _JUMP * eps:
            failed += 1  # diverged, or jumped to a distant assembly: nothing about this neighbourhood
        elif np.linalg.norm(t - base) > 0.2 * eps:
            out.append(t - base)
    return out, failed


def _branch(proj: _Projector, null: Null, theta: np.ndarray, N: np.ndarray,
            rng: np.random.Generator) -> tuple[int, np.ndarray, int]:
    """Dimension and tangent basis of the branch of ``V`` through its smooth point
    ``theta`` (near ``θ0``), and the loop-closure rank there: the span of the directions in
    which points ``theta + η d`` (``d`` from ``ker M(θ0)``, ``η = |theta|/8``) land. A
    branch is never wider than the instantaneous motions at ``theta`` (the tangent cone
    lies in ``ker M(theta)``): steps that reach a second branch, when ``theta`` lies within
    ``η`` of where two branches cross, count for the widest ``dim ker M(theta)`` only."""
    eta = float(np.linalg.norm(theta)) / 8
    theta = proj(theta, eta / 4)  # on V to within the accuracy the smaller steps need
    if theta is None:
        return 0, np.zeros((N.shape[0], 0)), 0
    r, Nt = null(theta)
    moved, _ = _landings(proj, theta, N, eta, rng, N.shape[1] + 4)
    k, T = _span([v / eta for v in moved], theta.size)
    if k > Nt.shape[1]:  # eigenvectors come in ascending order: keep the widest
        k, T = Nt.shape[1], T[:, k - Nt.shape[1]:]
    return k, T, r


def _one_sided(proj: _Projector, moved: list[np.ndarray], eps: float) -> bool:
    """Whether the motion leaves ``θ0`` one way only along a landing direction ``u``: the
    step ``-ε u`` finds no assembly opposite (it fails, jumps, stays near ``θ0`` or lands
    more than 30° off ``-u``), as on a cusp's half-line or Whitney's umbrella. On a smooth
    branch both ways land, symmetric to first order."""
    for i in _diverse(moved, 3):
        u = moved[i] / np.linalg.norm(moved[i])
        t = proj(-eps * u, eps)
        far = 0.0 if t is None else float(np.linalg.norm(t))
        if not 0.2 * eps < far <= _JUMP * eps or -float(t @ u) < _OPPOSITE * far:
            return True
    return False


def _diverse(vectors: list[np.ndarray], k: int) -> list[int]:
    """Indices of up to ``k`` vectors with the most different directions (greedy)."""
    units = [v / np.linalg.norm(v) for v in vectors]
    chosen = [0]
    while len(chosen) < min(k, len(units)):
        score = [min(1 - abs(float(u @ units[c])) for c in chosen) for u in units]
        best = int(np.argmax(score))
        if score[best] < 1e-3:
            break
        chosen.append(best)
    return chosen


def local_mobility(step: Step, null: Null, N: np.ndarray, rank0: int, tol: float, seed: int = 0,
                   eps: float = STEP) -> LocalMobility:
    """Finite mobility and kind of configuration at ``θ = 0`` (module docstring).

    ``step(θ)`` returns the closure error and the Gauss-Newton step (``M(θ)⁺ err``);
    ``null(θ)`` the rank of ``M(θ)`` and an orthonormal basis of its null space; ``N``
    the null space at ``θ = 0`` (``F × m``) and ``rank0`` its rank.

    Examples
    --------
    A point sliding on the parabola ``y = x²`` and also on the line ``y = 0``: the two
    constraints meet at the origin, where the Jacobian ``[[0, 1], [0, 1]]`` has rank 1, so
    one instantaneous freedom, but no finite motion (the origin is isolated): shaky.

    >>> import numpy as np
    >>> def closure(t):
    ...     return np.array([t[1] - t[0] ** 2, t[1]]), np.array([[-2 * t[0], 1.0], [0.0, 1.0]])
    >>> def step(t):
    ...     err, J = closure(t)
    ...     return err, np.linalg.lstsq(J, err, rcond=1e-6)[0]
    >>> def null(t):
    ...     _, s, vt = np.linalg.svd(closure(t)[1])
    ...     r = int(np.sum(s > 1e-6))
    ...     return r, vt[r:].T
    >>> lm = local_mobility(step, null, np.array([[1.0], [0.0]]), 1, 1e-6)
    >>> lm.instantaneous, lm.finite, lm.configuration
    (1, 0, 'shaky')
    """
    F, m = N.shape
    if m == 0:
        return LocalMobility(0, 0, "regular", 0, rank0)
    rng = np.random.default_rng(seed)
    proj = _Projector(step, tol)
    zero = np.zeros(F)
    if _extends(proj, zero, N, eps, rng, 3):
        return LocalMobility(m, m, "regular", m, rank0)
    e = eps / 4
    moved, failed = _landings(proj, zero, N, e, rng, min(m + 4, 24))
    if not moved:
        if failed:
            return LocalMobility(m, None, "not followed", None, None,
                                 ["the motion could not be followed numerically (closure did not converge)"])
        return LocalMobility(m, 0, "shaky", 0, None)  # isolated: no assembly near it
    dims, dirs, ranks = [], [v / e for v in moved], []
    for i in _diverse(moved, 3):
        k, T, r = _branch(proj, null, moved[i], N, rng)
        dims.append(k)
        ranks.append(r)
        dirs.extend(T.T)  # unit tangents of the branch
        if k and all(np.linalg.norm(v - T @ (T.T @ v)) <= _ON_BRANCH * np.linalg.norm(v) for v in moved):
            break  # every landing lies in this branch's tangent space: one smooth branch, measured
    finite = max(dims)
    span, S = _span(dirs, F)
    if span <= finite and span < m:  # probe the directions the samples missed
        comp = N - S @ (S.T @ N)
        u, s, _ = np.linalg.svd(comp, full_matrices=False)
        C = u[:, s > _MISSED]  # directions of ker M at more than about 17° from every one found
        extra, _ = _landings(proj, zero, C, e, rng, 2 * C.shape[1] + 2) if C.shape[1] else ([], 0)
        outside = [v for v in extra if np.linalg.norm(v - S @ (S.T @ v)) > 0.3 * np.linalg.norm(v)]
        if outside:
            span = max(span, finite + 1)
    configuration = "singular" if span > finite else ("shaky" if finite < m else "regular")
    if configuration == "shaky" and finite and _one_sided(proj, moved, e):
        configuration = "singular"  # the tangent cone is a half-space of its span: not smooth
    return LocalMobility(m, finite, configuration, span, max(ranks) or None)
