"""The regular sweep: a chain of a driver and RRR dyads clear of folds, in one pass of
complex arithmetic.

Points of the plane are complex numbers ``z = x + i y`` (the vector-loop notation of
Raven, "Velocity and acceleration analysis of plane and space mechanisms by means of
independent-position equations", *Journal of Applied Mechanics* 25, 1958; Erdman and
Sandor, *Mechanism Design*, 1984, ch. 3), so a rotation is one product and a vector
equation one array operation instead of two:

* a link ``i`` turned by ``e^{i phi_i}`` carries its local point ``s`` to
  ``P = P_a + e^{i phi_i} (s - s_a)`` from its anchor joint ``a``, with
  ``V = V_a + i omega_i (P - P_a)`` and ``A = A_a + (i alpha_i - omega_i^2) (P - P_a)``;
* an RRR dyad with known joints ``A``, ``C`` (``d = C - A``) places its middle joint at
  ``B = A + d (f + i sigma g)``, ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)``,
  ``g = sqrt(L1^2 / |d|^2 - f^2)`` (``g^2 |d|^2 / L1^2`` is the group's normalised
  discriminant of :func:`mechsyn.kinematics.tracking.solve_tracked`); with ``e1 = B - A``,
  ``e2 = B - C`` its links turn at ``omega_1 = Re((v_C - v_A) conj(e2)) / (e1 x e2)``,
  ``omega_2 = Re((v_C - v_A) conj(e1)) / (e1 x e2)`` and likewise for the accelerations.

:func:`regular_sweep` evaluates the sweep and the connecting paths from the drawn input
values together and gives up (None) as soon as a group's discriminant falls below
:data:`mechsyn.kinematics.tracking.REGULAR_DISC`: no group then folds, touches a change
point or reassembles, every group keeps its drawn mode and the answer is that of the
tracked outward sweeps (tests check both agree), at the cost of one pass.
:func:`sweep_through_folds` goes on through the folds when no group's discriminant has a
local minimum under 0.05 (no change or branch point near: every group keeps its drawn
mode), and reads the folds, reassembly and singular rows of the tracked sweeps off the
discriminant arrays (:func:`mechsyn.kinematics.folds.pass_fold_events`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from mechsyn.kinematics import kernel
from mechsyn.kinematics.chain import _chain_program, _drive_links, _link_angles
from mechsyn.kinematics.groups import DriveOp, Plan, circle_circle, geometry_memo, local_point, normalised_disc
from mechsyn.kinematics.refill import joint_points
from mechsyn.kinematics.system import PlanarSystem, frame_points
from mechsyn.kinematics.folds import pass_fold_events
from mechsyn.kinematics.tracking import REGULAR_DISC, _regular_rows, tracking_path

__all__ = ["regular_sweep", "sweep_through_folds", "Folded", "LinkStates"]


def _program(S: PlanarSystem, plan: Plan) -> tuple:
    """The chain's steps with complex constants, every link's anchor and origin joint
    (built once per system and plan). Its shape (:func:`_shape`: the steps' links,
    joints, drivers and signs, and which local joint points they take) depends on the
    topology only: it is kept in ``S.cache["programs"]``, which
    :func:`~mechsyn.kinematics.refill.with_geometry` shares among the systems of one
    topology, so a refilled system's program is its numbers put in (:func:`_filled`).
    With the kernel, the same numbers are written once more as the compiled pass's
    arrays (:func:`~mechsyn.kinematics.kernel.program_arrays`' ``fp`` and ``anc_s``, kept
    under ``("kernel", id(plan))``) while they are filled in, not read back off the steps."""
    memo = geometry_memo(S)
    key = ("regular", id(plan))
    hit = memo.get(key)
    if hit is not None and hit[0] is plan:
        return hit[1]
    rows: list | None = [] if kernel.active() else None
    out = _filled(S, S.topology.product("regular", lambda: _shape(S, plan), plan), rows)
    memo[key] = (plan, out)
    if rows is not None:  # (the integers of the kernel's program are the topology's)
        steps, anchor, origin = out
        shape = S.topology.product("kernel", lambda: kernel.program_arrays(steps, anchor, origin)[0], plan)
        rows += [anchor[i][1] if i in anchor else 0j for i in range(len(origin))]  # anc_s after fp's rows
        flat, n = np.array(rows, complex), 7 * len(steps)  # one array, two contiguous views
        memo[("kernel", id(plan))] = (plan, (shape, flat[:n].reshape(len(steps), 7), flat[n:]))
    return out


def _shape(S: PlanarSystem, plan: Plan) -> tuple:
    """The topology of :func:`_program`: its steps without numbers (a drive's links,
    joint, driver and sign; an RRR group's known links, links and joints), each link's
    anchor joint, origin joint, the (link, joint) pairs whose local points the numbers
    take, as index lists (link, joint's index in the file), and the file indices of
    every RRR group's joints (its drawn assembly mode)."""
    prog, anchor = _chain_program(S, plan, None)
    pairs: dict[tuple[int, str], int] = {}

    def at(i: int, jid: str) -> int:
        return pairs.setdefault((i, jid), len(pairs))

    steps = []
    for op in prog:
        if isinstance(op, DriveOp):  # the joint's local point on k (the frame: its fixed point)
            steps.append(("drive", op.new, op.known, op.joint, op.driver, op.sign, at(op.known, op.joint)))
        else:
            (k1, k3), (b1, b2), (J1, J2, J3) = op.known, op.links, op.joints
            steps.append(("RRR", op.known, op.links, op.joints, at(b1, J1), at(b1, J2), at(b2, J2), at(b2, J3),
                          at(k1, J1), at(k3, J3)))
    anchors = {i: (jid, at(i, jid)) for i, (jid, _) in anchor.items()}
    origin = []  # the joint at every link's origin (its first joint), by link
    for i, name in enumerate(S.links):
        j0 = next((j.id for j in S.mech.joints_of(name) if not np.any(local_point(S, i, j.id))), None)
        origin.append(j0)
    index = {j.id: k for k, j in enumerate(S.mech.joints)}
    drawn = [(index[st[3][0]], index[st[3][1]], index[st[3][2]]) if st[0] == "RRR" else None for st in steps]
    return steps, anchors, origin, [i for i, _ in pairs], [index[jid] for _, jid in pairs], drawn


def _locals(S: PlanarSystem, li: list, pj: list) -> list:
    """The local points (``(x, y)`` floats) of the joints ``pj`` (indices in the file) on
    the links ``li`` (-1: the frame, the point itself): :meth:`PlanarSystem.to_locals`'s
    numbers, on floats."""
    pts = joint_points(S)
    return frame_points(S.frames(), li, [pts[k] for k in pj])


def _filled(S: PlanarSystem, shape: tuple, rows: list | None = None) -> tuple:
    """:func:`_program` of ``S`` from its topology's shape (:func:`_shape`): the local
    points, squared link lengths, drawn assembly modes and rotation vectors of ``S``;
    with ``rows`` (a list), each step's row of the kernel's ``fp``
    (:func:`~mechsyn.kinematics.kernel.program_arrays`' layout) appended to it, flat."""
    steps_, anchors, origin, li, pj, drawn = shape
    loc = _locals(S, li, pj)
    pt = joint_points(S)
    steps = []
    for st, ks in zip(steps_, drawn):
        if st[0] == "drive":
            steps.append(st[:6] + (s_k := complex(*loc[st[6]]),))
            if rows is not None:
                rows += (st[5], s_k, 0j, 0j, 0j, 0j, 0j)
            continue
        _, known, links, joints, i1, i2, i3, i4, k1, k3 = st
        (x1, y1), (x2, y2), (x3, y3), (x4, y4) = loc[i1], loc[i2], loc[i3], loc[i4]
        ux, uy = x2 - x1, y2 - y1  # s2 - s1 on the first link, t2 - t3 on the second
        vx, vy = x3 - x4, y3 - y4
        L1s, L2s = ux * ux + uy * uy, vx * vx + vy * vy
        (ax, ay), (bx, by), (cx, cy) = pt[ks[0]], pt[ks[1]], pt[ks[2]]
        cross = (cx - ax) * (by - ay) - (cy - ay) * (bx - ax)
        sigma = 1.0 if cross >= 0 else -1.0
        num = (sigma, complex(ux / L1s, -(uy / L1s)), complex(vx / L2s, -(vy / L2s)), complex(*loc[k1]),
               complex(*loc[k3]))
        steps.append(("RRR", known, links, joints, L1s, L2s) + num)
        if rows is not None:
            rows += (complex(L1s, L2s), 0j) + num
    return steps, {i: (jid, complex(*loc[k])) for i, (jid, k) in anchors.items()}, origin


class _Pass:
    """The joints' and links' states of one regular pass (rows ``M``)."""

    def __init__(self, M: int, anchor: dict) -> None:
        self.M, self.anchor = M, anchor
        self.joint: dict[str, tuple] = {}  # id -> (P, V, A): complex arrays or numbers
        self.link: dict[int, tuple] = {}   # link -> (e^{i phi}, omega, alpha)
        self.discs: dict[int, np.ndarray] = {}  # step -> the group's normalised discriminant
        self.near = False  # a group came near a fold (below REGULAR_DISC)

    def point(self, i: int, s: complex) -> tuple:
        """State of the local point ``s`` of link ``i`` (the frame: -1)."""
        if i < 0:
            return s, 0j, 0j
        jid, sa = self.anchor[i]
        P, V, A = self.joint[jid]
        z, w, al = self.link[i]
        rel = z * (s - sa)
        if (not isinstance(w, np.ndarray) and isinstance(al, float) and al == 0.0
                and not isinstance(V, np.ndarray) and V == 0 and not isinstance(A, np.ndarray) and A == 0):
            # a link turned at constant speed about a frame pivot (a crank): two products
            return rel + P, rel * (1j * w), rel * (-w * w)
        iw_rel = rel * 1j
        acc = iw_rel * al if not isinstance(al, float) or al != 0.0 else None
        iw_rel *= w
        Pn = rel + P
        Vn = iw_rel + V
        rel *= w * w
        An = A - rel if acc is None else (acc - rel) + A
        return Pn, Vn, An

    def drive(self, step: tuple, U: np.ndarray, speeds: np.ndarray) -> None:
        _, new, k, jid, di, sgn, s_k = step
        z = np.empty(self.M, complex)
        th = U[:, di]
        np.cos(th, out=z.real)
        np.sin(th, out=z.imag)
        if sgn < 0:
            np.negative(z.imag, out=z.imag)
        if k < 0:
            self.joint[jid] = (s_k, 0j, 0j)
            self.link[new] = (z, sgn * float(speeds[di]), 0.0)
        else:
            zk, wk, alk = self.link[k]
            self.joint.setdefault(jid, self.point(k, s_k))
            self.link[new] = (z * zk, wk + sgn * float(speeds[di]), alk)

    def rrr(self, step: tuple, least: float, folds: bool) -> np.ndarray | None:
        """Place one RRR dyad and return its normalised discriminant (per row); None when
        it falls below ``least`` and ``folds`` is false. With ``folds`` a folded row is NaN
        (a fold within round-off is taken flat, as :func:`mechsyn.kinematics.chain.fast_chain`
        takes it) and NaN propagates downstream."""
        _, (k1, k3), (b1, b2), (J1, J2, J3), L1s, L2s, sigma, cbv1, cbv2, s1, s3 = step
        A = self.joint.get(J1) or self.point(k1, s1)
        C = self.joint.get(J3) or self.point(k3, s3)
        self.joint[J1], self.joint[J3] = A, C
        d = np.subtract(C[0], A[0]) if isinstance(C[0], np.ndarray) or isinstance(A[0], np.ndarray) \
            else np.full(self.M, C[0] - A[0])
        inv, f, g = circle_circle(d.real, d.imag, L1s, L2s)
        disc = normalised_disc(inv, g, L1s)
        if not disc.min() >= least:  # NaN too
            if not folds:
                return None
            self.near = True
            np.maximum(g, 0.0, out=g, where=g > -1e-12)
        np.sqrt(g, out=g)
        if sigma < 0:
            np.negative(g, out=g)
        u = np.empty(self.M, complex)
        u.real, u.imag = f, g
        e1 = d * u
        B = e1 + A[0]
        e2 = B - C[0]
        self.joint[J2] = (B,) + self._rates(A, C, e1, e2, (b1, b2), (cbv1, cbv2))
        return disc

    def _rates(self, A: tuple, C: tuple, e1: np.ndarray, e2: np.ndarray, links: tuple, cbv: tuple) -> tuple:
        """The dyad's link rotations and rates; the middle joint's velocity, acceleration."""
        ce1, ce2 = e1.conjugate(), e2.conjugate()
        den = (ce1 * e2).imag  # e1 x e2
        np.divide(1.0, den, out=den)
        dv = C[1] - A[1]
        w1 = (dv * ce2).real
        w1 *= den
        w2 = (dv * ce1).real
        w2 *= den
        w1s = w1 * w1
        da = (C[2] - A[2]) + w1s * e1
        da -= (w2 * w2) * e2
        a1 = (da * ce2).real
        a1 *= den
        a2 = (da * ce1).real
        a2 *= den
        self.link[links[0]] = (e1 * cbv[0], w1, a1)
        self.link[links[1]] = (e2 * cbv[1], w2, a2)
        ie1 = e1 * 1j
        VB = ie1 * w1
        VB += A[1]
        AB = ie1 * a1
        AB -= w1s * e1
        AB += A[2]
        return VB, AB


def regular_sweep(S: PlanarSystem, plan: Plan, U: np.ndarray, speeds: np.ndarray,
                  split: int | None) -> tuple | None:
    """Poses and rates (N, n) of a driver-R + RRR chain over the inputs ``U`` (N, k) in
    one pass, with the links' complex states (:class:`LinkStates`); None when a group
    comes near a fold on the sweep or on the way to it from the drawn configuration
    (``split``: the row after the drawn input values, see
    :func:`mechsyn.kinematics.engines.drawn_row`; :func:`sweep_through_folds` goes on
    through folds).

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.io import load_mechanism
    >>> from mechsyn.kinematics.analysis import compile_plan, input_grid
    >>> kp = compile_plan(load_mechanism("examples/kinematics/crank_rocker.yaml"), inputs=("A",))
    >>> U = np.radians(input_grid(0, 360, 1))[:, None]
    >>> q, qd, qdd, links = regular_sweep(kp.system, kp.groups, U, np.ones(1), None)
    >>> q.shape, bool(np.allclose(links.z, np.exp(1j * q[:, 2::3].T)))
    ((361, 9), True)
    """
    if not plan.closed_form_rates or S.n != 3 * len(S.links):
        return None
    steps, anchor, origin = _program(S, plan)
    st = _pass(S, plan, _regular_rows(S, U, split), speeds, folds=False)
    return None if st is None else _poses(S, plan, U, st, origin, split)


def _run(steps: list, anchor: dict, X: np.ndarray, speeds: np.ndarray, folds: bool) -> _Pass | None:
    """One pass of the chain's steps over the input rows ``X``; the groups' normalised
    discriminants in ``discs`` (by step). None when a group comes near a fold and
    ``folds`` is false."""
    st = _Pass(X.shape[0], anchor)
    with np.errstate(invalid="ignore", divide="ignore"):
        for k, step in enumerate(steps):
            if step[0] == "drive":
                st.drive(step, X, speeds)
                continue
            disc = st.rrr(step, REGULAR_DISC, folds)
            if disc is None:
                return None
            st.discs[k] = disc
    return st


def _pass(S: PlanarSystem, plan: Plan, X: np.ndarray | list, speeds: np.ndarray,
          folds: bool) -> _Pass | _Compiled | None:
    """One pass of the regular program over the input rows ``X`` (or the blocks of rows
    ``X``, a list, one after the other): compiled (:mod:`mechsyn.kinematics.kernel`) when
    Numba is installed, else :func:`_run`; the same states and discriminants either way.
    None when a group comes near a fold and ``folds`` is false."""
    steps, anchor, origin = _program(S, plan)
    if not kernel.active():
        return _run(steps, anchor, np.concatenate(X) if isinstance(X, list) else X, speeds, folds)
    memo = geometry_memo(S)
    key = ("kernel", id(plan))
    prog = memo.get(key)
    if prog is None or prog[0] is not plan:
        shape = S.topology.product("kernel", lambda: kernel.program_arrays(steps, anchor, origin)[0], plan)
        prog = memo[key] = (plan, kernel.program_arrays(steps, anchor, origin, shape))
    C, W, AL, D, near, Z = kernel.run(prog[1], X, speeds, REGULAR_DISC,
                                      planes=(X[0] if isinstance(X, list) else X).shape[0])
    if near and not folds:
        return None
    return _Compiled(C, W, AL, dict(zip(prog[1][0][4], D)), near, D, Z)


def _compiled_poses(S: PlanarSystem, plan: Plan, U: np.ndarray, st: "_Compiled", split: int | None,
                    folds: bool, parts: list | None = None) -> tuple:
    """:func:`_poses` / :func:`_fold_poses` of a compiled pass, compiled
    (:func:`mechsyn.kinematics.kernel.link_poses`): ``q, qd, qdd`` (n, N), the rows
    assembled (N,), the rows with rates and the number of singular rows (through folds;
    ``parts``: the fold scan's singular rows, blanked too). Which links frame drivers
    turn is kept with the topology."""
    dcol, dsgn, runs = S.topology.product("kernel-angles", lambda: _drive_arrays(S, plan), plan)
    memo = geometry_memo(S)
    ref = memo.get("drawn angles")
    if ref is None:  # the drawn angles: this geometry's
        ref = memo["drawn angles"] = np.ascontiguousarray(S.q0[2::3])
    pass_ = (st.C, st.W, st.AL) if st.Z is None else (st.C, st.W, st.AL, st.Z)
    return kernel.link_poses(pass_, U.shape[0], U, (dcol, dsgn, ref, runs), split, folds, S.n, parts)


def _drive_arrays(S: PlanarSystem, plan: Plan) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Each link's frame driver's input column (-1: none), the input's sign, and the runs
    ``(first, end)`` of consecutive links that no frame driver turns (their angles are
    ``atan2`` of their rotations)."""
    drive = _drive_links(S, plan)
    nl = len(S.links)
    free = [i for i in range(nl) if i not in drive]
    runs = [[i, i + 1] for i in free[:1]]
    for i in free[1:]:
        if i == runs[-1][1]:
            runs[-1][1] = i + 1
        else:
            runs.append([i, i + 1])
    return (np.array([drive[i][0] if i in drive else -1 for i in range(nl)], np.int64),
            np.array([drive[i][1] if i in drive else 1.0 for i in range(nl)], float), tuple(map(tuple, runs)))


class _Compiled:
    """The compiled pass's answer (:func:`mechsyn.kinematics.kernel.run`) in the terms of
    :class:`_Pass`: the links' states already gathered per link (``C``, ``W``, ``AL``),
    the groups' discriminants by step (and as rows of one block ``D``, in the order of the
    steps), whether one came near a fold, the rotations' real and imaginary parts ``Z``
    (2, links, M) when the pass wrote them."""

    def __init__(self, C: np.ndarray, W: np.ndarray, AL: np.ndarray, discs: dict, near: bool,
                 D: np.ndarray | None = None, Z: np.ndarray | None = None) -> None:
        self.C, self.W, self.AL, self.discs, self.near, self.D, self.Z = C, W, AL, discs, near, D, Z


def sweep_through_folds(S: PlanarSystem, plan: Plan, U: np.ndarray, speeds: np.ndarray,
                        split: int | None) -> tuple | Folded | None:
    """The regular pass of a driver-R + RRR chain through its folds (dead points, gaps).

    One pass over the sweep's rows and the connecting paths from the drawn input values
    (those of :func:`mechsyn.kinematics.tracking.solve_tracked_rates`) gives every group's
    normalised discriminant as an array. When no group comes near a fold the answer is
    :func:`regular_sweep`'s ``(q, qd, qdd, links)``. Else, when no group's discriminant
    has a local minimum under 0.05 (no change or branch point can be near, so every group
    keeps its drawn mode on every row and the pass's rows are the tracked ones), the
    events of each sweep (the one sweep, or forwards and backwards from the drawn
    configuration when ``split`` is a row) come from the discriminants by the branch
    rules of :func:`mechsyn.kinematics.tracking.solve_tracked` (folds found and refined
    on the group's discriminant, reassembly, singular rows): a :class:`Folded` (the
    poses, and per sweep its singular rows and events), the tracked chain's answer. None
    when a group's discriminant has such a minimum (the tracked chain decides what happens
    there) or the plan is not such a chain.

    Examples
    --------
    A textbook four-bar (crank sqrt(5), coupler and rocker sqrt(10), frame 5) from 100 to
    260 degrees, one sweep (the drawn crank angle, 63.4 degrees, lies outside it): its
    working range ends and starts again at the law-of-cosines angles 116.565 and 243.435
    degrees, the 31 rows between them not assembled.

    >>> import numpy as np
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.analysis import cached_plan
    >>> kp = cached_plan(ms.examples.load("fourbar"), inputs=("A",))
    >>> res = sweep_through_folds(kp.system, kp.groups, np.radians(np.arange(100.0, 261.0, 4.0))[:, None],
    ...                           np.ones(1), None)
    >>> (singular, events), = res.parts
    >>> [(e.kind, e.index, round(float(np.degrees(e.input[0])), 9)) for e in events]
    [('dead point', 5, 116.565051177), ('dead point', 36, 243.434948823), ('reassembled', 36, 244.0)]
    >>> int(np.isnan(res.q[:, 0]).sum())
    31
    """
    if not plan.closed_form_rates or S.n != 3 * len(S.links):
        return None
    steps, anchor, origin = _program(S, plan)
    paths = _tracking_paths(S, U, split)
    st = _pass(S, plan, [U] + [path for path, _ in paths], speeds, folds=True)
    if not st.near:
        return _poses(S, plan, U, st, origin, split)
    _scalar_memo(S, plan, steps, anchor)
    sigmas = [1.0 if step[0] == "drive" else step[6] for step in steps]  # every group in its drawn mode
    out = pass_fold_events(S, plan, st.discs, sigmas, U, split, paths, block=getattr(st, "D", None))
    if out is None:
        return None
    q, qd, qdd, *links = _fold_poses(S, plan, U, st, origin, split, out)
    return Folded(q, qd, qdd, out, *links)


def _tracking_paths(S: PlanarSystem, U: np.ndarray, split: int | None) -> list:
    """The connecting paths (:func:`mechsyn.kinematics.tracking.tracking_path`) of the
    tracked sweeps of the inputs ``U`` (forwards from row ``split``, backwards from row
    ``split - 1``, or the one sweep from row 0): the last answer is kept with ``S`` by
    the first rows' bytes (a drag or a design loop sweeps the same grid again)."""
    firsts = [U[0]] if split is None else [U[split], U[split - 1]]
    key = (split, *[f.tobytes() for f in firsts])
    memo = geometry_memo(S)
    hit = memo.get("tracking paths")
    if hit is not None and hit[0] == key:
        return hit[1]
    u0 = np.array([d.assembled for d in S.drivers], float)
    paths = [tracking_path(S, f, u0) for f in firsts]
    memo["tracking paths"] = (key, paths)
    return paths


def _scalar_memo(S: PlanarSystem, plan: Plan, steps: list, cx: dict) -> None:
    """Keep with ``S`` the chain as plain numbers for the fold search
    (:func:`mechsyn.kinematics.folds._scalar_program`'s layout) read off the regular
    program (the same local points, squared lengths and rotation vectors, so the same
    numbers) instead of building it again from the groups; made when first read (the
    compiled fold search and the closed-form four-bar folds do not read it)."""
    memo = geometry_memo(S)
    key = ("scalar", id(plan))
    if key not in memo:
        memo[key] = functools.partial(_scalar_of_regular, steps, cx)


def _scalar_of_regular(steps: list, cx: dict) -> list:
    """:func:`_scalar_memo`'s program: the regular program's steps ``steps`` and anchors
    ``cx`` as plain numbers."""
    prog = []
    for st in steps:
        if st[0] == "drive":
            _, new, k, _jid, di, sgn, s_k = st
            prog.append(("drive", new, k, (s_k.real, s_k.imag), di, sgn, (cx[new][1].real, cx[new][1].imag)))
            continue
        _, (k1, k3), (b1, b2), _j, L1s, L2s, _sigma, cbv1, cbv2, s1, s3 = st
        prog.append(("RRR", (k1, (s1.real, s1.imag)), (k3, (s3.real, s3.imag)), (b1, b2), L1s, L2s,
                     (cx[b1][1].real, cx[b1][1].imag), (cx[b2][1].real, cx[b2][1].imag),
                     (cbv1.real, -cbv1.imag), (cbv2.real, -cbv2.imag)))
    return prog


@dataclass
class Folded:
    """A sweep through folds in one pass (:func:`sweep_through_folds`): poses and rates (N,
    n) with NaN rows where the mechanism is not assembled and NaN rates where they are
    not defined (the group folded flat), and per tracked sweep (the one sweep, or the
    sweeps forwards from the drawn input values and backwards) its singular rows and
    events (rows counted along that sweep); from the compiled pass also the links'
    states (:class:`LinkStates`, NaN where the poses are: ``qd``'s and ``qdd``'s angle
    rows are its rates, so rows blanked later are blanked there too) and the rows
    assembled (``assembled``, N); from the compiled pass also the rows whose rates are
    defined (``rates_ok``, N: the singular rows of ``parts`` already blanked) and the
    number of assembled rows whose rates are not (``singular``)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    parts: list
    links: LinkStates | None = None
    assembled: np.ndarray | None = None
    rates_ok: np.ndarray | None = None
    singular: int = 0


def _fold_poses(S: PlanarSystem, plan: Plan, U: np.ndarray, st: _Pass, origin: list, split: int | None,
                parts: list | None = None) -> tuple:
    """The pose rows ``q, qd, qdd`` (N, n) of the sweep ``U`` (the first N rows of the
    pass) through folds: NaN rows where a group is not assembled, NaN rates where they
    are not defined (inf at a group folded flat), each link's angle continuous along
    each tracked sweep from the drawn one. Compiled, also the rates of the fold scan's
    singular rows (``parts``, see :class:`Folded`) blanked."""
    if isinstance(st, _Compiled):  # and the links' states (NaN where the poses are), the rows assembled, with rates
        q, qd, qdd, ok, rates_ok, singular = _compiled_poses(S, plan, U, st, split, True, parts)
        return (q.T, qd.T, qdd.T, LinkStates(st.C[:, :, :U.shape[0]], qd[2::3], qdd[2::3]), ok,
                None if parts is None else rates_ok, singular)
    C, q, qd, qdd = _pose_arrays(S, st, origin, U.shape[0])
    fin = np.isfinite(C[0].view(float)).all(axis=0)  # every link's rotation: real and imaginary parts
    ok = fin[0::2] & fin[1::2]
    parts = (slice(None),) if split is None else (slice(split, None), slice(split - 1, None, -1))
    _link_angles(S, plan, U, C[0].real, C[0].imag, ok, q[2::3], parts=parts)
    rates = np.isfinite(qd).all(axis=0)
    rates &= np.isfinite(qdd).all(axis=0)
    _blank((q, qd, qdd), ok)
    rates |= ~ok  # the rows where rates are not defined though the group is assembled (folded flat)
    _blank((qd, qdd), rates)
    return q.T, qd.T, qdd.T


def _blank(arrays: tuple, keep: np.ndarray) -> None:
    """NaN into the columns of ``arrays`` (n, N) where ``keep`` (N,) is false: by runs of
    columns (a sweep's gaps are a few runs), or all at once when there are many."""
    if keep.all():
        return
    edges = np.flatnonzero(keep[1:] != keep[:-1]).tolist()
    if len(edges) > 16:
        for a in arrays:
            np.copyto(a, np.nan, where=~keep)
        return
    bounds = ([] if keep[0] else [0]) + [e + 1 for e in edges] + ([] if keep[-1] else [len(keep)])
    for a, b in zip(bounds[0::2], bounds[1::2]):
        for x in arrays:
            x[:, a:b] = np.nan


def _pose_arrays(S: PlanarSystem, st: _Pass, origin: list, N: int) -> tuple:
    """The links' complex states (:func:`_states`) and the pose rows ``q, qd, qdd`` (n, N,
    component-major) of the first N rows of a pass, the dyads' link angles left to fill."""
    nl = len(S.links)
    compiled = isinstance(st, _Compiled)
    C = st.C[:, :, :N] if compiled else _states(st, origin, N, nl)
    q, qd, qdd = (np.empty((S.n, N)) for _ in range(3))
    for buf, x in ((q, C[1]), (qd, C[2]), (qdd, C[3])):
        buf[0::3], buf[1::3] = x.real, x.imag
    if compiled:
        qd[2::3], qdd[2::3] = st.W[:, :N], st.AL[:, :N]
        return C, q, qd, qdd
    for i in range(nl):  # angular velocity and acceleration
        for buf, x in ((qd, st.link[i][1]), (qdd, st.link[i][2])):
            buf[3 * i + 2] = x[:N] if isinstance(x, np.ndarray) else x
    return C, q, qd, qdd


def _states(st: _Pass, origin: list, N: int, nl: int) -> np.ndarray:
    """Every link's rotation and its origin's position, velocity, acceleration in the
    first N rows of a pass (4, n_links, N)."""
    C = np.empty((4, nl, N), complex)
    for i in range(nl):
        j = origin[i]
        for k, x in enumerate((st.link[i][0],) + (st.joint[j] if j in st.joint else st.point(i, 0j))):
            C[k, i] = x[:N] if isinstance(x, np.ndarray) else x
    return C


def _poses(S: PlanarSystem, plan: Plan, U: np.ndarray, st: _Pass, origin: list, split: int | None) -> tuple:
    """The pose rows ``q, qd, qdd`` (N, n) of the first N rows of a pass (every link's
    origin is its first joint, its angle continuous from the drawn one) and the links'
    complex states."""
    if isinstance(st, _Compiled):
        q, qd, qdd, *_ = _compiled_poses(S, plan, U, st, split, False)
        return q.T, qd.T, qdd.T, LinkStates(st.C[:, :, :U.shape[0]], qd[2::3], qdd[2::3])
    C, q, qd, qdd = _pose_arrays(S, st, origin, U.shape[0])
    _link_angles(S, plan, U, C[0].real, C[0].imag, None, q[2::3], split)
    return q.T, qd.T, qdd.T, LinkStates(C, qd[2::3], qdd[2::3])


class LinkStates:
    """Every link's rotation ``e^{i phi}`` and the complex position, velocity and
    acceleration of its origin (``C`` (4, n_links, N)), with its angular velocity and
    acceleration (n_links, N): the motion of any point of a link in a few products."""

    def __init__(self, C: np.ndarray, w: np.ndarray, al: np.ndarray) -> None:
        self.C, self.w, self.al = C, w, al

    @property
    def z(self) -> np.ndarray:
        """The links' rotations ``e^{i phi}`` (n_links, N)."""
        return self.C[0]

    def point(self, i: int, s: complex | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (N, 2) of the local point ``s`` (x, y, or a
        complex number) of link ``i``: views of one array (3, N, 2)."""
        C = self.C
        N = C.shape[2]
        got = kernel.point_states(C, self.w, self.al, np.array([i], np.int64),
                                  np.array([s if isinstance(s, complex) else complex(s[0], s[1])]))
        if got is not None:  # compiled
            P, V, A = got[:, 0].view(float).reshape(3, N, 2)
            return P, V, A
        w = self.w[i]
        out = np.empty((3, N), complex)
        rel = C[0, i] * (s if isinstance(s, complex) else complex(s[0], s[1]))
        np.add(rel, C[1, i], out=out[0])
        irel = rel * 1j
        np.multiply(irel, self.al[i], out=out[2])
        irel *= w
        np.add(irel, C[2, i], out=out[1])
        rel *= w ** 2
        out[2] -= rel
        out[2] += C[3, i]
        P, V, A = out.view(float).reshape(3, N, 2)
        return P, V, A

    def points(self, idx: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (m, N, 2) of the local points ``s`` (m,
        complex) of the links ``idx`` (m,, moving links only): :meth:`point` for all of
        them in the same few array operations (the same arithmetic, so the same bits).

        Examples
        --------
        >>> import numpy as np
        >>> from mechsyn.io import load_mechanism
        >>> from mechsyn.kinematics.analysis import compile_plan
        >>> kp = compile_plan(load_mechanism("examples/kinematics/crank_rocker.yaml"), inputs=("A",))
        >>> U = np.radians(np.arange(0.0, 360.0, 30.0))[:, None]
        >>> *_, links = regular_sweep(kp.system, kp.groups, U, np.ones(1), None)
        >>> P, V, A = links.points(np.array([0, 1]), np.array([1 + 0j, 0.5 + 0.2j]))
        >>> P.shape, bool(np.array_equal(A[1], links.point(1, (0.5, 0.2))[2]))
        ((2, 12, 2), True)
        """
        got = kernel.point_states(self.C, self.w, self.al, np.asarray(idx, np.int64), np.asarray(s, complex))
        if got is not None:  # compiled
            P, V, A = got.view(float).reshape(3, *got.shape[1:], 2)
            return P, V, A
        Z = self.C[:, idx]
        rel = Z[0] * s[:, None]
        P = rel + Z[1]
        irel = rel * 1j
        w = self.w[idx]
        A = irel * self.al[idx]
        irel *= w
        V = irel + Z[2]
        rel *= w ** 2
        A -= rel
        A += Z[3]
        m, N = rel.shape
        return tuple(x.view(float).reshape(m, N, 2) for x in (P, V, A))
