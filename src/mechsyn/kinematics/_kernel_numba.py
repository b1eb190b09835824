"""The regular pass's arithmetic compiled with Numba (imported only through
:mod:`mechsyn.kinematics.kernel`, only when Numba is installed: ``pip install mechsyn[fast]``).

One loop over the rows, and in each row over the chain's steps, with every joint's and
link's state as complex scalars: the same operations in the same order as
:class:`mechsyn.kinematics.regular._Pass` (its arrays, row by row), so the same numbers to
a few units in the last place (tests compare the two on every example). The program is
the regular pass's (:func:`mechsyn.kinematics.regular._program`) as arrays
(:func:`mechsyn.kinematics.kernel.program_arrays`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Numba options: compiled once per machine and kept (``cache``), NumPy's floating-point
#: rules (a division by zero gives inf, a square root of a negative number NaN, as the
#: NumPy pass), the GIL released (the studio's threads).
_OPTIONS = dict(cache=True, nogil=True, error_model="numpy")


@njit(inline="always", **_OPTIONS)
def _point(i, s, anc_j, anc_s, jP, jV, jA, lz, lw, lal):  # pragma: no cover - compiled
    """Position, velocity, acceleration of the local point ``s`` of link ``i`` (-1: the
    frame), from the link's anchor joint: ``regular._Pass.point``."""
    if i < 0:
        return s, 0j, 0j
    j = anc_j[i]
    rel = lz[i] * (s - anc_s[i])
    w = lw[i]
    irel = rel * 1j
    acc = irel * lal[i]
    return rel + jP[j], irel * w + jV[j], (acc - rel * (w * w)) + jA[j]


@njit(**_OPTIONS)
def regular_pass(ip, fp, anc_j, anc_s, org_j, X, speeds, nj, least, C, W, AL, D):  # pragma: no cover
    """Run the program (``ip`` int (steps, 11), ``fp`` complex (steps, 7)) over the input
    rows ``X`` (M, k); fill every link's rotation and its origin's position, velocity and
    acceleration ``C`` (4, links, M), its angular velocity and acceleration ``W``, ``AL``
    (links, M) and each RRR group's normalised discriminant ``D`` (groups, M). Returns
    True when a group's discriminant falls below ``least`` (or is NaN) on some row."""
    M = X.shape[0]
    ns = ip.shape[0]
    nl = anc_j.shape[0]
    jP = np.zeros(nj, np.complex128)
    jV = np.zeros(nj, np.complex128)
    jA = np.zeros(nj, np.complex128)
    lz = np.zeros(nl, np.complex128)
    lw = np.zeros(nl)
    lal = np.zeros(nl)
    near = False
    for r in range(M):
        for s in range(ns):
            if ip[s, 0] == 0:  # a driver: link new turned by the input di from link k
                new, k, j, di, need = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4], ip[s, 5]
                sgn = fp[s, 0].real
                th = X[r, di]
                z = complex(math.cos(th), sgn * math.sin(th))
                if k < 0:
                    jP[j] = fp[s, 1]
                    jV[j] = 0j
                    jA[j] = 0j
                    lz[new] = z
                    lw[new] = sgn * speeds[di]
                    lal[new] = 0.0
                else:
                    if need:
                        jP[j], jV[j], jA[j] = _point(k, fp[s, 1], anc_j, anc_s, jP, jV, jA, lz, lw, lal)
                    lz[new] = z * lz[k]
                    lw[new] = lw[k] + sgn * speeds[di]
                    lal[new] = lal[k]
                continue
            k1, k3, b1, b2 = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4]
            J1, J2, J3, slot = ip[s, 5], ip[s, 6], ip[s, 7], ip[s, 10]
            if ip[s, 8]:
                jP[J1], jV[J1], jA[J1] = _point(k1, fp[s, 5], anc_j, anc_s, jP, jV, jA, lz, lw, lal)
            if ip[s, 9]:
                jP[J3], jV[J3], jA[J3] = _point(k3, fp[s, 6], anc_j, anc_s, jP, jV, jA, lz, lw, lal)
            L1s = fp[s, 0].real
            L2s = fp[s, 0].imag
            d = jP[J3] - jP[J1]
            inv = d.real * d.real
            inv += d.imag * d.imag
            inv = 1.0 / inv
            f = inv * (0.5 * (L1s - L2s))
            f += 0.5
            g = inv * L1s
            g -= f * f
            disc = g / (inv * L1s)
            D[slot, r] = disc
            if not disc >= least:
                near = True
                if g > -1e-12 and g < 0.0:
                    g = 0.0
            g = math.sqrt(g) if g >= 0.0 else math.nan
            if fp[s, 2].real < 0:
                g = -g
            e1 = d * complex(f, g)
            B = e1 + jP[J1]
            e2 = B - jP[J3]
            ce1, ce2 = e1.conjugate(), e2.conjugate()
            den = 1.0 / (ce1 * e2).imag
            dv = jV[J3] - jV[J1]
            w1 = (dv * ce2).real * den
            w2 = (dv * ce1).real * den
            w1s = w1 * w1
            da = (jA[J3] - jA[J1]) + w1s * e1
            da -= (w2 * w2) * e2
            a1 = (da * ce2).real * den
            a2 = (da * ce1).real * den
            lz[b1], lw[b1], lal[b1] = e1 * fp[s, 3], w1, a1
            lz[b2], lw[b2], lal[b2] = e2 * fp[s, 4], w2, a2
            ie1 = e1 * 1j
            jP[J2] = B
            jV[J2] = ie1 * w1 + jV[J1]
            jA[J2] = (ie1 * a1 - w1s * e1) + jA[J1]
        for i in range(nl):
            C[0, i, r] = lz[i]
            W[i, r] = lw[i]
            AL[i, r] = lal[i]
            j = org_j[i]
            if j >= 0:
                C[1, i, r], C[2, i, r], C[3, i, r] = jP[j], jV[j], jA[j]
            else:
                C[1, i, r], C[2, i, r], C[3, i, r] = _point(i, 0j, anc_j, anc_s, jP, jV, jA, lz, lw, lal)
    return near
