"""The constraint equations of a spatial mechanism in link poses, their Jacobian in twist
form and the convective terms of the accelerations (used by :mod:`mechsyn.kinematics.spatial`).

Every moving link ``i`` carries a pose ``(R_i, p_i)`` (``x = R_i x_0 + p_i`` maps its points
from the drawn assembly to where they are now; all poses are the identity in the drawn
assembly, so a point or axis of the file is its own link-fixed coordinate). A motion of the
link is the spatial twist ``ξ_i = (ω_i, v_i)`` (``v_i``: velocity of the point at the
origin), so a point fixed on it moves at ``ẋ = v_i + ω_i × x`` and a vector at ``u̇ = ω_i × u``.
Each pair is written as a few scalar equations of four kinds, each with its exact
Jacobian row in the twists of its two links and its convective term
``γ = d²g/dt²`` at ``ξ̇ = 0`` (so ``J ξ̇ = g̈ - γ``):

========================  =====================================  =============================
kind                      equation                               pairs
========================  =====================================  =============================
coincidence (3 rows)      ``x_a - x_b = 0``                      R, U, S
dot (1 row)               ``u_a · w_b = u_0 · w_0``              R (2), U (1), C, H (2), P (3)
line (1 row)              ``(x_b - x_a) · n_a = 0``              C, H, P (2 each)
angle / slide (drives)    ``θ = θ_in``, ``(x_b - x_a) · a = s``  R, H (angle); P (slide)
helix (1 row)             ``s - h θ = 0``                        H
========================  =====================================  =============================

with ``x_a``, ``u_a``, ``n_a`` fixed on the pair's first link and ``x_b``, ``w_b`` on its
second. A revolute pair keeps its point and two vectors of the second link perpendicular
to the axis of the first (five equations, the five constraints of a class-5 pair); a
prismatic pair keeps the three frame vectors of the links perpendicular as drawn
(no relative rotation) and the second link's point on the first link's line; and so on.
The equations of a pair are exactly its class, so the rank of the stacked Jacobian is the
rank method's (:mod:`mechsyn.structure.rank`), and redundant constraints only add rows:
the solver takes least-squares, minimum-norm steps.

Lengths are measured from the centre of the joint points in units of the mechanism's
length scale (the largest distance of a joint point from that centre), so every equation
is dimensionless, the solver's tolerances are relative to the length scale, and a
mechanism scaled by 1e-3 or 1e4 gives the same numbers.

References
----------
.. [1] J. M. McCarthy and G. S. Soh, *Geometric Design of Linkages*, 2nd ed., Springer,
   2011, ch. 2-3 (spatial displacements, twists, constraint equations of the pairs).
.. [2] R. M. Murray, Z. Li and S. S. Sastry, *A Mathematical Introduction to Robotic
   Manipulation*, CRC Press, 1994, sec. 2.3-2.4 (the exponential of a twist).
.. [3] E. J. Haug, *Computer Aided Kinematics and Dynamics of Mechanical Systems*, Allyn
   and Bacon, 1989, ch. 9 (constraint equations of spatial joints in absolute coordinates;
   the right-hand side ``γ`` of the acceleration equations).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.structure.screws import _perp_basis, _unit

__all__ = ["SpatialModel", "compile_spatial", "SPATIAL_PAIRS", "exp_twists"]

#: Pair types the spatial engine moves.
SPATIAL_PAIRS = ("R", "P", "C", "U", "S", "H")

_EPS = np.zeros((3, 3, 3))
_EPS[0, 1, 2] = _EPS[1, 2, 0] = _EPS[2, 0, 1] = 1.0
_EPS[0, 2, 1] = _EPS[2, 1, 0] = _EPS[1, 0, 2] = -1.0


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of (k, 3) arrays."""
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


def _rows(x: np.ndarray) -> np.ndarray:
    return np.asarray(x, float).reshape(-1, 3)


@dataclass(frozen=True, eq=False)
class _Kind:
    """The equations of one kind: link indices ``ia``, ``ib`` and link-fixed vectors."""

    ia: np.ndarray
    ib: np.ndarray
    va: np.ndarray        # x_a (coincidence, line, slide) or u_a (dot, angle axis)
    vb: np.ndarray        # x_b or w_b
    n: np.ndarray         # n_a (line, slide); e1 of the first link (angle)
    m: np.ndarray         # e2 of the first link (angle)
    c0: np.ndarray

    @property
    def size(self) -> int:
        return len(self.ia)


def _kind(rows: list[tuple]) -> _Kind:
    z = np.zeros((0, 3))
    if not rows:
        return _Kind(np.zeros(0, int), np.zeros(0, int), z, z, z, z, np.zeros(0))
    ia, ib, va, vb, n, m, c0 = zip(*rows)
    return _Kind(np.array(ia), np.array(ib), _rows(va), _rows(vb), _rows(n), _rows(m), np.array(c0, float))


@dataclass(frozen=True, eq=False)
class SpatialModel:
    """A spatial mechanism compiled into its constraint equations (see the module doc).

    ``links`` are the moving links (pose ``k``); the frame is pose ``len(links)``.
    ``angles`` and ``slides`` measure the R/H/C rotations and P/H/C slides of the pairs
    named in ``angle_joints`` and ``slide_joints`` (drives and the coordinates reported);
    ``drives`` lists ``(joint id, "angle" | "slide", index)`` in the order of the inputs;
    ``helix`` holds ``(angle index, slide index, pitch / scale)`` of the H pairs.
    """

    mech: Mechanism
    links: tuple[str, ...]
    centre: np.ndarray
    scale: float
    pc: _Kind
    dot: _Kind
    line: _Kind
    angles: _Kind
    slides: _Kind
    angle_joints: tuple[str, ...]
    slide_joints: tuple[str, ...]
    helix: tuple[tuple[int, int, float], ...]
    drives: tuple[tuple[str, str, int], ...]

    @property
    def n(self) -> int:
        return len(self.links)

    @property
    def n_constraints(self) -> int:
        return 3 * self.pc.size + self.dot.size + self.line.size + len(self.helix)

    def local(self, x: np.ndarray) -> np.ndarray:
        """File coordinates -> the model's (centred, in units of the length scale)."""
        return (np.asarray(x, float) - self.centre) / self.scale

    def index(self, link: str) -> int:
        return self.n if link == self.mech.ground else self.links.index(link)


def _pair_rows(j: Joint, ia: int, ib: int, x: np.ndarray | None, rows: dict[str, list]) -> None:
    """Append the equations of pair ``j`` (between poses ``ia`` and ``ib``) to ``rows``."""
    z = np.zeros(3)
    t = j.type
    a = _unit(np.asarray(j.axis, float)) if j.axis is not None else None
    if t in ("R", "U", "S"):
        rows["pc"].append((ia, ib, x, x, z, z, 0.0))
    if t in ("R", "C", "H"):
        n1, n2 = _perp_basis(a)
        rows["dot"] += [(ia, ib, a, n1, z, z, 0.0), (ia, ib, a, n2, z, z, 0.0)]
    if t == "U":
        a2 = _unit(np.asarray(j.axis2, float))
        rows["dot"].append((ia, ib, a, a2, z, z, float(a @ a2)))
    if t == "P":
        e = np.eye(3)
        rows["dot"] += [(ia, ib, e[0], e[1], z, z, 0.0), (ia, ib, e[1], e[2], z, z, 0.0),
                        (ia, ib, e[2], e[0], z, z, 0.0)]
    if t in ("P", "C", "H"):
        n1, n2 = _perp_basis(a)
        rows["line"] += [(ia, ib, x, x, n1, z, 0.0), (ia, ib, x, x, n2, z, 0.0)]
    if t in ("R", "C", "H"):
        e1, e2 = _perp_basis(a)
        rows["angle"].append((ia, ib, a, e1, e1, e2, 0.0))
        rows["angle_joints"].append(j.id)
    if t in ("P", "C", "H"):
        rows["slide"].append((ia, ib, x, x, a, z, 0.0))
        rows["slide_joints"].append(j.id)


def _check_joint(mech: Mechanism, j: Joint) -> None:
    src = mech.source
    if j.type not in SPATIAL_PAIRS:
        raise MechsynInputError(
            f"joint {j.id} is a {j.type} pair: spatial kinematics moves R, P, C, U, S and H pairs",
            source=src, field=f"joints[{j.id}].type", hint="model the pair with R, P, C, U, S or H pairs")
    if j.type != "P" and j.point is None:
        raise MechsynInputError(f"joint {j.id} ({j.type}) has no point", source=src,
                                field=f"joints[{j.id}].point", hint="give point: [x, y, z]")
    if j.type != "S" and j.axis is None:
        raise MechsynInputError(f"joint {j.id} ({j.type}) has no axis", source=src,
                                field=f"joints[{j.id}].axis", hint="give axis: [dx, dy, dz]")
    if j.type == "U" and j.axis2 is None:
        raise MechsynInputError(f"joint {j.id} (U) has no axis2", source=src, field=f"joints[{j.id}].axis2",
                                hint="give axis2: the cross's arm fixed in the second link")
    if j.actuated and j.type not in ("R", "P", "H"):
        raise MechsynInputError(f"joint {j.id} ({j.type}) is driven, but only R, P and H pairs can be driven "
                                "(one input each)", source=src, field=f"joints[{j.id}].actuated",
                                hint="drive an R, P or H pair (split a C pair into R + P)")


def compile_spatial(mech: Mechanism, drives: tuple[str, ...]) -> SpatialModel:
    """The constraint equations of ``mech`` with the pairs ``drives`` driven.

    Raises :class:`~mechsyn.errors.MechsynInputError` naming the joint and the fix for a
    pair the engine does not move, missing geometry or an input on an undriven pair.
    """
    for j in mech.joints:
        _check_joint(mech, j)
    pts = np.array([np.asarray(j.point, float) for j in mech.joints if j.point is not None]).reshape(-1, 3)
    centre = pts.mean(axis=0) if len(pts) else np.zeros(3)
    spread = float(np.max(np.linalg.norm(pts - centre, axis=1))) if len(pts) else 0.0
    scale = spread if spread > 0 else max(1.0, float(np.abs(centre).max(initial=0.0)))
    links = tuple(mech.moving_links)
    index = {name: k for k, name in enumerate(links)}
    index[mech.ground] = len(links)
    rows: dict[str, list] = {k: [] for k in ("pc", "dot", "line", "angle", "slide", "angle_joints", "slide_joints")}
    for j in mech.joints:
        x = (np.asarray(j.point, float) - centre) / scale if j.point is not None else np.zeros(3)
        _pair_rows(j, index[j.links[0]], index[j.links[1]], x, rows)
    helix = tuple((rows["angle_joints"].index(j.id), rows["slide_joints"].index(j.id), (j.pitch or 0.0) / scale)
                  for j in mech.joints if j.type == "H")
    drive_rows = []
    for jid in drives:
        j = mech.joint(jid)
        if j.type in ("R", "H"):
            drive_rows.append((jid, "angle", rows["angle_joints"].index(jid)))
        else:
            drive_rows.append((jid, "slide", rows["slide_joints"].index(jid)))
    return SpatialModel(mech, links, centre, scale, _kind(rows["pc"]), _kind(rows["dot"]), _kind(rows["line"]),
                        _kind(rows["angle"]), _kind(rows["slide"]), tuple(rows["angle_joints"]),
                        tuple(rows["slide_joints"]), helix, tuple(drive_rows))


# --------------------------------------------------------------------------- poses
def exp_twists(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations ``E`` (k, 3, 3) and translations ``t`` (k, 3) of ``exp`` of the twists
    ``x`` (k, 6) = ``(ω, v)``: the displacement ``y = E y + t`` (Murray et al. [2]_, eq. 2.36).

    Examples
    --------
    >>> E, t = exp_twists(np.array([[0, 0, np.pi / 2, 1.0, 0, 0]]))
    >>> np.round(E[0] @ [1.0, 0, 0], 12).tolist(), np.round(t[0], 12).tolist()
    ([0.0, 1.0, 0.0], [0.63662, 0.63662, 0.0])
    """
    w, v = x[:, :3], x[:, 3:]
    th = np.sqrt(np.einsum("ij,ij->i", w, w))
    K = np.einsum("ijk,nk->nij", -_EPS, w)
    K2 = K @ K
    small = th < 1e-8
    ths = np.where(small, 1.0, th)
    a = np.where(small, 1.0 - th ** 2 / 6, np.sin(ths) / ths)
    b = np.where(small, 0.5 - th ** 2 / 24, (1 - np.cos(ths)) / ths ** 2)
    c = np.where(small, 1.0 / 6 - th ** 2 / 120, (ths - np.sin(ths)) / ths ** 3)
    eye = np.eye(3)
    E = eye + a[:, None, None] * K + b[:, None, None] * K2
    V = eye + b[:, None, None] * K + c[:, None, None] * K2
    return E, np.einsum("nij,nj->ni", V, v)


def move(R: np.ndarray, p: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses ``(R, p)`` of all links (frame last) displaced by the twists ``x`` (6 n,)."""
    E, t = exp_twists(x.reshape(-1, 6))
    R2, p2 = R.copy(), p.copy()
    R2[:-1] = E @ R[:-1]
    p2[:-1] = np.einsum("nij,nj->ni", E, p[:-1]) + t
    return R2, p2


def _apply(R: np.ndarray, p: np.ndarray | None, idx: np.ndarray, v: np.ndarray) -> np.ndarray:
    out = np.einsum("kij,kj->ki", R[idx], v)
    return out if p is None else out + p[idx]


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles to (-π, π]."""
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


def measures(M: SpatialModel, R: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotation angles (rad, in (-π, π], from the drawn assembly) of ``M.angle_joints``
    and slides (model units) of ``M.slide_joints``."""
    A, S = M.angles, M.slides
    e1b = _apply(R, None, A.ib, A.vb)
    th = np.arctan2(np.einsum("ij,ij->i", e1b, _apply(R, None, A.ia, A.m)),
                    np.einsum("ij,ij->i", e1b, _apply(R, None, A.ia, A.n)))
    d = _apply(R, p, S.ib, S.vb) - _apply(R, p, S.ia, S.va)
    s = np.einsum("ij,ij->i", d, _apply(R, None, S.ia, S.n))
    return th, s


# --------------------------------------------------------------------------- equations
@dataclass
class Frame:
    """World coordinates of the model's link-fixed points and vectors at one pose."""

    xa: np.ndarray    # coincidences
    xb: np.ndarray
    u: np.ndarray     # dot
    w: np.ndarray
    la: np.ndarray    # line
    lb: np.ndarray
    ln: np.ndarray
    aa: np.ndarray    # angle axes
    sa: np.ndarray    # slides
    sb: np.ndarray
    sn: np.ndarray


def frame(M: SpatialModel, R: np.ndarray, p: np.ndarray) -> Frame:
    """The model's points and vectors at poses ``(R, p)``."""
    pc, dt, ln, an, sl = M.pc, M.dot, M.line, M.angles, M.slides
    return Frame(_apply(R, p, pc.ia, pc.va), _apply(R, p, pc.ib, pc.vb), _apply(R, None, dt.ia, dt.va),
                 _apply(R, None, dt.ib, dt.vb), _apply(R, p, ln.ia, ln.va), _apply(R, p, ln.ib, ln.vb),
                 _apply(R, None, ln.ia, ln.n), _apply(R, None, an.ia, an.va), _apply(R, p, sl.ia, sl.va),
                 _apply(R, p, sl.ib, sl.vb), _apply(R, None, sl.ia, sl.n))


def residual(M: SpatialModel, F: Frame, theta: np.ndarray, s: np.ndarray, helix_ref: np.ndarray,
             target: np.ndarray) -> np.ndarray:
    """Residuals of the constraint equations, then of the drives (``target``: input values,
    rad or model units). ``helix_ref``: the H pairs' unwrapped angles at the previous pose."""
    parts = [(F.xa - F.xb).ravel(), np.einsum("ij,ij->i", F.u, F.w) - M.dot.c0,
             np.einsum("ij,ij->i", F.lb - F.la, F.ln) - M.line.c0]
    if M.helix:
        ia, isl, h = (np.array(c) for c in zip(*M.helix))
        th = helix_ref + wrap(theta[ia] - helix_ref)
        parts.append(s[isl] - h * th)
    drive = [wrap(theta[k] - u) if kind == "angle" else s[k] - u for (_, kind, k), u in zip(M.drives, target)]
    parts.append(np.array(drive, float))
    return np.concatenate(parts)


def jacobian(M: SpatialModel, F: Frame) -> np.ndarray:
    """Jacobian of :func:`residual` in the links' twists ``(ω_i, v_i)`` (columns ``6 i .. 6 i + 5``)."""
    n = M.n
    J = np.zeros((M.n_constraints + len(M.drives), 6 * (n + 1)))
    r = 0
    k = M.pc.size
    if k:
        rows = r + np.arange(3 * k).reshape(k, 3)
        for links, x, sign in ((M.pc.ia, F.xa, 1.0), (M.pc.ib, F.xb, -1.0)):
            cols = 6 * links[:, None] + np.arange(3)
            # d(x)/dω = -[x]x, the matrix of y -> y x x
            J[rows[:, :, None], cols[:, None, :]] = sign * np.einsum("ijk,nk->nij", _EPS, x)
            J[rows[:, :, None], cols[:, None, :] + 3] = sign * np.eye(3)
        r += 3 * k
    r = _scalar_rows(J, r, M.dot.ia, M.dot.ib, _cross(F.u, F.w), None)
    r = _scalar_rows(J, r, M.line.ia, M.line.ib, _cross(F.ln, F.lb), F.ln)
    for ia_, isl, h in M.helix:
        J[r] = _slide_row(M, F, isl, n) - h * _angle_row(M, F, ia_, n)
        r += 1
    for _, kind, k in M.drives:
        J[r] = _angle_row(M, F, k, n) if kind == "angle" else _slide_row(M, F, k, n)
        r += 1
    return J[:, :6 * n]


def _scalar_rows(J: np.ndarray, r: int, ia: np.ndarray, ib: np.ndarray, c: np.ndarray,
                 nv: np.ndarray | None) -> int:
    """Rows ``c · (ω_a - ω_b) + n · (v_b - v_a)`` (the dot and line kinds)."""
    k = len(ia)
    if not k:
        return r
    rows = (r + np.arange(k))[:, None]
    ar = np.arange(3)
    J[rows, 6 * ia[:, None] + ar] += c
    J[rows, 6 * ib[:, None] + ar] -= c
    if nv is not None:
        J[rows, 6 * ia[:, None] + 3 + ar] -= nv
        J[rows, 6 * ib[:, None] + 3 + ar] += nv
    return r + k


def _angle_row(M: SpatialModel, F: Frame, k: int, n: int) -> np.ndarray:
    row = np.zeros(6 * (n + 1))
    a = F.aa[k]
    row[6 * M.angles.ib[k]:6 * M.angles.ib[k] + 3] += a
    row[6 * M.angles.ia[k]:6 * M.angles.ia[k] + 3] -= a
    return row


def _slide_row(M: SpatialModel, F: Frame, k: int, n: int) -> np.ndarray:
    row = np.zeros(6 * (n + 1))
    a, b = 6 * M.slides.ia[k], 6 * M.slides.ib[k]
    c = np.cross(F.sn[k], F.sb[k])
    row[a:a + 3] += c
    row[b:b + 3] -= c
    row[a + 3:a + 6] -= F.sn[k]
    row[b + 3:b + 6] += F.sn[k]
    return row


def convective(M: SpatialModel, F: Frame, xi: np.ndarray) -> np.ndarray:
    """``γ``: the second time derivative of every residual at the twists ``xi`` (6 n,)
    with ``ξ̇ = 0``, so that the accelerations solve ``J ξ̇ = ü - γ``."""
    X = np.vstack([xi.reshape(-1, 6), np.zeros((1, 6))])
    w, v = X[:, :3], X[:, 3:]

    def vel(idx: np.ndarray, x: np.ndarray) -> np.ndarray:
        return v[idx] + _cross(w[idx], x)

    pc, dt, ln, an, sl = M.pc, M.dot, M.line, M.angles, M.slides
    g_pc = _cross(w[pc.ia], vel(pc.ia, F.xa)) - _cross(w[pc.ib], vel(pc.ib, F.xb))
    wa, wb = w[dt.ia], w[dt.ib]
    ud, wd = _cross(wa, F.u), _cross(wb, F.w)
    g_dot = (np.einsum("ij,ij->i", _cross(wa, ud), F.w) + 2 * np.einsum("ij,ij->i", ud, wd)
             + np.einsum("ij,ij->i", F.u, _cross(wb, wd)))
    g_line = _line_gamma(w, v, ln.ia, ln.ib, F.la, F.lb, F.ln)
    g_slide = _line_gamma(w, v, sl.ia, sl.ib, F.sa, F.sb, F.sn)
    g_angle = np.einsum("ij,ij->i", w[an.ib] - w[an.ia], _cross(w[an.ia], F.aa))
    parts = [g_pc.ravel(), g_dot, g_line]
    if M.helix:
        parts.append(np.array([g_slide[isl] - h * g_angle[ia_] for ia_, isl, h in M.helix]))
    parts.append(np.array([g_angle[k] if kind == "angle" else g_slide[k] for _, kind, k in M.drives], float))
    return np.concatenate(parts)


def _line_gamma(w: np.ndarray, v: np.ndarray, ia: np.ndarray, ib: np.ndarray, xa: np.ndarray,
                xb: np.ndarray, nv: np.ndarray) -> np.ndarray:
    """``γ`` of ``(x_b - x_a) · n_a``."""
    wa, wb = w[ia], w[ib]
    va, vb = v[ia] + _cross(wa, xa), v[ib] + _cross(wb, xb)
    dd = vb - va
    ddd = _cross(wb, vb) - _cross(wa, va)
    nd = _cross(wa, nv)
    return (np.einsum("ij,ij->i", ddd, nv) + 2 * np.einsum("ij,ij->i", dd, nd)
            + np.einsum("ij,ij->i", xb - xa, _cross(wa, nd)))
