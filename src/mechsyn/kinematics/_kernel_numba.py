"""The regular pass's arithmetic compiled with Numba (imported only through
:mod:`mechsyn.kinematics.kernel`, on the first sweep). Under ``NUMBA_DISABLE_JIT=1`` the
same functions run as plain Python (CI measures the kernel's coverage that way).

The chain's steps one after the other, each over all rows in one compiled loop (the
step's constants held in registers, no temporaries, the joints' and links' states as
complex arrays by row): the positions (:func:`_positions`, the one placement: the
regular pass, the fold search's discriminant and the batch of designs run it), then the
rates. The program is the
regular pass's as arrays (:func:`mechsyn.kinematics.kernel.program`). Step by step over all rows is 30 %
faster than row by row over all steps (crank-rocker 24 -> 17 us, Watt six-bar 40 -> 28 us
for 361 rows), with the same bits.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mechsyn.kinematics.groups import COINCIDENT

#: Numba options: compiled once per machine and kept (``cache``), NumPy's floating-point
#: rules (a division by zero gives inf, a square root of a negative number NaN, as
#: NumPy's), the GIL released (the studio's threads).
_OPTIONS = dict(cache=True, nogil=True, error_model="numpy")
_ALL = np.zeros(0, np.int8)  # (_positions: every rotation and joint written)


@njit(inline="always", **_OPTIONS)
def _rate_rows(i, s, anc_j, anc_s, jV, jA, lz, lw, lal, outV, outA, M):
    """Velocity and acceleration (rows ``M``) of the local point ``s`` of link ``i`` (-1:
    the frame) from the link's anchor joint into ``outV``, ``outA``: ``V = V_a + i w (P -
    P_a)``, ``A = A_a + (i al - w^2) (P - P_a)`` with ``P - P_a = z (s - s_a)``
    (:func:`_place_rows` places ``P``)."""
    if i < 0:
        for r in range(M):
            outV[r] = 0j
            outA[r] = 0j
        return
    j = anc_j[i]
    sa = s - anc_s[i]
    for r in range(M):
        rel = lz[i, r] * sa
        w = lw[i, r]
        irel = rel * 1j
        acc = irel * lal[i, r]
        outV[r] = irel * w + jV[j, r]
        outA[r] = (acc - rel * (w * w)) + jA[j, r]


@njit(inline="always", **_OPTIONS)
def circle(d, L1s, L2s):
    """The RRR group's circle intersection, the one implementation (every engine that
    places an RRR group runs it: the passes here, and through :func:`circles` the generic
    steps, the tracked chain, the batch and synthesis,
    :func:`mechsyn.kinematics.groups.circle_circle`): with ``d = C - A`` (complex) and
    the squared lengths ``L1s``, ``L2s`` of the group's links, ``f = 1/2 + (L1^2 -
    L2^2) / (2 |d|^2)``, ``g^2 = L1^2 / |d|^2 - f^2`` (the middle joint at ``B = A + d (f
    + i sigma g)``) and the normalised discriminant ``g^2 |d|^2 / L1^2`` (below zero the
    circles do not meet; 1 when the first link stands square on ``d``, 0 when the group
    is folded flat). Centres within :data:`mechsyn.kinematics.groups.COINCIDENT` of one
    point: NaN (the middle joint is indeterminate)."""
    inv = d.real * d.real
    inv += d.imag * d.imag
    inv = 1.0 / inv if inv > COINCIDENT * (L1s + L2s) else math.nan
    f = inv * (0.5 * (L1s - L2s))
    f += 0.5
    g = inv * L1s
    g -= f * f
    return f, g, g / (inv * L1s)


@njit(**_OPTIONS)
def circles(dx, dy, L1, L2, F, G, Dsc):
    """:func:`circle` over the rows of ``dx``, ``dy`` (n,) with the squared lengths
    ``L1``, ``L2`` (n,) or (1,) each: ``f``, ``g^2`` and the normalised discriminant into
    ``F``, ``G``, ``Dsc`` (n,)."""
    one1, one2 = L1.shape[0] == 1, L2.shape[0] == 1
    for r in range(dx.shape[0]):
        F[r], G[r], Dsc[r] = circle(complex(dx[r], dy[r]), L1[0 if one1 else r], L2[0 if one2 else r])


@njit(inline="always", **_OPTIONS)
def place(d, f, g, disc, sigma):
    """The RRR group's middle joint from :func:`circle`'s ``f``, ``g^2`` and normalised
    discriminant, the one implementation (the passes here, and through :func:`places` the
    generic steps): ``B - A = d (f + i sigma g)`` in the assembly mode ``sigma`` (+1 or
    -1), a fold within round-off (``g^2 < 0``, the discriminant above -1e-12) taken flat;
    NaN where the circles do not meet."""
    if g < 0.0 and disc > -1e-12:
        g = 0.0
    g = math.sqrt(g) if g >= 0.0 else math.nan
    return d * complex(f, -g if sigma < 0.0 else g)


@njit(**_OPTIONS)
def places(dx, dy, F, G, Dsc, sig, EX, EY):
    """:func:`place` over the rows of ``dx``, ``dy``, ``F``, ``G``, ``Dsc`` (n,) with the
    modes ``sig`` (n,) or (1,): ``B - A`` into ``EX``, ``EY`` (n,)."""
    one = sig.shape[0] == 1
    for r in range(dx.shape[0]):
        e = place(complex(dx[r], dy[r]), F[r], G[r], Dsc[r], sig[0 if one else r])
        EX[r], EY[r] = e.real, e.imag


@njit(**_OPTIONS)
def fill(fi, anc_p, loc, pt, fp, anc_s):
    """The numbers of the program of ``K`` designs of one topology, the one
    implementation (:func:`mechsyn.kinematics.kernel.program` fills one system's,
    :func:`mechsyn.kinematics.batch.simulate_batch` many designs'): from the local
    points ``loc`` (K, pairs) complex of the (link, joint) pairs ``fi`` names and the
    drawn joint points ``pt`` (K, joints) complex, each step's row of ``fp`` (K, steps,
    7): a driver's sign and its joint's point on the known link; an RRR group's squared
    lengths ``L1^2 + i L2^2``, its drawn assembly mode (the sign of ``(C - A) x (B -
    A)``), its links' rotation vectors ``conj(u) / |u|^2`` (``u`` the link's vector from
    its end joint to the middle joint, in its local points) and its known joints' local
    points; and every link's anchor point ``anc_s`` (K, links) (0 without an anchor).
    ``fi`` (steps, 10): a driver's pair and sign; a group's pairs ``s1, s2`` (first
    link), ``t2, t3`` (second link), ``k1, k3`` (its end joints on the known links) and
    its three joints' indices in ``pt``; the step's op (0 a driver, 1 a group) last."""
    for k in range(loc.shape[0]):
        lk, pk = loc[k], pt[k]
        for s in range(fi.shape[0]):
            row = fp[k, s]
            row[:] = 0j
            if fi[s, 9] == 0:
                row[0], row[1] = float(fi[s, 1]), lk[fi[s, 0]]
                continue
            u, v = lk[fi[s, 1]] - lk[fi[s, 0]], lk[fi[s, 2]] - lk[fi[s, 3]]
            L1s = u.real * u.real + u.imag * u.imag
            L2s = v.real * v.real + v.imag * v.imag
            a, b, c = pk[fi[s, 6]], pk[fi[s, 7]], pk[fi[s, 8]]
            cross = (c.real - a.real) * (b.imag - a.imag) - (c.imag - a.imag) * (b.real - a.real)
            row[0], row[2] = complex(L1s, L2s), 1.0 if cross >= 0 else -1.0
            row[3], row[4] = complex(u.real / L1s, -(u.imag / L1s)), complex(v.real / L2s, -(v.imag / L2s))
            row[5], row[6] = lk[fi[s, 4]], lk[fi[s, 5]]
        for i in range(anc_p.shape[0]):
            anc_s[k, i] = lk[anc_p[i]] if anc_p[i] >= 0 else 0j


@njit(inline="always", **_OPTIONS)
def _place_rows(i, s, anc_j, anc_s, jP, lz, out, M):
    """Position (rows ``M``) of the local point ``s`` of link ``i`` (-1: the frame) from
    the link's anchor joint into ``out``: ``P = P_a + z (s - s_a)``."""
    if i < 0:
        for r in range(M):
            out[r] = s
        return
    j = anc_j[i]
    sa = s - anc_s[i]
    for r in range(M):
        out[r] = lz[i, r] * sa + jP[j, r]


@njit(inline="always", **_OPTIONS)
def _kept(keep, x):
    """Whether :func:`_positions` writes the rotation or joint ``x`` (``keep`` empty: all)."""
    return keep.shape[0] == 0 or keep[x] != 0


@njit(inline="always", **_OPTIONS)
def _positions(ip, fp, anc_j, anc_s, CS, SN, last, SG, jP, lz, D, keep):
    """The program's steps ``0..last``, positions only, over the input rows whose cosines
    and sines are ``CS``, ``SN`` (M, k), the one placement (:func:`regular_pass`,
    :func:`scalar_disc` and :func:`batch_pass` run it): every placed joint's position
    ``jP`` (joints, M), every placed link's rotation ``lz`` (links, M) and each RRR
    group's normalised discriminant ``D`` (its row ``ip[s, 10]``), by :func:`circle` and
    :func:`place`, each group in its drawn mode (``fp[s, 2]``) or, when ``SG`` (steps, M)
    has M columns, in the mode ``SG[s, row]``. ``keep`` (links + joints) 0 / 1: the
    rotations and joints written (a joint an end of a group reads is always written),
    empty: all (the batch keeps only what its outputs need: a store per row and link or
    joint is a fifth of its time)."""
    M = CS.shape[0]
    nl = anc_j.shape[0]
    by_row = SG.shape[1] == M
    for s in range(last + 1):
        if ip[s, 0] == 0:  # a driver: link new turned by the input di from link k
            new, k, j, di = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4]
            sgn = fp[s, 0].real
            if (k < 0 or ip[s, 5]) and _kept(keep, nl + j):
                _place_rows(k, fp[s, 1], anc_j, anc_s, jP, lz, jP[j], M)
            if _kept(keep, new):
                for r in range(M):
                    z = complex(CS[r, di], sgn * SN[r, di])
                    lz[new, r] = z if k < 0 else z * lz[k, r]
            continue
        k1, k3, b1, b2 = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4]
        J1, J2, J3, slot = ip[s, 5], ip[s, 6], ip[s, 7], ip[s, 10]
        if ip[s, 8]:
            _place_rows(k1, fp[s, 5], anc_j, anc_s, jP, lz, jP[J1], M)
        if ip[s, 9]:
            _place_rows(k3, fp[s, 6], anc_j, anc_s, jP, lz, jP[J3], M)
        L1s, L2s, cbv1, cbv2 = fp[s, 0].real, fp[s, 0].imag, fp[s, 3], fp[s, 4]
        k1, k2, kj = _kept(keep, b1), _kept(keep, b2), _kept(keep, nl + J2)
        for r in range(M):
            d = jP[J3, r] - jP[J1, r]
            f, g, disc = circle(d, L1s, L2s)
            D[slot, r] = disc
            e1 = place(d, f, g, disc, SG[s, r] if by_row else fp[s, 2].real)
            B = e1 + jP[J1, r]
            if kj:
                jP[J2, r] = B
            if k1:
                lz[b1, r] = e1 * cbv1
            if k2:
                lz[b2, r] = (B - jP[J3, r]) * cbv2


@njit(**_OPTIONS)
def batch_pass(ip, fp, anc_j, anc_s, nj, keep, CS, SN, out_l, out_s, P, ok, jump, sin_mu, flags):
    """The program over ``K`` designs (its numbers ``fp`` (K, steps, 7), ``anc_s`` (K,
    links), :func:`fill`) times the input rows whose cosines and sines are ``CS``, ``SN``
    (1 or K, N, 1): per design the positions of the steps (:func:`_positions`, every
    group in its drawn mode, the rotations and joints ``keep`` names), then the rows where every group assembles (discriminant
    >= 0) into ``ok`` (K, N), the positions of the points ``out_s`` (K, m) on the links
    ``out_l`` (m,) into ``P`` (m, K, N), NaN where not assembled; with ``flags`` a
    group's discriminant with a positive local minimum whose parabola through its two
    neighbours dips below zero (a fold stepped over between rows) into ``jump`` (K,);
    when ``sin_mu`` (K,) has rows, the least ``sin mu = |d| sqrt(disc) / L2`` (the
    transmission angle at the middle joint) of each group's assembled rows."""
    K, ns, nl = fp.shape[0], ip.shape[0], anc_j.shape[0]
    N = CS.shape[1]
    jP = np.empty((nj, N), np.complex128)
    lz = np.empty((nl, N), np.complex128)
    D = np.empty((ns, N))
    drawn = np.empty((0, 0))
    least = sin_mu.shape[0] > 0
    for k in range(K):
        c = 0 if CS.shape[0] == 1 else k
        _positions(ip, fp[k], anc_j, anc_s[k], CS[c], SN[c], ns - 1, drawn, jP, lz, D, keep)
        okk = ok[k]
        okk[:] = True
        lo = math.inf
        for s in range(ns):
            if ip[s, 0] == 0:
                continue
            Dg, J1, J3, L2s = D[ip[s, 10]], ip[s, 5], ip[s, 7], fp[k, s, 0].imag
            for r in range(N):
                x = Dg[r]
                if not x >= 0.0:
                    okk[r] = False
                elif least:
                    d = jP[J3, r] - jP[J1, r]
                    lo = min(lo, math.sqrt(x * (d.real * d.real + d.imag * d.imag) / L2s))
            for r in range(1, N - 1 if flags else 1):
                a, m, b = Dg[r - 1], Dg[r], Dg[r + 1]
                curv = b - 2 * m + a
                if 0.0 < m <= a and m <= b and curv > 0 and m - (b - a) ** 2 / (8 * curv) < 0:
                    jump[k] = True
        if least:
            sin_mu[k] = lo
        for q in range(out_l.shape[0]):
            out = P[q, k]
            _place_rows(out_l[q], out_s[k, q], anc_j, anc_s[k], jP, lz, out, N)
            for r in range(N):
                if not okk[r]:
                    out[r] = complex(math.nan, math.nan)


@njit(**_OPTIONS)
def regular_pass(ip, fp, anc_j, anc_s, org_j, CS, SN, speeds, nj, least, C, W, AL, D, Z, SG):
    """Run the program (``ip`` int (steps, 11), ``fp`` complex (steps, 7)) over the input
    rows whose cosines and sines are ``CS``, ``SN`` (M, k; NumPy's): the positions
    (:func:`_positions`), then the rates step by step; fill every link's rotation and its
    origin's position, velocity and acceleration ``C`` (4, links, M), its angular
    velocity and acceleration ``W``, ``AL`` (links, M), each RRR group's normalised
    discriminant ``D`` (groups, M) and, when ``Z`` has rows (2, links, P),
    :func:`_planes`. Every group in its drawn mode (``fp[:, 2]``), or when ``SG`` (steps,
    M) has M columns, in the mode ``SG[step, row]`` (+1 or -1: the tracked chain's signs
    by row). Returns True when a group's discriminant falls below ``least`` (or is NaN)
    on some row."""
    M = CS.shape[0]
    ns = ip.shape[0]
    nl = anc_j.shape[0]
    jP = np.empty((nj, M), np.complex128)
    jV = np.empty((nj, M), np.complex128)
    jA = np.empty((nj, M), np.complex128)
    lz, lw, lal = C[0], W, AL  # every link's rotation, angular velocity and acceleration, written in place
    _positions(ip, fp, anc_j, anc_s, CS, SN, ns - 1, SG, jP, lz, D, _ALL)
    near = False
    for g in range(D.shape[0]):
        for r in range(M):
            if not D[g, r] >= least:
                near = True
    for s in range(ns):
        if ip[s, 0] == 0:  # a driver: link new turned by the input di from link k
            new, k, j, di = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4]
            spd = fp[s, 0].real * speeds[di]
            if k < 0:
                _rate_rows(-1, 0j, anc_j, anc_s, jV, jA, lz, lw, lal, jV[j], jA[j], M)
            elif ip[s, 5]:
                _rate_rows(k, fp[s, 1], anc_j, anc_s, jV, jA, lz, lw, lal, jV[j], jA[j], M)
            for r in range(M):
                lw[new, r] = spd if k < 0 else lw[k, r] + spd
                lal[new, r] = 0.0 if k < 0 else lal[k, r]
            continue
        # an RRR group: joints J1 (on known link k1), J3 (on k3), its links b1, b2 meet at J2
        k1, k3, b1, b2 = ip[s, 1], ip[s, 2], ip[s, 3], ip[s, 4]
        J1, J2, J3 = ip[s, 5], ip[s, 6], ip[s, 7]
        if ip[s, 8]:
            _rate_rows(k1, fp[s, 5], anc_j, anc_s, jV, jA, lz, lw, lal, jV[J1], jA[J1], M)
        if ip[s, 9]:
            _rate_rows(k3, fp[s, 6], anc_j, anc_s, jV, jA, lz, lw, lal, jV[J3], jA[J3], M)
        for r in range(M):
            B = jP[J2, r]
            e1, e2 = B - jP[J1, r], B - jP[J3, r]
            ce1, ce2 = e1.conjugate(), e2.conjugate()
            den = 1.0 / (ce1 * e2).imag
            dv = jV[J3, r] - jV[J1, r]
            w1 = (dv * ce2).real * den
            w2 = (dv * ce1).real * den
            w1s = w1 * w1
            da = (jA[J3, r] - jA[J1, r]) + w1s * e1
            da -= (w2 * w2) * e2
            a1 = (da * ce2).real * den
            a2 = (da * ce1).real * den
            lw[b1, r], lal[b1, r] = w1, a1
            lw[b2, r], lal[b2, r] = w2, a2
            ie1 = e1 * 1j
            jV[J2, r] = ie1 * w1 + jV[J1, r]
            jA[J2, r] = (ie1 * a1 - w1s * e1) + jA[J1, r]
    for i in range(nl):  # each link's origin: its first joint, or its point (0, 0) from its anchor
        j = org_j[i]
        if j >= 0:
            C[1, i] = jP[j]
            C[2, i] = jV[j]
            C[3, i] = jA[j]
        else:
            _place_rows(i, 0j, anc_j, anc_s, jP, lz, C[1, i], M)
            _rate_rows(i, 0j, anc_j, anc_s, jV, jA, lz, lw, lal, C[2, i], C[3, i], M)
    if Z.shape[1] == nl:
        _planes(lz, Z)
    return near


@njit(inline="always", **_OPTIONS)
def _planes(lz, Z):
    """The rotations ``lz`` (links, M) as planes ``Z`` (2, links, P <= M rows), real and imaginary
    parts: NumPy's ``arctan2`` reads contiguous rows a third faster, with the same numbers."""
    for i in range(lz.shape[0]):
        for r in range(Z.shape[2]):
            z = lz[i, r]
            Z[0, i, r] = z.real
            Z[1, i, r] = z.imag


@njit(inline="always", **_OPTIONS)
def _near(a, ref):
    """``ref + wrap(a - ref)``: the angle ``a`` moved by whole turns next to ``ref``
    (``wrap`` to [-pi, pi) by the floored remainder, as ``np.remainder``). With ``a`` an
    ``atan2`` and ``ref`` within half a turn, ``a - ref + pi`` lies in [-pi, 3 pi]: the
    remainder is one exact step of 2 pi or none (a step down is exact by Sterbenz's lemma,
    as ``fmod`` gives it), without the division."""
    x = a - ref + math.pi
    if -math.pi <= ref <= math.pi:
        if x >= 2 * math.pi:
            x -= 2 * math.pi
        elif x < 0.0:
            x += 2 * math.pi
    else:
        x %= 2 * math.pi
    return ref + (x - math.pi)


@njit(**_OPTIONS)
def link_poses(C, W, AL, N, U, dcol, dsgn, ref, split, folds, A, q, qd, qdd, ok, sb, sf, rok):
    """The pose rows ``q, qd, qdd`` (3 links, N; component-major) of the first N rows of a
    pass (``C``, ``W``, ``AL`` of :func:`regular_pass`): each link's origin, its angle and
    their rates. A link turned by a frame driver (``dcol[i]`` its input's column, ``dsgn``
    its sign) takes the input itself; the others ``atan2`` of their rotation, made
    continuous (``A``: the rotations' ``atan2``, links by rows, from NumPy, whose vector
    loops take a third of libm's time) and started next to their drawn angle ``ref[i]``
    (:func:`mechsyn.kinematics.positions.continuous_angles`): without ``folds`` one
    unwrapped run whose rows ``split`` and ``split - 1`` (when ``split`` >= 0) each start
    next to ``ref``; with ``folds`` each tracked sweep (forwards from ``split``, backwards
    from ``split - 1``, or the one sweep) on its own, its runs of assembled rows unwrapped
    and each run following the run before by whole turns, the rows where a link is not
    placed blanked (NaN) in the poses and in ``C`` and the rates of rows where they are
    not finite blanked (:func:`mechsyn.kinematics.regular._fold_poses`), and the rates of
    the singular rows the fold scan found (rows ``r < len(sb)``: ``sb[r]``, else ``sf[r -
    len(sb)]``) blanked too. Writes the rows assembled into ``ok`` (N,) and, with ``folds``,
    the rows with rates (assembled, finite, not singular) into ``rok`` (N,) (an array made
    here would cost its unpickled type on return); returns the number of singular rows
    (assembled, rates not defined)."""
    nl = C.shape[1]
    twopi = 2 * math.pi
    for r in range(N):
        ok[r] = True
    for i in range(nl):
        for r in range(N):
            p, v, a = C[1, i, r], C[2, i, r], C[3, i, r]
            q[3 * i, r], q[3 * i + 1, r] = p.real, p.imag
            qd[3 * i, r], qd[3 * i + 1, r], qd[3 * i + 2, r] = v.real, v.imag, W[i, r]
            qdd[3 * i, r], qdd[3 * i + 1, r], qdd[3 * i + 2, r] = a.real, a.imag, AL[i, r]
            if folds:
                z = C[0, i, r]
                if not (math.isfinite(z.real) and math.isfinite(z.imag)):
                    ok[r] = False
    for i in range(nl):
        out = q[3 * i + 2]
        if dcol[i] >= 0:
            for r in range(N):
                out[r] = U[r, dcol[i]] * dsgn[i]
            continue
        for r in range(N):
            out[r] = A[i, r]
        if not folds:  # one run, unwrapped forwards, its start row(s) next to the drawn angle
            raw = out[0]
            K = 0.0
            for r in range(1, N):
                a = out[r]
                d = a - raw
                if d > 3.0 or d < -3.0:  # else |d / 2 pi| < 0.48: no whole turn (rint 0), no division
                    K += np.rint(d / twopi)
                raw = a
                out[r] = a - twopi * K
            for part in range(2 if split >= 0 else 1):
                row = 0 if split < 0 else (split if part == 0 else split - 1)
                lo, hi = (0, N) if split < 0 else ((split, N) if part == 0 else (0, split))
                a0 = A[i, row]
                turns = np.rint((out[row] - _near(a0, ref[i])) / twopi)
                if turns != 0.0:
                    for r in range(lo, hi):
                        out[r] -= twopi * turns
            continue
        for part in range(2 if split >= 0 else 1):  # each tracked sweep in its own order
            start, n, step = (0, N, 1) if split < 0 else ((split, N - split, 1) if part == 0 else (split - 1, split, -1))
            has_prev, in_run = False, False
            prev, raw, K, shift = 0.0, 0.0, 0.0, 0.0
            for t in range(n):
                r = start + step * t
                if not ok[r]:
                    in_run = False
                    continue
                s = _near(out[r], ref[i])
                if not in_run:
                    in_run, raw, K = True, s, 0.0
                    x = s
                    shift = twopi * np.rint((x - prev) / twopi) if has_prev else 0.0
                else:
                    d = s - raw
                    if d > 3.0 or d < -3.0:  # else |d / 2 pi| < 0.48: no whole turn (rint 0), no division
                        K += np.rint(d / twopi)
                    raw = s
                    x = s - twopi * K
                out[r] = x - shift if shift != 0.0 else x
                prev, has_prev = out[r], True
    return _blank_rows(C, q, qd, qdd, ok, sb, sf, rok) if folds else 0


@njit(inline="always", **_OPTIONS)
def _blank_rows(C, q, qd, qdd, ok, sb, sf, rok):
    """:func:`link_poses`' blanking through folds (rows not assembled, rates not finite or
    singular: ``sb``, ``sf``); the rows with rates into ``rok``; returns how many have none."""
    nl, N = C.shape[1], ok.shape[0]
    singular = 0
    nb = sb.shape[0]
    for r in range(N):
        rok[r] = False
        if not ok[r]:
            for c in range(3 * nl):
                q[c, r] = math.nan
                qd[c, r] = math.nan
                qdd[c, r] = math.nan
            for i in range(nl):  # the links' states too: a point of any link is not placed here
                for c in range(4):
                    C[c, i, r] = complex(math.nan, math.nan)
            continue
        rates = not (sb[r] if r < nb else sf[r - nb])
        if rates:
            for c in range(3 * nl):
                if not (math.isfinite(qd[c, r]) and math.isfinite(qdd[c, r])):
                    rates = False
                    break
        if not rates:
            singular += 1
            for c in range(3 * nl):
                qd[c, r] = math.nan
                qdd[c, r] = math.nan
        rok[r] = rates
    return singular


@njit(**_OPTIONS)
def fold_rows(Dp, perm, b, zero, sing, Dl, singular, chg):
    """The regular pass's discriminants ``Dp`` (groups, pass rows) laid out in the tracked
    sweeps' order ``perm`` into ``Dl`` (groups, L), the rows where some assembled group is
    within ``sing`` of folding flat (``singular`` (L,)), the rows after which a group's
    assembly changes (``chg`` (groups, L - 1): assembled means ``D > -zero``), and whether
    an assembled group's discriminant has a local minimum under 0.05 on an inner row of a
    sweep (rows ``b - 1`` and ``b``, the sweeps' first, are not inner):
    :func:`mechsyn.kinematics.folds.pass_fold_events`'s masks in one loop."""
    ng, L = Dl.shape
    for t in range(L):
        singular[t] = False
    low = False
    for g in range(ng):
        for t in range(L):
            Dl[g, t] = Dp[g, perm[t]]
        prev_ok = False
        for t in range(L):
            x = Dl[g, t]
            ok = x > -zero
            if ok and max(x, 0.0) < sing:
                singular[t] = True
            if t >= 1:
                chg[g, t - 1] = ok != prev_ok
            prev_ok = ok
        for t in range(1, L - 1):
            if t == b - 1 or t == b:
                continue
            x = Dl[g, t]
            if not x > -zero:
                continue
            m = max(x, 0.0)
            if m < 0.05:
                a, c = Dl[g, t - 1], Dl[g, t + 1]
                if a > -zero and c > -zero and m <= max(a, 0.0) and m <= max(c, 0.0):
                    low = True
    return low


@njit(**_OPTIONS)
def point_states(C, w, al, idx, s, out):
    """Position, velocity, acceleration ``out`` (3, m, N) complex of the local points ``s``
    (m,) of the links ``idx`` (m,) from the links' states ``C`` (4, links, N) and rates
    ``w``, ``al`` (links, N): :meth:`mechsyn.kinematics.regular.LinkStates.points`'
    products in the same order, row by row."""
    N = out.shape[2]
    for k in range(idx.shape[0]):
        i, sk = idx[k], s[k]
        for r in range(N):
            rel = C[0, i, r] * sk
            wr = w[i, r]
            irel = rel * 1j
            out[0, k, r] = rel + C[1, i, r]
            out[1, k, r] = irel * wr + C[2, i, r]
            out[2, k, r] = ((irel * al[i, r]) - rel * (wr * wr)) + C[3, i, r]


@njit(**_OPTIONS)
def scalar_disc(ip, fp, anc_j, anc_s, u, nj, k, sg):
    """The normalised discriminant of step ``k`` (an RRR group) of the program at one input
    ``u`` (k inputs), every group upstream in its mode ``sg[s]`` (+1 or -1, by step; the
    drawn modes: ``fp[:, 2].real``), a group folded within 1e-12 taken flat, else NaN
    downstream (:func:`_positions` on one row): the fold search's function along a
    segment."""
    CS, SN = np.empty((1, u.shape[0])), np.empty((1, u.shape[0]))
    for i in range(u.shape[0]):
        CS[0, i], SN[0, i] = math.cos(u[i]), math.sin(u[i])
    jP = np.zeros((nj, 1), np.complex128)
    lz = np.zeros((anc_j.shape[0], 1), np.complex128)
    D = np.empty((ip.shape[0], 1))
    _positions(ip, fp, anc_j, anc_s, CS, SN, k, sg.reshape(-1, 1), jP, lz, D, _ALL)
    return D[ip[k, 10], 0]


@njit(inline="always", **_OPTIONS)
def _pos(w, i, b):
    """The layout column of row ``i`` of tracked sweep ``w`` (0 forwards from ``b``, 1 backwards)."""
    return b + i if w == 0 else b - 1 - i


@njit(inline="always", **_OPTIONS)
def _scan_row(X, perm, b, w, i, n0, shift, out):
    """Row ``i`` of tracked sweep ``w`` into ``out``: its connecting path's row (``i < n0``), else the
    sweep's row less the whole turns ``shift`` (:func:`mechsyn.kinematics.folds.pass_fold_events`)."""
    r = perm[_pos(w, i, b)]
    for c in range(out.shape[0]):
        out[c] = X[r, c] if i < n0 else X[r, c] - shift[c]


@njit(**_OPTIONS)
def _disc_along(c, t):
    """:func:`scalar_disc` of step ``k`` at the input ``xa + t d`` (the numbers of
    :func:`mechsyn.kinematics.folds._disc_line`), the groups in the modes ``sg``; ``c``:
    ``(ip, fp, anc_j, anc_s, nj, k, xa, d, sg)``."""
    ip, fp, anc_j, anc_s, nj, k, xa, d, sg = c
    u = np.empty(xa.shape[0])
    for i in range(xa.shape[0]):
        u[i] = xa[i] + t * d[i]
    return scalar_disc(ip, fp, anc_j, anc_s, u, nj, k, sg)


@njit(**_OPTIONS)
def fold_root(c, fa, fb, a, b):
    """The zero ``t`` in [a, b] of a group's discriminant ``f(c, t)`` along a segment of
    inputs, ``f(a) = fa``, ``f(b) = fb`` (known): secant steps through the last two
    iterates (order 1.6 on the smooth discriminant of a fold), regula falsi when one would
    leave the bracket, stopped when the next step is below 1e-14 (about four evaluations
    from one input step to 1e-14 of it; Dahlquist and Bjorck, *Numerical Methods*, 1974,
    sec. 6.3). NaN when the ends do not bracket a zero. ``f(c, t)`` is
    :func:`_disc_along`: compiled, the program's discriminant; run as plain Python
    (:func:`mechsyn.kinematics.kernel.scan_sweep`), the callable ``c`` (the generic
    steps' discriminant, :mod:`mechsyn.kinematics.folds`)."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    if (fa > 0.0) == (fb > 0.0) or not (math.isfinite(fa) and math.isfinite(fb)):
        return math.nan
    x0, f0, x1, f1 = a, fa, b, fb  # the bracket [a, b] (f(a) has the sign of fa)
    t = (a * fb - b * fa) / (fb - fa)
    for _ in range(100):
        if not a < t < b:
            t = (a * fb - b * fa) / (fb - fa)
            if not a < t < b:
                t = 0.5 * (a + b)
        ft = _disc_along(c, t)
        if ft == 0.0 or not math.isfinite(ft):
            return t
        if (ft > 0.0) == (fa > 0.0):
            a, fa = t, ft
        else:
            b, fb = t, ft
        x0, f0, x1, f1 = x1, f1, t, ft
        step = f1 * (x1 - x0) / (f1 - f0) if f1 != f0 else 0.0
        if abs(step) <= 1e-14 or b - a <= 1e-14:
            return min(max(x1 - step, a), b)
        t = x1 - step
    return t


@njit(**_OPTIONS)
def hidden_fold(c, fa, fb, tc, hidden, zero):
    """Where (t) a group folds between two rows (``_disc_along(c, t)`` its discriminant along the
    segment, ``fa``, ``fb`` its values at the rows). ``hidden`` 0: its own discriminant
    changes sign between the rows (t at the ends when the change is round-off only); 1:
    it is assembled at the first row and an upstream group ends the assembly at ``tc``:
    the group's own fold before that point, if its discriminant is negative there (else
    NaN); -1: likewise after an upstream start at ``tc``."""
    if hidden == 0:
        t = fold_root(c, fa, fb, 0.0, 1.0)
        return t if not math.isnan(t) else (0.0 if fa > -zero else 1.0)
    fc = _disc_along(c, tc)
    if not fc <= -zero:
        return math.nan
    return fold_root(c, fa, fc, 0.0, tc) if hidden > 0 else fold_root(c, fc, fb, tc, 1.0)


@njit(**_OPTIONS)
def _refine(c, g, i, hidden, xa, xb, fa, fb, ends, starts):
    """The refinement of a fold of group ``g`` between rows ``i - 1`` and ``i`` (inputs
    ``xa``, ``xb``): :func:`_four_bar_t`, else :func:`hidden_fold` along :func:`_segment`;
    ``c``: the groups' closed-form numbers, the round-off zero, then :func:`_segment`'s."""
    specs, zero = c[0], c[1]
    t = _four_bar_t(specs[g], xa[0], xb[0]) if hidden == 0 else math.nan
    if not math.isnan(t):
        return t
    tc = 0.0 if hidden == 0 else (ends[i] if hidden > 0 else starts[i])
    return hidden_fold(_segment(c, g, i, xa, xb), fa, fb, tc, hidden, zero)


@njit(**_OPTIONS)
def _segment(c, g, i, xa, xb):
    """:func:`_disc_along`'s context for group ``g`` from ``xa`` to ``xb`` (compiled: the
    program's; as plain Python a callable of the context, :func:`mechsyn.kinematics.kernel.scan_sweep`)."""
    _, _, ip, fp, anc_j, anc_s, nj, ks, sg = c
    d = np.empty(xa.shape[0])
    for k in range(xa.shape[0]):
        d[k] = xb[k] - xa[k]
    return ip, fp, anc_j, anc_s, nj, ks[g], xa, d, sg


@njit(**_OPTIONS)
def _four_bar_t(spec, ua, ub):
    """Where a group closing a four-bar folds, from its numbers ``spec``
    (:func:`mechsyn.kinematics.folds._four_bar_specs`: a four-bar or not,
    ``|v|``, ``|w|``, ``arg w - arg v``, the input's sign, the two squared distances): t
    in [0, 1] of the one fold angle between the inputs ``ua`` and ``ub``, else NaN."""
    if spec[0] == 0.0:
        return math.nan
    av, aw, beta, sgn = spec[1], spec[2], spec[3], spec[4]
    lo, hi = min(ua, ub), max(ua, ub)
    slack = 1e-12 * (hi - lo)
    count = 0
    found = 0.0
    for q in range(2):
        c = (spec[5 + q] - av * av - aw * aw) / (2 * av * aw)
        if not -1.0 < c < 1.0:
            continue
        ac = math.acos(c)
        for psi in (ac - beta, -ac - beta):
            u = sgn * psi
            u += 2 * math.pi * np.rint((0.5 * (lo + hi) - u) / (2 * math.pi))
            if lo - slack <= u <= hi + slack:
                found = u
                count += 1
    if count != 1:
        return math.nan
    return min(1.0, max(0.0, (found - ua) / (ub - ua)))


@njit(**_OPTIONS)
def scan_sweep(D, X, n0, shift, zero, c, ev, ne, w):
    """The fold scan of one tracked sweep, the one implementation (the kernel's
    :func:`fold_scan` runs it compiled, the tracked groups run it as plain Python,
    :func:`mechsyn.kinematics.folds.fold_events`): from the groups' normalised
    discriminants ``D`` (groups, n) on the sweep's input rows ``X`` (n, inputs; the first
    ``n0`` its connecting path, the rest shifted by the whole turns ``shift``), per group
    the rows where its assembly changes (assembled: ``D > -zero``), its folds (both rows
    evaluated: its own; assembled at one row and cut off at the next by an upstream
    group's fold: its own fold may come first, hidden between the rows: ``ends``,
    ``starts``), each refined by :func:`_refine` ``(c, g, i, hidden, xa, xb, fa, fb,
    ends, starts)`` (t in [0, 1] between rows ``i - 1`` and ``i``, NaN: none; run as plain
    Python, the context ``c`` brings its own discriminant), then its
    reassemblies. Writes the events as rows of ``ev`` from row ``ne``: ``w``, row, kind
    (0 the assembly ends, 1 it starts again, 2 reassembled), group, then the input (whole
    turns added back past the connecting path); returns the next free row."""
    ng, n = D.shape
    nin = X.shape[1]
    ends, starts = np.full(n, math.nan), np.full(n, math.nan)  # NaN: no fold there yet
    rows, hide, backs = np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64)
    xa, xb = np.empty(nin), np.empty(nin)
    for g in range(ng):
        nr = nb = 0
        for i in range(1, n):
            fa, fb = D[g, i - 1], D[g, i]
            if (fa > -zero) == (fb > -zero):
                continue
            if fb > -zero:
                backs[nb] = i
                nb += 1
            hidden = 0 if math.isfinite(fa) and math.isfinite(fb) else (
                1 if fa > -zero and not math.isnan(ends[i]) else (
                    -1 if fb > -zero and not math.isnan(starts[i]) else 2))
            if hidden != 2:
                rows[nr], hide[nr] = i, hidden
                nr += 1
        for r in range(nr):
            i, hidden = rows[r], hide[r]
            fa, fb = D[g, i - 1], D[g, i]
            for k in range(nin):
                xa[k], xb[k] = X[i - 1, k], X[i, k]
            t = _refine(c, g, i, hidden, xa, xb, fa, fb, ends, starts)
            if math.isnan(t):
                continue
            inside = fa > -zero if hidden == 0 else hidden > 0
            if inside:
                ends[i] = t if math.isnan(ends[i]) else min(t, ends[i])
            else:
                starts[i] = t if math.isnan(starts[i]) else max(t, starts[i])
            ev[ne, 0], ev[ne, 1], ev[ne, 2], ev[ne, 3] = w, i, 0 if inside else 1, g
            for k in range(nin):  # the numbers of xa + t (xb - xa), whole turns added back
                u = xa[k] + t * (xb[k] - xa[k])
                ev[ne, 4 + k] = u if i < n0 else u + shift[k]
            ne += 1
        for r in range(nb):
            i = backs[r]
            if i < n0:
                continue
            ev[ne, 0], ev[ne, 1], ev[ne, 2], ev[ne, 3] = w, i, 2, g
            for k in range(nin):
                ev[ne, 4 + k] = X[i, k] + shift[k]
            ne += 1
    return ne


@njit(**_OPTIONS)
def fold_scan(Dp, perm, b, zero, sing, X, nsw, n0a, sha, n0b, shb, ks, specs, ip, fp, anc_j, anc_s,
              nj):
    """:func:`mechsyn.kinematics.folds.pass_fold_events` in one call: the masks of
    :func:`fold_rows` (the discriminants ``Dp`` (groups, pass rows) laid out by ``perm``),
    then each tracked sweep's :func:`scan_sweep` on its rows, folds refined in closed form
    (``specs[g]``, :func:`_four_bar_t`) or on the program's discriminant along the
    segment of inputs (:func:`_refine`, every group in its drawn mode). ``X``: the pass's
    input rows; ``nsw``: the number of sweeps (1 or 2), their connecting paths' lengths
    and whole turns ``n0a``, ``sha`` (forwards) and ``n0b``, ``shb`` (backwards). Returns
    whether a change point may be near (nothing scanned then), the singular rows (L,) and
    the events by row: sweep, row along it, kind, group, input (:func:`scan_sweep`)."""
    ng, L = Dp.shape[0], perm.shape[0]
    nin = X.shape[1]
    Dl = np.empty((ng, L))
    singular = np.empty(L, np.bool_)
    chg = np.empty((ng, max(L - 1, 0)), np.bool_)
    low = fold_rows(Dp, perm, b, zero, sing, Dl, singular, chg)
    cap = 0
    if not low:
        for g in range(ng):
            for t in range(L - 1):
                cap += chg[g, t]
    ev = np.empty((2 * cap, 4 + nin))
    ne = 0
    sg = np.empty(fp.shape[0])  # every group in its drawn mode
    for st in range(fp.shape[0]):
        sg[st] = fp[st, 2].real
    c = (specs, zero, ip, fp, anc_j, anc_s, nj, ks, sg)
    for w in range(nsw if cap else 0):
        n0, shift = (n0a, sha) if w == 0 else (n0b, shb)
        n = L - b if w == 0 else b
        Dw, Xw = np.empty((ng, n)), np.empty((n, nin))  # the sweep's rows in its order
        for i in range(n):
            _scan_row(X, perm, b, w, i, n0, shift, Xw[i])
            for g in range(ng):
                Dw[g, i] = Dl[g, _pos(w, i, b)]
        ne = scan_sweep(Dw, Xw, n0, shift, zero, c, ev, ne, w)
    return low, singular, ev[:ne]
