"""Singular configurations of a spatial sweep (used by :mod:`mechsyn.kinematics.spatial`):
where the Jacobian of the constraints and drives loses rank along the path, and how the walk
leaves a singular pose (a file drawn at a dead point or a change point).

**Crossings by the sign of a determinant.** Between two rows ``k`` and ``k + 1`` of one motion
the Jacobian ``J`` (constraints and drives, in twists at the links' centres) keeps its regular
rank ``r`` unless the path crosses a singular configuration. With ``U_k``, ``V_k`` the first
``r`` left and right singular vectors of ``J_k``, ``d(t) = det(U_kᵀ J(t) V_k)`` equals
``σ_1 ... σ_r > 0`` at ``t = 0`` and is zero where ``J(t)`` has rank below ``r``; a simple crossing
(a change or bifurcation point, where two branches meet) makes it change sign (Allgower and
Georg [1]_, sec. 8.1: bifurcation detection by the sign of the augmented Jacobian's
determinant). The pairs where it can change at all are few: by Weyl's inequality
``σ_r(J(t)) >= σ_r(J_k) - ‖J(t) - J_k‖``, so a crossing needs ``σ_r(J_k)`` (a lower bound from
the Gram matrix) within ``‖J_{k+1} - J_k‖_F`` (twice, for the path's curvature) of zero at one
of the two rows; only those pairs are tested (:func:`_flips`: at full column or row rank by
``det(J_kᵀ J_{k+1})`` or ``det(J_{k+1} J_kᵀ)``, of the same sign, else by an SVD). A sign change
is bracketed and refined (below) and
reported with its input value; a crossing that falls on a row (within ``REFINE`` of the step)
makes that row singular. Minima of ``σ_r/σ_1`` that touch zero without a sign change (a V at a
row's neighbours) are candidates too. Each candidate is bracketed by a zoom of ``σ_r/σ_1``
over its bracket to ``REFINE`` of the step (a V about the crossing on either branch that meets
there, so it does not matter which one Newton lands on that close to it; the sign of the
determinant does, which is why it only brackets), is a crossing where the least ratio is under
the singular tolerance, and is located at the apex of the V fitted to its clean samples
(:func:`_apex`).

**Leaving a singular pose** (:func:`~mechsyn.kinematics.spatial_track.leave`). At a dead point of the input the mechanism moves like the square
root of the input step, at a change point along either of two branches: the linear predictor
of the continuation cannot leave such a pose. ``leave`` tries Newton from the pose moved by
the minimum-norm tangent plus ``±σ`` along each null direction of ``J`` that moves a joint
point (``σ`` a few multiples of ``√|Δu|`` and ``|Δu|``), and keeps the converged true assembly
nearest the pose (ties: the positive direction first, each null vector signed so that its
largest entry is positive) — or, leaving the same pose the other way, the one nearest the
branch it left by first (the same branch through a change point).

References
----------
.. [1] E. L. Allgower and K. Georg, *Introduction to Numerical Continuation Methods*, SIAM,
   2003, ch. 8 (detecting bifurcation points along a path).
.. [2] C. M. Gosselin and J. Angeles, "Singularity analysis of closed-loop kinematic chains",
   *IEEE Trans. Robotics and Automation* 6(3), 281-290, 1990.
"""

from __future__ import annotations


import numpy as np

from mechsyn.kinematics.spatial_model import move
from mechsyn.kinematics.spatial_track import REFINE, Tracker, Walk, polished_ratio, singular_tol, taylor

__all__ = ["crossings", "REFINE"]

#: Newton steps past the tolerance on each pose of the search: next to a singular point
#: Newton reaches a residual ε only within √ε of the pose (it converges linearly there), which
#: blurs the ratio's V by that much; each further step halves the distance.
POLISH = 8
#: Points a zoom step of the search evaluates at once (the bracket shrinks by ``(ZOOM - 1) / 2``).
ZOOM = 17



# --------------------------------------------------------------------------- crossings
def _flips(Ja: np.ndarray, Jb: np.ndarray, r: int) -> np.ndarray:
    """Whether ``det(U_aᵀ J_b V_a)`` is not positive, for pairs of Jacobians ``Ja``, ``Jb``
    (B, m, k) of regular rank ``r`` at ``Ja`` (``U_a``, ``V_a``: its first ``r`` singular
    vectors). At full column rank (``r = k``) ``det(J_aᵀ J_b) = det(Σ_a) det(U_aᵀ J_b V_a)``
    (``det(V_a)² = 1``), at full row rank (``r = m``) ``det(J_b J_aᵀ)`` likewise: the same sign
    without an SVD (which would cost more than the rest of a sweep); otherwise the bases by an SVD."""
    m, k = Ja.shape[1:]
    if r == k:
        return np.linalg.det(np.swapaxes(Ja, -1, -2) @ Jb) <= 0
    if r == m:
        return np.linalg.det(Jb @ np.swapaxes(Ja, -1, -2)) <= 0
    Ua, _, Vat = np.linalg.svd(Ja, full_matrices=False)
    return np.linalg.det(np.swapaxes(Ua[..., :r], -1, -2) @ Jb @ np.swapaxes(Vat[..., :r, :], -1, -2)) <= 0


def crossings(tr: Tracker, w: Walk, U: np.ndarray, ratio: np.ndarray,
              Jc: np.ndarray, idx: np.ndarray) -> list[tuple[int, np.ndarray, float, int | None]]:
    """Singular configurations the sweep passes: ``(row, inputs, ratio, on_row)`` with
    ``on_row`` the row it falls on (within ``REFINE`` of the step) or None (see the module
    doc). ``Jc`` (B, m, k): the Jacobians of the assembled rows ``idx``; ``ratio``: every
    row's ``σ_r / σ_1`` (NaN where not assembled)."""
    r = tr.rank
    if not r or len(idx) < 2:
        return []
    ks = np.flatnonzero((w.ok[:-1] & w.ok[1:]) & (w.how[:-1] == w.how[1:]))  # pairs of rows on one motion
    a = np.searchsorted(idx, ks)  # the positions of rows k and k + 1 in idx (its rows are w.ok's)
    b = a + 1
    flat = Jc.reshape(len(Jc), -1)
    n2 = np.einsum("bi,bi->b", flat, flat)
    low = np.nan_to_num(ratio[idx]) * np.sqrt(n2) / np.sqrt(max(r, 1))  # lower bounds of σ_r
    # ‖J_b - J_a‖_F of consecutive rows without their difference, its rounding added (over, never under)
    s2 = n2[:-1] + n2[1:]
    jump = np.sqrt(np.maximum(s2 - 2 * np.einsum("bi,bi->b", flat[:-1], flat[1:]), 0.0) + 1e-14 * s2)[a]
    near = (low[a] <= 2 * jump) | (low[b] <= 2 * jump)
    tol = singular_tol(tr.M)
    near &= (ratio[ks] >= tol) & (ratio[ks + 1] >= tol)  # a singular row is its own event
    out = []
    for k in ks[near][_flips(Jc[a[near]], Jc[b[near]], r)].tolist():
        found = _golden(tr, w, U, [k, k + 1])  # (None: the sign changed by a frame effect, not a rank drop)
        if found is not None:  # on a row when within REFINE of the step of it
            t = float((found[0] - U[k]) @ (U[k + 1] - U[k]) / ((U[k + 1] - U[k]) @ (U[k + 1] - U[k])))
            out.append((k, *found, k if t < REFINE else (k + 1 if t > 1 - REFINE else None)))
    seen = {c[0] for c in out} | {c[0] + 1 for c in out}
    return out + _v_minima(tr, w, U, ratio, seen, Jc, idx)


def _v_minima(tr: Tracker, w: Walk, U: np.ndarray, ratio: np.ndarray, seen: set, Jc: np.ndarray,
              idx: np.ndarray) -> list:
    """Rows whose ratio is a local minimum that may touch zero refined by a golden-section
    search; a crossing where it falls under the singular tolerance. A local minimum may touch
    zero when it is a sharp V (``r0 + r2 >= 4 r1``: every symmetric V passes) or when
    :func:`_may_touch` allows it (a crossing where two singular values vanish at once keeps
    the determinant's sign, and its V is bent by the largest one's change). Rows in ``seen``
    (next to a crossing found by the determinant) are skipped."""
    tol = singular_tol(tr.M)
    ok, how = w.ok, w.how
    same = ok[:-2] & ok[1:-1] & ok[2:] & (how[:-2] == how[1:-1]) & (how[1:-1] == how[2:])
    r0, r1, r2 = ratio[:-2], ratio[1:-1], ratio[2:]
    with np.errstate(invalid="ignore"):
        low = same & (r1 <= r0) & (r1 <= r2) & (r1 >= tol)
        vee = r0 + r2 >= 4 * r1
    a, b = U[1:-1] - U[:-2], U[2:] - U[1:-1]
    ab = np.einsum("ij,ij->i", a, b)
    low &= (ab > 0) & (np.abs(ab) >= (1 - 1e-9) * np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
    out = []  # (the last test: on one straight stretch of the sweep)
    for k in np.flatnonzero(low) + 1:
        if seen & {k - 1, k, k + 1}:
            continue
        if not vee[k - 1] and not _may_touch(Jc[np.searchsorted(idx, k) + np.arange(-1, 2)], tr.rank):
            continue
        found = _golden(tr, w, U, [k - 1, k, k + 1])
        if found is not None:
            out.append((int(k), *found, None))
    return out


def _may_touch(J3: np.ndarray, r: int, samples: int = 17) -> bool:
    """Whether ``σ_r`` may vanish between the first and last of three consecutive rows'
    Jacobians ``J3`` (3, m, k): along the path ``J(t)`` differs from the piecewise linear
    interpolation of the rows by at most about ``‖Δ²J‖ / 8`` (the second difference), so by
    Weyl's inequality ``σ_r`` can vanish only where ``σ_r`` of the interpolation is within
    that of zero (taken within four times it, ``‖Δ²J‖ / 2``, sampled at ``samples`` points)."""
    curv = np.linalg.norm(J3[2] - 2 * J3[1] + J3[0], 2)
    t = np.linspace(0.0, 1.0, samples // 2 + 1)[:, None, None]
    lines = np.concatenate([J3[0] + t * (J3[1] - J3[0]), J3[1] + t[1:] * (J3[2] - J3[1])])
    sv = np.linalg.svd(lines, compute_uv=False)[:, r - 1]
    return bool(sv.min() <= 0.5 * curv)


def _golden(tr: Tracker, w: Walk, U: np.ndarray, rows: list[int]) -> tuple[np.ndarray, float] | None:
    """The least ``σ_r / σ_1`` over the inputs from row ``rows[0]`` to row ``rows[-1]``, to
    ``REFINE`` of a row step: a zoom of ``ZOOM`` points at a time, each batch predicted from
    the nearest of ``rows`` (the Taylor predictor), corrected by Newton together and polished
    ``POLISH`` steps past the tolerance (next to a singular point Newton converges only
    linearly, and reaches a residual ε only within √ε of the pose, which blurs the V by that
    much); the bracket then shrinks to the two cells about the least. The ratio is a V about
    a crossing on either branch that meets there, so it does not matter which one Newton
    lands on that close to it. None when the least ratio is not under the singular
    tolerance (:func:`~mechsyn.kinematics.spatial_track.singular_tol`): no crossing."""
    states = {k: tr.state(*w.at(k), U[k][None]) for k in rows}
    lo, hi = U[rows[0]], U[rows[-1]]
    span = len(rows) - 1
    tol = tr.tol

    def f(ts: np.ndarray) -> np.ndarray:
        out = np.full(len(ts), np.inf)
        near = np.clip(np.rint(ts * span), 0, span).astype(int)
        for j in np.unique(near):
            k, sel = rows[j], np.flatnonzero(near == j)
            st = states[k]
            u = lo + ts[sel, None] * (hi - lo)
            x1, x2 = taylor(tr, st, u - U[k])
            z = np.zeros(len(sel), int)
            R, p = move(st.R[z], st.p[z], x1 + 0.5 * x2)
            out[sel] = polished_ratio(tr, R, p, st.href[z], u, polish=POLISH)
        return out

    a, b = 0.0, 1.0
    best_t, best = 0.5, np.inf
    seen_t, seen_f = [], []
    while b - a > REFINE / span:
        ts = np.linspace(a, b, ZOOM)
        fs = f(ts)
        seen_t.append(ts)
        seen_f.append(fs)
        i = int(np.argmin(fs))
        if not np.isfinite(fs[i]):
            break
        best_t, best = ts[i], fs[i]
        h = (b - a) / (ZOOM - 1)
        a, b = max(0.0, ts[i] - h), min(1.0, ts[i] + h)
    if not best < singular_tol(tr.M):  # (nor where Newton did not converge)
        return None
    best_t = _apex(np.concatenate(seen_t), np.concatenate(seen_f), best_t, np.sqrt(tol))
    return lo + best_t * (hi - lo), float(best)


def _apex(t: np.ndarray, f: np.ndarray, t0: float, clean: float) -> float:
    """The apex of the V ``f = |λ(t)|`` (``λ`` smooth with a simple root: a crossing) sampled
    at ``t``, least at ``t0``: the root of ``λ`` fitted (a quadratic, a line through fewer than
    five points) to the three samples a side nearest ``t0`` that are *clean*, ``f >= clean``,
    negative on the left. Within ``δ`` of the crossing Newton's pose is off by about
    ``ε / σ_r`` (``ε`` its residual, at rounding when polished), which moves ``σ_r`` by about
    as much: relatively ``ε / σ_r²``, under ``1e-4`` where ``σ_r / σ_1 >= √tol``, so the clean
    samples lie on the V to that accuracy while those nearer the apex are blurred (the least
    sample alone is only within ``√ε`` of it). ``t0`` when there is no clean sample on a side,
    or the root falls outside the nearest clean ones (a touch, not a simple crossing)."""
    t, i = np.unique(t, return_index=True)
    f = f[i]
    good = np.isfinite(f) & (f >= clean)
    left, right = np.flatnonzero(good & (t < t0)), np.flatnonzero(good & (t > t0))
    left, right = left[np.argsort(t0 - t[left])[:3]], right[np.argsort(t[right] - t0)[:3]]
    if not len(left) or not len(right) or len(left) + len(right) < 3:
        return t0
    x = np.concatenate([t[left], t[right]]) - t0
    scale = np.abs(x).max()
    c = np.polyfit(x / scale, np.concatenate([-f[left], f[right]]), 2 if len(x) >= 5 else 1)
    roots = np.roots(c)
    roots = roots.real[np.abs(roots.imag) <= 1e-12 * (1 + np.abs(roots.real))] * scale + t0
    roots = roots[(roots > t[left].max()) & (roots < t[right].min())]
    return float(roots[np.argmin(np.abs(roots - t0))]) if len(roots) else t0
