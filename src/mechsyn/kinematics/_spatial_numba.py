"""The spatial engine's arithmetic compiled with Numba (imported only through
:func:`mechsyn.kinematics.spatial_model._nb`, on the first spatial sweep). Under
``NUMBA_DISABLE_JIT=1`` the same functions run as plain Python.

The equations of :mod:`mechsyn.kinematics.spatial_model` as two tables (its
:func:`~mechsyn.kinematics.spatial_model.tables`): *items*, each a few link-fixed points or
vectors on the two links of a pair (``it``: kind, first and second link; ``loc``: four
local 3-vectors), and *rows*, each one scalar equation on an item (``ri``: kind, item, a
second item, a component or an input column; ``rf``: a constant). Item kinds: 0 two points
(``x_a``, ``x_b``), 1 two vectors (``u_a``, ``w_b``), 2 a line (``x_a``, ``x_b`` and ``n_a``:
``s = (x_b - x_a) · n_a``), 3 a bar's ends, 4 an angle (``a_a``, ``e1_b``, ``e1_a``, ``e2_a``:
``θ = atan2(e1_b · e2_a, e1_b · e1_a)``). Row kinds: 0 a coordinate of ``x_a - x_b``, 1
``u_a · w_b - c``, 2 ``s - c``, 3 ``(|x_a - x_b|² - ℓ²) / 2ℓ``, 4 a helix ``s - h θ`` (``θ``
unwrapped next to its previous value), 5 an angle input ``θ - u``, 6 a slide input ``s - u``.
Every function works on one pose ``R`` (n + 1, 3, 3), ``p`` (n + 1, 3) (the frame last) or
on a batch of them, row after row in compiled loops (no temporaries of NumPy's per call):
a block of rows is corrected in one call (:func:`correct`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_OPTIONS = dict(cache=True, nogil=True, error_model="numpy")


@njit(inline="always", **_OPTIONS)
def _v(W, q, s):
    return W[q, s, 0], W[q, s, 1], W[q, s, 2]


@njit(inline="always", **_OPTIONS)
def _x(a, b):
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(inline="always", **_OPTIONS)
def _d(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(inline="always", **_OPTIONS)
def _ax(a, k, b):
    """``a + k b``."""
    return a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2]


@njit(inline="always", **_OPTIONS)
def _wrap(a):
    return math.pi - (math.pi - a) % (2 * math.pi)


@njit(inline="always", **_OPTIONS)
def _rotation(w, a, c, t2):
    """``(1 - c t2) I + a [w]x + c w wᵀ`` (3, 3): with ``|w|² = t2``, ``a = sin θ / θ`` and
    ``c = (1 - cos θ) / θ²`` the rotation by the angle ``θ = |w|`` about ``w`` (Rodrigues)."""
    E = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            k = 3 - i - j
            skew = 0.0 if i == j else (w[k] if (j - i) % 3 == 2 else -w[k])  # [w]x y = w × y
            E[i, j] = c * w[i] * w[j] + (1 - c * t2 if i == j else 0.0) + a * skew
    return E


@njit(**_OPTIONS)
def world(R, p, it, loc, W):
    """Every item's points and vectors at the pose into ``W`` (items, 4, 3): slot 1 on the
    second link, the others on the first; slots 0 and 1 are points for kinds 0, 2, 3."""
    for q in range(it.shape[0]):
        pts = it[q, 0] != 1 and it[q, 0] != 4
        for s in range(4):
            k = it[q, 2] if s == 1 else it[q, 1]
            for i in range(3):
                W[q, s, i] = R[k, i, 0] * loc[q, s, 0] + R[k, i, 1] * loc[q, s, 1] + R[k, i, 2] * loc[q, s, 2] + (
                    p[k, i] if pts and s < 2 else 0.0)


@njit(inline="always", **_OPTIONS)
def _theta(W, q):
    e = _v(W, q, 1)
    return math.atan2(_d(e, _v(W, q, 3)), _d(e, _v(W, q, 2)))


@njit(inline="always", **_OPTIONS)
def _slide(W, q):
    return _d(_ax(_v(W, q, 1), -1.0, _v(W, q, 0)), _v(W, q, 2))


@njit(inline="always", **_OPTIONS)
def _put(J, r, k, C, w, v):
    """Coefficients ``w · ω + v · v`` of link ``k``'s twist (origin) into row ``r`` of ``J``
    in the twist at its centre ``C[k]`` (``v = u + c × ω``: ``w += v × c``); the frame's
    (``k = n``) are not unknowns."""
    if k < C.shape[0]:
        wc = _ax(w, 1.0, _x(v, (C[k, 0], C[k, 1], C[k, 2])))
        for i in range(3):
            J[r, 6 * k + i] += wc[i]
            J[r, 6 * k + 3 + i] += v[i]


@njit(**_OPTIONS)
def evaluate(R, p, T, href, u, W, g, J, C, th, sl):
    """Residuals ``g`` (m,) at one pose (``href``: the H pairs' previous angles, ``u``: the
    inputs), the angles ``th`` and slides ``sl`` of the pairs measured, and, when ``J`` has
    rows, the Jacobian (m, 6 n) in the links' twists at their centres ``C`` (n, 3), which
    it sets."""
    it, loc, ri, rf, cen = T[0], T[1], T[2], T[3], T[4]
    world(R, p, it, loc, W)
    for k in range(T[5].shape[0]):
        th[k] = _theta(W, T[5][k])
    for k in range(T[6].shape[0]):
        sl[k] = _slide(W, T[6][k])
    jac = J.shape[0] > 0
    if jac:
        J[:] = 0.0
        for k in range(C.shape[0]):
            for i in range(3):
                C[k, i] = R[k, i, 0] * cen[k, 0] + R[k, i, 1] * cen[k, 1] + R[k, i, 2] * cen[k, 2] + p[k, i]
    z = (0.0, 0.0, 0.0)
    for r in range(ri.shape[0]):
        kind, q, q2, aux = ri[r, 0], ri[r, 1], ri[r, 2], ri[r, 3]
        c, n = z, z
        if kind == 0:
            g[r] = W[q, 0, aux] - W[q, 1, aux]
            if jac:
                e = (1.0 if aux == 0 else 0.0, 1.0 if aux == 1 else 0.0, 1.0 if aux == 2 else 0.0)
                _put(J, r, it[q, 1], C, _x(_v(W, q, 0), e), e)
                _put(J, r, it[q, 2], C, _x(e, _v(W, q, 1)), _ax(z, -1.0, e))
            continue
        if kind == 1:
            g[r] = _d(_v(W, q, 0), _v(W, q, 1)) - rf[r]
            c = _x(_v(W, q, 0), _v(W, q, 1))
        elif kind == 2 or kind == 6:
            g[r] = _slide(W, q) - (rf[r] if kind == 2 else u[aux])
            c, n = _x(_v(W, q, 2), _v(W, q, 1)), _v(W, q, 2)
        elif kind == 3:
            d = _ax(_v(W, q, 0), -1.0, _v(W, q, 1))
            g[r] = (_d(d, d) - rf[r] * rf[r]) / (2 * rf[r])
            n = _ax(z, -1.0 / rf[r], d)
            c = _x(n, _v(W, q, 0))
        elif kind == 4:
            g[r] = _slide(W, q) - rf[r] * (href[aux] + _wrap(_theta(W, q2) - href[aux]))
            c, n = _ax(_x(_v(W, q, 2), _v(W, q, 1)), rf[r], _v(W, q2, 0)), _v(W, q, 2)
        else:
            g[r] = _wrap(_theta(W, q) - u[aux])
            c = _ax(z, -1.0, _v(W, q, 0))
        if jac:  # c · (ω_a - ω_b) + n · (v_b - v_a)
            _put(J, r, it[q, 1], C, c, _ax(z, -1.0, n))
            _put(J, r, it[q, 2], C, _ax(z, -1.0, c), n)


@njit(inline="always", **_OPTIONS)
def _twist(X, k, n):
    if k >= n:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    return (X[6 * k], X[6 * k + 1], X[6 * k + 2]), (X[6 * k + 3], X[6 * k + 4], X[6 * k + 5])


@njit(inline="always", **_OPTIONS)
def _line_gamma(W, q, wa, va, wb, vb):
    """``γ`` of ``(x_b - x_a) · n_a``."""
    xa, xb, nv = _v(W, q, 0), _v(W, q, 1), _v(W, q, 2)
    Va, Vb = _ax(va, 1.0, _x(wa, xa)), _ax(vb, 1.0, _x(wb, xb))
    nd = _x(wa, nv)
    return (_d(_ax(_x(wb, Vb), -1.0, _x(wa, Va)), nv) + 2 * _d(_ax(Vb, -1.0, Va), nd)
            + _d(_ax(xb, -1.0, xa), _x(wa, nd)))


@njit(**_OPTIONS)
def convective(T, R, p, X, W, out):
    """``γ`` (m,) at the pose ``R``, ``p`` and origin twists ``X`` (6 n): every residual's
    second time derivative with ``ξ̇ = 0``."""
    it, loc, ri, rf = T[0], T[1], T[2], T[3]
    n = R.shape[0] - 1
    world(R, p, it, loc, W)
    for r in range(ri.shape[0]):
        kind, q, q2, aux = ri[r, 0], ri[r, 1], ri[r, 2], ri[r, 3]
        wa, va = _twist(X, it[q, 1], n)
        wb, vb = _twist(X, it[q, 2], n)
        if kind == 0:
            ga = _x(wa, _ax(va, 1.0, _x(wa, _v(W, q, 0))))
            gb = _x(wb, _ax(vb, 1.0, _x(wb, _v(W, q, 1))))
            out[r] = ga[aux] - gb[aux]
        elif kind == 1:
            u, w = _v(W, q, 0), _v(W, q, 1)
            ud, wd = _x(wa, u), _x(wb, w)
            out[r] = _d(_x(wa, ud), w) + 2 * _d(ud, wd) + _d(u, _x(wb, wd))
        elif kind == 2 or kind == 6:
            out[r] = _line_gamma(W, q, wa, va, wb, vb)
        elif kind == 3:
            xa, xb = _v(W, q, 0), _v(W, q, 1)
            Va, Vb = _ax(va, 1.0, _x(wa, xa)), _ax(vb, 1.0, _x(wb, xb))
            dv = _ax(Va, -1.0, Vb)
            out[r] = (_d(dv, dv) + _d(_ax(xa, -1.0, xb), _ax(_x(wa, Va), -1.0, _x(wb, Vb)))) / rf[r]
        else:
            qa = q2 if kind == 4 else q  # the angle's item
            ga = _d(_ax(wb, -1.0, wa), _x(wa, _v(W, qa, 0)))
            out[r] = _line_gamma(W, q, wa, va, wb, vb) - rf[r] * ga if kind == 4 else ga


@njit(**_OPTIONS)
def move(R, p, x, R2, p2):
    """The poses ``R``, ``p`` (B, ...) displaced by the twists ``x`` (B, 6 n) of the moving
    links (``exp`` of each twist, Murray et al., eq. 2.36) into ``R2``, ``p2`` (may be ``R``,
    ``p``)."""
    n = R.shape[1] - 1
    for b in range(R.shape[0]):
        for k in range(n):
            w, v = (x[b, 6 * k], x[b, 6 * k + 1], x[b, 6 * k + 2]), (x[b, 6 * k + 3], x[b, 6 * k + 4], x[b, 6 * k + 5])
            t2 = _d(w, w)
            if t2 < 1e-4:  # sin θ / θ, (1 - cos θ) / θ², (θ - sin θ) / θ³ by their series to θ⁴
                a, c, e = 1 - t2 / 6 + t2 * t2 / 120, 0.5 - t2 / 24 + t2 * t2 / 720, 1.0 / 6 - t2 / 120 + t2 * t2 / 5040
            else:
                t = math.sqrt(t2)
                a, c, e = math.sin(t) / t, 2 * (math.sin(0.5 * t) / t) ** 2, (t - math.sin(t)) / (t * t2)
            wv = _x(w, v)
            tr = _ax(_ax(v, c, wv), e, _x(w, wv))
            E = _rotation(w, a, c, t2)
            Rk, pk = R[b, k].copy(), (p[b, k, 0], p[b, k, 1], p[b, k, 2])
            for i in range(3):
                for j in range(3):
                    R2[b, k, i, j] = E[i, 0] * Rk[0, j] + E[i, 1] * Rk[1, j] + E[i, 2] * Rk[2, j]
                p2[b, k, i] = E[i, 0] * pk[0] + E[i, 1] * pk[1] + E[i, 2] * pk[2] + tr[i]
        R2[b, n], p2[b, n] = R[b, n], p[b, n]


@njit(**_OPTIONS)
def _spd_inverse(G, Gi):
    """``G⁻¹`` of a symmetric positive definite ``G`` into ``Gi`` by its Cholesky factor:
    ``G = Uᵀ U``, ``G⁻¹ = V Vᵀ`` with ``V = U⁻¹`` (the loops run along rows, without
    reductions, so they vectorise); False when ``G`` is not positive definite to rounding."""
    k = G.shape[0]
    U, V = G.copy(), np.zeros((k, k))
    for j in range(k):
        if not U[j, j] > 0.0:
            return False
        d = 1.0 / math.sqrt(U[j, j])
        for c in range(j, k):
            U[j, c] *= d
        for i in range(j + 1, k):
            f = U[j, i]
            for c in range(i, k):
                U[i, c] -= f * U[j, c]
    for i in range(k - 1, -1, -1):
        V[i, i] = 1.0
        for t in range(i + 1, k):
            f = U[i, t]
            for c in range(t, k):
                V[i, c] -= f * V[t, c]
        d = 1.0 / U[i, i]
        for c in range(i, k):
            V[i, c] *= d
    Gi[:] = V @ V.T
    return True


@njit(**_OPTIONS)
def gram(J, rows, Gi):
    """The inverse ``Gi`` of the damped Gram matrix of ``J`` (``J Jᵀ`` when ``rows``, else
    ``Jᵀ J``, plus ``1e-14`` of its largest diagonal entry), and the lower bound
    ``1 / √(‖G‖_F ‖G⁻¹‖_F)`` of ``σ_r / σ_1`` (0 where not finite)."""
    G = J @ J.T if rows else J.T @ J
    top, trace = np.max(np.diag(G)), np.sum(np.diag(G))
    for i in range(G.shape[0]):
        G[i, i] += 1e-14 * top + 1e-300
    if not np.isfinite(trace):  # (a NaN or inf in J is one on the diagonal)
        Gi[:] = np.nan
        return 0.0
    if not _spd_inverse(G, Gi):  # (positive definite but for rounding: a rank drop)
        Gi[:] = np.linalg.inv(G)
    out = 1.0 / math.sqrt(math.sqrt(np.sum(G * G) * np.sum(Gi * Gi)))
    return out if np.isfinite(out) else 0.0


@njit(inline="always", **_OPTIONS)
def _acc(A, x, y):
    """``y += Aᵀ x`` along the rows of ``A`` (no reductions: it vectorises)."""
    for r in range(A.shape[0]):
        for c in range(A.shape[1]):
            y[c] += x[r] * A[r, c]


@njit(inline="always", **_OPTIONS)
def _apply(J, Gi, rows, b, t, y):
    """``y += J⁺ b`` by ``Gi`` (``t``: scratch of ``Gi``'s size): ``Jᵀ (Gi b)`` or ``Gi (Jᵀ b)``."""
    t[:] = 0.0
    _acc(Gi if rows else J, b, t)  # (Gi is symmetric)
    _acc(J if rows else Gi, t, y)


@njit(**_OPTIONS)
def solve(J, Gi, C, rows, b, refine, out):
    """``J⁺ b`` by the inverse Gram matrix ``Gi`` with ``refine`` steps of iterative
    refinement, as twists at the origin into ``out`` (6 n) (``v = u + c × ω``)."""
    t, y, e = np.empty(Gi.shape[0]), np.zeros(J.shape[1]), np.empty(J.shape[0])
    _apply(J, Gi, rows, b, t, y)
    for _ in range(refine):
        for r in range(J.shape[0]):
            e[r] = b[r]
            for c in range(J.shape[1]):
                e[r] -= J[r, c] * y[c]
        _apply(J, Gi, rows, e, t, y)
    for k in range(C.shape[0]):
        w = (y[6 * k], y[6 * k + 1], y[6 * k + 2])
        v = _ax((y[6 * k + 3], y[6 * k + 4], y[6 * k + 5]), 1.0, _x((C[k, 0], C[k, 1], C[k, 2]), w))
        for i in range(3):
            out[6 * k + i], out[6 * k + 3 + i] = w[i], v[i]


@njit(**_OPTIONS)
def states(T, R, p, href, U, rows, g, J, Gi, C, bound, th, sl, du, ddu, refine, x1, x2):
    """:func:`evaluate` and :func:`gram` at every pose of a batch (B, ...) (``Gi`` (B, ...),
    or with no columns: not kept), and, where ``du`` (B, drives) has rows, the rates with
    ``refine`` steps of refinement: ``J x1 = (0, du)``, ``J x2 = (0, ddu) - γ(x1)``."""
    W = np.empty((T[0].shape[0], 4, 3))
    m, nc = g.shape[1], g.shape[1] - U.shape[1]
    Gs, rhs, gam = np.empty((J.shape[1], J.shape[1]) if rows else (J.shape[2], J.shape[2])), np.zeros(m), np.empty(m)
    for b in range(R.shape[0]):
        Gb = Gi[b] if Gi.shape[1] else Gs
        evaluate(R[b], p[b], T, href[b], U[b], W, g[b], J[b], C[b], th[b], sl[b])
        bound[b] = gram(J[b], rows, Gb)
        if du.shape[0]:
            rhs[:nc] = 0.0
            rhs[nc:] = du[b]
            solve(J[b], Gb, C[b], rows, rhs, refine, x1[b])
            convective(T, R[b], p[b], x1[b], W, gam)
            rhs[:] = -gam
            rhs[nc:] += ddu[b]
            solve(J[b], Gb, C[b], rows, rhs, refine, x2[b])


@njit(**_OPTIONS)
def correct(T, R, p, href, U, limit, iters, tol, Ja, Ga, Ca, rows, first, ok, th, sl):
    """Newton corrections of the poses ``R``, ``p`` (B, ...) in place towards the inputs
    ``U`` (B, drives) (see :meth:`mechsyn.kinematics.spatial_track.Tracker.correct`):
    ``ok`` is set where a pose's residual fell under ``tol`` without the corrector moving
    it further than ``limit``. Chord steps with the linearisation ``Ja``, ``Ga``, ``Ca``
    (of an anchor pose, or the latest one an earlier pose took; none when ``Ja`` has no
    rows: each pose starts with its own) while the residual falls at least tenfold per
    step, else with the Jacobian of the current iterate. ``first``: stop at
    the first pose that fails (the rest are left). ``th``, ``sl``: the measured angles
    and slides of the last iterate."""
    m, nk = T[2].shape[0], 6 * (R.shape[1] - 1)
    W = np.empty((T[0].shape[0], 4, 3))
    g, dx, no_J = np.empty(m), np.empty(nk), np.empty((0, nk))
    J, C, Gi = np.empty((m, nk)), np.empty((R.shape[1] - 1, 3)), np.empty_like(Ga)
    Jl, Gl, Cl = Ja, Ga, Ca
    for b in range(R.shape[0]):
        have = Ja.shape[0] > 0  # (then the latest linearisation: the anchor's or a row's before)
        moved, last, done = 0.0, np.inf, False
        for i in range(iters):
            evaluate(R[b], p[b], T, href[b], U[b], W, g, no_J, C, th[b], sl[b])
            err = np.max(np.abs(g)) if m else 0.0
            if err < tol:
                done = True
                break
            if i >= 10 and err > 0.5 * last:
                break
            if err > 0.1 * last or not have:
                evaluate(R[b], p[b], T, href[b], U[b], W, g, J, C, th[b], sl[b])
                gram(J, rows, Gi)
                Jl, Gl, Cl, have = J, Gi, C, True
            last = err
            solve(Jl, Gl, Cl, rows, g, 0, dx)
            moved += np.max(np.abs(dx))
            if moved > limit[b]:
                break
            dx *= -1.0
            move(R[b:b + 1], p[b:b + 1], dx.reshape(1, nk), R[b:b + 1], p[b:b + 1])
        ok[b] = done
        if first and not done:
            return


@njit(**_OPTIONS)
def pair_errors(R, pi, pf, out):
    """Per pose and pair (B, pairs): the largest entry of ``R_rel - Rot(a, θ)`` (``pi``:
    links and whether the pair turns; ``pf``: its axis ``a`` and ``e1``, ``e2``
    perpendicular), ``R_rel = R_aᵀ R_b``, ``θ`` read from ``R_rel e1`` (see
    :func:`mechsyn.kinematics.spatial_model.pair_error`)."""
    for b in range(R.shape[0]):
        for j in range(pi.shape[0]):
            Rr = R[b, pi[j, 0]].T @ R[b, pi[j, 1]]
            r1 = Rr @ pf[j, 1]
            t = math.atan2(_d(r1, pf[j, 2]), _d(r1, pf[j, 1])) if pi[j, 2] else 0.0
            out[b, j] = np.max(np.abs(Rr - _rotation(pf[j, 0], math.sin(t), 1 - math.cos(t), 1.0)))


@njit(inline="always", **_OPTIONS)
def _end(R, p, X, Xd, k, i, x0):
    """A bar's end ``x0`` on link ``i`` (the frame: ``i = n``) at row ``k``: its position,
    velocity and acceleration."""
    if i >= R.shape[1]:
        return x0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    y = (_d(R[k, i, 0], x0) + p[k, i, 0], _d(R[k, i, 1], x0) + p[k, i, 1], _d(R[k, i, 2], x0) + p[k, i, 2])
    w, v = _twist(X[k], i, R.shape[1])
    wd, vd = _twist(Xd[k], i, R.shape[1])
    yd = _ax(v, 1.0, _x(w, y))
    return y, yd, _ax(_ax(vd, 1.0, _x(wd, y)), 1.0, _x(w, yd))


@njit(**_OPTIONS)
def bars(R, p, X, Xd, ia, ib, va, vb, Rb, pb, Xb, Xbd):
    """The bars' poses ``Rb``, ``pb`` and twists ``Xb``, ``Xbd`` over the rows of a sweep
    from those of the links they join (``R`` (N, n, 3, 3), ``p``, ``X``, ``Xd`` (N, 6 n);
    bar ``j`` from ``va[j]`` on link ``ia[j]`` to ``vb[j]`` on ``ib[j]``, ``n`` the frame):
    see :func:`mechsyn.kinematics.spatial_model.bar_motion`. The bar's spin ``φ`` about its
    drawn line is carried from row to row by the least rotation between the lines, through
    every row with a pose, and is zero at the row of each stretch nearest the drawn line."""
    N = R.shape[0]
    A, Bv, Uu = np.empty((N, 3)), np.empty((N, 3)), np.empty((N, 3))
    c, phi = np.empty(N), np.empty(N)
    for j in range(ia.shape[0]):
        u0 = _ax(vb[j], -1.0, va[j])
        u0 = _ax((0.0, 0.0, 0.0), 1.0 / math.sqrt(_d(u0, u0)), u0)
        m = 0 if abs(u0[0]) <= min(abs(u0[1]), abs(u0[2])) else (1 if abs(u0[1]) <= abs(u0[2]) else 2)
        e1 = _x(u0, (1.0 if m == 0 else 0.0, 1.0 if m == 1 else 0.0, 1.0 if m == 2 else 0.0))
        e1 = _ax((0.0, 0.0, 0.0), 1.0 / math.sqrt(_d(e1, e1)), e1)
        e2 = _x(u0, e1)
        for k in range(N):
            y1, y1d, y1dd = _end(R, p, X, Xd, k, ia[j], (va[j, 0], va[j, 1], va[j, 2]))
            y2, y2d, y2dd = _end(R, p, X, Xd, k, ib[j], (vb[j, 0], vb[j, 1], vb[j, 2]))
            d = _ax(y2, -1.0, y1)
            l2 = _d(d, d)
            w = _ax((0.0, 0.0, 0.0), 1.0 / l2, _x(d, _ax(y2d, -1.0, y1d)))
            wd = _ax((0.0, 0.0, 0.0), 1.0 / l2, _x(d, _ax(y2dd, -1.0, y1dd)))
            v = _ax(y1d, -1.0, _x(w, y1))
            vd = _ax(_ax(y1dd, -1.0, _x(wd, y1)), -1.0, _x(w, y1d))
            u = _ax((0.0, 0.0, 0.0), 1.0 / math.sqrt(l2), d)
            c[k] = _d(u0, u)
            s = 1.0 if c[k] >= 0 else -1.0
            h = _ax(u, s, u0)
            a = _ax(e1, -_d(u, e1) / (1 + abs(c[k])), h)
            b = _ax(e2, -_d(u, e2) / (1 + abs(c[k])), h)
            for i in range(3):
                A[k, i], Bv[k, i], Uu[k, i] = a[i], s * b[i], u[i]
                Xb[k, 6 * j + i], Xb[k, 6 * j + 3 + i] = w[i], v[i]
                Xbd[k, 6 * j + i], Xbd[k, 6 * j + 3 + i] = wd[i], vd[i]
                pb[k, j, i] = 0.5 * (y1[i] + y2[i])
        k = 0
        while k < N:  # each stretch of rows with poses, from its row nearest the drawn line
            lo = best = k
            phi[k] = 0.0
            k += 1
            while k < N and np.isfinite(c[k]) and np.isfinite(c[k - 1]):
                u, a = (Uu[k, 0], Uu[k, 1], Uu[k, 2]), (A[k - 1, 0], A[k - 1, 1], A[k - 1, 2])
                ck = 1.0 + _d((Uu[k - 1, 0], Uu[k - 1, 1], Uu[k - 1, 2]), u)
                qa = _ax(a, -_d(u, a) / ck, _ax(u, 1.0, (Uu[k - 1, 0], Uu[k - 1, 1], Uu[k - 1, 2]))) if ck > 1e-8 else a
                phi[k] = phi[k - 1] + math.atan2(_d(qa, Bv[k]), _d(qa, A[k]))
                best = k if c[k] > c[best] else best
                k += 1
            top = phi[best]
            for r in range(lo, k):
                cp, sp = math.cos(phi[r] - top), math.sin(phi[r] - top)
                for i in range(3):
                    a_i, b_i = cp * A[r, i] + sp * Bv[r, i], cp * Bv[r, i] - sp * A[r, i]
                    for t in range(3):
                        Rb[r, j, i, t] = a_i * e1[t] + b_i * e2[t] + Uu[r, i] * u0[t]
                for i in range(3):
                    pb[r, j, i] -= 0.5 * _d(Rb[r, j, i], _ax(va[j], 1.0, vb[j]))
