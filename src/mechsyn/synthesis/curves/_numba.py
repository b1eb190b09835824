"""The correspondence in order of the curve error compiled with Numba (imported by
:mod:`mechsyn.synthesis.curves.fitting` on first use). Under ``NUMBA_DISABLE_JIT=1`` the
same functions run as plain Python.

Dynamic time warping over a cost matrix ``c (n, m)`` whose closed curve (its rows' or its
columns') may start at any sample: the matrix is read through the start shift, never
copied. Steps are weighted 2 diagonally and 1 along one curve: the least sum to cell
``(i, j)`` is ``D[i, j] = min(D[i-1, j] + c, D[i, j-1] + c, D[i-1, j-1] + 2c)`` with
``c = c[i, j]`` and ``D[0, 0] = 2 c[0, 0]``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_OPTIONS = dict(cache=True, nogil=True, error_model="numpy")


@njit(**_OPTIONS)
def _row(c, i, shift, rows, out):
    """Row ``i`` of the cost matrix read through the start shift, into ``out (m,)``."""
    n, m = c.shape
    if rows:
        r = (i + shift) % n
        for j in range(m):
            out[j] = c[r, j]
    else:
        for j in range(m):
            k = j + shift
            out[j] = c[i, k - m if k >= m else k]


@njit(**_OPTIONS)
def costs(c, shifts, rows):
    """``(V,)``: the least weighted sum over monotone paths from ``(0, 0)`` to ``(n-1, m-1)``
    of ``c (n, m)`` started at each shift (of the rows when ``rows``, else of the columns),
    over ``n + m``."""
    n, m = c.shape
    out = np.empty(len(shifts))
    D = np.empty(m)
    x = np.empty(m)
    for v in range(len(shifts)):
        _row(c, 0, shifts[v], rows, x)
        D[0] = 2.0 * x[0]
        for j in range(1, m):
            D[j] = D[j - 1] + x[j]
        for i in range(1, n):
            _row(c, i, shifts[v], rows, x)
            diag = D[0]
            D[0] = diag + x[0]
            for j in range(1, m):
                up = D[j]
                D[j] = min(up + x[j], diag + 2.0 * x[j], D[j - 1] + x[j])
                diag = up
        out[v] = D[m - 1] / (n + m)
    return out


@njit(**_OPTIONS)
def pairs(c, shift, rows):
    """The rows and columns ``(L,)`` (in the shifted matrix's own indices) of the
    least-cost monotone path of :func:`costs` through ``c`` started at ``shift``,
    backtracked from ``(n-1, m-1)`` (a diagonal step where it is as good as the best other)."""
    n, m = c.shape
    C = np.empty((n, m))
    D = np.empty((n, m))
    for i in range(n):
        _row(c, i, shift, rows, C[i])
    D[0, 0] = 2.0 * C[0, 0]
    for j in range(1, m):
        D[0, j] = D[0, j - 1] + C[0, j]
    for i in range(1, n):
        D[i, 0] = D[i - 1, 0] + C[i, 0]
        for j in range(1, m):
            D[i, j] = min(D[i - 1, j] + C[i, j], D[i - 1, j - 1] + 2.0 * C[i, j], D[i, j - 1] + C[i, j])
    ri = np.empty(n + m, np.int64)
    ci = np.empty(n + m, np.int64)
    i, j, k = n - 1, m - 1, 0
    ri[0], ci[0] = i, j
    while i > 0 or j > 0:
        if i > 0 and j > 0 and D[i - 1, j - 1] + 2.0 * C[i, j] <= min(D[i - 1, j], D[i, j - 1]) + C[i, j]:
            i -= 1
            j -= 1
        elif j == 0 or (i > 0 and D[i - 1, j] <= D[i, j - 1]):
            i -= 1
        else:
            j -= 1
        k += 1
        ri[k], ci[k] = i, j
    return ri[k::-1].copy(), ci[k::-1].copy()


@njit(**_OPTIONS)
def seg_dist(X, F, closed):
    """``(n, S)``: the distance from each point of ``X (n, 2)`` to each segment of the
    polyline ``F (f, 2)`` (``S = f`` closed, ``f - 1`` open)."""
    n, f = X.shape[0], F.shape[0]
    S = f if closed else f - 1
    out = np.empty((n, S))
    for s in range(S):
        e = s + 1 if s + 1 < f else 0
        ax, ay = F[s, 0], F[s, 1]
        vx, vy = F[e, 0] - ax, F[e, 1] - ay
        L2 = max(vx * vx + vy * vy, 1e-300)
        for i in range(n):
            dx, dy = X[i, 0] - ax, X[i, 1] - ay
            t = min(max((dx * vx + dy * vy) / L2, 0.0), 1.0)
            dx -= t * vx
            dy -= t * vy
            out[i, s] = np.sqrt(dx * dx + dy * dy)
    return out


@njit(**_OPTIONS)
def stretches(seg, closed, k):
    """Segment distances ``seg (n, S)`` (``k`` segments per sample step) reduced to the
    distance to the stretch beside each sample: from the sample before to the one after
    (one side at an open end)."""
    n = seg.shape[0]
    steps = seg.shape[1] // k
    g = np.empty((n, steps))
    for i in range(n):
        for j in range(steps):
            v = seg[i, j * k]
            for q in range(1, k):
                v = min(v, seg[i, j * k + q])
            g[i, j] = v
    if closed:
        out = np.empty((n, steps))
        for i in range(n):
            for j in range(steps):
                out[i, j] = min(g[i, j], g[i, j - 1 if j > 0 else steps - 1])
        return out
    out = np.empty((n, steps + 1))
    for i in range(n):
        out[i, 0] = g[i, 0]
        for j in range(1, steps):
            out[i, j] = min(g[i, j], g[i, j - 1])
        out[i, steps] = g[i, steps - 1]
    return out


@njit(**_OPTIONS)
def toward(X, S, V, k):
    """``(K, n, 2)``: the vector from each point ``X[d, i]`` to the nearest point of
    segment ``k[d, i]`` (starts ``S``, vectors ``V``); ``X (KX, n, 2)``, ``S`` and ``V``
    ``(KS, s, 2)`` with ``KX`` and ``KS`` either 1 (shared by every design) or ``K``."""
    K, n = k.shape
    out = np.empty((K, n, 2))
    for d in range(K):
        x = X[d if X.shape[0] > 1 else 0]
        s = S[d if S.shape[0] > 1 else 0]
        v = V[d if V.shape[0] > 1 else 0]
        for i in range(n):
            q = k[d, i]
            dx, dy = x[i, 0] - s[q, 0], x[i, 1] - s[q, 1]
            vx, vy = v[q, 0], v[q, 1]
            L2 = vx * vx + vy * vy
            t = min(max((dx * vx + dy * vy) / L2, 0.0), 1.0) if L2 > 0 else 0.0
            out[d, i, 0] = t * vx - dx
            out[d, i, 1] = t * vy - dy
    return out


@njit(**_OPTIONS)
def nearest_beside(D, W, closed, k):
    """``(n,)``: for each row of segment distances ``D (n, S)`` (``k`` segments per sample
    step of the columns' curve) the nearest segment among those beside the samples matched
    to the row by ``W (n, m)``, from the sample before each to the one after (the first
    such segment where several are as near)."""
    n, S = D.shape
    m = W.shape[1]
    out = np.zeros(n, np.int64)
    for i in range(n):
        best = np.inf
        for s in range(S):
            g = s // k
            h = g + 1 if g + 1 < m else 0
            if (W[i, g] or W[i, h]) and D[i, s] < best:
                best = D[i, s]
                out[i] = s
    return out
