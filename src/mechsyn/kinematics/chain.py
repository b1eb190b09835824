"""Driver-R + RRR chains in closed form: positions, velocities and accelerations of every
joint without angles (:func:`fast_chain`), the links' poses and continuous angles from
them, and :func:`solve_all` (the positions and rates of any plan: this chain where it
applies, else the generic steps of :mod:`mechsyn.kinematics.positions` with batched
linear solves for the rates).

RRR: ``B = A + f d + sigma g R90 d`` with ``d = C - A`` (:func:`mechsyn.kinematics.groups.circle_circle`);
rates ``omega_1 = (v_C - v_A) . e2 / (e1 x e2)``, ``omega_2 = (v_C - v_A) . e1 / (e1 x e2)``
with ``e1 = B - A``, ``e2 = B - C``, and likewise the accelerations (Artobolevsky, *Theory
of Mechanisms and Machines*, ch. 4).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.kinematics.groups import (DriveOp, Plan, RRRChooser, RRROp, circle_circle, cons_of,
                                       geometry_memo, local_point)
from mechsyn.kinematics.positions import TrackedPositions, continuous_angles, solve_positions
from mechsyn.kinematics.rates import batch_rates
from mechsyn.kinematics.plane import cross
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["ChainResult", "chain_supported", "fast_chain", "solve_all"]


def solve_all(S: PlanarSystem, plan: Plan, inputs: np.ndarray, speeds: np.ndarray,
              chunk: int = 20000, tracked: TrackedPositions | None = None
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, velocities, accelerations (N, n) for all inputs (closed form where possible).

    ``tracked``: the sweep's positions and modes from :func:`solve_tracked` (the drawn
    branch followed through bifurcations); without it every group keeps its drawn mode.
    """
    inputs = np.atleast_2d(np.asarray(inputs, float))
    if plan.closed_form_rates:
        sig = tracked.sigmas if tracked is not None else None
        return poses_from_chain(S, plan, inputs, fast_chain(S, plan, inputs, speeds, rates=True, sigmas=sig))
    q = tracked.q if tracked is not None else solve_positions(S, plan, inputs)[0]
    ok = np.all(np.isfinite(q), axis=1)
    qd = np.full_like(q, np.nan)
    qdd = np.full_like(q, np.nan)
    idx = np.flatnonzero(ok)
    for start in range(0, len(idx), chunk):
        sel = idx[start:start + chunk]
        qd[sel], qdd[sel] = batch_rates(S, q[sel], speeds)
    return q, qd, qdd


def poses_from_chain(S: PlanarSystem, plan: Plan, U: np.ndarray, r: "ChainResult") -> tuple:
    """Pose coordinates (origin, angle) and their rates from a chain's anchors and rotations."""
    with np.errstate(invalid="ignore", over="ignore"):  # inf rates at singular rows become NaN
        return _poses_from_chain_(S, plan, U, r)


def frame_driven_links(S: PlanarSystem, plan: Plan) -> dict[int, tuple[int, float]]:
    """Links turned by a frame driver: link -> (driver index, sign of the input), kept
    in the system's memo for the plan (a sweep's angles of these links are the inputs)."""
    memo = geometry_memo(S)
    hit = memo.get(("drive_links", id(plan)))
    if hit is not None and hit[0] is plan:
        return hit[1]
    out = {}
    for step in plan.steps:
        if step.kind == "drive_R" and step.known[0] < 0:
            con = next(c for c in cons_of(S, step.joints[0]) if c.role == "drive")
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
                 ok: np.ndarray | None, out: np.ndarray, split: int | None = None, parts: tuple | None = None) -> None:
    """Continuous angles of the chain's links into ``out`` (nl, N) from their rotations
    ``cos``, ``sin`` (nl, N or more rows): the links of frame drivers take the input
    itself, the others ``atan2`` made continuous (``ok`` None: every row assembled;
    ``split``: see :func:`continuous_angles`; ``parts``: the rows (slices, in the
    order swept) of sweeps tracked on their own, each made continuous from its start)."""
    drive_links, others, ref = _angle_plan(S, plan)
    N = out.shape[1]
    for i, (k, sgn) in drive_links.items():
        np.multiply(U[:N, k], sgn, out=out[i])
    if not isinstance(others, slice) and not others:
        return
    # atan2 only for the links not driven directly (a range of links: into out itself)
    ang = np.arctan2(sin[others, :N], cos[others, :N], out=out[others] if isinstance(others, slice) else None)
    if parts is not None:
        for rows in parts:
            if ok[rows].any():
                continuous_angles(ang[:, rows], ref, ok[rows], None, fresh=True)
    elif ok is None or ok.any():
        continuous_angles(ang, ref, ok, split, fresh=True)
    if not isinstance(others, slice):
        out[others] = ang


def _angle_plan(S: PlanarSystem, plan: Plan) -> tuple:
    """The links turned by frame drivers, the others (a slice when they are a range)
    and their drawn angles (m, 1), kept with the system; the links (the topology's):
    the :class:`~mechsyn.kinematics.topology.Topology`'s product ``"angles"``, which a
    refilled geometry shares (:func:`~mechsyn.kinematics.refill.with_geometry`)."""
    memo = geometry_memo(S)
    key = ("angles", id(plan))
    hit = memo.get(key)
    if hit is None or hit[0] is not plan:
        drive_links, others, cols = S.topology.product("angles", lambda: _angle_links(S, plan), plan)
        hit = memo[key] = (plan, (drive_links, others, S.q0[cols][:, None]))
    return hit[1]


def _angle_links(S: PlanarSystem, plan: Plan) -> tuple:
    """The links turned by frame drivers, the others (a slice when they are a range) and
    the columns of their angles in ``q``."""
    drive_links = frame_driven_links(S, plan)
    others = [i for i in range(len(S.links)) if i not in drive_links]
    cols = [3 * i + 2 for i in others]
    if others and others == list(range(others[0], others[-1] + 1)):
        others = slice(others[0], others[-1] + 1)
    return drive_links, others, cols


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
    prog, anchor = chain_program(S, plan, sigmas)
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
                if isinstance(op, DriveOp):
                    ch.drive(op, U[sl], speeds, fixed)
                else:
                    ch.rrr(op, want)
            ch.write(nl, want, rotations, filled)
    return out


def chain_program(S: PlanarSystem, plan: Plan, sigmas: list | None) -> tuple[list[DriveOp | RRROp], dict]:
    """The chain's steps as typed ops, and every link's anchor joint (built once per
    system and plan; the signs ``sigmas`` put in per call)."""
    memo = geometry_memo(S)
    key = ("chain", id(plan))
    if key not in memo:
        memo[key] = _chain_program_(S, plan)
    prog, anchor = memo[key]
    if sigmas is None:
        return prog, anchor
    out = []
    for op in prog:
        sg = sigmas[op.step] if isinstance(op, RRROp) else None
        if isinstance(sg, np.ndarray):
            op = op.with_sigma(np.asarray(sg, float))
        elif callable(sg):
            op = op.with_sigma(RRRChooser(sg, S.mech.joint(op.joints[1]).point))
        out.append(op)
    return out, anchor


def _chain_program_(S: PlanarSystem, plan: Plan) -> tuple[list[DriveOp | RRROp], dict]:
    prog: list[DriveOp | RRROp] = []
    anchor: dict[int, tuple[str, np.ndarray]] = {}
    for si, step in enumerate(plan.steps):
        if step.kind == "drive_R":
            (new,), (k,), (jid,) = step.links, step.known, step.joints
            con = next(c for c in cons_of(S, jid) if c.role == "drive")
            sgn = 1.0 if con.b == new else -1.0
            anchor[new] = (jid, local_point(S, new, jid))
            prog.append(DriveOp(new, k, jid, con.driver, sgn))
            continue
        (k1, k3), (b1, b2), (J1, J2, J3) = step.known, step.links, step.joints
        s1, s2 = local_point(S, b1, J1), local_point(S, b1, J2)
        t2, t3 = local_point(S, b2, J2), local_point(S, b2, J3)
        L1s, L2s = float(np.sum((s2 - s1) ** 2)), float(np.sum((t2 - t3) ** 2))
        A0, B0, C0 = (S.mech.joint(j).point for j in (J1, J2, J3))
        sigma = 1.0 if cross(C0 - A0, B0 - A0) >= 0 else -1.0
        anchor[b1] = (J1, s1)
        anchor[b2] = (J3, t3)
        prog.append(RRROp(si, (k1, k3), (b1, b2), (J1, J2, J3), L1s, L2s, sigma, (s2 - s1) / L1s, (t2 - t3) / L2s))
    return prog, anchor


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

    def drive(self, op: DriveOp, U: np.ndarray, speeds: np.ndarray, fixed: dict) -> None:
        new, k, jid, di, sgn = op.new, op.known, op.joint, op.driver, op.sign
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
            self.jst[jid] = self.point(k, jid, local_point(self.S, k, jid))

    def rrr(self, op: RRROp, want: list) -> None:
        """The RRR kernel: ``B = A + f d + sigma g R90 d`` (see :func:`fast_chain`)."""
        (k1, k3), (b1, b2), (J1, J2, J3), L1s, L2s = op.known, op.links, op.joints, op.L1s, op.L2s
        sigma, bv1, bv2 = op.sigma, op.bv1, op.bv2
        S, sl, jst = self.S, self.sl, self.jst
        A = self.point(k1, J1, local_point(S, k1, J1))
        C = self.point(k3, J3, local_point(S, k3, J3))
        jst[J1], jst[J3] = A, C
        dx = C[0] - A[0]
        dy = C[1] - A[1]
        f, g, disc = circle_circle(dx, dy, L1s, L2s)
        if isinstance(sigma, RRRChooser):  # a chooser: the signs from the discriminant of positions.solve_step
            sigma = self._choose(sigma, A, dx, dy, disc)
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

    def _choose(self, chooser: RRRChooser, A: tuple, dx: np.ndarray, dy: np.ndarray, disc: np.ndarray) -> np.ndarray:
        """Signs of an RRR group from its chooser (``solve_tracked_rates``), given the
        normalised discriminant from the kernel :func:`~mechsyn.kinematics.groups.circle_circle`
        as the generic step computes it (the same numbers, so the same decisions) and the
        drawn mode read at the first row."""
        choose, B0 = chooser.choose, chooser.drawn_b
        ax, ay = (float(np.ravel(c)[0]) for c in A[:2])  # a frame joint's are numbers
        s_file = 1.0 if dx[0] * (B0[1] - ay) - dy[0] * (B0[0] - ax) >= 0 else -1.0
        return choose(disc, s_file)

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
                P = self.point(side, None, local_point(self.S, side, jid))
            o.points[jid][sl, 0], o.points[jid][sl, 1] = P[0], P[1]
            if rates:
                o.velocities[jid][sl, 0], o.velocities[jid][sl, 1] = P[2], P[3]
                o.accelerations[jid][sl, 0], o.accelerations[jid][sl, 1] = P[4], P[5]
