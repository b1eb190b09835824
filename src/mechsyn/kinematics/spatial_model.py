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
angle / slide (drives)    ``θ = θ_in``, ``(x_b - x_a) · a = s``  R, H, C, U (angle); P, C (slide)
helix (1 row)             ``s - h θ = 0``                        H
distance (1 row)          ``(|x_a - x_b|² - ℓ²) / 2ℓ = 0``       an S-S bar
========================  =====================================  =============================

with ``x_a``, ``u_a``, ``n_a`` fixed on the pair's first link and ``x_b``, ``w_b`` on its
second. A revolute pair keeps its point and two vectors of the second link perpendicular
to the axis of the first (five equations, the five constraints of a class-5 pair); a
prismatic pair keeps the three frame vectors of the links perpendicular as drawn
(no relative rotation) and the second link's point on the first link's line; and so on.
A *bar* (a link with no other joint than two S pairs, to two other links, and no named
point) is not an unknown: its two pairs are the one distance equation between its ends on
those links (the exact elimination of its pose: five of its six equations fix the bar given
its ends, the sixth is the distance; its spin about its line is an idle motion). Its rates
are those of its ends with no spin: ``ω = d × ḋ / |d|²``; its pose is carried along the sweep
the same way (:func:`bar_motion`): from row to row by the least rotation between its lines,
from the least rotation of its drawn line onto its line at the row nearest the drawn line.
So the pose is defined and continuous wherever the line goes, also through the opposite of
its drawn line (a drag-link's coupler turning fully), where the least rotation from the
drawn line is undefined; no rule that depends on the row's line alone can be (there is no
continuous rotation taking one line to every line: the hairy ball theorem), so the pose
depends on the path (a bar whose line sweeps a loop comes back turned about it).
The equations of a pair are exactly its class, so the rank of the stacked Jacobian is the
rank method's (:mod:`mechsyn.structure.rank`), and redundant constraints only add rows:
the solver takes least-squares, minimum-norm steps.

Lengths are measured from the centre of the joint points in units of the mechanism's
length scale (the largest distance of a joint point from that centre), so every equation
is dimensionless, the solver's tolerances are relative to the length scale, and a
mechanism scaled by 1e-3 or 1e4 gives the same numbers. The file's coordinates carry
rounding of one unit in the last place of their magnitude: ``ulp`` is that rounding in
model units (``eps · max|x| / scale``), the floor of every tolerance, so a mechanism placed
1e6 of its sizes from the origin (or a spherical linkage whose points cluster near its
centre) is not asked to close better than its own coordinates do.

The dot equations of an R pair (its axis perpendicular to two normals of the other link)
also hold with the axis reversed on one link, and those of a P pair (three frame vectors
kept perpendicular) with a half-turn about a frame vector: roots that are not the pair.
:func:`pair_error` measures every pair's relative rotation against the rotation its
reported joint value gives (``Rot(a, θ)`` for R, C and H, the identity for P); a pose is a
true assembly only where that is zero. U and S pairs' equations admit exactly the pair.

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

from dataclasses import dataclass, replace
from typing import Any

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


_I, _I1, _I2 = np.arange(3), np.array([1, 2, 0]), np.array([2, 0, 1])
_SKEW = -_EPS.transpose(2, 0, 1).reshape(3, 9)  # ω @ _SKEW: [ω]x (ω x y = [ω]x y), flattened
_EYE9 = np.eye(3).ravel()


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product over the last axis (fewer NumPy calls than ``np.cross``)."""
    return a[..., _I1] * b[..., _I2] - a[..., _I2] * b[..., _I1]


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return (a * b).sum(axis=-1)


def rotate(R: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``R @ x`` over the last axes for rotations ``R`` (..., k, 3, 3) and vectors ``x`` (k, 3),
    as three products of columns (a stack of 3 x 3 products against a broadcast vector is
    several times slower in NumPy)."""
    return R[..., 0] * x[:, 0, None] + R[..., 1] * x[:, 1, None] + R[..., 2] * x[:, 2, None]


def matvec(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``A @ x`` over the last axes for matrices ``A`` (..., 3, 3) and vectors ``x`` (..., 3)."""
    return A[..., 0] * x[..., 0, None] + A[..., 1] * x[..., 1, None] + A[..., 2] * x[..., 2, None]


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
    dist: _Kind
    angles: _Kind
    slides: _Kind
    angle_joints: tuple[str, ...]
    slide_joints: tuple[str, ...]
    helix: tuple[tuple[int, int, float], ...]
    drives: tuple[tuple[str, str, int], ...]
    lay: "_Layout | None" = None
    ulp: float = float(np.finfo(float).eps)
    pairs: "_Pairs | None" = None
    #: per angle joint (``angle_joints``), its input's value at the drawn assembly (rad):
    #: :func:`input_zero`
    zeros: np.ndarray | None = None
    #: the S-S bars not solved for (their poses from ``dist``'s ends, in order)
    bars: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        return len(self.links)

    @property
    def n_constraints(self) -> int:
        return 3 * self.pc.size + self.dot.size + self.line.size + self.dist.size + len(self.helix)

    @property
    def all_links(self) -> tuple[str, ...]:
        """The moving links solved for, then the bars."""
        return self.links + self.bars

    def local(self, x: np.ndarray) -> np.ndarray:
        """File coordinates -> the model's (centred, in units of the length scale)."""
        return (np.asarray(x, float) - self.centre) / self.scale

    def index(self, link: str) -> int:
        """A link's pose: ``n`` for the frame, above it for a bar (no unknown)."""
        if link in self.bars:
            return self.n + 1 + self.bars.index(link)
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
    if t == "U" and abs(float(a @ _unit(np.asarray(j.axis2, float)))) < 1e-9:
        # a right-angled cross: its two angles, each an angle row with the axis on the link it
        # is fixed to: the second arm turning about the first axis (on the first link), and
        # the first arm turning about the second axis reversed (on the second link: the
        # second link turns by +θ2 about it relative to the first)
        a2 = _unit(np.asarray(j.axis2, float))
        rows["angle"].append((ia, ib, a, a2, a2, np.cross(a, a2), 0.0))
        rows["angle"].append((ib, ia, -a2, a, a, np.cross(-a2, a), 0.0))
        rows["angle_joints"] += [j.id, j.id + "/2"]
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
    if j.actuated and j.type not in ("R", "P", "H", "C", "U"):
        raise MechsynInputError(f"joint {j.id} ({j.type}) is driven, but only R, P, H, C and U pairs can be driven",
                                source=src, field=f"joints[{j.id}].actuated", hint="drive an R, P, H, C or U pair")
    if j.type == "U" and j.axis is not None and j.axis2 is not None and abs(
            float(_unit(np.asarray(j.axis, float)) @ _unit(np.asarray(j.axis2, float)))) > 1e-9 and j.actuated:
        raise MechsynInputError(f"joint {j.id} (U) is driven, but its axes are not at right angles: its two "
                                "angles are defined for a right-angled cross only", source=src,
                                field=f"joints[{j.id}].axis2", hint="make axis2 perpendicular to axis")


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
    bars = _bars(mech)
    links = tuple(link for link in mech.moving_links if link not in bars)
    index = {name: k for k, name in enumerate(links)}
    index[mech.ground] = len(links)
    rows: dict[str, list] = {k: [] for k in ("pc", "dot", "line", "dist", "angle", "slide", "angle_joints",
                                             "slide_joints")}
    local = {j.id: (np.asarray(j.point, float) - centre) / scale for j in mech.joints if j.point is not None}
    for j in mech.joints:
        if not bars.keys() & set(j.links):
            _pair_rows(j, index[j.links[0]], index[j.links[1]], local.get(j.id, np.zeros(3)), rows)
    z = np.zeros(3)
    for bar, (j1, j2) in bars.items():
        a, b = (next(link for link in j.links if link != bar) for j in (j1, j2))
        ell = float(np.linalg.norm(local[j1.id] - local[j2.id]))
        rows["dist"].append((index[a], index[b], local[j1.id], local[j2.id], z, z, ell))
    helix = tuple((rows["angle_joints"].index(j.id), rows["slide_joints"].index(j.id), (j.pitch or 0.0) / scale)
                  for j in mech.joints if j.type == "H")
    drive_rows = []
    for name in drives:
        jid, _, part = name.partition("/")
        j = mech.joint(jid)
        if j.type in ("R", "H", "U") or (j.type == "C" and part == "turn"):
            drive_rows.append((name, "angle", rows["angle_joints"].index(name if j.type == "U" else jid)))
        else:
            drive_rows.append((name, "slide", rows["slide_joints"].index(jid)))
    big = max([float(np.abs(np.asarray(j.point, float)).max()) for j in mech.joints if j.point is not None]
              + [float(np.abs(np.asarray(pt.at, float)).max()) for pt in mech.points.values()], default=0.0)
    M = SpatialModel(mech, links, centre, scale, _kind(rows["pc"]), _kind(rows["dot"]), _kind(rows["line"]),
                     _kind(rows["dist"]), _kind(rows["angle"]), _kind(rows["slide"]), tuple(rows["angle_joints"]),
                     tuple(rows["slide_joints"]), helix, tuple(drive_rows),
                     ulp=float(np.finfo(float).eps) * max(1.0, big / scale), bars=tuple(bars))
    zeros = np.array([input_zero(mech, mech.joint(jid.partition("/")[0])) for jid in M.angle_joints], float)
    return replace(M, lay=_layout(M), pairs=_pairs(mech, index), zeros=zeros)


def _bars(mech: Mechanism) -> dict[str, tuple[Joint, Joint]]:
    """The S-S bars not solved for (see the module doc): link -> its two S pairs, each to
    another link that is not such a bar, their points apart."""
    named = {p.link for p in mech.points.values()}
    cand = {}
    for link in mech.moving_links:
        js = mech.joints_of(link)
        if link not in named and len(js) == 2 and all(j.type == "S" and not j.actuated for j in js):
            ends = [next((x for x in j.links if x != link), link) for j in js]
            if ends[0] != ends[1] and link not in ends and np.linalg.norm(
                    np.subtract(js[0].point, js[1].point)) > 0:
                cand[link] = (js[0], js[1], ends)
    return {link: (j1, j2) for link, (j1, j2, ends) in cand.items() if not cand.keys() & set(ends)}


# --------------------------------------------------------------------------- input zeros
def _p3(v: Any) -> np.ndarray:
    v = np.asarray(v, float)
    return np.pad(v, (0, 3 - len(v)))


def reference_direction(mech: Mechanism, link: str) -> np.ndarray:
    """A link's reference line in the drawn assembly (3-D): from its first joint's point (file
    order) to the first other joint point apart from it, the planar engines' rule (a crank's
    angle is its line's); the frame's is ``+x``, as is that of a link with one point."""
    x = np.array([1.0, 0.0, 0.0])
    if link == mech.ground:
        return x
    pts = [_p3(j.point) for j in mech.joints_of(link) if j.point is not None]
    size = max((float(np.abs(p - pts[0]).max()) for p in pts), default=0.0)
    for p in pts[1:]:
        if np.linalg.norm(p - pts[0]) > 1e-12 * max(size, 1e-300):
            return p - pts[0]
    return x


def planar_as_spatial(mech: Mechanism) -> Mechanism:
    """A planar mechanism as the spatial engine's file: its 3-D equivalent
    (:func:`~mechsyn.structure.screws.as_spatial`: points at ``z = 0``, R axes along ``z``)
    with every R pair's ``zero`` set to the planar zero (the first link's reference line, the
    frame's ``x``), so that an input means the same pose as in the planar engines.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = planar_as_spatial(ms.examples.load("fourbar"))
    >>> m.kind, m.joint("A").attrs["zero"]
    ('spatial', [1.0, 0.0, 0.0])
    """
    from mechsyn.structure.screws import as_spatial

    if mech.kind == "spatial":
        return mech
    out = as_spatial(mech)
    joints = tuple(replace(j, attrs={**j.attrs, "zero": [float(v) for v in reference_direction(mech, j.links[0])]})
                   if j.type == "R" else j for j in out.joints)
    return replace(out, joints=joints)


def input_zero(mech: Mechanism, j: Joint) -> float:
    """The value (rad) of the input of R, H or C pair ``j`` in the drawn assembly: the angle
    about its axis from its zero (on the first link) to the second link's reference line
    (:func:`reference_direction`). The zero is the file's ``zero`` direction; for a planar
    mechanism (axis ``z``) the first link's reference line, so that an input means what the
    planar engines make of it (the angle of the driven link's line, relative to the first
    link's); else there is none and the drawn pose is 0.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("crank_rocker")
    >>> A = m.joint(next(j.id for j in m.joints if j.actuated))
    >>> round(float(np.degrees(input_zero(m, A))), 6) == round(float(np.degrees(np.arctan2(
    ...     *(reference_direction(m, A.links[1])[[1, 0]])))), 6)
    True
    """
    if j.type not in ("R", "H", "C"):
        return 0.0  # (a U pair's angles are measured from the drawn cross)
    z = j.attrs.get("zero")
    planar = mech.kind == "planar"
    if z is None and not planar:
        return 0.0
    a = np.array([0.0, 0.0, 1.0]) if planar else _unit(np.asarray(j.axis, float))
    z = reference_direction(mech, j.links[0]) if z is None else np.asarray(z, float)
    r = reference_direction(mech, j.links[1])
    z, r = z - (z @ a) * a, r - (r @ a) * a
    if not np.linalg.norm(r) > 1e-12 * np.linalg.norm(reference_direction(mech, j.links[1])):
        raise MechsynInputError(
            f"joint {j.id}: link {j.links[1]!r}'s reference line (its first joint to its first other joint) runs "
            "along the axis, so the zero cannot measure its angle", source=mech.source, field=f"joints[{j.id}].zero",
            hint="remove `zero` (the input is then measured from the drawn pose)")
    return float(np.arctan2(a @ np.cross(z, r), z @ r))


# --------------------------------------------------------------------------- pair integrity
@dataclass(frozen=True, eq=False)
class _Pairs:
    """The pairs whose equations admit other roots: R, C, H (axis ``a`` with ``e1``, ``e2``
    perpendicular, ``turns``) and P (``turns`` False), between poses ``ia`` and ``ib``."""

    ids: tuple[str, ...]
    ia: np.ndarray
    ib: np.ndarray
    a: np.ndarray
    e1: np.ndarray
    e2: np.ndarray
    turns: np.ndarray


def _pairs(mech: Mechanism, index: dict[str, int]) -> _Pairs:
    rows = []
    for j in mech.joints:
        if j.type in ("R", "C", "H", "P"):
            a = _unit(np.asarray(j.axis, float))
            e1, e2 = _perp_basis(a)
            rows.append((j.id, index[j.links[0]], index[j.links[1]], a, e1, e2, j.type != "P"))
    if not rows:
        z = np.zeros((0, 3))
        return _Pairs((), np.zeros(0, int), np.zeros(0, int), z, z, z, np.zeros(0, bool))
    ids, ia, ib, a, e1, e2, turns = zip(*rows)
    return _Pairs(ids, np.array(ia), np.array(ib), np.array(a), np.array(e1), np.array(e2), np.array(turns))


def pair_error(M: SpatialModel, R: np.ndarray) -> np.ndarray:
    """Per pose and pair (B, pairs): the largest entry of ``R_rel - Rot(a, θ)`` (R, C, H;
    ``θ`` the pair's joint value read from ``R_rel``) or of ``R_rel - I`` (P), where
    ``R_rel = R_a^T R_b`` is the second link's rotation relative to the first from the drawn
    assembly. Zero (to the residual) on a true assembly; about 2 where an R axis is reversed
    or a P pair half-turned. Because every pair's relative displacement is then the one its
    joint values give, the joint values close every loop (their displacements compose, around
    any loop, to the product of the links' relative poses, which is the identity)."""
    P = M.pairs
    if P is None or not len(P.ia):
        return np.zeros((len(R), 0))
    Rr = np.swapaxes(R[:, P.ia], -1, -2) @ R[:, P.ib]
    r1 = matvec(Rr, P.e1)                                 # R_rel e1 (B, pairs, 3)
    c, s = _dot(r1, P.e1), _dot(r1, P.e2)
    th = np.where(P.turns, np.arctan2(s, c), 0.0)
    K = np.einsum("ijk,nk->nij", -_EPS, P.a)              # [a]x: K y = a x y
    aa = P.a[:, :, None] * P.a[:, None, :]
    ct, st = np.cos(th)[..., None, None], np.sin(th)[..., None, None]
    Rot = ct * np.eye(3) + st * K + (1 - ct) * aa
    return np.abs(Rr - Rot).max(axis=(-1, -2))


# --------------------------------------------------------------------------- layout
@dataclass(frozen=True, eq=False)
class _Layout:
    """Gather and scatter indices of the equations, built once per model: every link-fixed
    point (``pidx``, ``ploc``) and vector (``vidx``, ``vloc``) transformed in one product,
    every variable Jacobian entry written in one scatter (``ri``, ``ci``) over a template
    holding the constant ones, the scalar rows' links (``sa``, ``sb``)."""

    pidx: np.ndarray
    ploc: np.ndarray
    vidx: np.ndarray
    vloc: np.ndarray
    psl: dict
    vsl: dict
    J0: np.ndarray
    ri: np.ndarray
    ci: np.ndarray
    h_ang: np.ndarray
    h_sl: np.ndarray
    h_pitch: np.ndarray
    d_meas: np.ndarray
    d_angle: np.ndarray


def _slices(parts: list[tuple[str, np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray, dict]:
    sl, start = {}, 0
    for name, idx, _ in parts:
        sl[name] = slice(start, start + len(idx))
        start += len(idx)
    idx = np.concatenate([p[1] for p in parts]).astype(int)
    loc = np.concatenate([p[2].reshape(-1, 3) for p in parts])
    return idx, loc, sl


def _layout(M: SpatialModel) -> _Layout:
    pc, dt, ln, an, sl, ds = M.pc, M.dot, M.line, M.angles, M.slides, M.dist
    pidx, ploc, psl = _slices([("xa", pc.ia, pc.va), ("xb", pc.ib, pc.vb), ("la", ln.ia, ln.va),
                               ("lb", ln.ib, ln.vb), ("sa", sl.ia, sl.va), ("sb", sl.ib, sl.vb),
                               ("da", ds.ia, ds.va), ("db", ds.ib, ds.vb)])
    vidx, vloc, vsl = _slices([("u", dt.ia, dt.va), ("w", dt.ib, dt.vb), ("ln", ln.ia, ln.n),
                               ("aa", an.ia, an.va), ("e1b", an.ib, an.vb), ("e1a", an.ia, an.n),
                               ("e2a", an.ia, an.m), ("sn", sl.ia, sl.n)])
    n, k = M.n, pc.size
    m = M.n_constraints + len(M.drives)
    J0 = np.zeros((m, 6 * (n + 1)))
    rows = np.arange(3 * k).reshape(k, 3)
    ar = np.arange(3)
    J0[rows, 6 * pc.ia[:, None] + 3 + ar] = 1.0
    J0[rows, 6 * pc.ib[:, None] + 3 + ar] = -1.0
    ri, ci = [], []
    for links in (pc.ia, pc.ib):  # the 3 x 3 blocks d(x)/dω of the coincidences
        ri.append(np.broadcast_to(rows[:, :, None], (k, 3, 3)).ravel())
        ci.append(np.broadcast_to((6 * links[:, None] + ar)[:, None, :], (k, 3, 3)).ravel())
    h = np.array(M.helix, float).reshape(-1, 3)
    d_angle = np.array([kind == "angle" for _, kind, _ in M.drives], bool)
    d_meas = np.array([kk if kind == "angle" else an.size + kk for _, kind, kk in M.drives], int)
    d_links = [(an.ia[kk], an.ib[kk]) if kind == "angle" else (sl.ia[kk], sl.ib[kk]) for _, kind, kk in M.drives]
    h_sl = h[:, 1].astype(int)
    sa = np.concatenate([dt.ia, ln.ia, ds.ia, sl.ia[h_sl], [a for a, _ in d_links]]).astype(int)
    sb = np.concatenate([dt.ib, ln.ib, ds.ib, sl.ib[h_sl], [b for _, b in d_links]]).astype(int)
    srow = 3 * k + np.arange(len(sa))
    for links in (sa, sb, sa, sb):  # c at a, -c at b, -n at a, +n at b
        ri.append(np.repeat(srow, 3))
        ci.append((6 * links[:, None] + ar).ravel())
    ci[-2:] = [c + 3 for c in ci[-2:]]
    return _Layout(pidx, ploc, vidx, vloc, psl, vsl, J0, np.concatenate(ri), np.concatenate(ci),
                   h[:, 0].astype(int), h[:, 1].astype(int), h[:, 2], d_meas, d_angle)


# --------------------------------------------------------------------------- poses
# Every function below works on a batch of B poses at once: rotations R (B, n + 1, 3, 3),
# positions p (B, n + 1, 3) (the frame last, at rest), twists (B, 6 n), targets (B, drives).
def exp_twists(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rotations ``E`` (k, 3, 3) and translations ``t`` (k, 3) of ``exp`` of the twists
    ``x`` (k, 6) = ``(ω, v)``: the displacement ``y = E y + t`` (Murray et al. [2]_, eq. 2.36).

    Examples
    --------
    >>> E, t = exp_twists(np.array([[0, 0, np.pi / 2, 1.0, 0, 0]]))
    >>> np.round(E[0] @ [1.0, 0, 0], 12).tolist(), np.round(t[0], 6).tolist()
    ([0.0, 1.0, 0.0], [0.63662, 0.63662, 0.0])
    """
    w, v = x[:, :3], x[:, 3:]
    th2 = (w * w).sum(axis=1)
    q = th2 * th2
    # sin θ / θ, (1 - cos θ) / θ², (θ - sin θ) / θ³: their series to θ⁴ below θ = 1e-2 (the
    # next terms under an ulp), most of a Newton walk's steps
    a, b, c = 1 - th2 / 6 + q / 120, 0.5 - th2 / 24 + q / 720, 1.0 / 6 - th2 / 120 + q / 5040
    small = th2 < 1e-4
    if not small.all():
        ths = np.sqrt(np.where(small, 1.0, th2))
        h, s = np.sin(0.5 * ths), np.sin(ths)
        a = np.where(small, a, s / ths)
        b = np.where(small, b, 2 * (h / ths) ** 2)
        c = np.where(small, c, (ths - s) / ths ** 3)
    # E = I + a [ω]x + b [ω]x², [ω]x² = ω ωᵀ - θ² I; t = (I + b [ω]x + c [ω]x²) v
    bw = b[:, None] * w
    E = ((bw[:, :, None] * w[:, None, :]).reshape(-1, 9) + (a[:, None] * w) @ _SKEW
         + (1 - b * th2)[:, None] * _EYE9).reshape(-1, 3, 3)
    wv = _cross(w, v)
    t = v + b[:, None] * wv + c[:, None] * _cross(w, wv)
    return E, t


def move(R: np.ndarray, p: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses ``(R, p)`` displaced by the twists ``x`` (B, 6 n) of the moving links."""
    B, n1 = p.shape[:2]
    E, t = exp_twists(x.reshape(-1, 6))
    E = E.reshape(B, n1 - 1, 3, 3)
    R2, p2 = R.copy(), p.copy()
    R2[:, :-1] = E @ R[:, :-1]
    p2[:, :-1] = matvec(E, p[:, :-1]) + t.reshape(B, n1 - 1, 3)
    return R2, p2


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles to (-π, π]."""
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


class Frame:
    """World coordinates of the model's link-fixed points and vectors at poses ``(R, p)``,
    and the pairs' rotations ``theta`` (rad, from the drawn assembly, in (-π, π]) and slides
    ``s`` (model units), each with the batch axis first. Attributes are views of two arrays
    (see :class:`_Layout`)."""

    def __init__(self, M: SpatialModel, R: np.ndarray, p: np.ndarray) -> None:
        lay = M.lay
        P = rotate(R[:, lay.pidx], lay.ploc) + p[:, lay.pidx]
        V = rotate(R[:, lay.vidx], lay.vloc)
        for name, sl in lay.psl.items():
            setattr(self, name, P[:, sl])
        for name, sl in lay.vsl.items():
            setattr(self, name, V[:, sl])
        self.theta = np.arctan2(_dot(self.e1b, self.e2a), _dot(self.e1b, self.e1a))
        self.s = _dot(self.sb - self.sa, self.sn)

    def take(self, idx: np.ndarray) -> "Frame":
        """The frame of the poses ``idx`` of the batch."""
        out = object.__new__(Frame)
        out.__dict__.update({k: v[idx] for k, v in vars(self).items()})
        return out


# --------------------------------------------------------------------------- equations
def helix_angles(M: SpatialModel, F: Frame, helix_ref: np.ndarray) -> np.ndarray:
    """The H pairs' rotations unwrapped next to ``helix_ref`` (their previous values)."""
    return helix_ref + wrap(F.theta[:, M.lay.h_ang] - helix_ref)


def residual(M: SpatialModel, F: Frame, helix_ref: np.ndarray, target: np.ndarray) -> np.ndarray:
    """Residuals (B, m) of the constraint equations, then of the drives (``target``: input
    values, rad or model units). ``helix_ref``: the H pairs' unwrapped angles before."""
    lay = M.lay
    B = len(target)
    d = np.concatenate([F.theta, F.s], axis=1)[:, lay.d_meas] - target
    d[:, lay.d_angle] = wrap(d[:, lay.d_angle])
    parts = [(F.xa - F.xb).reshape(B, -1), _dot(F.u, F.w) - M.dot.c0, _dot(F.lb - F.la, F.ln) - M.line.c0]
    if M.bars:
        bar, ell = F.da - F.db, M.dist.c0
        parts.append((_dot(bar, bar) - ell * ell) / (2 * ell))
    if M.helix:
        parts.append(F.s[:, lay.h_sl] - lay.h_pitch * helix_angles(M, F, helix_ref))
    parts.append(d)
    return np.concatenate(parts, axis=1)


def _scalar_coefficients(M: SpatialModel, F: Frame) -> tuple[np.ndarray, np.ndarray]:
    """``c`` and ``n`` of the scalar rows, each ``c · (ω_a - ω_b) + n · (v_b - v_a)``."""
    lay = M.lay
    c_slide = _cross(F.sn, F.sb)
    cs = [_cross(F.u, F.w), _cross(F.ln, F.lb)]
    ns = [np.zeros_like(F.u), F.ln]
    if M.bars:
        d = (F.da - F.db) / M.dist.c0[:, None]  # (x_a × d = x_b × d: one c for both links)
        cs.append(_cross(F.da, d))
        ns.append(-d)
    if M.helix:
        cs.append(c_slide[:, lay.h_sl] + lay.h_pitch[:, None] * F.aa[:, lay.h_ang])
        ns.append(F.sn[:, lay.h_sl])
    if M.drives:
        cs.append(np.concatenate([-F.aa, c_slide], axis=1)[:, lay.d_meas])
        ns.append(np.concatenate([np.zeros_like(F.aa), F.sn], axis=1)[:, lay.d_meas])
    return np.concatenate(cs, axis=1), np.concatenate(ns, axis=1)


def jacobian(M: SpatialModel, F: Frame) -> np.ndarray:
    """Jacobians (B, m, 6 n) of :func:`residual` in the links' twists ``(ω_i, v_i)``
    (columns ``6 i .. 6 i + 5``)."""
    lay = M.lay
    B = F.xa.shape[0]
    k = 6 * M.n
    J = np.empty((B, lay.J0.shape[0], k))
    J[:] = lay.J0[:, :k]
    c, nv = _scalar_coefficients(M, F)
    # d(x)/dω = -[x]x, the matrix of y -> y x x: ε_ijk x_k
    Sa = np.einsum("ijk,bnk->bnij", _EPS, F.xa)
    Sb = np.einsum("ijk,bnk->bnij", _EPS, F.xb)
    keep = lay.ci < k  # the frame's columns are not unknowns
    J[:, lay.ri[keep], lay.ci[keep]] = np.concatenate(
        [Sa.reshape(B, -1), -Sb.reshape(B, -1), c.reshape(B, -1), -c.reshape(B, -1), -nv.reshape(B, -1),
         nv.reshape(B, -1)], axis=1)[:, keep]
    return J


def convective(M: SpatialModel, F: Frame, xi: np.ndarray) -> np.ndarray:
    """``γ`` (B, m): the second time derivative of every residual at the twists ``xi``
    (B, 6 n) with ``ξ̇ = 0``, so that the accelerations solve ``J ξ̇ = ü - γ``."""
    lay = M.lay
    B = xi.shape[0]
    X = np.zeros((B, M.n + 1, 6))
    X[:, :-1] = xi.reshape(B, -1, 6)
    w, v = X[..., :3], X[..., 3:]
    pc, dt, ln, an, sl = M.pc, M.dot, M.line, M.angles, M.slides
    wa, wb = w[:, pc.ia], w[:, pc.ib]
    g_pc = _cross(wa, v[:, pc.ia] + _cross(wa, F.xa)) - _cross(wb, v[:, pc.ib] + _cross(wb, F.xb))
    wa, wb = w[:, dt.ia], w[:, dt.ib]
    ud, wd = _cross(wa, F.u), _cross(wb, F.w)
    g_dot = _dot(_cross(wa, ud), F.w) + 2 * _dot(ud, wd) + _dot(F.u, _cross(wb, wd))
    parts = [g_pc.reshape(B, -1), g_dot, _line_gamma(w, v, ln.ia, ln.ib, F.la, F.lb, F.ln)]
    if M.bars:
        ds = M.dist
        wa, wb = w[:, ds.ia], w[:, ds.ib]
        va, vb = v[:, ds.ia] + _cross(wa, F.da), v[:, ds.ib] + _cross(wb, F.db)
        parts.append((_dot(va - vb, va - vb) + _dot(F.da - F.db, _cross(wa, va) - _cross(wb, vb))) / ds.c0)
    if M.helix or M.drives:
        g_slide = _line_gamma(w, v, sl.ia, sl.ib, F.sa, F.sb, F.sn)
        g_angle = _dot(w[:, an.ib] - w[:, an.ia], _cross(w[:, an.ia], F.aa))
        if M.helix:
            parts.append(g_slide[:, lay.h_sl] - lay.h_pitch * g_angle[:, lay.h_ang])
        parts.append(np.concatenate([g_angle, g_slide], axis=1)[:, lay.d_meas])
    return np.concatenate(parts, axis=1)


def _line_gamma(w: np.ndarray, v: np.ndarray, ia: np.ndarray, ib: np.ndarray, xa: np.ndarray,
                xb: np.ndarray, nv: np.ndarray) -> np.ndarray:
    """``γ`` of ``(x_b - x_a) · n_a``."""
    wa, wb = w[:, ia], w[:, ib]
    va, vb = v[:, ia] + _cross(wa, xa), v[:, ib] + _cross(wb, xb)
    nd = _cross(wa, nv)
    return (_dot(_cross(wb, vb) - _cross(wa, va), nv) + 2 * _dot(vb - va, nd)
            + _dot(xb - xa, _cross(wa, nd)))


# --------------------------------------------------------------------------- bars
def _bar_frames(d0: np.ndarray, d: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Rotations (N, bars, 3, 3) of the bars with drawn lines ``d0`` (bars, 3) along their
    lines ``d`` (N, bars, 3) over the rows of a sweep (``ok``: the rows assembled), carried
    along the sweep with no spin about their lines (see :func:`bar_motion`).

    Each row's rotation is written ``T = C Rot(u_0, φ)``: a chart ``C`` taking the drawn unit
    line ``u_0`` to the line ``u`` (the least rotation from ``u_0`` where ``u · u_0 ≥ 0``, else
    a half-turn about ``e_1`` then the least rotation from ``-u_0``: both well conditioned),
    turned first about the drawn line by the bar's spin ``φ``. Between consecutive assembled
    rows the bar turns by the least rotation ``Q`` from one line to the next (its discrete
    parallel transport), which adds ``δ = atan2(Q a_k · b_{k+1}, Q a_k · a_{k+1})`` to ``φ``
    (``a``, ``b``: the chart's images of ``e_1``, ``e_2``); so ``φ`` is a cumulative sum, zero
    at each stretch's row nearest the drawn line."""
    u0 = d0 / np.linalg.norm(d0, axis=1)[:, None]
    e1 = _cross(u0, np.eye(3)[np.argmin(np.abs(u0), axis=1)])  # (⟂ u_0, as _perp_basis)
    e1 /= np.sqrt(_dot(e1, e1))[:, None]
    e2 = _cross(u0, e1)
    u = d / np.sqrt(_dot(d, d))[..., None]
    c = _dot(u0, u)
    s = np.where(c >= 0, 1.0, -1.0)[..., None]
    h, den = s * u0 + u, (1 + np.abs(c))[..., None]
    a = e1 - h * _dot(u, e1)[..., None] / den
    b = s * (e2 - h * _dot(u, e2)[..., None] / den)
    ck = _dot(u[:-1], u[1:])[..., None]
    qa = a[:-1] - (u[:-1] + u[1:]) * _dot(u[1:], a[:-1])[..., None] / np.where(1 + ck > 1e-8, 1 + ck, np.inf)
    link = (ok[:-1] & ok[1:])[:, None]
    delta = np.where(link, np.arctan2(_dot(qa, b[1:]), _dot(qa, a[1:])), 0.0)
    phi = np.concatenate([np.zeros((1, len(d0))), np.cumsum(delta, axis=0)])
    edges = np.flatnonzero(np.diff(np.concatenate([[0], ok.astype(int), [0]])))
    cols = np.arange(len(d0))
    for lo, hi in zip(edges[::2], edges[1::2]):  # each stretch of assembled rows from its anchor
        phi[lo:hi] -= phi[lo + np.argmax(c[lo:hi], axis=0), cols]
    phi[~ok] = 0.0
    cp, sp = np.cos(phi)[..., None], np.sin(phi)[..., None]
    A, Bv = cp * a + sp * b, cp * b - sp * a
    return A[..., :, None] * e1[:, None, :] + Bv[..., :, None] * e2[:, None, :] + u[..., :, None] * u0[:, None, :]


def bar_motion(M: SpatialModel, R: np.ndarray, p: np.ndarray, xi: np.ndarray,
               xid: np.ndarray, ok: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
    """Poses ``(R, p)`` (N, links, ...) and twists ``ξ``, ``ξ̇`` (N, 6 links) of
    :attr:`SpatialModel.all_links` from those of the links solved for (the frame's pose not
    included), over the rows of a sweep in order (``ok``: the rows assembled; default all).
    Each bar runs between its ends ``y_1``, ``y_2`` on the links it joins, on the line
    ``d = y_2 - y_1``, moving at ``ω = d × ḋ / |d|²``, ``ω̇ = d × d̈ / |d|²`` (no spin about its
    line: its spin is an idle motion) and ``v = ẏ_1 - ω × y_1``, ``v̇ = ÿ_1 - ω̇ × y_1 - ω × ẏ_1``.

    Its rotation is carried along the sweep the same way, with no spin (:func:`_bar_frames`):
    from one assembled row to the next it turns by the least rotation between their lines,
    and in each stretch of assembled rows the row nearest the drawn line (largest
    ``d_0 · d``) is the least rotation from the drawn line ``d_0``. No rule that depends on
    the line alone can do this: a rotation taking ``d_0`` to every line ``d`` continuously
    would be a continuous section of ``SO(3) -> S²``, which does not exist (hairy ball
    theorem); the least rotation, ``cos I + [k]x + k kᵀ / (1 + cos)`` with ``k = d_0 × d``, is
    undefined where ``d`` is opposite ``d_0`` (a drag-link's coupler turning fully). The price
    of continuity: the pose depends on the path, not on the row's line alone (a bar brought
    back to its line along a loop has turned about it by the solid angle its line swept) and,
    by the square of the step, on the rows sampled; a row not assembled (but with poses)
    takes its chart's rotation."""
    N, n = len(R), M.n
    if not M.bars:
        return R, p, xi, xid
    ds = M.dist
    z = np.zeros((N, 1, 6))
    X, Xd = (np.concatenate([x.reshape(N, n, 6), z], axis=1) for x in (xi, xid))
    R1 = np.concatenate([R, np.broadcast_to(np.eye(3), (N, 1, 3, 3))], axis=1)
    p1 = np.concatenate([p, np.zeros((N, 1, 3))], axis=1)
    ends = []
    for i, x0 in ((ds.ia, ds.va), (ds.ib, ds.vb)):
        y = rotate(R1[:, i], x0) + p1[:, i]
        w, v, wd, vd = X[:, i, :3], X[:, i, 3:], Xd[:, i, :3], Xd[:, i, 3:]
        yd = v + _cross(w, y)
        ends.append((y, yd, vd + _cross(wd, y) + _cross(w, yd)))
    (y1, y1d, y1dd), (y2, y2d, y2dd) = ends
    d = y2 - y1
    Rb = _bar_frames(ds.vb - ds.va, d, np.ones(N, bool) if ok is None else np.asarray(ok, bool))
    pb = 0.5 * (y1 + y2 - rotate(Rb, ds.va + ds.vb))
    l2 = _dot(d, d)[..., None]
    w, wd = _cross(d, y2d - y1d) / l2, _cross(d, y2dd - y1dd) / l2
    Xb = np.concatenate([w, y1d - _cross(w, y1)], axis=2)
    Xbd = np.concatenate([wd, y1dd - _cross(wd, y1) - _cross(w, y1d)], axis=2)
    return (np.concatenate([R, Rb], axis=1), np.concatenate([p, pb], axis=1),
            np.concatenate([X[:, :n], Xb], axis=1).reshape(N, -1),
            np.concatenate([Xd[:, :n], Xbd], axis=1).reshape(N, -1))
