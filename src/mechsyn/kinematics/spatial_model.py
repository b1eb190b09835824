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

import importlib
from dataclasses import dataclass, replace
from types import ModuleType
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.structure.screws import _perp_basis, _unit

__all__ = ["SpatialModel", "compile_spatial", "SPATIAL_PAIRS", "move", "tables"]

#: Pair types the spatial engine moves.
SPATIAL_PAIRS = ("R", "P", "C", "U", "S", "H")


#: The inputs a pair takes: its id, and for a C pair ``<id>/turn``, for a U pair ``<id>/2``.
INPUT_NAMES = {"R": ("",), "H": ("",), "P": ("",), "C": ("", "/turn"), "U": ("", "/2")}


def input_kind(mech: Mechanism, name: str) -> str:
    """The pair type an input ``name`` moves as: ``"R"`` for an angle (R, a C pair's turn,
    a U pair's angles), ``"H"`` for an H pair's, ``"P"`` for a slide (P, a C pair's slide)."""
    jid, _, part = name.partition("/")
    t = mech.joint(jid).type
    return "P" if t == "P" or (t == "C" and not part) else ("H" if t == "H" else "R")


#: The kinds of equations' items (link-fixed points and vectors on the two links of a pair) and
#: their codes in the compiled tables (:func:`tables`): a slide's item is a line's.
ITEMS = {"pc": 0, "dot": 1, "line": 2, "dist": 3, "angle": 4, "slide": 2}


@dataclass(frozen=True, eq=False)
class SpatialModel:
    """A spatial mechanism compiled into its constraint equations (see the module doc).

    ``links`` are the moving links (pose ``k``); the frame is pose ``len(links)``.
    The equations measure the R/H/C rotations and P/H/C slides of the pairs named in
    ``angle_joints`` and ``slide_joints`` (drives and the coordinates reported);
    ``drives`` lists ``(joint id, "angle" | "slide", index)`` in the order of the inputs;
    ``helix`` holds ``(angle index, slide index, pitch / scale)`` of the H pairs.
    """

    mech: Mechanism
    links: tuple[str, ...]
    centre: np.ndarray
    scale: float
    angle_joints: tuple[str, ...]
    slide_joints: tuple[str, ...]
    helix: tuple[tuple[int, int, float], ...]
    drives: tuple[tuple[str, str, int], ...]
    #: the equations as the compiled functions' tables (:func:`tables`)
    tables: tuple = ()
    ulp: float = float(np.finfo(float).eps)
    pairs: "_Pairs | None" = None
    #: per angle joint (``angle_joints``), its input's value at the drawn assembly (rad):
    #: :func:`input_zero`
    zeros: np.ndarray | None = None
    #: per slide joint (``slide_joints``), its input's value at the drawn assembly (model units):
    #: its attribute ``slide0`` (the spatial engine's of a planar P joint), else 0
    slide0: np.ndarray | None = None
    #: the S-S bars not solved for (their poses from the ends of their distance equations, in order)
    bars: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        return len(self.links)

    @property
    def n_constraints(self) -> int:
        return len(self.tables[2]) - len(self.drives)

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
    n1, n2 = _perp_basis(a) if a is not None else (z, z)
    if t in ("R", "U", "S"):
        rows["pc"].append((ia, ib, x, x, z, z, 0.0))
    if t in ("R", "C", "H"):
        rows["dot"] += [(ia, ib, a, n1, z, z, 0.0), (ia, ib, a, n2, z, z, 0.0)]
        rows["angle"].append((ia, ib, a, n1, n1, n2, 0.0))
        rows["angle_joints"].append(j.id)
    if t in ("P", "C", "H"):
        rows["line"] += [(ia, ib, x, x, n1, z, 0.0), (ia, ib, x, x, n2, z, 0.0)]
        rows["slide"].append((ia, ib, x, x, a, z, 0.0))
        rows["slide_joints"].append(j.id)
    if t == "P":  # the three frame vectors kept perpendicular as drawn
        e = np.eye(3)
        rows["dot"] += [(ia, ib, e[k], e[(k + 1) % 3], z, z, 0.0) for k in range(3)]
    if t == "U":
        a2 = _unit(np.asarray(j.axis2, float))
        rows["dot"].append((ia, ib, a, a2, z, z, float(a @ a2)))
        if abs(float(a @ a2)) < 1e-9:
            # a right-angled cross: its two angles, each an angle row with the axis on the link it
            # is fixed to: the second arm turning about the first axis (on the first link), and
            # the first arm turning about the second axis reversed (on the second link: the
            # second link turns by +θ2 about it relative to the first)
            rows["angle"] += [(ia, ib, a, a2, a2, np.cross(a, a2), 0.0), (ib, ia, -a2, a, a, np.cross(-a2, a), 0.0)]
            rows["angle_joints"] += [j.id, j.id + "/2"]


def _check_joint(mech: Mechanism, j: Joint) -> None:
    src = mech.source
    if j.type not in SPATIAL_PAIRS:
        raise MechsynInputError(
            f"joint {j.id} is a {j.type} pair: spatial kinematics moves R, P, C, U, S and H pairs",
            source=src, field=f"joints[{j.id}].type", hint="model the pair with R, P, C, U, S or H pairs")
    for attr, needed, hint in (("point", j.type != "P", "give point: [x, y, z]"),
                               ("axis", j.type != "S", "give axis: [dx, dy, dz]"),
                               ("axis2", j.type == "U", "give axis2: the cross's arm fixed in the second link")):
        if needed and getattr(j, attr) is None:
            raise MechsynInputError(f"joint {j.id} ({j.type}) has no {attr}", source=src,
                                    field=f"joints[{j.id}].{attr}", hint=hint)
    if j.actuated and j.type not in ("R", "P", "H", "C", "U"):
        raise MechsynInputError(f"joint {j.id} ({j.type}) is driven, but only R, P, H, C and U pairs can be driven",
                                source=src, field=f"joints[{j.id}].actuated", hint="drive an R, P, H, C or U pair")
    if j.type == "U" and j.actuated and abs(float(_unit(np.asarray(j.axis, float))
                                                  @ _unit(np.asarray(j.axis2, float)))) > 1e-9:
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
    index = {name: k for k, name in enumerate(links + (mech.ground,))}
    rows: dict[str, list] = {k: [] for k in (*ITEMS, "angle_joints", "slide_joints")}
    local = {j.id: (np.asarray(j.point, float) - centre) / scale for j in mech.joints if j.point is not None}
    for j in mech.joints:
        if not bars.keys() & set(j.links):
            _pair_rows(j, index[j.links[0]], index[j.links[1]], local.get(j.id, np.zeros(3)), rows)
    z = np.zeros(3)
    for bar, (j1, j2) in bars.items():
        a, b = (next(link for link in j.links if link != bar) for j in (j1, j2))
        rows["dist"].append((index[a], index[b], local[j1.id], local[j2.id], z, z,
                             float(np.linalg.norm(local[j1.id] - local[j2.id]))))
    helix = tuple((rows["angle_joints"].index(j.id), rows["slide_joints"].index(j.id), (j.pitch or 0.0) / scale)
                  for j in mech.joints if j.type == "H")
    drive_rows = [(name, "slide", rows["slide_joints"].index(name)) if input_kind(mech, name) == "P" else
                  (name, "angle", rows["angle_joints"].index(name.replace("/turn", ""))) for name in drives]
    big = max([float(np.abs(np.asarray(j.point, float)).max()) for j in mech.joints if j.point is not None]
              + [float(np.abs(np.asarray(pt.at, float)).max()) for pt in mech.points.values()], default=0.0)
    M = SpatialModel(mech, links, centre, scale, tuple(rows["angle_joints"]), tuple(rows["slide_joints"]), helix,
                     tuple(drive_rows), ulp=float(np.finfo(float).eps) * max(1.0, big / scale), bars=tuple(bars))
    zeros = np.array([input_zero(mech, mech.joint(jid.partition("/")[0])) for jid in M.angle_joints], float)
    slide0 = np.array([mech.joint(jid).attrs.get("slide0", 0.0) for jid in M.slide_joints], float) / scale
    return replace(M, tables=tables(M, rows), pairs=_pairs(mech, index), zeros=zeros, slide0=slide0)


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
    perpendicular, turning) and P (not turning), as :func:`pair_error`'s arrays: ``pi``
    (pairs, 3) the two links and whether the pair turns, ``pf`` (pairs, 3, 3) ``a``, ``e1``,
    ``e2``."""

    ids: tuple[str, ...]
    pi: np.ndarray
    pf: np.ndarray


def _pairs(mech: Mechanism, index: dict[str, int]) -> _Pairs:
    ids, pi, pf = [], [], []
    for j in mech.joints:
        if j.type in ("R", "C", "H", "P"):
            a = _unit(np.asarray(j.axis, float))
            ids.append(j.id)
            pi.append((index[j.links[0]], index[j.links[1]], int(j.type != "P")))
            pf.append((a, *_perp_basis(a)))
    return _Pairs(tuple(ids), np.array(pi, np.int64).reshape(-1, 3), np.array(pf, float).reshape(-1, 3, 3))


def pair_error(M: SpatialModel, R: np.ndarray) -> np.ndarray:
    """Per pose and pair (B, pairs): the largest entry of ``R_rel - Rot(a, θ)`` (R, C, H;
    ``θ`` the pair's joint value read from ``R_rel``) or of ``R_rel - I`` (P), where
    ``R_rel = R_a^T R_b`` is the second link's rotation relative to the first from the drawn
    assembly. Zero (to the residual) on a true assembly; about 2 where an R axis is reversed
    or a P pair half-turned. Because every pair's relative displacement is then the one its
    joint values give, the joint values close every loop (their displacements compose, around
    any loop, to the product of the links' relative poses, which is the identity)."""
    out = np.zeros((len(R), len(M.pairs.ids)))
    if out.size:
        numba_kernel().pair_errors(np.ascontiguousarray(R), M.pairs.pi, M.pairs.pf, out)
    return out


# --------------------------------------------------------------------------- tables
def numba_kernel() -> ModuleType:
    """The compiled functions (:mod:`mechsyn.kinematics._spatial_numba`), imported on the
    first spatial sweep (importing Numba costs a command that moves nothing)."""
    return importlib.import_module("mechsyn.kinematics._spatial_numba")


def tables(M: SpatialModel, rows: dict[str, list]) -> tuple:
    """The equations ``rows`` of :func:`_pair_rows` (per kind of :data:`ITEMS`, a list of
    ``(ia, ib, va, vb, n, m, c0)``) as the compiled functions' tables (see
    :mod:`mechsyn.kinematics._spatial_numba`): items ``it`` (kind, links), ``loc`` (their four
    local vectors), rows ``ri`` (kind, item, second item, component or input column), ``rf``
    (constants), the links' centres, the items of the angles and slides measured. Rows in
    :func:`residual`'s order: coincidences, dots, lines, distances, helices, drives."""
    items = [(code, *t) for kind, code in ITEMS.items() for t in rows[kind]]
    first = dict(zip(ITEMS, np.cumsum([0] + [len(rows[k]) for k in ITEMS])))
    ang, sl = (first[k] + np.arange(len(rows[k]), dtype=np.int64) for k in ("angle", "slide"))
    eqs = [(0, first["pc"] + q, 0, c, 0.0) for q in range(len(rows["pc"])) for c in range(3)]
    eqs += [(ITEMS[k], first[k] + q, 0, 0, t[-1]) for k in ("dot", "line", "dist") for q, t in enumerate(rows[k])]
    eqs += [(4, sl[s], ang[a], h, pitch) for h, (a, s, pitch) in enumerate(M.helix)]
    eqs += [(5, ang[k], 0, col, 0.0) if kind == "angle" else (6, sl[k], 0, col, 0.0)
            for col, (_, kind, k) in enumerate(M.drives)]
    cen = np.array([np.mean([M.local(j.point) for j in M.mech.joints if link in j.links and j.point is not None]
                            or [np.zeros(3)], axis=0) for link in M.links]).reshape(-1, 3)
    return (np.array([t[:3] for t in items], np.int64).reshape(-1, 3),
            np.array([t[3:7] for t in items], float).reshape(-1, 4, 3),
            np.array([e[:4] for e in eqs], np.int64).reshape(-1, 4), np.array([e[4] for e in eqs], float), cen, ang, sl)


# --------------------------------------------------------------------------- poses
# Batches of B poses: rotations R (B, n + 1, 3, 3), positions p (B, n + 1, 3) (the frame
# last, at rest), twists (B, 6 n), targets (B, drives).
def move(R: np.ndarray, p: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Poses ``(R, p)`` displaced by the twists ``x`` (B, 6 n) of the moving links (the
    exponential of each twist: Murray et al. [2]_, eq. 2.36).

    Examples
    --------
    >>> R, p = move(np.eye(3)[None, None].repeat(2, 1), np.zeros((1, 2, 3)), np.array([[0, 0, np.pi / 2, 1.0, 0, 0]]))
    >>> np.round(R[0, 0] @ [1.0, 0, 0], 12).tolist(), np.round(p[0, 0], 6).tolist()
    ([0.0, 1.0, 0.0], [0.63662, 0.63662, 0.0])
    """
    R2, p2 = np.empty(R.shape), np.empty(p.shape)
    numba_kernel().move(*(np.ascontiguousarray(a, float) for a in (R, p, x)), R2, p2)
    return R2, p2


def helix_angles(M: SpatialModel, theta: np.ndarray, helix_ref: np.ndarray) -> np.ndarray:
    """The H pairs' rotations unwrapped next to ``helix_ref`` (their previous values), from
    the pairs' angles ``theta`` (B, angles)."""
    h = np.array([a for a, _, _ in M.helix], int)
    return helix_ref + np.pi - np.mod(np.pi - theta[:, h] + helix_ref, 2 * np.pi)  # (the change to (-π, π])


# --------------------------------------------------------------------------- bars
def bar_motion(M: SpatialModel, R: np.ndarray, p: np.ndarray, xi: np.ndarray,
               xid: np.ndarray) -> tuple[np.ndarray, ...]:
    """Poses ``(R, p)`` (N, links, ...) and twists ``ξ``, ``ξ̇`` (N, 6 links) of
    :attr:`SpatialModel.all_links` from those of the links solved for (the frame's pose not
    included), over the rows of a sweep in order (NaN where a row has no pose). Each bar
    runs between its ends ``y_1``, ``y_2`` on the links it joins, on the line
    ``d = y_2 - y_1``, moving at ``ω = d × ḋ / |d|²``, ``ω̇ = d × d̈ / |d|²`` (no spin about its
    line: its spin is an idle motion) and ``v = ẏ_1 - ω × y_1``, ``v̇ = ÿ_1 - ω̇ × y_1 - ω × ẏ_1``
    (:func:`mechsyn.kinematics._spatial_numba.bars`).

    Its rotation is carried along the sweep the same way, with no spin: ``T = C Rot(u_0, φ)``,
    a chart ``C`` taking the drawn unit line ``u_0`` to the line ``u`` (the least rotation
    from ``u_0`` where ``u · u_0 ≥ 0``, else a half-turn about ``e_1`` then the least rotation
    from ``-u_0``: both well conditioned), turned first about the drawn line by the bar's
    spin ``φ``. From one row with a pose to the next the bar turns by the least rotation
    ``Q`` between their lines (its discrete parallel transport), which adds
    ``δ = atan2(Q a_k · b_{k+1}, Q a_k · a_{k+1})`` to ``φ`` (``a``, ``b``: the chart's images
    of ``e_1``, ``e_2``); in each stretch of rows with poses (a row refused after the walk
    included) the row nearest the drawn line (largest ``d_0 · d``) has ``φ = 0``, the least
    rotation from the drawn line ``d_0``. No rule that depends on the line alone can do
    this: a rotation taking ``d_0`` to every line ``d`` continuously would be a continuous
    section of ``SO(3) -> S²``, which does not exist (hairy ball theorem); the least
    rotation, ``cos I + [k]x + k kᵀ / (1 + cos)`` with ``k = d_0 × d``, is undefined where
    ``d`` is opposite ``d_0`` (a drag-link's coupler turning fully). The price of
    continuity: the pose depends on the path, not on the row's line alone (a bar brought
    back to its line along a loop has turned about it by the solid angle its line swept)
    and, by the square of the step, on the rows sampled."""
    N, nb = len(R), len(M.bars)
    if not nb:
        return R, p, xi, xid
    it, loc = M.tables[0], M.tables[1]
    d = np.flatnonzero(it[:, 0] == ITEMS["dist"])  # the bars' ends, in order
    Rb, pb, Xb, Xbd = np.empty((N, nb, 3, 3)), np.empty((N, nb, 3)), np.empty((N, 6 * nb)), np.empty((N, 6 * nb))
    numba_kernel().bars(*(np.ascontiguousarray(x, float) for x in (R, p, xi, xid)), it[d, 1], it[d, 2],
                        loc[d, 0], loc[d, 1], Rb, pb, Xb, Xbd)
    return (np.concatenate([R, Rb], axis=1), np.concatenate([p, pb], axis=1), np.concatenate([xi, Xb], axis=1),
            np.concatenate([xid, Xbd], axis=1))
