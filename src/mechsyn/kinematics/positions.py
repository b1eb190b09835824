"""Closed-form position analysis by Assur groups of class II (dyads), vectorised.

A mechanism of R and P pairs whose links can be found one driver at a time and then
two at a time (a *dyad*: two links, three pairs, joined to links already known) is
solved in closed form for all input values at once (Artobolevsky, *Theory of
Mechanisms and Machines*, ch. 4; the dyads RRR, RRP, PRR, RPR, RPP, PRP):

* RRR: the middle joint ``B`` is the intersection of the circles ``|B - A| = L1`` and
  ``|B - C| = L2``: with ``d = C - A``, ``a = (L1^2 - L2^2 + |d|^2) / (2|d|)``,
  ``h = sqrt(L1^2 - a^2)``, ``B = A + a d/|d| + sigma h R90 d/|d|``;
* RRP / PRR: the intersection of a circle and a line, ``lambda^2 + 2 p lambda + c = 0``;
* RPR: the slide line keeps the offset ``e`` from both pivots:
  ``cos(phi + nu - delta) = e / |C - A|``;
* RPP / PRP: the orientations follow from the P pairs, the positions from two linear
  equations ``n_1 . X = h_1``, ``n_2 . X = h_2`` (the two slide lines).

The assembly mode ``sigma`` of each dyad is taken from the file's configuration, so the
result equals the continuation of :func:`mechsyn.kinematics.solve.sweep` on that branch
(tests check both agree). Where a square root is negative the dyad cannot be assembled:
the row is NaN and ``assembled`` is false (dead points are then located by the Newton
path). Velocities and accelerations of driver + RRR chains are in closed form
(``omega_1 = (v_C - v_A) . e2 / (e1 x e2)``, ``e1 = B - A``, ``e2 = B - C``); other
chains use batched linear solves of the differentiated constraints.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mechsyn.kinematics.groups import (Plan, Sigma, Step, circle_circle, circle_middle, cons_of, local_point, pair_line,
                                       rel_angle)
from mechsyn.kinematics.plane import cos_sin, cross, dot, perp, rotate
from mechsyn.kinematics.system import Con, PlanarSystem

__all__ = ["TrackedPositions", "solve_positions"]


class PoseState:
    """The poses of the links known so far, for all N inputs: origins ``r`` (N, nl, 2) and
    angles ``phi`` (N, nl), NaN until a step places the link (:func:`solve_step`).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.system import build_system
    >>> st = PoseState(build_system(ms.examples.load("crank_rocker")), 4)
    >>> st.r.shape, st.phi.shape, [a.shape for a in st.pose(-1)]
    ((4, 3, 2), (4, 3), [(4, 2), (4,)])
    """

    def __init__(self, S: PlanarSystem, N: int) -> None:
        self.S = S
        self.r = np.full((N, len(S.links), 2), np.nan)
        self.phi = np.full((N, len(S.links)), np.nan)
        self.N = N

    def pose(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        if i < 0:
            return np.zeros((self.N, 2)), np.zeros(self.N)
        return self.r[:, i], self.phi[:, i]

    def point(self, i: int, s: np.ndarray) -> np.ndarray:
        r, phi = self.pose(i)
        c, sn = cos_sin(phi)
        return r + rotate(c, sn, s)

    def set(self, i: int, r: np.ndarray, phi: np.ndarray) -> None:
        self.r[:, i] = r
        self.phi[:, i] = phi


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2 * np.pi) - np.pi


def _unwrap_rows(p: np.ndarray) -> np.ndarray:
    """``np.unwrap(p, axis=-1)`` for angles whose steps stay below a whole turn (as those of
    ``atan2`` do), into a copy: the whole turns of each step counted (a step of exactly
    half a turn is kept, as ``np.unwrap`` keeps it) and removed as the kernel removes them
    (:func:`mechsyn.kinematics._kernel_numba.link_poses`)."""
    out = np.array(p, float)
    out[..., 1:] -= 2 * np.pi * np.cumsum(np.rint(np.diff(p, axis=-1) / (2 * np.pi)), axis=-1)
    return out


def continuous_angles(phi: np.ndarray, ref: np.ndarray, ok: np.ndarray | None) -> np.ndarray:
    """Link angles ``phi`` (N, m) made continuous along a sweep: started next to the
    file's angles ``ref`` (m,), each run of assembled rows unwrapped, the turn count
    kept across gaps (``ok`` None: every row assembled). The kernel's passes do the same
    (:func:`mechsyn.kinematics._kernel_numba.link_poses`).

    Examples
    --------
    >>> import numpy as np
    >>> phi = np.radians([[170.0], [-170.0], [-150.0]])
    >>> np.degrees(continuous_angles(phi, np.radians([160.0]), None)).round(6).ravel().tolist()
    [170.0, 190.0, 210.0]
    """
    phi, col = phi.T, ref[:, None]
    if ok is None or ok.all():  # one run: unwrapped, then moved by whole turns to start next to ref
        block = _unwrap_rows(phi)
        for i, (a, b, r0) in enumerate(zip(phi[:, 0].tolist(), block[:, 0].tolist(), ref.tolist())):
            turns = round((b - (r0 + ((a - r0 + math.pi) % (2 * math.pi) - math.pi))) / (2 * math.pi))
            if turns:
                block[i] -= 2 * math.pi * turns
        return block.T
    sub = col + _wrap(phi - col)  # every angle next to ref, then
    # the runs of assembled rows [a, b): each unwrapped, then shifted by whole turns to
    # follow the run before (on floats: a run's first angles are not changed by its
    # unwrapping)
    edges = np.flatnonzero(ok[1:] != ok[:-1])
    bounds = ([0] if ok[0] else []) + (edges + 1).tolist() + ([len(ok)] if ok[-1] else [])
    prev = None
    for a, b in zip(bounds[0::2], bounds[1::2]):
        sub[:, a:b] = _unwrap_rows(sub[:, a:b])
        block = sub[:, a:b]
        if prev is not None:
            for i, (x, y) in enumerate(zip(block[:, 0].tolist(), prev)):
                turns = round((x - y) / (2 * math.pi))
                if turns:
                    block[i] -= 2 * math.pi * turns
        prev = block[:, -1].tolist()
    return sub.T


def _pin(st: PoseState, i: int, P: np.ndarray, s_local: np.ndarray, phi: np.ndarray) -> None:
    c, sn = cos_sin(phi)
    st.set(i, P - rotate(c, sn, s_local), phi)


def solve_step(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """Solve one step of a plan in place in ``st`` (the poses of its new links at the
    inputs ``u``, radians or lengths per driver, (N, nd)); return its assembly sign
    (sigma) for the branch: ``sigma`` given (a number or one per row), None (the drawn
    mode) or a chooser called with the normalised discriminant and the drawn mode.
    Every step kind of :func:`~mechsyn.kinematics.groups.decompose` has one."""
    return _STEP_KERNELS[step.kind](S, st, step, u, sigma)


def _step_drive_R(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """A link turned by an R drive about a known link."""
    (new,), (k,), (jid,) = step.links, step.known, step.joints
    con = next(c for c in cons_of(S, jid) if c.role == "drive")
    th = u[:, con.driver]
    _, phik = st.pose(k)
    phi = phik + th if con.b == new else phik - th
    P = st.point(k, local_point(S, k, jid))
    _pin(st, new, P, local_point(S, new, jid), phi)
    return 1.0


def _step_drive_P(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """A link slid by a P drive along a known link."""
    (new,), (k,), (jid,) = step.links, step.known, step.joints
    drive = next(c for c in cons_of(S, jid) if c.role == "drive")
    line = pair_line(S, jid)
    val = u[:, drive.driver]
    ra, pa = st.pose(k)
    if drive.a != k:  # the new link carries the axis
        pa = pa + rel_angle(S, jid, k, new)
    ca, sa_ = cos_sin(pa)
    w, n = rotate(ca, sa_, drive.w), rotate(ca, sa_, line.w)
    if drive.a == k:
        Pa = st.point(k, line.sa)
        Pb = ra + val[:, None] * w + n * dot(n, Pa - ra)[:, None]
        _pin(st, new, Pb, drive.sb, pa + rel_angle(S, jid, k, new))
    else:  # O_a = u (u.P_b - s) + n (n.(P_b - A_a s_a))
        Pb = st.point(k, drive.sb)
        Oa = w * (dot(w, Pb) - val)[:, None] + n * dot(n, Pb - rotate(ca, sa_, line.sa))[:, None]
        st.set(new, Oa, pa)
    return 1.0


def _step_RRR(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """RRR dyad: the intersection of two circles."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    A = st.point(A_s, local_point(S, A_s, J1))
    C = st.point(B_s, local_point(S, B_s, J3))
    s1, s2 = local_point(S, b1, J1), local_point(S, b1, J2)
    t2, t3 = local_point(S, b2, J2), local_point(S, b2, J3)
    L1s, L2s = float(np.sum((s2 - s1) ** 2)), float(np.sum((t2 - t3) ** 2))
    d = C - A
    f, g2, disc = circle_circle(d[:, 0], d[:, 1], L1s, L2s)
    if sigma is None or callable(sigma):
        s_file = 1.0 if cross(d[0], (S.mech.joint(J2).point - A[0]))[()] >= 0 else -1.0
        sigma = s_file if sigma is None else sigma(disc, s_file)
    B = A + circle_middle(d, f, g2, disc, sigma)
    beta1 = np.arctan2(*(s2 - s1)[::-1])
    beta2 = np.arctan2(*(t2 - t3)[::-1])
    phi1 = np.arctan2((B - A)[:, 1], (B - A)[:, 0]) - beta1
    phi2 = np.arctan2((B - C)[:, 1], (B - C)[:, 0]) - beta2
    _pin(st, b1, A, s1, phi1)
    _pin(st, b2, C, t3, phi2)
    return sigma


def _oriented(step: Step, kind: str) -> tuple:
    """A dyad's links, known links and end joints in the order of ``kind`` (the step's
    own order, or reversed for its mirror kind, e.g. PRR as RRP)."""
    (A_s, B_s), (b1, b2), (J1, _, J3) = step.known, step.links, step.joints
    if step.kind == kind:
        return b1, b2, A_s, B_s, J1, J3
    return b2, b1, B_s, A_s, J3, J1


def _step_RRP(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """RRP / PRR dyad: the intersection of a circle and a line."""
    # orient as R(J_r) - R(J2) - P(J_p): link `lr` pinned at A, link `lp` slides on `kp`
    lr, lp, kr, kp, Jr, Jp = _oriented(step, "RRP")
    J2 = step.joints[1]
    A = st.point(kr, local_point(S, kr, Jr))
    phi_p = st.pose(kp)[1] + rel_angle(S, Jp, kp, lp)
    line = pair_line(S, Jp)
    # the P joint's point on lp and the known line through kp's joint point
    t_p = line.sb if line.b == lp else line.sa
    s_k = line.sa if line.a == kp else line.sb
    Pk = st.point(kp, s_k)
    phi_axis = st.pose(line.a)[1] if line.a == kp else phi_p
    ca, sa_ = cos_sin(phi_axis)
    w = perp(rotate(ca, sa_, line.w)) * -1.0  # slide direction (line.w is the normal)
    cp, sp = cos_sin(phi_p)
    tB = local_point(S, lp, J2)
    Q = Pk + rotate(cp, sp, tB - t_p)
    L1 = np.linalg.norm(local_point(S, lr, J2) - local_point(S, lr, Jr))
    p = dot(w, Q - A)
    cc = dot(Q - A, Q - A) - L1 ** 2
    disc = p ** 2 - cc
    if sigma is None or callable(sigma):
        lam0 = dot(w[0], S.mech.joint(J2).point - Q[0])
        s_file = 1.0 if lam0 + p[0] >= 0 else -1.0
        sigma = s_file if sigma is None else sigma(disc / L1 ** 2, s_file)
    disc = np.where((disc < 0) & (disc > -1e-12 * L1 ** 2), 0.0, disc)
    root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    lam = -p + sigma * root
    B = Q + lam[:, None] * w
    sr = local_point(S, lr, Jr)
    beta = np.arctan2(*(local_point(S, lr, J2) - sr)[::-1])
    phi_r = np.arctan2((B - A)[:, 1], (B - A)[:, 0]) - beta
    _pin(st, lr, A, sr, phi_r)
    _pin(st, lp, B, tB, phi_p)
    return sigma


def _step_RPR(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """RPR dyad: the slide line keeps its offset from both pivots."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    A = st.point(A_s, local_point(S, A_s, J1))
    C = st.point(B_s, local_point(S, B_s, J3))
    c = rel_angle(S, J2, b1, b2)  # phi_b2 - phi_b1
    line = pair_line(S, J2)
    n_loc = line.w if line.a == b1 else np.array([np.cos(c) * line.w[0] - np.sin(c) * line.w[1],
                                                  np.sin(c) * line.w[0] + np.cos(c) * line.w[1]])
    # n_loc: the slide normal in b1's frame
    sA, sP = local_point(S, b1, J1), local_point(S, b1, J2)
    tC, tP = local_point(S, b2, J3), local_point(S, b2, J2)
    cc, sc = np.cos(c), np.sin(c)
    Rc = np.array([[cc, -sc], [sc, cc]])
    e = float(n_loc @ (sP - sA) - n_loc @ (Rc @ (tP - tC)))
    d = C - A
    D = np.sqrt(dot(d, d))
    delta = np.arctan2(d[:, 1], d[:, 0])
    nu = np.arctan2(n_loc[1], n_loc[0])
    ratio = e / D
    if sigma is None or callable(sigma):
        phi0 = float(st.S.q0[3 * b1 + 2])
        s_file = 1.0 if _wrap(phi0 + nu - delta[0]) >= 0 else -1.0
        sigma = s_file if sigma is None else sigma(1.0 - ratio ** 2, s_file)
    ratio = np.where((np.abs(ratio) > 1) & (np.abs(ratio) < 1 + 1e-12), np.sign(ratio), ratio)
    ac = np.arccos(np.where(np.abs(ratio) <= 1, ratio, np.nan))
    phi1 = delta - nu + sigma * ac
    _pin(st, b1, A, sA, phi1)
    _pin(st, b2, C, tC, phi1 + c)
    return sigma


def _step_RPP(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """RPP / PPR dyad: orientations from the P pairs, position from two lines."""
    # orient as R(Jr) on link lr - P(J2) - P(Jp) on link lp sliding on kp
    lr, lp, kr, kp, Jr, Jp = _oriented(step, "RPP")
    J2 = step.joints[1]
    phi_p = st.pose(kp)[1] + rel_angle(S, Jp, kp, lp)
    phi_r = phi_p + rel_angle(S, J2, lp, lr)
    A = st.point(kr, local_point(S, kr, Jr))
    _pin(st, lr, A, local_point(S, lr, Jr), phi_r)
    w1, h1 = _line_eq(S, st, pair_line(S, J2), lp, phi_p, np.zeros(2))
    w2, h2 = _line_eq(S, st, pair_line(S, Jp), lp, phi_p, np.zeros(2))
    st.set(lp, _solve2(w1, h1, w2, h2), phi_p)
    return 1.0


def _step_PRP(S: PlanarSystem, st: PoseState, step: Step, u: np.ndarray, sigma: Sigma) -> float | np.ndarray:
    """PRP dyad: the intersection of two slide lines."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    phi1 = st.pose(A_s)[1] + rel_angle(S, J1, A_s, b1)
    phi2 = st.pose(B_s)[1] + rel_angle(S, J3, B_s, b2)
    sB, tB = local_point(S, b1, J2), local_point(S, b2, J2)
    w1, h1 = _line_eq(S, st, pair_line(S, J1), b1, phi1, sB)
    w2, h2 = _line_eq(S, st, pair_line(S, J3), b2, phi2, tB)
    B = _solve2(w1, h1, w2, h2)
    _pin(st, b1, B, sB, phi1)
    _pin(st, b2, B, tB, phi2)
    return 1.0


_STEP_KERNELS = {"drive_R": _step_drive_R, "drive_P": _step_drive_P, "RRR": _step_RRR, "RRP": _step_RRP,
                 "PRR": _step_RRP, "RPR": _step_RPR, "RPP": _step_RPP, "PPR": _step_RPP, "PRP": _step_PRP}


def _line_eq(S: PlanarSystem, st: "PoseState", con: Con, unknown: int, phi_u: np.ndarray,
             s_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A P pair's line condition ``n . (P_b - P_a) = 0`` as ``n . X = h`` for the unknown
    position ``X`` of the local point ``s_ref`` of a link whose angle ``phi_u`` is known."""
    cu, su = cos_sin(phi_u)
    if con.b == unknown:
        _, pa = st.pose(con.a)
        ca, sa_ = cos_sin(pa)
        n = rotate(ca, sa_, con.w)
        Pa = st.point(con.a, con.sa)
        return n, dot(n, Pa - rotate(cu, su, con.sb - s_ref))
    n = rotate(cu, su, con.w)
    Pb = st.point(con.b, con.sb)
    return n, dot(n, Pb - rotate(cu, su, con.sa - s_ref))


def _solve2(w1: np.ndarray, h1: np.ndarray, w2: np.ndarray, h2: np.ndarray) -> np.ndarray:
    """Solve ``w1 . X = h1``, ``w2 . X = h2`` (NaN where the two lines are parallel)."""
    det = w1[:, 0] * w2[:, 1] - w1[:, 1] * w2[:, 0]
    det = np.where(np.abs(det) < 1e-12, np.nan, det)
    return np.stack([(h1 * w2[:, 1] - h2 * w1[:, 1]) / det, (w1[:, 0] * h2 - w2[:, 0] * h1) / det], axis=1)


def solve_positions(S: PlanarSystem, plan: Plan, inputs: np.ndarray,
                    sigmas: list[float] | None = None) -> tuple[np.ndarray, list[float]]:
    """Poses ``q`` (N, n) for all inputs, NaN rows where a dyad cannot be assembled.

    Angles of links placed by a dyad come from ``atan2``; they are made continuous along
    each run of assembled inputs, and each run is shifted by whole turns to follow the
    previous one (links turned by a driver keep the input's own value).
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    st = PoseState(S, inputs.shape[0])
    out_sig = []
    for k, step in enumerate(plan.steps):
        out_sig.append(solve_step(S, st, step, inputs, None if sigmas is None else sigmas[k]))
    return pose_rows(S, st, plan), out_sig


def pose_rows(S: PlanarSystem, st: PoseState, plan: Plan) -> np.ndarray:
    """The solved state ``st`` as pose rows ``q`` (N, n: x, y, angle of every link), the
    dyads' link angles unwrapped to turn continuously from the file's configuration."""
    nl = len(S.links)
    q = np.empty((st.phi.shape[0], S.n))
    q[:, 0:3 * nl:3] = st.r[:, :, 0]
    q[:, 1:3 * nl:3] = st.r[:, :, 1]
    phi = st.phi.copy()
    dyad_links = sorted({i for step in plan.steps if not step.kind.startswith("drive") for i in step.links})
    ok = np.all(np.isfinite(phi), axis=1)
    if dyad_links and ok.any():
        phi[:, dyad_links] = continuous_angles(phi[:, dyad_links], S.q0[[3 * i + 2 for i in dyad_links]], ok)
    q[:, 2:3 * nl:3] = phi
    return q


@dataclass
class TrackedPositions:
    """Positions of a sweep on the drawn branch (see :func:`solve_tracked`).

    ``q`` (N, n) poses (NaN rows: not assembled); ``sigmas`` the assembly sign of every
    step per row (``None`` for steps without one); ``discs`` the normalised
    discriminant of every branched step per row; ``singular`` rows where a group is
    folded flat (rates undefined); ``events`` dead points, reassembly and singular
    crossings with their input refined on the group's discriminant (input units:
    radians for R, length for P).
    """

    q: np.ndarray
    sigmas: list
    discs: dict
    singular: np.ndarray
    events: list
