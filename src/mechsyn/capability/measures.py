"""Velocity capability measures of an arm configuration under joint speed limits.

The joint rates lie in the box ``|q_dot_i| <= w_i`` (``w`` = joint speed limits); the end
point velocities ``v = J q_dot`` then fill the *velocity zonotope*
``Z = { sum_i a_i g_i : |a_i| <= 1 }`` with generators ``g_i = w_i J[:, i]``.
For a unit direction ``d`` (paper 004, "mobility"):

* :func:`exact_limit` -- the largest speed of *pure* motion along ``d``:
  ``max s`` s.t. ``J q_dot = s d``, ``|q_dot_i| <= w_i``. In 2-D, closed form:
  ``s* = min_k h(n_k) / |n_k . d|`` over the facet normals ``n_k = perp(g_k)`` of Z with
  the support function ``h(n) = sum_i |n . g_i|``. In m-D (spatial arms) the same over
  the normals of (m-1)-subsets of generators; a linear program (HiGHS) where J is
  rank-deficient (:func:`exact_limit_lp`).
* :func:`component_limit` -- the largest component along ``d`` with the perpendicular
  part free: ``h(d) = sum_i w_i |d . J[:, i]|`` (>= the exact limit).
* :func:`min_norm_limit` -- the limit of the (weighted) minimum-norm joint rates
  ``q_dot = J^+ s d`` (paper 004's Q_dot_N): ``1 / max_i |(J^+ d)_i| / w_i``.
* :func:`stepped_limit` -- paper 004's procedure: raise the speed from 5 mm/s in 5 mm/s
  steps until a joint rate limit is broken; the last feasible value (0 if none).

All functions take stacks: ``J`` of shape (N, m, n); ``w`` (n,) or (N, n); ``d`` (m,) or
(N, m) (normalised inside). Singular configurations give finite values, never NaN.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# relative tolerance for "this facet normal is perpendicular to d" (round-off level)
_PERP_TOL = 1e-12


def _prep(J, w, d):
    J = np.asarray(J, float)
    if J.ndim == 2:
        J = J[None]
    N, m, n = J.shape
    w = np.broadcast_to(np.asarray(w, float), (N, n))
    d = np.broadcast_to(np.asarray(d, float), (N, m))
    norm = np.linalg.norm(d, axis=-1, keepdims=True)
    if np.any(norm == 0) or not np.all(np.isfinite(d)):
        raise ValueError("direction must be a finite non-zero vector")
    return J, w, d / norm


def exact_limit(J, w, d, dual: bool = False):
    """Largest speed of pure motion along ``d`` (see module docstring), shape (N,).

    2-D tasks: the closed form over the zonotope's facets, vectorised. Candidate normals
    are ``perp(g_k)`` (the facet normals of a full zonotope) and ``g_k`` itself (each a
    valid bound; they make the degenerate case exact, where Z is a segment along
    ``d``). Normals perpendicular to ``d`` give no bound; if no normal is left (J = 0)
    the limit is 0. Other task dimensions: facet enumeration (see the module docstring),
    a linear program for rank-deficient Jacobians.

    With ``dual``, also the optimal dual vectors ``y`` (N, m), ``y . d = 1``: the normal
    of the bounding facet, scaled so that the limit is ``sum_i w_i |J_i . y|`` (zero rows
    where no facet bounds); :func:`optimal_rates` gives the joint rates that attain it.

    >>> s, y = exact_limit(np.array([[1.0, 1.0], [0.0, 1.0]]), [1.0, 1.0], [1.0, 0.0], dual=True)
    >>> s.tolist(), y.tolist()
    ([1.0], [[1.0, -1.0]])
    """
    J, w, d = _prep(J, w, d)
    m, n = J.shape[1], J.shape[2]
    if m != 2:
        if m < 2 or m > 6 or n > 12:
            return exact_limit_lp(J, w, d, dual=dual)
        return _exact_limit_facets(J, w, d, dual)
    G = J * w[:, None, :]  # (N, 2, n) generators
    P = np.stack([-G[:, 1], G[:, 0]], 1)  # perpendiculars
    normals = np.concatenate([P, G], axis=2)  # (N, 2, 2n)
    s, y = _limit_from_normals(G, normals, d)
    return (s, y) if dual else s


def _limit_from_normals(G: np.ndarray, normals: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``min_k h(n_k) / |n_k . d|`` over candidate normals (N, m, K); 0 if none bounds.
    Also the minimising normal scaled to ``y . d = 1`` (the dual vector; 0 if none)."""
    length = np.linalg.norm(normals, axis=1)  # (N, K)
    size = length.max(axis=1, keepdims=True)
    usable = length > _PERP_TOL * size
    unit = normals / np.where(usable, length, 1.0)[:, None, :]
    h = np.abs(np.einsum("nik,nij->nkj", unit, G)).sum(-1)  # support values (N, 2n)
    sd = np.einsum("nik,ni->nk", unit, d)
    nd = np.abs(sd)
    usable &= nd > _PERP_TOL
    ratio = np.where(usable, h / np.where(usable, nd, 1.0), np.inf)
    k = ratio.argmin(axis=1)
    rows = np.arange(len(k))
    s = ratio[rows, k]
    bounded = np.isfinite(s)
    y = unit[rows, :, k] / np.where(bounded, sd[rows, k], 1.0)[:, None]
    return np.where(bounded, s, 0.0), np.where(bounded[:, None], y, 0.0)


def _exact_limit_facets(J: np.ndarray, w: np.ndarray, d: np.ndarray, dual: bool = False):
    """m-D closed form: the facet normals of a full-dimensional zonotope are the normals
    of the hyperplanes spanned by (m-1)-subsets of generators (generalised cross products,
    by cofactors); configurations whose J is rank-deficient go to the linear program."""
    from itertools import combinations

    N, m, n = J.shape
    G = J * w[:, None, :]
    subsets = np.array(list(combinations(range(n), m - 1)))  # (C, m-1)
    if subsets.size == 0:
        return exact_limit_lp(J, w, d, dual=dual)
    if m == 3:  # cross products g_i x g_j of the generator pairs
        a, b = G[:, :, subsets[:, 0]], G[:, :, subsets[:, 1]]  # (N, 3, C)
        normals = np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1],
                            a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                            a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], 1)
    else:
        sub = np.moveaxis(G[:, :, subsets], 2, 1)  # (N, C, m, m-1)
        normals = np.empty((N, m, subsets.shape[0]))
        for r in range(m):
            minor = np.delete(sub, r, axis=2)  # (N, C, m-1, m-1)
            normals[:, r, :] = (-1) ** r * np.linalg.det(minor)
    normals = np.concatenate([normals, G], axis=2)
    out, y = _limit_from_normals(G, normals, d)
    sv = np.linalg.svd(G, compute_uv=False)
    deficient = sv[:, -1] <= 1e-9 * np.maximum(sv[:, 0], 1e-300)
    if deficient.any():
        out[deficient], y[deficient] = exact_limit_lp(J[deficient], w[deficient], d[deficient], dual=True)
    return (out, y) if dual else out


def exact_limit_lp(J, w, d, dual: bool = False):
    """The same as :func:`exact_limit` by linear programming, any task dimension.

    ``max s`` over ``(q_dot, s)`` s.t. ``J q_dot - s d = 0``, ``-w <= q_dot <= w``,
    ``s >= 0`` (scipy.optimize.linprog, HiGHS). The configurations' programs are
    independent, so up to :data:`_LP_BLOCK` variables of them are solved as one program
    with a block-diagonal constraint matrix (maximising the sum of the ``s`` maximises
    each): one call per block instead of one per configuration, whose fixed cost
    (about 9 ms) made a long URDF chain's capability cost seconds per joint. With
    ``dual``, also the dual vectors ``y`` (N, m) of the equality rows, ``y . d = 1``
    (as :func:`exact_limit`).

    >>> J = np.array([[[1.0, 0.0, 1.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]] * 3)
    >>> exact_limit_lp(J, [1.0, 2.0, 0.5], [1.0, 0.0, 0.0]).round(6).tolist()
    [1.5, 1.5, 1.5]
    """
    J, w, d = _prep(J, w, d)
    N, m, n = J.shape
    out, y = np.zeros(N), np.zeros((N, m))
    per = max(1, _LP_BLOCK // (n + 1))
    for start in range(0, N, per):
        stop = min(N, start + per)
        out[start:stop], y[start:stop] = _lp_block(J[start:stop], w[start:stop], d[start:stop])
    return (out, y) if dual else out


#: variables of one block-diagonal linear program of :func:`exact_limit_lp`
_LP_BLOCK = 20_000


def _lp_block(J: np.ndarray, w: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`exact_limit_lp` of the configurations ``J (B, m, n)`` as one program, with
    the dual vectors (the equality rows' marginals, scaled to ``y . d = 1``; 0 where
    that is not possible); a configuration whose program HiGHS does not solve (never
    seen) is solved alone."""
    from scipy.optimize import linprog  # lazy: 0.5 s of start-up
    from scipy.sparse import csr_matrix

    B, m, n = J.shape
    k = n + 1  # columns of a block: the joint rates, then s
    rows = np.concatenate([J, -d[:, :, None]], axis=2).reshape(-1)  # each row of each block, dense
    cols = (np.arange(B)[:, None, None] * k + np.arange(k)[None, None, :]).repeat(m, axis=1).reshape(-1)
    A = csr_matrix((rows, cols, np.arange(B * m + 1) * k), shape=(B * m, B * k))
    c = np.tile(np.r_[np.zeros(n), -1.0], B)
    lo = np.concatenate([-w, np.zeros((B, 1))], axis=1).reshape(-1)
    hi = np.concatenate([w, np.full((B, 1), np.inf)], axis=1).reshape(-1)
    # no presolve: its reductions of a block of independent small programs cost twice the solve
    res = linprog(c, A_eq=A, b_eq=np.zeros(B * m), bounds=np.c_[lo, hi], method="highs",
                  options={"presolve": False})
    if res.status == 0:
        lam = res.eqlin.marginals.reshape(B, m)
        ld = np.einsum("bm,bm->b", lam, d)
        ok = np.abs(ld) > _PERP_TOL * np.maximum(np.linalg.norm(lam, axis=1), 1e-300)
        y = np.where(ok[:, None], lam / np.where(ok, ld, 1.0)[:, None], 0.0)
        return np.maximum(res.x.reshape(B, n + 1)[:, -1], 0.0), y
    if B == 1:
        return np.zeros(1), np.zeros((1, m))
    parts = [_lp_block(J[k:k + 1], w[k:k + 1], d[k:k + 1]) for k in range(B)]
    return np.concatenate([p[0] for p in parts]), np.concatenate([p[1] for p in parts])


def optimal_rates(J, w, d, limit, y) -> np.ndarray:
    """Joint rates (N, n) attaining :func:`exact_limit` ``limit`` along ``d``, from its
    dual vectors ``y``: ``w_i sign(J_i . y)`` for every joint whose column is not
    perpendicular to ``y`` (complementary slackness), the rest the least-norm rates
    that close ``J q_dot = limit d``.

    >>> J = np.array([[1.0, 1.0], [0.0, 1.0]])
    >>> s, y = exact_limit(J, [1.0, 1.0], [1.0, 0.0], dual=True)
    >>> optimal_rates(J, [1.0, 1.0], [1.0, 0.0], s, y).tolist()
    [[1.0, 0.0]]
    """
    J, w, d = _prep(J, w, d)
    G = J * w[:, None, :]
    gy = np.einsum("nmk,nm->nk", G, np.asarray(y, float))
    limit = np.asarray(limit, float)
    free = np.abs(gy) <= 1e-9 * np.maximum(limit, 1e-300)[:, None]
    qd = np.where(free, 0.0, w * np.sign(gy))
    rest = limit[:, None] * d - np.einsum("nmk,nk->nm", J, qd)
    JF = np.where(free[:, None, :], J, 0.0)
    lam = np.einsum("nij,nj->ni", np.linalg.pinv(JF @ np.swapaxes(JF, 1, 2), hermitian=True), rest)
    return qd + np.einsum("nmk,nm->nk", JF, lam)


def component_limit(J, w, d) -> np.ndarray:
    """Largest component of the velocity along ``d``, the rest free: ``sum_i w_i |d.J_i|``."""
    J, w, d = _prep(J, w, d)
    return np.abs(np.einsum("nmk,nm->nk", J, d) * w).sum(-1)


def min_norm_rates(J, d, weights=None, rcond: float = 1e-12) -> tuple[np.ndarray, np.ndarray]:
    """(Weighted) minimum-norm joint rates for a unit velocity along ``d``.

    ``q_dot = W^-1 J^T (J W^-1 J^T)^+ d`` (W = diag(weights); W = I is the
    pseudo-inverse of paper 004). Returns ``q_dot`` (N, n) and ``attains`` (N,): whether
    ``J q_dot = d`` (false where ``d`` leaves the range of a singular J).
    """
    J = np.asarray(J, float)
    if J.ndim == 2:
        J = J[None]
    N, m, n = J.shape
    d = np.broadcast_to(np.asarray(d, float), (N, m))
    winv = np.ones(n) if weights is None else 1.0 / np.asarray(weights, float)
    JW = J * winv[None, None, :]
    A = JW @ np.swapaxes(J, 1, 2)  # (N, m, m)
    lam = np.einsum("nij,nj->ni", np.linalg.pinv(A, rcond=rcond, hermitian=True), d)
    qd = np.einsum("nmk,nm->nk", JW, lam)
    residual = np.linalg.norm(np.einsum("nmk,nk->nm", J, qd) - d, axis=1)
    return qd, residual < 1e-9 * np.maximum(1.0, np.linalg.norm(d, axis=1))


def min_norm_limit(J, w, d, weights=None) -> np.ndarray:
    """Largest speed along ``d`` with minimum-norm joint rates: ``1 / max_i |q_dot_i| / w_i``
    for the unit-speed rates of :func:`min_norm_rates`; 0 where ``d`` is out of reach."""
    J, w, d = _prep(J, w, d)
    qd, ok = min_norm_rates(J, d, weights)
    worst = np.max(np.abs(qd) / w, axis=1)
    return np.where(ok & (worst > 0), 1.0 / np.where(worst > 0, worst, 1.0), 0.0)


def stepped_limit(limit: np.ndarray, step: float = 5.0) -> np.ndarray:
    """Paper 004's stepping: speeds ``step, 2 step, ...`` are tried until one breaks a
    joint rate limit; the last feasible one is returned (0 if even ``step`` fails).

    ``limit`` is the exact feasibility threshold of the rates used (:func:`min_norm_limit`
    for the paper's minimum-norm rates, :func:`exact_limit` when the null space is used to
    full effect): a speed ``v`` is feasible iff ``v <= limit`` (the rates scale linearly
    with ``v``). So the loop's answer is ``step * floor(limit / step)``, computed with an
    exact check of the neighbouring steps against round-off.
    """
    limit = np.asarray(limit, float)
    k = np.floor(limit / step)
    k = np.where((k + 1) * step <= limit, k + 1, k)
    k = np.where(k * step > limit, k - 1, k)
    return np.maximum(k, 0.0) * step


# --------------------------------------------------------------------------- polytope, ellipse
@dataclass
class VelocityPolytope:
    """The velocity zonotope of one configuration: ``vertices`` (V, m) (counter-clockwise
    in 2-D) and facets ``normals . v <= offsets`` (unit ``normals`` (F, m)); ``equalities``
    (E, m) with ``equalities . v = 0`` when the polytope is flat (singular J)."""

    vertices: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray
    equalities: np.ndarray

    def directional_limit(self, d) -> float:
        """Largest ``s`` with ``s d`` in the polytope."""
        d = np.asarray(d, float) / np.linalg.norm(d)
        if self.equalities.size and np.any(np.abs(self.equalities @ d) > 1e-9):
            return 0.0
        nd = self.normals @ d
        pos = nd > _PERP_TOL
        return float(np.min(self.offsets[pos] / nd[pos])) if pos.any() else 0.0


def velocity_polytope(J, w) -> VelocityPolytope:
    """Vertices and facets of ``{J q_dot : |q_dot_i| <= w_i}`` for one configuration.

    The vertices are images of box corners; the hull is taken in the range of J (SVD), so
    singular configurations give a flat polytope with equality rows. Facet offsets are
    the support values ``h(n) = sum_i |n . g_i|``.
    """
    from scipy.spatial import ConvexHull, QhullError  # lazy: start-up

    J = np.asarray(J, float)
    m, n = J.shape
    G = J * np.asarray(w, float)
    U, S, _ = np.linalg.svd(G)
    r = int(np.sum(S > 1e-12 * max(S.max() if S.size else 0.0, 1e-300)))
    basis, null = U[:, :r], U[:, r:]
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * n, indexing="ij")).reshape(n, -1).T
    pts = corners @ G.T  # (2^n, m)
    if r == 0:
        return VelocityPolytope(np.zeros((1, m)), np.zeros((0, m)), np.zeros(0), null.T)
    local = pts @ basis
    if r == 1:
        lo, hi = local[:, 0].min(), local[:, 0].max()
        verts = np.array([[lo], [hi]]) @ basis.T
        normals = np.array([basis[:, 0], -basis[:, 0]])
    else:
        try:
            hull = ConvexHull(local)
        except QhullError:
            hull = ConvexHull(local, qhull_options="QJ")
        verts = local[hull.vertices] @ basis.T
        if m == 2:  # order counter-clockwise
            c = verts - verts.mean(0)
            verts = verts[np.argsort(np.arctan2(c[:, 1], c[:, 0]))]
        if m == 2:  # a zonogon's edges are its generators: normals +-perp(g_k), exactly
            normals = _zonogon_normals(G)
        else:
            eq = np.unique(np.round(hull.equations, 12), axis=0)
            normals = eq[:, :-1] @ basis.T
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    offsets = np.abs(normals @ G).sum(1)
    return VelocityPolytope(verts, normals, offsets, null.T)


def _zonogon_normals(G: np.ndarray) -> np.ndarray:
    """Unit outward normals of the planar zonotope (zonogon) of generators ``G`` (2, n).

    Each edge of a zonogon is a generator (parallel generators make one edge), so its
    normals are ``+-perp(g_k)`` of the non-zero generators. Taken from the generators, not
    from the hull: near a singular configuration the zonogon is a thin sliver and Qhull's
    normals, fitted to nearly collinear vertices, lose digits (a planar 3R arm almost
    stretched out gave a directional limit 2.3e-7 too large, relative)."""
    norms = np.linalg.norm(G, axis=0)
    g = G[:, norms > 1e-12 * norms.max()] / norms[norms > 1e-12 * norms.max()]
    perp = np.stack([-g[1], g[0]], 1)
    return np.unique(np.round(np.concatenate([perp, -perp]), 15), axis=0)


@dataclass
class VelocityEllipse:
    """Image of the joint-rate ball ``sum (q_dot_i / w_i)^2 <= 1`` (inscribed in the box):
    ``semi_axes`` (m,) along the columns of ``axes`` (m, m), largest first."""

    semi_axes: np.ndarray
    axes: np.ndarray

    def radius(self, d) -> float:
        """Speed along ``d`` on the ellipse's boundary (0 if ``d`` leaves a flat ellipse)."""
        d = np.asarray(d, float) / np.linalg.norm(d)
        c = self.axes.T @ d
        small = self.semi_axes <= 1e-12 * max(self.semi_axes.max(), 1e-300)
        if np.any(np.abs(c[small]) > 1e-9):
            return 0.0
        val = np.sum((c[~small] / self.semi_axes[~small]) ** 2)
        return float(1 / np.sqrt(val)) if val > 0 else 0.0


def velocity_ellipse(J, w) -> VelocityEllipse:
    """Velocity ellipse(-oid) of ``J diag(w^2) J^T``, from the SVD of ``J diag(w)``
    (semi-axes = singular values, accurate also at singular configurations)."""
    J = np.asarray(J, float)
    U, S, _ = np.linalg.svd(J * np.asarray(w, float))
    semi = np.zeros(J.shape[0])
    semi[: S.size] = S
    return VelocityEllipse(semi, U)


MEASURES = ("exact", "component", "min_norm", "stepped_min_norm", "stepped")


def all_measures(J, w, d, weights=None, step: float = 5.0) -> dict[str, np.ndarray]:
    """Every directional measure for a stack of configurations (see module docstring)."""
    exact = exact_limit(J, w, d)
    mn = min_norm_limit(J, w, d, weights)
    return {
        "exact": exact,
        "component": component_limit(J, w, d),
        "min_norm": mn,
        "stepped_min_norm": stepped_limit(mn, step),
        "stepped": stepped_limit(exact, step),
    }
