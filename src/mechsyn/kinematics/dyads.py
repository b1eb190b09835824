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
from typing import Any

import numpy as np

from mechsyn.kinematics.rates import batch_rates
from mechsyn.kinematics.sweep import Event
from mechsyn.kinematics.system import Con, PlanarSystem, _apply, _perp, _rot

__all__ = ["Plan", "decompose", "solve_positions", "solve_all", "fast_chain", "ChainResult"]


@dataclass(frozen=True)
class Step:
    kind: str                 # "drive_R", "drive_P", "RRR", "RRP", "RPR", "RPP", "PRP"
    links: tuple[int, ...]    # new links
    known: tuple[int, ...]    # known links used
    joints: tuple[str, ...]
    data: dict
    sigma: float = 1.0


@dataclass(frozen=True)
class Plan:
    steps: tuple[Step, ...]

    @property
    def closed_form_rates(self) -> bool:
        return all(s.kind in ("drive_R", "RRR") for s in self.steps)

    def describe(self) -> list[str]:
        return [f"{s.kind} ({', '.join(s.joints)})" for s in self.steps]


def _cons_of(S: PlanarSystem, jid: str) -> list[Con]:
    memo = _memo(S)
    key = ("cons", jid)
    out = memo.get(key)
    if out is None:
        out = memo[key] = [c for c in S.cons if c.joint == jid]
    return out


def _jtype(S: PlanarSystem, jid: str) -> str:
    return S.mech.joint(jid).type


def decompose(S: PlanarSystem) -> Plan | None:
    """Drivers and dyads in solving order, or None when the mechanism does not decompose."""
    mech = S.mech
    if any(c.kind in ("gear", "curve", "belt") or c.role in ("lock", "idle") for c in S.cons):
        return None
    known = {-1}
    steps: list[Step] = []
    used: set[str] = set()
    joints = {j.id: j for j in mech.joints}
    link_joints: dict[int, list[str]] = {}
    for j in mech.joints:
        for ln in j.links:
            link_joints.setdefault(S.index(ln), []).append(j.id)
    drivers = {d.joint for d in S.drivers}

    def ends(jid: str) -> tuple[int, int]:
        a, b = joints[jid].links
        return S.index(a), S.index(b)

    progress = True
    while progress and len(known) < len(S.links) + 1:
        progress = False
        for jid in drivers - used:
            a, b = ends(jid)
            if (a in known) == (b in known):
                continue
            k, new = (a, b) if a in known else (b, a)
            steps.append(Step("drive_" + _jtype(S, jid), (new,), (k,), (jid,), {}))
            known.add(new)
            used.add(jid)
            progress = True
        if progress:
            continue
        # dyads: b1, b2 unknown, J2 between them, J1: known-b1, J3: b2-known
        for b1 in range(len(S.links)):
            if b1 in known:
                continue
            j1s = [j for j in link_joints.get(b1, []) if j not in used and (set(ends(j)) - {b1}) <= known
                   and j not in drivers]
            if len(j1s) != 1:
                continue
            J1 = j1s[0]
            for J2 in link_joints.get(b1, []):
                if J2 in used or J2 == J1 or J2 in drivers:
                    continue
                a2, c2 = ends(J2)
                b2 = c2 if a2 == b1 else a2
                if b2 in known:
                    continue
                j3s = [j for j in link_joints.get(b2, []) if j not in used and j != J2
                       and (set(ends(j)) - {b2}) <= known and j not in drivers]
                if len(j3s) != 1:
                    continue
                J3 = j3s[0]
                types = "".join(_jtype(S, j) for j in (J1, J2, J3))
                if types not in ("RRR", "RRP", "PRR", "RPR", "RPP", "PPR", "PRP"):
                    continue  # PPP: not a dyad of a planar mechanism
                k1 = (set(ends(J1)) - {b1}).pop()
                k3 = (set(ends(J3)) - {b2}).pop()
                steps.append(Step(types, (b1, b2), (k1, k3), (J1, J2, J3), {}))
                known.update((b1, b2))
                used.update((J1, J2, J3))
                progress = True
                break
            if progress:
                break
        if not progress:
            progress = _double_joint_dyad(S, known, used, drivers, link_joints, ends, steps)
    if len(known) < len(S.links) + 1:
        return None
    if set(j.id for j in mech.joints) - used:
        return None  # closing constraints left over (redundant): Newton handles them
    return Plan(tuple(steps))


def _double_joint_dyad(S: PlanarSystem, known: set, used: set, drivers: set, link_joints: dict, ends,
                       steps: list) -> bool:
    """A dyad whose middle joint is a *double joint*: links ``b1`` and ``b2`` both pinned to
    a third link ``m`` at one point (two R pairs ``b1-m``, ``b2-m`` at the same place).

    The point is the intersection of the circles about ``b1``'s and ``b2``'s known joints,
    as in an RRR dyad; ``m`` is placed later through the pair ``b1-m`` (the pair ``b2-m``
    is then satisfied, being at the same point). Appends the step and returns True when
    one is found."""
    mech = S.mech
    pts = {j.id: np.asarray(j.point, float) for j in mech.joints}
    for b1 in range(len(S.links)):
        if b1 in known:
            continue
        j1s = [j for j in link_joints.get(b1, []) if j not in used and j not in drivers
               and (set(ends(j)) - {b1}) <= known]
        if len(j1s) != 1 or _jtype(S, j1s[0]) != "R":
            continue
        for J2a in link_joints.get(b1, []):
            if J2a in used or J2a in drivers or _jtype(S, J2a) != "R":
                continue
            m = (set(ends(J2a)) - {b1}).pop()
            if m in known:
                continue
            for J2b in link_joints.get(m, []):
                if J2b == J2a or J2b in used or J2b in drivers or _jtype(S, J2b) != "R":
                    continue
                b2 = (set(ends(J2b)) - {m}).pop()
                if b2 in known or b2 == b1 or np.abs(pts[J2a] - pts[J2b]).max() > 1e-9 * S.scale:
                    continue
                j3s = [j for j in link_joints.get(b2, []) if j not in used and j not in drivers and j != J2b
                       and (set(ends(j)) - {b2}) <= known]
                if len(j3s) != 1 or _jtype(S, j3s[0]) != "R":
                    continue
                J1, J3 = j1s[0], j3s[0]
                k1 = (set(ends(J1)) - {b1}).pop()
                k3 = (set(ends(J3)) - {b2}).pop()
                steps.append(Step("RRR", (b1, b2), (k1, k3), (J1, J2a, J3), {"double": J2b}))
                known.update((b1, b2))
                used.update((J1, J3, J2b))
                return True
    return False


# --------------------------------------------------------------------------- states
class _State:
    """Poses of the links known so far, for all N inputs."""

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
        c, sn = _rot(phi)
        return r + _apply(c, sn, s)

    def set(self, i: int, r: np.ndarray, phi: np.ndarray) -> None:
        self.r[:, i] = r
        self.phi[:, i] = phi


def _memo(S: PlanarSystem) -> dict:
    """Per-system cache of look-ups that depend only on the system (local joint points,
    constraints of a joint): a plan evaluated many times (events, drags) reuses them."""
    memo = S.__dict__.get("_dyads_memo")
    if memo is None:
        memo = {}
        object.__setattr__(S, "_dyads_memo", memo)
    return memo


def _local(S: PlanarSystem, i: int, jid: str) -> np.ndarray:
    memo = _memo(S)
    key = ("local", i, jid)
    out = memo.get(key)
    if out is None:
        j = S.mech.joint(jid)
        name = S.mech.ground if i < 0 else S.links[i]
        out = memo[key] = S.to_local(name, j.point)
    return out


def _rel_angle(S: PlanarSystem, jid: str, frm: int, to: int) -> float:
    """Constant ``phi_to - phi_from`` of a P joint between links frm and to."""
    con = next(c for c in _cons_of(S, jid) if c.kind == "angle" and c.role == "rotation")
    return con.c0 if (con.a, con.b) == (frm, to) else -con.c0


def _line(S: PlanarSystem, jid: str) -> Con:
    return next(c for c in _cons_of(S, jid) if c.kind == "line" and c.role == "pair")


def _wrap(x: np.ndarray) -> np.ndarray:
    return (x + np.pi) % (2 * np.pi) - np.pi


def _unwrap_rows(p: np.ndarray, inplace: bool = False) -> np.ndarray:
    """``np.unwrap(p, axis=-1)`` for angles whose steps stay below a whole turn (as those of
    ``atan2`` do): the whole turns removed are counted exactly (a step of exactly half a
    turn is kept, as ``np.unwrap`` keeps it); ``inplace``: into ``p`` itself."""
    out = p if inplace else np.array(p, float)
    if p.shape[-1] > 1:
        k = np.subtract(p[..., 1:], p[..., :-1])
        k /= 2 * np.pi
        np.rint(k, out=k)
        jumps = np.flatnonzero(k)
        if len(jumps) > 16:  # many turns: count them all at once
            np.cumsum(k, axis=-1, out=k)
            k *= 2 * np.pi
            out[..., 1:] -= k
        else:  # a few: each shifts the rest of its row
            o2, k2 = out.reshape(-1, out.shape[-1]), k.reshape(-1, k.shape[-1])
            for j in jumps.tolist():
                row, col = divmod(j, k2.shape[1])
                o2[row, col + 1:] -= 2 * np.pi * k2[row, col]
    return out


def _continuous_angles(phi: np.ndarray, ref: np.ndarray, ok: np.ndarray | None, split: int | None = None,
                       fresh: bool = False) -> np.ndarray:
    """Link angles made continuous along a sweep: start near the file's angles ``ref``,
    unwrap each run of assembled rows and keep the turn count across gaps (``phi`` (N,
    m), or (m, N) with ``ref`` (m, 1); ``ok`` None: every row assembled).

    ``split``: the sweep (assembled throughout) was run outwards from the drawn
    configuration, between rows ``split - 1`` and ``split``: both rows start near
    ``ref`` and the angles are unwrapped away from them (as two runs would be).
    ``fresh``: ``phi`` (m, N) is a work array the angles may be written into."""
    if ref.ndim == 1:
        return _continuous_angles(phi.T, ref[:, None], ok, split).T
    if ok is None or ok.all():  # one run: unwrap, then put the start row(s) next to ref
        block = _unwrap_rows(phi, inplace=fresh)
        parts = ((0, slice(None)),) if split is None else ((split, slice(split, None)), (split - 1, slice(0, split)))
        for row, rows in parts:  # the few start values on floats (the numbers of _wrap)
            for i, (a, b, r0) in enumerate(zip(phi[:, row].tolist(), block[:, row].tolist(), ref[:, 0].tolist())):
                near = r0 + ((a - r0 + math.pi) % (2 * math.pi) - math.pi)
                turns = round((b - near) / (2 * math.pi))
                if turns:
                    block[i, rows] -= 2 * math.pi * turns
        return block
    sub = ref + _wrap(phi - ref)
    idx = np.flatnonzero(ok)
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
    prev = None
    for run in runs:
        block = _unwrap_rows(sub[:, run])
        if prev is not None:
            block -= 2 * np.pi * np.round((block[:, :1] - prev) / (2 * np.pi))
        sub[:, run] = block
        prev = block[:, -1:]
    return sub


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _pin(st: _State, i: int, P: np.ndarray, s_local: np.ndarray, phi: np.ndarray) -> None:
    c, sn = _rot(phi)
    st.set(i, P - _apply(c, sn, s_local), phi)


def _solve_step(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """Solve one step in place; return its assembly sign (sigma) for the branch: ``sigma``
    given (a number or one per row), None (the drawn mode) or a chooser called with the
    normalised discriminant and the drawn mode."""
    kernel = _STEP_KERNELS.get(step.kind)
    if kernel is None:
        raise _NotHandled
    return kernel(S, st, step, u, sigma)


def _step_drive_R(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """A link turned by an R drive about a known link."""
    (new,), (k,), (jid,) = step.links, step.known, step.joints
    con = next(c for c in _cons_of(S, jid) if c.role == "drive")
    th = u[:, con.driver]
    _, phik = st.pose(k)
    phi = phik + th if con.b == new else phik - th
    P = st.point(k, _local(S, k, jid))
    _pin(st, new, P, _local(S, new, jid), phi)
    return 1.0


def _step_drive_P(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """A link slid by a P drive along a known link."""
    (new,), (k,), (jid,) = step.links, step.known, step.joints
    drive = next(c for c in _cons_of(S, jid) if c.role == "drive")
    line = _line(S, jid)
    val = u[:, drive.driver]
    if drive.a == k:
        ra, pa = st.pose(k)
        ca, sa_ = _rot(pa)
        w, n = _apply(ca, sa_, drive.w), _apply(ca, sa_, line.w)
        Pa = st.point(k, line.sa)
        Pb = ra + val[:, None] * w + n * _dot(n, Pa - ra)[:, None]
        _pin(st, new, Pb, drive.sb, pa + _rel_angle(S, jid, k, new))
    else:  # the new link carries the axis: O_a = u (u.P_b - s) + n (n.(P_b - A_a s_a))
        pa = st.pose(k)[1] + _rel_angle(S, jid, k, new)
        ca, sa_ = _rot(pa)
        w, n = _apply(ca, sa_, drive.w), _apply(ca, sa_, line.w)
        Pb = st.point(k, drive.sb)
        Oa = w * (_dot(w, Pb) - val)[:, None] + n * _dot(n, Pb - _apply(ca, sa_, line.sa))[:, None]
        st.set(new, Oa, pa)
    return 1.0


def _step_RRR(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """RRR dyad: the intersection of two circles."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    A = st.point(A_s, _local(S, A_s, J1))
    C = st.point(B_s, _local(S, B_s, J3))
    s1, s2 = _local(S, b1, J1), _local(S, b1, J2)
    t2, t3 = _local(S, b2, J2), _local(S, b2, J3)
    L1, L2 = np.linalg.norm(s2 - s1), np.linalg.norm(t2 - t3)
    d = C - A
    D2 = _dot(d, d)
    D = np.sqrt(D2)
    a = (L1 ** 2 - L2 ** 2 + D2) / (2 * D)
    h2 = L1 ** 2 - a ** 2
    if sigma is None or callable(sigma):
        s_file = 1.0 if _cross(d[0], (S.mech.joint(J2).point - A[0]))[()] >= 0 else -1.0
        sigma = s_file if sigma is None else sigma(h2 / L1 ** 2, s_file)
    h2 = np.where((h2 < 0) & (h2 > -1e-12 * L1 ** 2), 0.0, h2)
    h = np.sqrt(np.where(h2 >= 0, h2, np.nan))
    e = d / D[:, None]
    B = A + a[:, None] * e + (sigma * h)[:, None] * _perp(e)
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


def _step_RRP(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """RRP / PRR dyad: the intersection of a circle and a line."""
    # orient as R(J_r) - R(J2) - P(J_p): link `lr` pinned at A, link `lp` slides on `kp`
    lr, lp, kr, kp, Jr, Jp = _oriented(step, "RRP")
    J2 = step.joints[1]
    A = st.point(kr, _local(S, kr, Jr))
    phi_p = st.pose(kp)[1] + _rel_angle(S, Jp, kp, lp)
    line = _line(S, Jp)
    # the P joint's point on lp and the known line through kp's joint point
    t_p = line.sb if line.b == lp else line.sa
    s_k = line.sa if line.a == kp else line.sb
    Pk = st.point(kp, s_k)
    phi_axis = st.pose(line.a)[1] if line.a == kp else phi_p
    ca, sa_ = _rot(phi_axis)
    w = _perp(_apply(ca, sa_, line.w)) * -1.0  # slide direction (line.w is the normal)
    cp, sp = _rot(phi_p)
    tB = _local(S, lp, J2)
    Q = Pk + _apply(cp, sp, tB - t_p)
    L1 = np.linalg.norm(_local(S, lr, J2) - _local(S, lr, Jr))
    p = _dot(w, Q - A)
    cc = _dot(Q - A, Q - A) - L1 ** 2
    disc = p ** 2 - cc
    if sigma is None or callable(sigma):
        lam0 = _dot(w[0], S.mech.joint(J2).point - Q[0])
        s_file = 1.0 if lam0 + p[0] >= 0 else -1.0
        sigma = s_file if sigma is None else sigma(disc / L1 ** 2, s_file)
    disc = np.where((disc < 0) & (disc > -1e-12 * L1 ** 2), 0.0, disc)
    root = np.sqrt(np.where(disc >= 0, disc, np.nan))
    lam = -p + sigma * root
    B = Q + lam[:, None] * w
    sr = _local(S, lr, Jr)
    beta = np.arctan2(*(_local(S, lr, J2) - sr)[::-1])
    phi_r = np.arctan2((B - A)[:, 1], (B - A)[:, 0]) - beta
    _pin(st, lr, A, sr, phi_r)
    _pin(st, lp, B, tB, phi_p)
    return sigma


def _step_RPR(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """RPR dyad: the slide line keeps its offset from both pivots."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    A = st.point(A_s, _local(S, A_s, J1))
    C = st.point(B_s, _local(S, B_s, J3))
    c = _rel_angle(S, J2, b1, b2)  # phi_b2 - phi_b1
    line = _line(S, J2)
    n_loc = line.w if line.a == b1 else np.array([np.cos(c) * line.w[0] - np.sin(c) * line.w[1],
                                                  np.sin(c) * line.w[0] + np.cos(c) * line.w[1]])
    # n_loc: the slide normal in b1's frame
    sA, sP = _local(S, b1, J1), _local(S, b1, J2)
    tC, tP = _local(S, b2, J3), _local(S, b2, J2)
    cc, sc = np.cos(c), np.sin(c)
    Rc = np.array([[cc, -sc], [sc, cc]])
    e = float(n_loc @ (sP - sA) - n_loc @ (Rc @ (tP - tC)))
    d = C - A
    D = np.sqrt(_dot(d, d))
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


def _step_RPP(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """RPP / PPR dyad: orientations from the P pairs, position from two lines."""
    # orient as R(Jr) on link lr - P(J2) - P(Jp) on link lp sliding on kp
    lr, lp, kr, kp, Jr, Jp = _oriented(step, "RPP")
    J2 = step.joints[1]
    phi_p = st.pose(kp)[1] + _rel_angle(S, Jp, kp, lp)
    phi_r = phi_p + _rel_angle(S, J2, lp, lr)
    A = st.point(kr, _local(S, kr, Jr))
    _pin(st, lr, A, _local(S, lr, Jr), phi_r)
    w1, h1 = _line_eq(S, st, _line(S, J2), lp, phi_p, np.zeros(2))
    w2, h2 = _line_eq(S, st, _line(S, Jp), lp, phi_p, np.zeros(2))
    st.set(lp, _solve2(w1, h1, w2, h2), phi_p)
    return 1.0


def _step_PRP(S: PlanarSystem, st: _State, step: Step, u: np.ndarray, sigma: Any) -> Any:
    """PRP dyad: the intersection of two slide lines."""
    A_s, B_s = step.known
    b1, b2 = step.links
    J1, J2, J3 = step.joints
    phi1 = st.pose(A_s)[1] + _rel_angle(S, J1, A_s, b1)
    phi2 = st.pose(B_s)[1] + _rel_angle(S, J3, B_s, b2)
    sB, tB = _local(S, b1, J2), _local(S, b2, J2)
    w1, h1 = _line_eq(S, st, _line(S, J1), b1, phi1, sB)
    w2, h2 = _line_eq(S, st, _line(S, J3), b2, phi2, tB)
    B = _solve2(w1, h1, w2, h2)
    _pin(st, b1, B, sB, phi1)
    _pin(st, b2, B, tB, phi2)
    return 1.0


_STEP_KERNELS = {"drive_R": _step_drive_R, "drive_P": _step_drive_P, "RRR": _step_RRR, "RRP": _step_RRP,
                 "PRR": _step_RRP, "RPR": _step_RPR, "RPP": _step_RPP, "PPR": _step_RPP, "PRP": _step_PRP}



def _line_eq(S: PlanarSystem, st: "_State", con: Con, unknown: int, phi_u: np.ndarray,
             s_ref: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A P pair's line condition ``n . (P_b - P_a) = 0`` as ``n . X = h`` for the unknown
    position ``X`` of the local point ``s_ref`` of a link whose angle ``phi_u`` is known."""
    cu, su = _rot(phi_u)
    if con.b == unknown:
        _, pa = st.pose(con.a)
        ca, sa_ = _rot(pa)
        n = _apply(ca, sa_, con.w)
        Pa = st.point(con.a, con.sa)
        return n, _dot(n, Pa - _apply(cu, su, con.sb - s_ref))
    n = _apply(cu, su, con.w)
    Pb = st.point(con.b, con.sb)
    return n, _dot(n, Pb - _apply(cu, su, con.sa - s_ref))


def _solve2(w1: np.ndarray, h1: np.ndarray, w2: np.ndarray, h2: np.ndarray) -> np.ndarray:
    """Solve ``w1 . X = h1``, ``w2 . X = h2`` (NaN where the two lines are parallel)."""
    det = w1[:, 0] * w2[:, 1] - w1[:, 1] * w2[:, 0]
    det = np.where(np.abs(det) < 1e-12, np.nan, det)
    return np.stack([(h1 * w2[:, 1] - h2 * w1[:, 1]) / det, (w1[:, 0] * h2 - w2[:, 0] * h1) / det], axis=1)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


class _NotHandled(Exception):
    pass


def solve_positions(S: PlanarSystem, plan: Plan, inputs: np.ndarray,
                    sigmas: list[float] | None = None) -> tuple[np.ndarray, list[float]]:
    """Poses ``q`` (N, n) for all inputs, NaN rows where a dyad cannot be assembled.

    Angles of links placed by a dyad come from ``atan2``; they are made continuous along
    each run of assembled inputs, and each run is shifted by whole turns to follow the
    previous one (links turned by a driver keep the input's own value).
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    st = _State(S, inputs.shape[0])
    out_sig = []
    for k, step in enumerate(plan.steps):
        out_sig.append(_solve_step(S, st, step, inputs, None if sigmas is None else sigmas[k]))
    return _pose_rows(S, st, plan), out_sig


def _pose_rows(S: PlanarSystem, st: _State, plan: Plan) -> np.ndarray:
    """The solved state as pose rows ``q`` (x, y, angle of every link), the dyads' link
    angles unwrapped to turn continuously from the file's configuration."""
    nl = len(S.links)
    q = np.empty((st.phi.shape[0], S.n))
    q[:, 0:3 * nl:3] = st.r[:, :, 0]
    q[:, 1:3 * nl:3] = st.r[:, :, 1]
    phi = st.phi.copy()
    dyad_links = sorted({i for step in plan.steps if not step.kind.startswith("drive") for i in step.links})
    ok = np.all(np.isfinite(phi), axis=1)
    if dyad_links and ok.any():
        phi[:, dyad_links] = _continuous_angles(phi[:, dyad_links], S.q0[[3 * i + 2 for i in dyad_links]], ok)
    q[:, 2:3 * nl:3] = phi
    return q


def solve_all(S: PlanarSystem, plan: Plan, inputs: np.ndarray, speeds: np.ndarray,
              chunk: int = 20000, tracked: "TrackedPositions | None" = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities, accelerations (N, n) for all inputs (closed form where possible).

    ``tracked``: the sweep's positions and modes from :func:`solve_tracked` (the drawn
    branch followed through bifurcations); without it every group keeps its drawn mode.
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    if plan.closed_form_rates:
        sig = tracked.sigmas if tracked is not None else None
        return _poses_from_chain(S, plan, inputs, fast_chain(S, plan, inputs, speeds, rates=True, sigmas=sig))
    q = tracked.q if tracked is not None else solve_positions(S, plan, inputs)[0]
    ok = np.all(np.isfinite(q), axis=1)
    qd = np.full_like(q, np.nan)
    qdd = np.full_like(q, np.nan)
    idx = np.flatnonzero(ok)
    for start in range(0, len(idx), chunk):
        sel = idx[start:start + chunk]
        qd[sel], qdd[sel] = batch_rates(S, q[sel], speeds)
    return q, qd, qdd


def _poses_from_chain(S: PlanarSystem, plan: Plan, U: np.ndarray, r: "ChainResult") -> tuple:
    """Pose coordinates (origin, angle) and their rates from a chain's anchors and rotations."""
    with np.errstate(invalid="ignore", over="ignore"):  # inf rates at singular rows become NaN
        return _poses_from_chain_(S, plan, U, r)


def _drive_links(S: PlanarSystem, plan: Plan) -> dict[int, tuple[int, float]]:
    """Links turned by a frame driver: link -> (driver index, sign of the input), kept
    in the system's memo for the plan (a sweep's angles of these links are the inputs)."""
    memo = _memo(S)
    hit = memo.get(("drive_links", id(plan)))
    if hit is not None and hit[0] is plan:
        return hit[1]
    out = {}
    for step in plan.steps:
        if step.kind == "drive_R" and step.known[0] < 0:
            con = next(c for c in _cons_of(S, step.joints[0]) if c.role == "drive")
            out[step.links[0]] = (con.driver, 1.0 if con.b == step.links[0] else -1.0)
    memo[("drive_links", id(plan))] = (plan, out)
    return out


def _anchor_states(r: "ChainResult", jids: list[str], N: int) -> tuple:
    """Position, velocity, acceleration of the anchor joint of every link in the first
    ``N`` rows, each (2, N, nl): one take from the chain's buffers when it has them."""
    if r.buffers is not None:
        index, bufs = r.buffers
        idx = [index[j] for j in jids]
        return tuple(b[idx, :, :N].transpose(1, 2, 0) for b in bufs)
    out = (np.stack([d[j][:N] for j in jids], axis=2) for d in (r.points, r.velocities, r.accelerations))
    return tuple(a.transpose(1, 0, 2) for a in out)


def _poses_from_chain_(S: PlanarSystem, plan: Plan, U: np.ndarray, r: "ChainResult") -> tuple:
    N, nl = U.shape[0], r.cos.shape[1]
    # component-major buffers (returned transposed): every column written is contiguous
    q = np.empty((S.n, N)).T
    qd = np.empty((S.n, N)).T
    qdd = np.empty((S.n, N)).T
    if nl:  # all links at once: (N, nl) arrays, the anchors' states gathered per link
        jids = [r.anchor[i][0] for i in range(nl)]
        msa = -np.array([r.anchor[i][1] for i in range(nl)], float).reshape(nl, 2)  # r - P_anchor, local
        c, s = r.cos[:N], r.sin[:N]
        relx = c * msa[:, 0]
        relx -= s * msa[:, 1]
        rely = s * msa[:, 0]
        rely += c * msa[:, 1]
        P, V, A = _anchor_states(r, jids, N)  # (2, N, nl)
        w, al = r.omega[:N], r.alpha[:N]
        x, y = slice(0, 3 * nl, 3), slice(1, 3 * nl, 3)  # written in place (no temporaries)
        np.add(P[0], relx, out=q[:, x])
        np.add(P[1], rely, out=q[:, y])
        wx, wy = w * relx, w * rely
        np.subtract(V[0], wy, out=qd[:, x])
        np.add(V[1], wx, out=qd[:, y])
        ax = np.subtract(A[0], w * wx, out=qdd[:, x])
        ax -= al * rely
        ay = np.subtract(A[1], w * wy, out=qdd[:, y])
        ay += al * relx
        qd[:, 2:3 * nl:3], qdd[:, 2:3 * nl:3] = w, al
    ok = np.all(np.isfinite(r.cos[:N]), axis=1)
    _link_angles(S, plan, U, r.cos.T, r.sin.T, ok, q.T[2:3 * nl:3])
    if not ok.all():
        for a in (q, qd, qdd):
            a[~ok] = np.nan
    # at a singular configuration (e.g. folded flat) the position exists but the rates
    # do not: NaN rates, reported as "singular" events by the caller
    bad = ~(np.all(np.isfinite(qd), axis=1) & np.all(np.isfinite(qdd), axis=1))
    if bad.any():
        qd[bad] = np.nan
        qdd[bad] = np.nan
    return q, qd, qdd


def _link_angles(S: PlanarSystem, plan: Plan, U: np.ndarray, cos: np.ndarray, sin: np.ndarray,
                 ok: np.ndarray | None, out: np.ndarray, split: int | None = None) -> None:
    """Continuous angles of the chain's links into ``out`` (nl, N) from their rotations
    ``cos``, ``sin`` (nl, N or more rows): the links of frame drivers take the input
    itself, the others ``atan2`` made continuous (``ok`` None: every row assembled;
    ``split``: see :func:`_continuous_angles`)."""
    drive_links, others, ref = _angle_plan(S, plan)
    N = out.shape[1]
    for i, (k, sgn) in drive_links.items():
        np.multiply(U[:N, k], sgn, out=out[i])
    if others:  # atan2 only for the links not driven directly
        ang = np.arctan2(sin[others, :N], cos[others, :N])
        if ok is None or ok.any():
            ang = _continuous_angles(ang, ref, ok, split, fresh=True)
        out[others] = ang


def _angle_plan(S: PlanarSystem, plan: Plan) -> tuple:
    """The links turned by frame drivers, the others and their drawn angles (m, 1), kept
    with the system."""
    memo = _memo(S)
    hit = memo.get(("angles", id(plan)))
    if hit is None or hit[0] is not plan:
        drive_links = _drive_links(S, plan)
        others = [i for i in range(len(S.links)) if i not in drive_links]
        hit = memo[("angles", id(plan))] = (plan, (drive_links, others, S.q0[[3 * i + 2 for i in others]][:, None]))
    return hit[1]


# --------------------------------------------------------------------------- fast chains
@dataclass
class ChainResult:
    """Joint points (and their rates) and link rotations for driver-R + RRR chains.

    ``points[j]``: (N, 2) position of joint ``j`` (on its second moving link);
    ``velocities[j]``, ``accelerations[j]`` likewise (when rates were asked for);
    ``cos, sin, omega, alpha``: (N, n_links) rotation of every moving link and its rates.
    """

    points: dict[str, np.ndarray]
    velocities: dict[str, np.ndarray] | None
    accelerations: dict[str, np.ndarray] | None
    cos: np.ndarray
    sin: np.ndarray
    omega: np.ndarray | None
    alpha: np.ndarray | None
    anchor: dict[int, tuple[str, np.ndarray]]
    #: ``(index, buffers)``: the joints' row in the (joints, 2, N) buffers behind
    #: ``points`` (and ``velocities``, ``accelerations``), when they are laid out so
    buffers: tuple | None = None

    def rows(self, rows: slice) -> "ChainResult":
        """The rows ``rows`` of the result (views)."""
        def part(d: dict | None) -> dict | None:
            return None if d is None else {j: v[rows] for j, v in d.items()}

        def arr(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a[rows]

        bufs = None if self.buffers is None else (self.buffers[0], tuple(b[:, :, rows] for b in self.buffers[1]))
        return ChainResult(part(self.points), part(self.velocities), part(self.accelerations), arr(self.cos),
                           arr(self.sin), arr(self.omega), arr(self.alpha), self.anchor, bufs)


def chain_supported(plan: Plan | None) -> bool:
    return plan is not None and plan.closed_form_rates


def fast_chain(S: PlanarSystem, plan: Plan, U: np.ndarray, speeds: np.ndarray | None = None,
               rates: bool = False, chunk: int = 1 << 13, joints: list[str] | None = None,
               rotations: bool = True, sigmas: list | None = None) -> ChainResult:
    """Closed-form positions (and rates) of a driver-R + RRR chain, without angles.

    Every link is carried by an *anchor* (the joint that placed it: its position,
    velocity, acceleration) and its rotation ``(cos phi, sin phi)``, computed only when
    a point off the joints is asked for, so no ``atan2`` or trigonometric call is made
    except for the input angles. RRR: ``B = A + f d + sigma g R90 d`` with ``d = C - A``,
    ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)``, ``g = sqrt(L1^2 / |d|^2 - f^2)``; rates:
    ``omega_1 = (v_C - v_A) . e2 / (e1 x e2)``, ``omega_2 = (v_C - v_A) . e1 / (e1 x e2)``
    and likewise for the accelerations. The work is done
    in chunks that stay in the processor's cache. ``sigmas``: the assembly sign of every
    step per input row (from :func:`solve_tracked`); default: the drawn modes.
    """
    U = np.atleast_2d(np.asarray(U, float))
    N = U.shape[0]
    nl = len(S.links)
    speeds = np.ones(U.shape[1]) if speeds is None else np.asarray(speeds, float)
    want = joints if joints is not None else [j.id for j in S.mech.joints]
    prog, anchor = _chain_program(S, plan, sigmas)
    # outputs stored component-major ((2, N) and (nl, N) buffers, returned transposed) so
    # that every chunk writes contiguous memory
    # outputs stored component-major (one (joints, 2, N) buffer per kind and (nl, N)
    # buffers, returned transposed) so that every chunk writes contiguous memory and the
    # anchors of all links are gathered in one take
    index = {j: k for k, j in enumerate(want)}
    bufs = tuple(np.empty((len(want), 2, N)) for _ in range(3 if rates else 1))
    out = ChainResult({j: bufs[0][k].T for j, k in index.items()},
                      {j: bufs[1][k].T for j, k in index.items()} if rates else None,
                      {j: bufs[2][k].T for j, k in index.items()} if rates else None,
                      np.empty((nl, N)).T if rotations else None, np.empty((nl, N)).T if rotations else None,
                      np.empty((nl, N)).T if rates else None, np.empty((nl, N)).T if rates else None, anchor,
                      (index, bufs))
    fixed = {j.id: j.point for j in S.mech.joints}
    filled: set[str] = set()
    with np.errstate(invalid="ignore", divide="ignore"):
        for start in range(0, N, chunk):
            sl = slice(start, min(N, start + chunk))
            ch = _Chunk(S, anchor, rates, out, sl)
            for op in prog:
                if op[0] == "drive":
                    ch.drive(op, U[sl], speeds, fixed)
                else:
                    ch.rrr(op, want)
            ch.write(nl, want, rotations, filled)
    return out


def _chain_program(S: PlanarSystem, plan: Plan, sigmas: list | None) -> tuple[list, dict]:
    """The chain's steps as kernels' arguments, and every link's anchor joint (built once
    per system and plan; the signs ``sigmas`` put in per call)."""
    memo = _memo(S)
    key = ("chain", id(plan))
    if key not in memo:
        memo[key] = _chain_program_(S, plan)
    prog, anchor = memo[key]
    if sigmas is None:
        return prog, anchor
    out = []
    for op in prog:
        sg = sigmas[op[1]] if op[0] == "RRR" else None
        if isinstance(sg, np.ndarray):
            op = op[:7] + (np.asarray(sg, float),) + op[8:]
        elif callable(sg):
            op = op[:7] + ((sg, (op[5] ** 0.5, op[6] ** 0.5), S.mech.joint(op[4][1]).point),) + op[8:]
        out.append(op)
    return out, anchor


def _chain_program_(S: PlanarSystem, plan: Plan) -> tuple[list, dict]:
    prog = []
    anchor: dict[int, tuple[str, np.ndarray]] = {}
    for si, step in enumerate(plan.steps):
        if step.kind == "drive_R":
            (new,), (k,), (jid,) = step.links, step.known, step.joints
            con = next(c for c in _cons_of(S, jid) if c.role == "drive")
            sgn = 1.0 if con.b == new else -1.0
            anchor[new] = (jid, _local(S, new, jid))
            prog.append(("drive", new, k, jid, con.driver, sgn))
            continue
        (k1, k3), (b1, b2), (J1, J2, J3) = step.known, step.links, step.joints
        s1, s2 = _local(S, b1, J1), _local(S, b1, J2)
        t2, t3 = _local(S, b2, J2), _local(S, b2, J3)
        L1s, L2s = float(np.sum((s2 - s1) ** 2)), float(np.sum((t2 - t3) ** 2))
        A0, B0, C0 = (S.mech.joint(j).point for j in (J1, J2, J3))
        sigma = 1.0 if _cross(C0 - A0, B0 - A0) >= 0 else -1.0
        anchor[b1] = (J1, s1)
        anchor[b2] = (J3, t3)
        prog.append(("RRR", si, (k1, k3), (b1, b2), (J1, J2, J3), L1s, L2s, sigma,
                     (s2 - s1) / L1s, (t2 - t3) / L2s))
    return prog, anchor


def circle_circle(dx: np.ndarray, dy: np.ndarray, L1s: float, L2s: float) -> tuple:
    """The RRR dyad's intersection of the circles ``|B - A| = L1``, ``|B - C| = L2`` with
    ``d = C - A = (dx, dy)``: ``1/|d|^2``, ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)`` and
    ``g^2 = L1^2 / |d|^2 - f^2`` (``B = A + f d + sigma g R90 d``; ``g^2 |d|^2 / L1^2`` is
    the group's normalised discriminant)."""
    inv = dx * dx
    inv += dy * dy
    np.divide(1.0, inv, out=inv)
    f = inv * (0.5 * (L1s - L2s))
    f += 0.5
    g = inv * L1s
    g -= f * f
    return inv, f, g


class _Chunk:
    """One chunk of rows of :func:`fast_chain`: the joints' states and the links'
    rotations and rates found so far, and the kernels that extend them."""

    def __init__(self, S: PlanarSystem, anchor: dict, rates: bool, out: "ChainResult", sl: slice) -> None:
        self.S, self.anchor, self.rates, self.out, self.sl = S, anchor, rates, out, sl
        self.written: set[str] = set()    # joints whose outputs were computed in place
        self.rot: dict[int, tuple] = {}   # link -> ("cs", c, s) or ("vec", ex, ey, local / L^2)
        self.rate: dict[int, tuple] = {}  # link -> (omega, alpha)
        self.jst: dict[str, tuple] = {}   # joint -> (Px, Py[, Vx, Vy, Ax, Ay])

    def rotation(self, i: int) -> tuple:
        r = self.rot[i]
        if r[0] == "vec":  # from a joint-to-joint vector e and its local vector / L^2
            _, ex, ey, bv = r
            c = ex * bv[0] + ey * bv[1]
            sn = ey * bv[0] - ex * bv[1]
            self.rot[i] = ("cs", c, sn)
            return c, sn
        return r[1], r[2]

    def point(self, i: int, jid: str | None, s: np.ndarray) -> tuple:
        """State of the point ``s`` (local) of link ``i`` (of joint ``jid`` when known)."""
        if jid is not None and jid in self.jst:
            return self.jst[jid]
        if i < 0:
            return (s[0], s[1], 0.0, 0.0, 0.0, 0.0) if self.rates else (s[0], s[1])
        ajid, sa = self.anchor[i]
        A = self.jst[ajid]
        dxl, dyl = float(s[0] - sa[0]), float(s[1] - sa[1])
        c, sn = self.rotation(i)
        if dyl == 0.0:
            dx, dy = c * dxl, sn * dxl
        elif dxl == 0.0:
            dx, dy = sn * -dyl, c * dyl
        else:
            dx = c * dxl - sn * dyl
            dy = sn * dxl + c * dyl
        if not self.rates:
            return (A[0] + dx, A[1] + dy)
        w, al = self.rate[i]
        w2 = w * w
        wdx, wdy = w * dx, w * dy
        if isinstance(al, float) and al == 0.0:  # a driver at constant speed
            return (A[0] + dx, A[1] + dy, A[2] - wdy, A[3] + wdx, A[4] - w * wdx, A[5] - w * wdy)
        return (A[0] + dx, A[1] + dy, A[2] - wdy, A[3] + wdx,
                A[4] - al * dy - w2 * dx, A[5] + al * dx - w2 * dy)

    def drive(self, op: tuple, U: np.ndarray, speeds: np.ndarray, fixed: dict) -> None:
        _, new, k, jid, di, sgn = op
        th = U[:, di]
        ct, st = np.cos(th), np.sin(th)
        if sgn < 0:
            st = -st
        if k < 0:
            self.rot[new] = ("cs", ct, st)
            if self.rates:
                self.rate[new] = (sgn * speeds[di], 0.0)
            P = fixed[jid]
            self.jst[jid] = (P[0], P[1], 0.0, 0.0, 0.0, 0.0) if self.rates else (P[0], P[1])
        else:
            ck, sk = self.rotation(k)
            self.rot[new] = ("cs", ck * ct - sk * st, sk * ct + ck * st)
            if self.rates:
                self.rate[new] = (self.rate[k][0] + sgn * speeds[di], self.rate[k][1])
            self.jst[jid] = self.point(k, jid, _local(self.S, k, jid))

    def rrr(self, op: tuple, want: list) -> None:
        """The RRR kernel: ``B = A + f d + sigma g R90 d`` (see :func:`fast_chain`)."""
        _, si, (k1, k3), (b1, b2), (J1, J2, J3), L1s, L2s, sigma, bv1, bv2 = op
        S, sl, jst = self.S, self.sl, self.jst
        A = self.point(k1, J1, _local(S, k1, J1))
        C = self.point(k3, J3, _local(S, k3, J3))
        jst[J1], jst[J3] = A, C
        dx = C[0] - A[0]
        dy = C[1] - A[1]
        inv, f, g = circle_circle(dx, dy, L1s, L2s)
        if isinstance(sigma, tuple):  # a chooser: the signs from the discriminant of _solve_step
            sigma = self._choose(sigma, A, dx, dy, inv)
        np.maximum(g, 0.0, out=g, where=g > -1e-12)
        np.sqrt(g, out=g)
        if isinstance(sigma, np.ndarray):
            g *= sigma[sl]
        elif sigma < 0:
            np.negative(g, out=g)
        e1x = f * dx
        e1x -= g * dy
        e1y = f * dy
        e1y += g * dx
        pos = self.out.points
        if J2 in pos:  # straight into the output buffers
            Bx = np.add(e1x, A[0], out=pos[J2][sl, 0])
            By = np.add(e1y, A[1], out=pos[J2][sl, 1])
            self.written.add(J2)
        else:
            Bx = e1x + A[0]
            By = e1y + A[1]
        e2x = Bx - C[0]
        e2y = By - C[1]
        self.rot[b1] = ("vec", e1x, e1y, bv1)
        self.rot[b2] = ("vec", e2x, e2y, bv2)
        if self.rates:
            jst[J2] = self._rrr_rates(A, C, (e1x, e1y, e2x, e2y), (Bx, By), (b1, b2), J2)
        else:
            jst[J2] = (Bx, By)

    def _choose(self, chooser: tuple, A: tuple, dx: np.ndarray, dy: np.ndarray, inv: np.ndarray) -> np.ndarray:
        """Signs of an RRR group from its chooser (``solve_tracked_rates``), given the
        discriminant ``h^2 / L1^2`` as :func:`_solve_step` computes it (the same numbers,
        so the same decisions) and the drawn mode read at the first row."""
        choose, (L1, L2), B0 = chooser
        D2 = 1.0 / inv
        a = (L1 ** 2 - L2 ** 2 + D2) / (2 * np.sqrt(D2))
        h2 = L1 ** 2 - a ** 2
        ax, ay = (float(np.ravel(c)[0]) for c in A[:2])  # a frame joint's are numbers
        s_file = 1.0 if dx[0] * (B0[1] - ay) - dy[0] * (B0[0] - ax) >= 0 else -1.0
        return choose(h2 / L1 ** 2, s_file)

    def _rrr_rates(self, A: tuple, C: tuple, e: tuple, B: tuple, links: tuple, J2: str) -> tuple:
        """Rates of an RRR dyad: ``omega_1 = (v_C - v_A) . e2 / (e1 x e2)``,
        ``omega_2 = (v_C - v_A) . e1 / (e1 x e2)``, and likewise the accelerations."""
        e1x, e1y, e2x, e2y = e
        den = e1x * e2y
        den -= e1y * e2x
        np.divide(1.0, den, out=den)
        dvx, dvy = C[2] - A[2], C[3] - A[3]
        w1 = dvx * e2x
        w1 += dvy * e2y
        w1 *= den
        w2 = dvx * e1x
        w2 += dvy * e1y
        w2 *= den
        w1s, w2s = w1 * w1, w2 * w2
        dax = C[4] - A[4]
        dax -= w2s * e2x
        dax += w1s * e1x
        day = C[5] - A[5]
        day -= w2s * e2y
        day += w1s * e1y
        a1 = dax * e2x
        a1 += day * e2y
        a1 *= den
        a2 = dax * e1x
        a2 += day * e1y
        a2 *= den
        self.rate[links[0]], self.rate[links[1]] = (w1, a1), (w2, a2)
        sl, o = self.sl, self.out
        outs = ((o.velocities[J2][sl, 0], o.velocities[J2][sl, 1], o.accelerations[J2][sl, 0],
                 o.accelerations[J2][sl, 1]) if J2 in o.points else (None,) * 4)
        VBx = np.subtract(A[2], w1 * e1y, out=outs[0])
        VBy = np.add(A[3], w1 * e1x, out=outs[1])
        ABx = np.subtract(A[4], a1 * e1y, out=outs[2])
        ABx -= w1s * e1x
        ABy = np.add(A[5], a1 * e1x, out=outs[3])
        ABy -= w1s * e1y
        return (B[0], B[1], VBx, VBy, ABx, ABy)

    def write(self, nl: int, want: list, rotations: bool, filled: set) -> None:
        """The chunk's rotations, rates and joint states into the outputs."""
        o, sl, rates = self.out, self.sl, self.rates
        if rotations:
            for i in range(nl):
                o.cos[sl, i], o.sin[sl, i] = self.rotation(i)
        if rates:
            for i in range(nl):
                o.omega[sl, i], o.alpha[sl, i] = self.rate[i]
        for jid in want:
            if jid in self.written or jid in filled:
                continue
            if jid in self.jst:
                P = self.jst[jid]
                if not isinstance(P[0], np.ndarray):  # a point of the frame: fill once
                    o.points[jid][:, 0], o.points[jid][:, 1] = P[0], P[1]
                    if rates:
                        o.velocities[jid][:] = 0.0
                        o.accelerations[jid][:] = 0.0
                    filled.add(jid)
                    continue
            else:
                j = self.S.mech.joint(jid)
                side = self.S.index(j.links[1]) if self.S.index(j.links[1]) >= 0 else self.S.index(j.links[0])
                P = self.point(side, None, _local(self.S, side, jid))
            o.points[jid][sl, 0], o.points[jid][sl, 1] = P[0], P[1]
            if rates:
                o.velocities[jid][sl, 0], o.velocities[jid][sl, 1] = P[2], P[3]
                o.accelerations[jid][sl, 0], o.accelerations[jid][sl, 1] = P[4], P[5]


# --------------------------------------------------------------------------- branches
#: Kinds of group with two assembly modes (a sign ``sigma`` chooses one).
BRANCHED = ("RRR", "RRP", "PRR", "RPR")
#: Normalised discriminant below which a group counts as folded (tangent circles,
#: collinear links): its rates there are not defined.
SINGULAR_DISC = 1e-12
#: Relative size of the negative discriminant still taken as zero (round-off).
_ZERO_DISC = 1e-12


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


def _shifted_start(S: PlanarSystem, u0: np.ndarray, u_first: np.ndarray) -> np.ndarray:
    """The first input moved by whole turns (R inputs) to the value nearest the drawn one."""
    out = np.array(u_first, float)
    for k, d in enumerate(S.drivers):
        if d.type == "R":  # a decision per driver: on floats
            out[k] -= 2 * math.pi * round((float(u_first[k]) - float(u0[k])) / (2 * math.pi))
    return out


def _connecting_path(S: PlanarSystem, u0: np.ndarray, u1: np.ndarray, max_rows: int = 4000) -> np.ndarray:
    """Inputs from the drawn values ``u0`` towards ``u1`` (excluded) in steps of at most
    1 degree (R) or 1 % of the mechanism's size (P)."""
    steps = (abs(float(b) - float(a)) / (math.radians(1.0) if d.type == "R" else 0.01 * S.scale)
             for a, b, d in zip(u0, u1, S.drivers))
    n = int(min(max_rows, max(1, math.ceil(max(steps)))))
    if n == 1:  # the drawn values themselves (t = 0)
        return np.array(u0, float)[None, :]
    t = np.arange(n) / n
    return u0[None, :] + t[:, None] * (u1 - u0)[None, :]


def _regular_rows(S: PlanarSystem, U: np.ndarray, split: int | None) -> np.ndarray:
    """The rows ``U`` followed by the connecting paths from the drawn input values to the
    sweep (to rows ``split`` and ``split - 1`` when the drawn values lie between them,
    else to row 0), for :func:`mechsyn.kinematics.regular.regular_sweep`."""
    u0 = np.array([d.assembled for d in S.drivers], float)
    ends = [0] if split is None else [split, split - 1]
    return np.concatenate([U] + [_connecting_path(S, u0, _shifted_start(S, u0, U[e])) for e in ends])


#: Smallest normalised discriminant of every group over a sweep for which
#: :func:`mechsyn.kinematics.regular.regular_sweep` answers (below it :func:`solve_tracked` looks for folds and
#: change points: its candidates are local minima under 0.05).
REGULAR_DISC = 0.05 + 1e-9


def solve_tracked(S: PlanarSystem, plan: Plan, inputs: np.ndarray, switch: bool = False) -> TrackedPositions:
    """Poses for all inputs on the branch of the drawn configuration, with branch events.

    The branch rules (docs/kinematics.md, "Branches"):

    1. The drawn (file) configuration decides every group's assembly mode. The sweep is
       reached from the drawn input values along a straight path of inputs (backwards if
       the sweep starts below them), so the mode at the first input is the drawn mode
       continued, not the mode re-read there.
    2. A group's normalised discriminant ``Delta`` (RRR: ``h^2 / L1^2``; RRP: the
       circle-line discriminant over ``L1^2``; RPR: ``1 - (e/|AC|)^2``) crossing zero is a
       *fold* (dead point): the group cannot be assembled beyond it; the input is found by
       Brent's method on ``Delta`` of that group alone (upstream groups re-evaluated at the
       trial input), to 1e-12 of the step.
    3. ``Delta`` touching zero without changing sign (a local minimum at zero, found by
       Brent's method on ``dDelta/du``) is a *bifurcation* (change point, flat rhombus):
       both modes meet, and the motion whose velocity is continuous is the one on which
       the signed height ``sigma sqrt(Delta)`` changes sign, so ``sigma`` flips there.
    4. After a gap the group reassembles in the drawn mode.

    ``inputs`` (N, n_inputs) in radians / length. ``switch``: at change / branch points
    take the other branch instead (``sigma`` kept: a parallelogram becomes an
    anti-parallelogram there); the events say so.
    """
    X, n0, shift = _tracking_rows(S, inputs)
    M = X.shape[0]
    st = _State(S, M)
    sigmas: list = []
    discs: dict = {}
    singular = np.zeros(M, bool)
    raw_events: list = []
    for k, step in enumerate(plan.steps):
        if step.kind not in BRANCHED:
            sigmas.append(_solve_step(S, st, step, X, None))
            continue
        choose = _chooser(S, plan, k, sigmas, X, n0, switch, discs, raw_events, singular)
        sigmas.append(_solve_step(S, st, step, X, choose))
    q = _pose_rows(S, st, plan)
    for step in plan.steps:  # a link driven from the frame takes the input's own turn count
        if step.kind == "drive_R" and step.known[0] < 0:
            con = next(c for c in _cons_of(S, step.joints[0]) if c.role == "drive")
            sgn = 1.0 if con.b == step.links[0] else -1.0
            q[n0:, 3 * step.links[0] + 2] += sgn * shift[con.driver]
    sig_out = [s[n0:] if isinstance(s, np.ndarray) else s for s in sigmas]
    return TrackedPositions(q[n0:], sig_out, {k: v[n0:] for k, v in discs.items()}, singular[n0:],
                            _sweep_events(raw_events, n0, shift))


def solve_tracked_rates(S: PlanarSystem, plan: Plan, parts: list, speeds: np.ndarray,
                        switch: bool = False) -> list[tuple]:
    """:func:`solve_tracked` and :func:`solve_all` of a driver-R + RRR chain for several
    sweeps (``parts``: arrays of input rows, each reached from the drawn configuration on
    its own) in one array pass of :func:`fast_chain`: each group's signs are chosen by
    the branch rules on its discriminant, sweep by sweep, as the pass reaches the group.
    Returns per sweep ``q, qd, qdd`` (N, n), its singular rows and its events."""
    parts = [np.atleast_2d(np.asarray(p, float)) for p in parts]
    rows = [_tracking_rows(S, p) for p in parts]
    starts = np.cumsum([0] + [X.shape[0] for X, _, _ in rows])
    segs = [slice(int(a), int(b)) for a, b in zip(starts[:-1], starts[1:])]
    sigmas: list = [1.0] * len(plan.steps)
    singular = np.zeros(int(starts[-1]), bool)
    raw_events: list = [[] for _ in parts]
    for k, step in enumerate(plan.steps):
        if step.kind in BRANCHED:
            sigmas[k] = _parts_chooser(S, plan, k, sigmas, rows, segs, switch, raw_events, singular)
    # the sweeps' own rows (not shifted by turns: the same numbers as an untracked pass);
    # the choosers' events and root searches use the shifted rows
    E = np.vstack([blk for (X, n0, _), U in zip(rows, parts) for blk in (X[:n0], U)])
    r = fast_chain(S, plan, E, speeds, rates=True, sigmas=sigmas, chunk=max(E.shape[0], 1))
    out = []
    for (X, n0, shift), U, seg, evs in zip(rows, parts, segs, raw_events):
        sweep_rows = slice(seg.start + n0, seg.stop)
        q, qd, qdd = _poses_from_chain(S, plan, U, r.rows(sweep_rows))
        out.append((q, qd, qdd, singular[sweep_rows], _sweep_events(evs, n0, shift)))
    return out


def _parts_chooser(S: PlanarSystem, plan: Plan, k: int, sigmas: list, rows: list, segs: list, switch: bool,
                   raw_events: list, singular: np.ndarray):
    """The sign chooser of branched step ``k`` over several sweeps' rows (``segs`` of the
    pass): the branch rules (:func:`_branch_signs`) applied to each sweep's rows alone;
    the signs are also put in ``sigmas[k]``."""
    def choose(disc: np.ndarray, s_file: float) -> np.ndarray:
        sig = np.empty(len(disc))
        for (X, n0, _), seg, evs in zip(rows, segs, raw_events):
            up = [s[seg] if isinstance(s, np.ndarray) else s for s in sigmas[:k]]
            sig[seg], found, sing = _branch_signs(S, plan, k, up, X, disc[seg], s_file, n0, switch)
            evs.extend(found)
            singular[seg][sing] = True
        sigmas[k] = sig
        return sig
    return choose


def _tracking_rows(S: PlanarSystem, inputs: np.ndarray) -> tuple[np.ndarray, int, np.ndarray]:
    """The rows a tracked sweep evaluates: the connecting path from the drawn input
    values (``n0`` rows), then the sweep shifted by whole turns next to them."""
    U = np.atleast_2d(np.asarray(inputs, float))
    u0 = np.array([d.assembled for d in S.drivers], float)
    # R inputs a whole number of turns from the drawn values are the same configurations:
    # track the sweep shifted next to the drawn values (its rows then follow each other)
    shift = U[0] - _shifted_start(S, u0, U[0])
    path = _connecting_path(S, u0, U[0] - shift)
    return np.vstack([path, U - shift]), path.shape[0], shift


def _chooser(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, n0: int, switch: bool,
             discs: dict, raw_events: list, singular: np.ndarray):
    """The sign chooser of branched step ``k``: called with the step's normalised
    discriminant and the drawn mode, it applies the branch rules (:func:`_branch_signs`),
    records the discriminant, events and singular rows, and returns the signs."""
    def choose(disc: np.ndarray, s_file: float) -> np.ndarray:
        sig, evs, sing = _branch_signs(S, plan, k, sigmas, X, disc, s_file, n0, switch)
        discs[k] = disc
        raw_events.extend(evs)
        singular[sing] = True
        return sig
    return choose


def _sweep_events(raw_events: list, n0: int, shift: np.ndarray) -> list:
    """Events of the tracked rows as events of the sweep (the connecting path's marked)."""
    events = []
    for e in raw_events:
        if e.index < n0:  # on the way from the drawn configuration to the sweep
            e = e.with_(message="between the drawn configuration and the first input: " + e.message,
                        before_sweep=True)
        e = e.with_(index=max(0, e.index - n0))
        if not e.before_sweep:
            e = e.with_(input=(np.asarray(e.input) + shift).tolist())
        events.append(e)
    return events


def _disc_at(S: PlanarSystem, plan: Plan, k: int, sigmas: list, rows: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Normalised discriminant of step ``k`` at the inputs ``X`` (M, n_inputs), upstream
    steps solved with their modes of the sweep rows ``rows`` (M,)."""
    st = _State(S, X.shape[0])
    for j in range(k):
        s = sigmas[j]
        _solve_step(S, st, plan.steps[j], X, s[rows] if isinstance(s, np.ndarray) else s)
    out = []

    def capture(disc: np.ndarray, s_file: float) -> float:
        out.append(disc)
        return 1.0

    with np.errstate(invalid="ignore", divide="ignore"):
        _solve_step(S, st, plan.steps[k], X, capture)
    return out[0]


def _scalar_program(S: PlanarSystem, plan: Plan) -> list:
    """A driver-R + RRR chain as plain numbers for :func:`_scalar_disc` (built once per
    system and plan)."""
    memo = _memo(S)
    key = ("scalar", id(plan))
    prog = memo.get(key)
    if prog is not None:
        return prog
    prog = []
    for step in plan.steps:
        if step.kind == "drive_R":
            (new,), (k,), (jid,) = step.links, step.known, step.joints
            con = next(c for c in _cons_of(S, jid) if c.role == "drive")
            prog.append(("drive", new, k, tuple(_local(S, k, jid)), con.driver, 1.0 if con.b == new else -1.0,
                         tuple(_local(S, new, jid))))
            continue
        (k1, k3), (b1, b2), (J1, J2, J3) = step.known, step.links, step.joints
        s1, s2 = _local(S, b1, J1), _local(S, b1, J2)
        t2, t3 = _local(S, b2, J2), _local(S, b2, J3)
        L1, L2 = float(np.linalg.norm(s2 - s1)), float(np.linalg.norm(t2 - t3))
        prog.append(("RRR", (k1, tuple(_local(S, k1, J1))), (k3, tuple(_local(S, k3, J3))), (b1, b2),
                     L1, L2, tuple(s1), tuple(t3), tuple((s2 - s1) / L1 ** 2), tuple((t2 - t3) / L2 ** 2)))
    memo[key] = prog
    return prog


def _scalar_disc(prog: list, k: int, sigmas: list, u: np.ndarray) -> float:
    """Normalised discriminant ``h^2 / L1^2`` of RRR step ``k`` of a driver-R + RRR chain
    at one input ``u``, the upstream groups in the modes ``sigmas`` (floats): the
    formulas of :func:`_solve_step` in plain floats (a root search calls it a few times
    per event; an array pass would cost a hundred times more per call)."""
    pose: dict[int, tuple] = {}  # link -> (anchor x, y, local x, y, cos, sin)

    def point(i: int, s: tuple) -> tuple:
        if i < 0:
            return s
        ax, ay, lx, ly, c, sn = pose[i]
        dx, dy = s[0] - lx, s[1] - ly
        return ax + c * dx - sn * dy, ay + sn * dx + c * dy

    for j, op in enumerate(prog):
        if op[0] == "drive":
            _, new, kk, sk, di, sgn, snew = op
            P = point(kk, sk)
            ck, sk_ = (1.0, 0.0) if kk < 0 else pose[kk][4:]
            ct, st = math.cos(u[di]), sgn * math.sin(u[di])
            pose[new] = (P[0], P[1], snew[0], snew[1], ck * ct - sk_ * st, sk_ * ct + ck * st)
            continue
        _, (k1, sa), (k3, sc), (b1, b2), L1, L2, s1, t3, bv1, bv2 = op
        A, C = point(k1, sa), point(k3, sc)
        dx, dy = C[0] - A[0], C[1] - A[1]
        D2 = dx * dx + dy * dy
        D = math.sqrt(D2)
        a = (L1 ** 2 - L2 ** 2 + D2) / (2 * D) if D > 0 else math.nan
        h2 = L1 ** 2 - a ** 2
        if j == k:
            return h2 / L1 ** 2
        if not h2 >= 0:  # folded (NaN downstream, as in the array pass) or round-off
            h2 = 0.0 if h2 > -1e-12 * L1 ** 2 else math.nan
        h = float(sigmas[j]) * (math.sqrt(h2) if h2 >= 0 else math.nan)
        ex, ey = dx / D, dy / D
        Bx, By = A[0] + a * ex - h * ey, A[1] + a * ey + h * ex
        for link, P, loc, bv in ((b1, A, s1, bv1), (b2, C, t3, bv2)):
            vx, vy = Bx - P[0], By - P[1]
            pose[link] = (P[0], P[1], loc[0], loc[1], vx * bv[0] + vy * bv[1], vy * bv[0] - vx * bv[1])
    return math.nan


def _disc_line(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, i0: int, i1: int):
    """Discriminant of step ``k`` on the segment of inputs from row ``i0`` (t = 0) to row
    ``i1`` (t = 1), the upstream groups in their modes of row ``i0``: a scalar function."""
    if plan.closed_form_rates:
        prog = _scalar_program(S, plan)
        sig = [float(s[i0]) if isinstance(s, np.ndarray) else float(s) for s in sigmas[:k]]
        x0, dx = X[i0], X[i1] - X[i0]
        return lambda t: _scalar_disc(prog, k, sig, x0 + t * dx)
    rows = np.array([i0])
    return lambda t: float(_disc_at(S, plan, k, sigmas, rows, (X[i0] + t * (X[i1] - X[i0]))[None])[0])


def _branch_signs(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, disc: np.ndarray,
                  s_file: float, n0: int, switch: bool = False) -> tuple[np.ndarray, list, np.ndarray]:
    """Assembly sign per row of a branched step (rules of :func:`solve_tracked`)."""
    from scipy.optimize import brentq

    M = len(disc)
    step = plan.steps[k]
    group = "-".join(step.joints)
    size = np.array([1.0 if d.type == "R" else S.scale for d in S.drivers])  # inputs relative to the size
    ok = disc > -_ZERO_DISC
    d = np.where(ok, np.maximum(disc, 0.0), np.nan)

    def f_line(i0: int, i1: int):
        return _disc_line(S, plan, k, sigmas, X, i0, i1)

    events: list = []
    singular = np.zeros(M, bool)
    singular[ok & (d < SINGULAR_DISC)] = True
    breaks: list[tuple[int, str]] = []  # (row, "flip" | "reset")
    finite = np.isfinite(disc)
    # folds: the group's own discriminant changes sign between two rows
    for i in np.flatnonzero(ok[1:] != ok[:-1]) + 1:
        if not (finite[i] and finite[i - 1]):
            continue
        inside = i - 1 if ok[i - 1] else i
        try:
            t = brentq(f_line(i - 1, i), 0.0, 1.0, xtol=1e-13, rtol=4 * np.finfo(float).eps)
        except ValueError:
            t = 0.0 if inside == i - 1 else 1.0
        u = X[i - 1] + t * (X[i] - X[i - 1])
        if ok[i - 1]:
            events.append(Event(i, "dead point", f"assembly ends: the group {group} folds flat (its discriminant "
                                "changes sign: a dead point / limit of the working range)", u.tolist(), group))
        else:
            events.append(Event(i, "dead point", "assembly starts again here: the other limit of a working range",
                                u.tolist(), group))
    # reassembly after a gap (own or upstream): the drawn mode
    for i in np.flatnonzero(ok[1:] & ~ok[:-1]) + 1:
        breaks.append((int(i), "reset"))
        if i >= n0:
            events.append(Event(int(i), "reassembled", f"assembles again after a gap, in the assembly mode of the "
                                f"drawn configuration for the group {group} (the mode nearest the drawn one)",
                                X[i].tolist(), group))
    # bifurcations: local minima of the discriminant at zero
    touched: list = []
    cand = np.flatnonzero((d[1:-1] <= d[:-2]) & (d[1:-1] <= d[2:]) & (d[1:-1] < 0.05)) + 1
    for i in cand.tolist():
        t_star, dmin = _touch(S, plan, k, sigmas, X, i)
        if dmin > 1e-10:
            continue  # a sharp but regular turn
        if dmin < -1e-10:  # the group folds and unfolds within one step: a short gap
            events.append(Event(i, "dead point", f"the group {group} cannot be assembled in a short interval near "
                                "this input (it folds and unfolds within one step): refine the input step",
                                X[i].tolist(), group))
            breaks.append((i + 1, "reset"))
            continue
        # where the crossing lies: at row i (|t| tiny), or between i and a neighbour
        if abs(t_star) < 1e-7:
            row, at = i + 1, i
            singular[i] = True
        elif t_star > 0:
            row, at = i + 1, i + 1
        else:
            row, at = i, i
        u = X[i] + t_star * (X[i + 1] - X[i]) if t_star >= 0 else X[i] + t_star * (X[i] - X[i - 1])
        if any(abs(i - j) <= 2 and np.abs((u - v) / size).max() < 1e-8 for j, v in touched):
            continue  # the same crossing seen from the neighbouring sample
        touched.append((i, u))
        if not switch:
            breaks.append((row, "flip"))
        events.append(Event(at, "singular", input=u.tolist(), group=group, crossed=bool(not singular[i]),
                       message=f"change / branch point: the group {group} is folded flat here (its two "
                                  "assembly modes meet); "
                                  + ("the motion switches to the other branch (change_points='switch')" if switch
                                     else "the motion continues on the branch whose velocity is continuous "
                                          "(the drawn branch)")
                                  + ("; velocities and accelerations are not defined at this input (null)"
                                     if singular[i] else "")))
    sig = np.full(M, s_file)
    cur = s_file
    last = 0
    for row, kind in sorted(breaks):
        sig[last:row] = cur
        cur = -cur if kind == "flip" else s_file
        last = row
    sig[last:] = cur
    return sig, events, singular


def _touch(S: PlanarSystem, plan: Plan, k: int, sigmas: list, X: np.ndarray, i: int) -> tuple[float, float]:
    """Where the discriminant of step ``k`` is least near row ``i``: (t, value), with ``t``
    in [-1, 1] (``t < 0`` towards row i-1, ``t > 0`` towards row i+1), by Brent's method on
    the central difference of the discriminant."""
    from scipy.optimize import brentq

    da, db = X[i] - X[i - 1], X[i + 1] - X[i]

    def at(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        P = X[i] + np.where(t[:, None] >= 0, t[:, None] * db, t[:, None] * da)
        return _disc_at(S, plan, k, sigmas, np.full(len(t), i), P)

    h = 1e-6

    def slope(t: float) -> float:
        v = at(np.array([t - h, t + h]))
        return float(v[1] - v[0])

    ts = np.linspace(-1, 1, 9)
    vals = at(ts)
    j = int(np.nanargmin(vals))
    lo, hi = ts[max(0, j - 1)], ts[min(8, j + 1)]
    try:
        t = brentq(slope, lo + h, hi - h, xtol=1e-12)
    except ValueError:
        t = float(ts[j])
    dmin = float(at(np.array([t]))[0])
    if abs(dmin) <= 1e-10:
        # the minimum of a quadratic is found by its slope only to about sqrt(eps): at a
        # tangency the signed height sqrt(Delta) is linear on each side, so the secants
        # of sqrt(Delta) from both sides, extrapolated to zero spacing (Richardson),
        # give its zero to round-off
        def secant_roots(dt: float) -> float:
            ts_ = t + np.array([-2 * dt, -dt, dt, 2 * dt])
            f = np.sqrt(np.maximum(at(ts_), 0.0))
            left = ts_[1] - f[1] * (ts_[1] - ts_[0]) / (f[1] - f[0])
            right = ts_[2] - f[2] * (ts_[3] - ts_[2]) / (f[3] - f[2])
            return 0.5 * (left + right)

        with np.errstate(invalid="ignore", divide="ignore"):
            r1, r2 = secant_roots(1e-2), secant_roots(2e-2)
        t_fine = (4 * r1 - r2) / 3
        if np.isfinite(t_fine) and abs(t_fine - t) < 0.1:
            t = float(t_fine)
    return t, dmin
