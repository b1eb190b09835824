"""Exact mobility from the joints' geometry: screw-theory rank analysis.

Each kinematic pair permits a set of relative twists (unit screws) at the assembled
configuration. Walking each independent contour ``L0 -j1-> L1 -j2-> ... -jk-> L0`` the
relative twists must sum to zero (loop closure)::

    Σ_t  s_t · $_t · q̇_t = 0,        s_t = +1 if j_t's links are (L(t-1), L(t)), else -1

Stacking the ``λ`` closure equations of the ``K`` contours (``λ = 6`` for spatial motion,
``3`` for planar motion: rows ``ω_z, v_x, v_y``) gives the loop-closure twist matrix
``M`` (``λK × F``, ``F = Σ`` pair freedoms). Then (Hunt 1978, *Kinematic geometry of
mechanisms*; Davies 1981; Gogu 2005, "Mobility of mechanisms: a critical review"):

- instantaneous mobility ``m = F - rank M`` (null space of ``M``: the joint rates);
- redundant constraints ``q = λK - rank M``; per contour, in the contours' order,
  ``q_j = λ - (rank M_{1..j} - rank M_{1..j-1})`` (the sequential reading of paper 003),
  and the redundant constraint *directions* are the left null vectors of ``M`` (states of
  self-stress: wrenches ``[moment about the origin; force]`` that load the contour
  without moving anything), described in the file's axes;
- Malyshev's ``W = 6n - Σ i·p_i = F - 6K`` therefore always equals ``m - q``: every
  difference between the formula and the motion is a redundant constraint located here.

Twists are ``$ = [ω; v]`` with ``v`` the velocity of the point at the origin:
``R`` about unit axis ``a`` through ``p``: ``[a; p × a]``; ``P`` along ``a``: ``[0; a]``;
``H`` with pitch ``h`` (lead per radian): ``[a; p × a + h a]``.

**Tolerance.** Lengths are measured from the centroid of the joint points in units of
``L`` (the largest distance of a joint point from that centroid), so every entry of ``M``
is of order one. A singular value counts as zero when it is below
``tol = max(1e-6, min(1e-3, 50·ε/L))`` where ``ε`` is the rounding of the coordinates the
file gives (half a unit in the last decimal written, when coordinates are written with
3..9 decimals; exact otherwise), so that special geometry typed with a few decimals
(Bennett's linkage, 4 decimals) is still recognised. Singular values between ``tol`` and
``1e-2`` are reported as a near-singularity.

**Singularity check.** The configuration is followed numerically along a few random
null-space directions (step ``0.05`` rad / ``0.05 L``, seeded), re-assembled by
Gauss-Newton on the product-of-exponentials loop closure, and the rank recomputed at
the nearby assembled configurations: if the rank there is larger, the given
configuration is singular (instantaneous mobility > finite mobility). Higher pairs are
followed as their instantaneously equivalent chain of lower pairs (the contact surfaces'
curvature is not in the file).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.contour import contour_links
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.structure.contours import independent_contours
from mechsyn.structure.idle import IdleInputs, IdleMobility, find_idle_mobilities

__all__ = [
    "RankAnalysis", "IdleMobility", "ContourRank", "InsufficientGeometry",
    "analyze_rank", "pair_twists", "missing_geometry", "as_spatial", "describe_wrenches",
]

_E = np.eye(3)
PLANAR_ROWS = np.array([2, 3, 4])  # ω_z, v_x, v_y of [ω; v]
_AXIS_NAMES = ("x", "y", "z")


class InsufficientGeometry(MechsynInputError):
    """The file does not give enough geometry for the rank method."""


# --------------------------------------------------------------------------- pairs
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perp_basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors perpendicular to unit ``n`` and to each other."""
    k = int(np.argmin(np.abs(n)))
    t1 = _unit(np.cross(n, _E[k]))
    return t1, np.cross(n, t1)


def _rot(p: np.ndarray, a: np.ndarray) -> np.ndarray:
    return np.concatenate([a, _cross(p, a)])


def _tr(a: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros(3), a])


def _pad3(v: np.ndarray | None) -> np.ndarray | None:
    if v is None:
        return None
    v = np.asarray(v, dtype=float)
    return v if v.size == 3 else np.array([v[0], v[1], 0.0])


def _need(joint: Joint, what: str, hint: str) -> InsufficientGeometry:
    return InsufficientGeometry(
        f"joint {joint.id} ({joint.type}) has no {what}: the rank method cannot build its twists",
        field=f"joints[{joint.id}]", hint=hint)


def _gear_geometry(joint: Joint, mech: Mechanism | None) -> tuple[np.ndarray, np.ndarray]:
    """Pitch point and line of action of a gear mesh given by ``ratio`` (20° pressure angle).

    The wheels' centres are their revolute pairs (preferably on a common link: carrier or
    frame); the pitch point divides the centre line so that ``|ratio| = r_a/r_b``
    (``ω_b/ω_a`` relative to the carrier; negative: external mesh, positive: internal).
    """
    if mech is None:
        raise _need(joint, "point and normal", "give point (pitch point) and normal (line of action)")
    a, b = joint.links
    pivots: dict[str, dict[str, Joint]] = {a: {}, b: {}}
    for j in mech.joints:
        if j is joint or j.type != "R" or j.point is None:
            continue
        for wheel in (a, b):
            if wheel in j.links:
                pivots[wheel][j.other(wheel)] = j
    common = [c for c in pivots[a] if c in pivots[b]]
    if common:
        oa, ob = _pad3(pivots[a][common[0]].point), _pad3(pivots[b][common[0]].point)
    elif pivots[a] and pivots[b]:  # e.g. a planet on its carrier meshing with a sun on the frame
        oa, ob = _pad3(next(iter(pivots[a].values())).point), _pad3(next(iter(pivots[b].values())).point)
    else:
        raise _need(joint, "point and normal", "give point and normal, or turn both wheels in R pairs")
    d = ob - oa
    if joint.point is not None:
        p = _pad3(joint.point)
    elif joint.ratio is not None and joint.ratio != 0:
        # ω_b/ω_a = ratio: r_a/r_b = |ratio|; external (ratio < 0) between the centres.
        r = abs(joint.ratio)
        p = oa + d * (r / (1 + r)) if joint.ratio < 0 else oa + d * (r / (r - 1) if r != 1 else 0.5)
    else:
        raise _need(joint, "point", "give point (pitch point) or ratio")
    z = np.array([0.0, 0.0, 1.0])
    tangent = _unit(np.cross(z, d))
    ang = np.radians(20.0)
    normal = np.cos(ang) * tangent + np.sin(ang) * _unit(d)
    return p, normal


def _belt_geometry(joint: Joint) -> tuple[np.ndarray, np.ndarray]:
    """Contact point and normal of a belt pair's instantaneous equivalent: the straight belt
    run is the tension's line of action, so the belt acts like a higher pair (rolling
    contact) with normal along the run through the tangent point
    (:func:`mechsyn.model.pairs.belt_tangent`)."""
    from mechsyn.model.pairs import belt_tangent

    anchor, radius, wrap = (joint.attrs.get(k) for k in ("anchor", "radius", "wrap"))
    if joint.point is None or anchor is None or radius is None or wrap is None:
        raise _need(joint, "point, anchor, radius and wrap", "give the pulley centre, anchor, radius and wrap")
    if len(anchor) != 2:
        raise InsufficientGeometry(
            f"joint {joint.id}: rank analysis is not supported for belt pairs in a spatial file",
            field=f"joints[{joint.id}]", hint="describe the belt drive in a planar file (kind: planar)")
    try:
        T, g, _ = belt_tangent(joint.point, np.asarray(anchor, float), float(radius), wrap)
    except ValueError as exc:
        raise InsufficientGeometry(f"joint {joint.id} (belt): {exc}", field=f"joints[{joint.id}]",
                                   hint="put the anchor outside the pulley") from None
    return _pad3(T), _pad3(g)


def pair_twists(joint: Joint, planar: bool, mech: Mechanism | None = None) -> np.ndarray:
    """Unit twists ``[ω; v]`` (``f × 6``) the pair permits at the assembled configuration.

    ``planar``: the joint's 2-D geometry is embedded in the plane ``z = 0`` (R turns about
    ``z``; cam and gear permit rotation about ``z`` through the contact point and sliding
    along the tangent). Raises :class:`InsufficientGeometry` naming what is missing.

    Pair conventions: ``C`` rotation then slide along ``axis``; ``U`` ``axis`` then
    ``axis2``; ``S`` rotations about x, y, z through ``point``; ``S_pin`` rotations about
    ``axis`` and ``axis2`` through ``point`` (or every axis perpendicular to ``normal``,
    the blocked rotation); ``E`` rotation about the plane normal ``axis`` and two slides in
    the plane; ``line_contact`` rotations about ``normal`` and the contact line ``axis``,
    slides along the line and across it; ``point_contact`` three rotations about the
    contact point and two slides perpendicular to ``normal``.
    """
    t = joint.type
    p = _pad3(joint.point)
    a = _pad3(joint.axis)
    if a is not None:
        a = _unit(a)
    z = np.array([0.0, 0.0, 1.0])
    if t == "generic":
        raise InsufficientGeometry(
            f"joint {joint.id} is a generic pair of class {joint.pair_class}: its permitted motions are unknown",
            field=f"joints[{joint.id}]", hint="give the pair's real type (R, P, C, S, ...) with its point and axis")
    if t == "belt":
        p, n = _belt_geometry(joint)
        if planar:
            return np.array([_rot(p, z), _tr(np.cross(z, n))])
        t = "line_contact" if joint.pair_class == 2 else ("point_contact" if joint.pair_class == 1 else "generic")
        if t == "generic":
            raise InsufficientGeometry(f"joint {joint.id}: a spatial belt of class {joint.pair_class} "
                                       "has unknown permitted motions", field=f"joints[{joint.id}]",
                                       hint="use class 2 (the belt's instantaneous line contact along z)")
        if a is None:
            a = z
        joint = replace(joint, normal=n)
    if planar:
        if t in ("cam", "gear"):
            if t == "gear" and joint.normal is None:
                p, n = _gear_geometry(joint, mech)
            else:
                if p is None:
                    raise _need(joint, "point", "give point: the contact point")
                if joint.normal is None:
                    raise _need(joint, "normal", "give normal: the contact normal")
                n = _unit(_pad3(joint.normal))
            return np.array([_rot(p, z), _tr(np.cross(z, n))])
        if t == "R":
            if p is None:
                raise _need(joint, "point", "give point: [x, y]")
            return np.array([_rot(p, z)])
        if t == "P":
            if a is None:
                raise _need(joint, "axis", "give axis: the sliding direction [dx, dy]")
            return np.array([_tr(a)])
        raise _need(joint, "planar twist", "use R, P, cam, gear or belt in a planar file")
    if t in ("cam", "gear"):
        t = "line_contact" if joint.pair_class == 2 else ("point_contact" if joint.pair_class == 1 else "generic")
        if t == "generic":
            raise InsufficientGeometry(f"joint {joint.id}: a spatial {joint.type} of class {joint.pair_class} "
                                       "has unknown permitted motions", field=f"joints[{joint.id}]",
                                       hint="use class 2 (line contact, with axis) or 1 (point contact)")
    if t != "P" and p is None:
        raise _need(joint, "point", "give point: [x, y, z]")
    if t == "R":
        if a is None:
            raise _need(joint, "axis", "give axis: the rotation axis")
        return np.array([_rot(p, a)])
    if t == "P":
        if a is None:
            raise _need(joint, "axis", "give axis: the sliding direction")
        return np.array([_tr(a)])
    if t == "H":
        if a is None:
            raise _need(joint, "axis", "give axis: the screw axis")
        h = joint.pitch or 0.0
        return np.array([_rot(p, a) + _tr(h * a)])
    if t == "C":
        if a is None:
            raise _need(joint, "axis", "give axis: the cylinder axis")
        return np.array([_rot(p, a), _tr(a)])
    if t == "U":
        if a is None or joint.axis2 is None:
            raise _need(joint, "axis and axis2", "give axis (fixed in the first link) and axis2 (in the second)")
        return np.array([_rot(p, a), _rot(p, _unit(_pad3(joint.axis2)))])
    if t == "S":
        return np.array([_rot(p, e) for e in _E])
    if t == "S_pin":
        if a is not None and joint.axis2 is not None:
            return np.array([_rot(p, a), _rot(p, _unit(_pad3(joint.axis2)))])
        if joint.normal is not None:
            t1, t2 = _perp_basis(_unit(_pad3(joint.normal)))
            return np.array([_rot(p, t1), _rot(p, t2)])
        raise _need(joint, "axis and axis2 (or normal)",
                    "give axis and axis2 (the two permitted rotations) or normal (the blocked rotation)")
    if t == "E":
        if a is None:
            raise _need(joint, "axis", "give axis: the normal of the contact plane")
        t1, t2 = _perp_basis(a)
        return np.array([_rot(p, a), _tr(t1), _tr(t2)])
    if t == "line_contact":
        if joint.normal is None or a is None:
            raise _need(joint, "normal and axis", "give normal (contact normal) and axis (contact line)")
        n = _unit(_pad3(joint.normal))
        lin = _unit(a - n * (a @ n))
        return np.array([_rot(p, n), _rot(p, lin), _tr(lin), _tr(np.cross(lin, n))])
    if t == "point_contact":
        if joint.normal is None:
            raise _need(joint, "normal", "give normal: the contact normal")
        t1, t2 = _perp_basis(_unit(_pad3(joint.normal)))
        return np.array([_rot(p, e) for e in _E] + [_tr(t1), _tr(t2)])
    raise _need(joint, "known twists", "use a catalogue pair type")


def missing_geometry(mech: Mechanism, planar: bool | None = None) -> list[str]:
    """Messages for the joints whose geometry is insufficient for the rank method."""
    planar = mech.kind == "planar" if planar is None else planar
    out = []
    for j in mech.joints:
        try:
            pair_twists(j, planar, mech)
        except InsufficientGeometry as exc:
            out.append(exc.message + (f" ({exc.hint})" if exc.hint else ""))
    return out


def as_spatial(mech: Mechanism) -> Mechanism:
    """A planar mechanism seen in 3-D: points at ``z = 0``, R axes along ``z``, P axes in
    the plane, cams and gears as line contacts (class 2) along ``z``."""
    from mechsyn.model.pairs import PAIR_KINDS

    if mech.kind == "spatial":
        return mech
    z = np.array([0.0, 0.0, 1.0])
    joints = []
    for j in mech.joints:
        kw: dict[str, Any] = {"point": _pad3(j.point)}
        if j.type == "R":
            kw["axis"] = z
        elif j.type == "P":
            kw["axis"] = _pad3(j.axis)
        elif j.type == "belt":
            kw["axis"] = z
            try:  # its instantaneous equivalent: a line contact along the belt's tangent line
                kw["point"], kw["normal"] = _belt_geometry(j)
            except InsufficientGeometry:
                pass
        elif j.type in ("cam", "gear"):
            kw["axis"] = z
            if j.type == "gear" and j.normal is None:
                try:
                    p, n = _gear_geometry(j, mech)
                    kw["point"], kw["normal"] = p, n
                except InsufficientGeometry:
                    pass
            else:
                kw["normal"] = _pad3(j.normal)
        cls = PAIR_KINDS[j.type].pair_class or (2 if j.type in ("cam", "gear", "belt") else j.pair_class)
        joints.append(replace(j, pair_class=cls, higher_override=None if j.type != "generic" else j.higher_override, **kw))
    points = {k: replace(v, at=_pad3(v.at)) for k, v in mech.points.items()}
    return replace(mech, kind="spatial", joints=tuple(joints), points=points,
                   name=f"{mech.name} (as spatial)", states={})


# --------------------------------------------------------------------------- linear algebra
def _exp(xi: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Batched ``exp(θ ξ̂)`` (``m × 4 × 4``) of unit-rotation or pure-translation twists."""
    m = xi.shape[0]
    w, v = xi[:, :3], xi[:, 3:]
    g = np.tile(np.eye(4), (m, 1, 1))
    rotating = np.linalg.norm(w, axis=1) > 0.5
    th = theta[:, None]
    # translation part for pure translations
    g[~rotating, :3, 3] = v[~rotating] * th[~rotating]
    if np.any(rotating):
        wr, vr, t = w[rotating], v[rotating], theta[rotating]
        K = np.zeros((wr.shape[0], 3, 3))
        K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -wr[:, 2], wr[:, 1], -wr[:, 0]
        K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = wr[:, 2], -wr[:, 1], wr[:, 0]
        s, c = np.sin(t)[:, None, None], np.cos(t)[:, None, None]
        R = np.eye(3) + s * K + (1 - c) * (K @ K)
        wxv = np.cross(wr, vr)
        p = np.einsum("nij,nj->ni", np.eye(3) - R, wxv) + wr * np.sum(wr * vr, axis=1, keepdims=True) * t[:, None]
        idx = np.flatnonzero(rotating)
        g[idx, :3, :3] = R
        g[idx, :3, 3] = p
    return g


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _svd(a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if a.size == 0:
        return (np.zeros((a.shape[0], 0)), np.zeros(0), np.zeros((0, a.shape[1])))
    return np.linalg.svd(a, full_matrices=True)


def _rank(a: np.ndarray, tol: float) -> int:
    if a.size == 0:
        return 0
    s = np.linalg.svd(a, compute_uv=False)
    return int(np.sum(s > tol))


def _null(a: np.ndarray, tol: float) -> np.ndarray:
    """Orthonormal basis (columns) of the null space of ``a``."""
    n = a.shape[1]
    if a.shape[0] == 0:
        return np.eye(n)
    _, s, vt = np.linalg.svd(a, full_matrices=True)
    r = int(np.sum(s > tol))
    return vt[r:].T


def _orth(a: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    if a.size == 0:
        return a.reshape(a.shape[0], 0)
    u, s, _ = np.linalg.svd(a, full_matrices=False)
    return u[:, : int(np.sum(s > tol * max(1.0, s[0] if s.size else 1.0)))]


#: Above this many pair freedoms the loop-closure matrix is reduced contour by contour
#: (:func:`_eliminate`) instead of by one dense SVD (``O(F³)``).
DENSE_MAX_FREEDOMS = 120


@dataclass
class _Reduction:
    """Rank, null space and per-contour increments of a loop-closure matrix."""

    rank: int
    null: np.ndarray  # F × m, orthonormal columns
    increments: list[int]  # per contour: new independent equations
    left: list[np.ndarray]  # per contour: λ × λ left singular vectors (redundant ones last)
    singular_values: np.ndarray  # what the rank decisions were taken on


def _reduce_dense(M: np.ndarray, lam: int, tol: float) -> _Reduction:
    """One SVD for rank and null space; each contour's rows reduced against the row space
    of the contours before it (orthonormal basis ``Q``)."""
    F = M.shape[1]
    sv = np.linalg.svd(M, compute_uv=False) if M.size else np.zeros(0)
    rank = int(np.sum(sv > tol))
    N = _null(M, tol) if F else np.zeros((0, 0))
    incs, lefts = [], []
    Q = np.zeros((F, 0))
    for k in range(M.shape[0] // lam):
        B = M[lam * k: lam * (k + 1)]
        res = B - (B @ Q) @ Q.T if Q.shape[1] else B
        u_k, s_k, vt_k = np.linalg.svd(res, full_matrices=True)
        s_full = np.zeros(lam)
        s_full[: s_k.size] = s_k
        inc = int(np.sum(s_full > tol))
        Q = np.concatenate([Q, vt_k[:inc].T], axis=1)
        incs.append(inc)
        lefts.append(u_k)
    return _Reduction(rank, N[:, : F - rank], incs, lefts, sv)


def _eliminate(M: np.ndarray, cols: list[np.ndarray], lam: int, tol: float) -> _Reduction:
    """Rank and null space contour by contour, touching only each contour's columns.

    The motions allowed by contours ``1..k-1`` are kept as orthonormal parameter vectors
    (a pair freedom not yet met by any contour, or a combination stored as a full vector).
    Contour ``k`` (rows ``B``, columns ``cols[k]``) meets only the parameters that move
    its columns: the SVD of ``B P_J`` (``λ × |J|``) gives its new independent equations
    (the sequential reading), its redundant ones (left null vectors, as in
    :func:`_reduce_dense`) and the combinations of ``P_J`` it leaves free. A column no
    later contour touches is retired from the bookkeeping. For a chain of loops ``|J|``
    stays small: the work grows about linearly with the contours (a dense SVD, cubically).
    """
    F = M.shape[1]
    last = np.full(F, -1)  # the last contour that touches each column: later, it is retired
    for k, ck in enumerate(cols):
        last[ck] = k
    unit: dict[int, int] = {c: c for c in range(F)}  # parameter -> its column (unit vector)
    dense: dict[int, np.ndarray] = {}  # parameter -> full vector
    active: dict[int, np.ndarray] = {}  # dense parameter -> columns it moves that a later contour touches
    touch: list[set[int]] = [{c} for c in range(F)]
    next_id = F
    incs, lefts, svs = [], [], []
    for k, ck in enumerate(cols):
        B = M[lam * k: lam * (k + 1), ck]
        J = sorted(set().union(*(touch[c] for c in ck)))
        if not J:  # every freedom of the contour is already locked
            incs.append(0)
            lefts.append(np.eye(lam))
            svs.append(np.zeros(lam))
            continue
        pos = {c: i for i, c in enumerate(ck)}
        BP = np.empty((lam, len(J)))
        for i, pid in enumerate(J):
            BP[:, i] = B[:, pos[unit[pid]]] if pid in unit else B @ dense[pid][ck]
        u, s, vt = np.linalg.svd(BP, full_matrices=True)
        s_full = np.zeros(lam)
        s_full[: s.size] = s
        inc = int(np.sum(s_full > tol))
        incs.append(inc)
        lefts.append(u)
        svs.append(s_full)
        if inc == 0:
            continue
        Z = vt[inc:].T
        new = np.zeros((F, Z.shape[1]))
        for i, pid in enumerate(J):
            if pid in unit:
                c = unit.pop(pid)
                new[c] += Z[i]
                touch[c].discard(pid)
            else:
                new += np.outer(dense.pop(pid), Z[i])
                for c in active.pop(pid):
                    touch[c].discard(pid)
        for i in range(new.shape[1]):
            v = new[:, i]
            v[np.abs(v) <= 1e-15 * np.max(np.abs(v))] = 0.0
            moved = np.flatnonzero(v)
            act = moved[last[moved] > k]
            dense[next_id], active[next_id] = v, act
            for c in act:
                touch[c].add(next_id)
            next_id += 1
    N = np.zeros((F, len(unit) + len(dense)))
    for i, c in enumerate(sorted(unit.values())):
        N[c, i] = 1.0
    for i, pid in enumerate(sorted(dense), start=len(unit)):
        N[:, i] = dense[pid]
    sv = np.concatenate(svs) if svs else np.zeros(0)
    return _Reduction(F - N.shape[1], N, incs, lefts, sv)


def _reduce(sysm: "_System", M: np.ndarray, tol: float) -> _Reduction:
    """Rank and null space of the loop-closure matrix ``M``: one dense SVD for small
    systems, contour-by-contour elimination above :data:`DENSE_MAX_FREEDOMS`."""
    if M.shape[1] <= DENSE_MAX_FREEDOMS:
        return _reduce_dense(M, sysm.lam, tol)
    return _eliminate(M, sysm.contour_columns(), sysm.lam, tol)


# --------------------------------------------------------------------------- results
@dataclass(frozen=True)
class ContourRank:
    """Rank results of one contour, in the contours' order (sequential reading)."""

    index: int
    joints: list[str]
    redundant: int
    directions: list[str]
    reason: str

    def to_dict(self) -> dict[str, Any]:
        return {"index": self.index, "joints": self.joints, "redundant": self.redundant,
                "directions": self.directions, "reason": self.reason}


@dataclass(frozen=True)
class RankAnalysis:
    """The rank method's answer (see the module docstring for the definitions)."""

    motion: str
    mobility: int
    useful_mobility: int
    idle_mobilities: list[IdleMobility]
    redundant_constraints: int
    contours: list[ContourRank]
    drives_needed: int
    actuated: list[str]
    actuation_determined: bool | None
    actuation_note: str
    singular: bool
    finite_mobility: int | None
    tolerance: float
    length_scale: float
    pair_freedoms: int
    equations: int
    rank: int
    smallest_singular_values: list[float]
    near_singular: bool
    notes: list[str] = field(default_factory=list)

    @property
    def redundant_by_contour(self) -> list[int]:
        return [c.redundant for c in self.contours]

    @property
    def redundant_directions(self) -> list[list[str]]:
        return [c.directions for c in self.contours]

    def to_dict(self) -> dict[str, Any]:
        return {
            "mobility": self.mobility, "useful_mobility": self.useful_mobility,
            "idle_mobilities": [i.to_dict() for i in self.idle_mobilities],
            "redundant_constraints": self.redundant_constraints,
            "redundant_by_contour": self.redundant_by_contour,
            "redundant_directions": self.redundant_directions,
            "drives_needed": self.drives_needed, "actuation_determined": self.actuation_determined,
            "singular": self.singular, "tolerance": self.tolerance,
            "finite_mobility": self.finite_mobility, "motion": self.motion,
            "contours": [c.to_dict() for c in self.contours], "actuated": self.actuated,
            "actuation_note": self.actuation_note, "length_scale": self.length_scale,
            "pair_freedoms": self.pair_freedoms, "equations": self.equations, "rank": self.rank,
            "smallest_singular_values": self.smallest_singular_values,
            "near_singular": self.near_singular, "notes": self.notes,
        }


# --------------------------------------------------------------------------- helpers
def _decimals(x: float) -> int:
    """Decimals written for ``x`` (0..12), from its shortest repr."""
    s = repr(float(x))
    if "e" in s or "E" in s:
        m = re.match(r"-?\d(?:\.(\d+))?[eE]([-+]\d+)", s)
        if not m:
            return 12
        return max(0, len(m.group(1) or "") - int(m.group(2)))
    return len(s.split(".")[1].rstrip("0")) if "." in s else 0


def _input_rounding(mech: Mechanism) -> float:
    """Half a unit in the last decimal of the coordinates, when they look rounded (3..9 decimals)."""
    vals = [float(x) for j in mech.joints if j.point is not None for x in j.point]
    vals += [float(x) for p in mech.points.values() for x in p.at]
    if not vals:
        return 0.0
    d = max(_decimals(x) for x in vals)
    return 0.5 * 10.0 ** (-d) if 3 <= d <= 9 else 0.0


@dataclass
class _System:
    """The loop-closure system of a mechanism in normalised units."""

    planar: bool
    joints: list[Joint]
    twists: np.ndarray  # F × 6, normalised
    col_joint: np.ndarray  # F: joint index of each column
    contours: list[tuple[str, ...]]
    factors: list[list[tuple[int, int]]]  # per contour: (column, sign) in product order
    centre: np.ndarray
    scale: float

    @property
    def lam(self) -> int:
        return 3 if self.planar else 6

    def rows(self, mat: np.ndarray) -> np.ndarray:
        return mat[PLANAR_ROWS] if self.planar else mat

    def contour_columns(self) -> list[np.ndarray]:
        """The columns (pair freedoms) each contour's equations touch."""
        return [np.array(sorted({c for c, _ in fac}), dtype=int) for fac in self.factors]

    def closure(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Loop-closure twist matrix ``M(θ)`` (λK × F) and the closure error (λK).

        Every contour's product of exponentials is taken step by step for all contours at
        once (contours padded to the longest one)."""
        F = self.twists.shape[0]
        K = len(self.factors)
        lam = self.lam
        M = np.zeros((lam * K, F))
        err = np.zeros(lam * K)
        if K == 0:
            return M, err
        exps = np.concatenate([_exp(self.twists, theta), _exp(self.twists, -theta)])  # + then - sign
        L = max(len(f) for f in self.factors)
        cols = np.full((K, L), -1)
        signs = np.zeros((K, L))
        for k, fac in enumerate(self.factors):
            cols[k, : len(fac)] = [c for c, _ in fac]
            signs[k, : len(fac)] = [sg for _, sg in fac]
        rows = PLANAR_ROWS if self.planar else np.arange(6)
        g = np.tile(np.eye(4), (K, 1, 1))
        for t in range(L):
            k = np.flatnonzero(cols[:, t] >= 0)
            c, sg = cols[k, t], signs[k, t]
            xi = self.twists[c] * sg[:, None]
            R, p = g[k, :3, :3], g[k, :3, 3]
            w = np.einsum("kij,kj->ki", R, xi[:, :3])
            v = np.einsum("kij,kj->ki", R, xi[:, 3:]) + np.cross(p, w)
            adj = np.concatenate([w, v], axis=1)[:, rows]
            M[(k * lam)[:, None] + np.arange(lam), c[:, None]] = adj
            g[k] = g[k] @ exps[np.where(sg > 0, c, c + F)]
        R, p = g[:, :3, :3], g[:, :3, 3]
        e = np.concatenate([0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0],
                                             R[:, 1, 0] - R[:, 0, 1]], axis=1), p], axis=1)
        err[:] = e[:, rows].reshape(-1)
        return M, err


def _build_system(mech: Mechanism, planar: bool) -> _System:
    pts = [_pad3(j.point) for j in mech.joints if j.point is not None]
    pts += [_pad3(p.at) for p in mech.points.values()]
    centre = np.mean(pts, axis=0) if pts else np.zeros(3)
    scale = max((float(np.linalg.norm(p - centre)) for p in pts), default=0.0)
    scale = scale if scale > 1e-12 else 1.0
    problems = missing_geometry(mech, planar)
    if problems:
        raise InsufficientGeometry(
            "geometry insufficient for the rank method: " + "; ".join(problems),
            source=mech.source, hint="add the missing point/axis/normal, or use --method formulas")
    cols = []
    col_joint = []
    per_joint_cols: list[list[int]] = []
    for k, j in enumerate(mech.joints):
        tw = pair_twists(j, planar, mech)
        # normalise: move the origin to the centre and divide lengths by the scale
        # twists of rotation: v becomes the velocity of the point at the centre,
        # v_c = v_O + ω × c, in units of the scale (joint angles stay radians); slides
        # keep unit length (their rates are measured in units of the scale).
        w, v = tw[:, :3], tw[:, 3:]
        rotating = np.linalg.norm(w, axis=1) > 0.5
        v = np.where(rotating[:, None], (v + np.cross(w, centre)) / scale, v)
        tw = np.concatenate([w, v], axis=1)
        start = len(cols)
        cols.extend(tw)
        col_joint.extend([k] * tw.shape[0])
        per_joint_cols.append(list(range(start, len(cols))))
    contours, _ = independent_contours(mech)
    jindex = {j.id: k for k, j in enumerate(mech.joints)}
    factors = []
    for c in contours:
        js = [mech.joints[jindex[i]] for i in c]
        links = contour_links(js)
        assert links is not None
        fac: list[tuple[int, int]] = []
        for t, j in enumerate(js):
            prev = links[t]
            sign = 1 if j.links[0] == prev else -1
            cs = per_joint_cols[jindex[j.id]]
            fac.extend((col, sign) for col in (cs if sign > 0 else cs[::-1]))
        factors.append(fac)
    twists = np.array(cols) if cols else np.zeros((0, 6))
    return _System(planar, list(mech.joints), twists, np.array(col_joint, dtype=int), contours, factors,
                   centre, scale)


def _link_twists(mech: Mechanism, sysm: _System, N: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Moving links and their twists per null-space motion (``n × 6 × m``), propagated
    from the frame along a breadth-first spanning tree of the link graph."""
    from collections import deque

    adj: dict[str, list[tuple[str, int, int]]] = {n: [] for n in mech.link_names}
    for k, j in enumerate(mech.joints):
        a, b = j.links
        adj[a].append((b, k, 1))
        adj[b].append((a, k, -1))
    cols_of = [[] for _ in mech.joints]  # type: list[list[int]]
    for c, k in enumerate(sysm.col_joint):
        cols_of[int(k)].append(c)
    tw: dict[str, np.ndarray] = {mech.ground: np.zeros((6, N.shape[1]))}
    queue = deque([mech.ground])
    while queue:
        u = queue.popleft()
        for v, k, sign in adj[u]:
            if v not in tw:
                cols = cols_of[k]
                tw[v] = tw[u] + sign * (sysm.twists[cols].T @ N[cols])
                queue.append(v)
    names = list(mech.moving_links)
    return names, np.array([tw[n] for n in names]) if names else np.zeros((0, 6, N.shape[1]))


_CENTRED_PAIRS = ("R", "H", "C", "U", "S", "S_pin")
_HIGHER_PAIRS = ("cam", "gear", "belt", "line_contact", "point_contact")


def _contact(j: Joint, mech: Mechanism) -> tuple[np.ndarray, np.ndarray] | None:
    """Contact point and normal of a higher pair (None when the file gives neither)."""
    if j.type == "belt":
        return _belt_geometry(j)
    if j.type == "gear" and j.normal is None and mech.kind == "planar":
        return _gear_geometry(j, mech)
    if j.point is None or j.normal is None:
        return None
    return _pad3(j.point), _unit(_pad3(j.normal))


def _idle_inputs(mech: Mechanism, sysm: _System, N: np.ndarray, Z0: np.ndarray) -> IdleInputs:
    """The arrays :func:`~mechsyn.structure.idle.find_idle_mobilities` needs (motions ``N @ Z0``)."""
    names, LT = _link_twists(mech, sysm, N)
    index = {n: i for i, n in enumerate(names)}

    def norm(p: Any) -> np.ndarray:
        return (_pad3(p) - sysm.centre) / sysm.scale

    centres, contacts = [], []
    for j in mech.joints:
        on = [index[x] for x in j.links if x in index]
        if j.type in _CENTRED_PAIRS and j.point is not None:
            centres += [(i, norm(j.point)) for i in on]
        elif j.type in _HIGHER_PAIRS:
            pn = _contact(j, mech)
            if pn is not None:
                contacts += [(i, norm(pn[0]), pn[1]) for i in on]
    named = [(index[p.link], norm(p.at)) for p in mech.points.values() if p.link in index]
    edges = [tuple(index.get(x, -1) for x in j.links) for j in mech.joints]
    return IdleInputs(A=LT @ Z0, rates=N @ Z0, col_joint=sysm.col_joint, links=names, edges=edges,  # type: ignore[arg-type]
                      centres=centres, named=named, contacts=contacts, joint_ids=[j.id for j in mech.joints],
                      centre=sysm.centre, scale=sysm.scale, drives=any(j.actuated for j in mech.joints))


def _axis_words(basis: np.ndarray, word: str) -> str:
    """``"moments about x, y"`` for a subspace of R³ (columns orthonormal)."""
    d = basis.shape[1]
    if d == 0:
        return ""
    proj = basis @ basis.T
    named = [_AXIS_NAMES[k] for k in range(3) if abs(proj[k, k] - 1.0) < 1e-6]
    plural = word + ("s" if d > 1 else "")
    if len(named) == d:
        return f"{plural} {'about' if word == 'moment' else 'along'} {', '.join(named)}"
    if d == 1:
        v = basis[:, 0] * np.sign(basis[np.argmax(np.abs(basis[:, 0])), 0])
        return f"{plural} {'about' if word == 'moment' else 'along'} {_vec(v)}"
    if d == 2:
        n = np.cross(basis[:, 0], basis[:, 1])
        n = n * np.sign(n[np.argmax(np.abs(n))])
        name = next((_AXIS_NAMES[k] for k in range(3) if abs(abs(n[k]) - 1) < 1e-6), _vec(n))
        return f"{plural} {'about' if word == 'moment' else 'along'} every axis perpendicular to {name}"
    return f"{plural} {'about' if word == 'moment' else 'along'} x, y, z"


def _num(x: float) -> str:
    x = 0.0 if abs(x) < 5e-10 else x
    return f"{x:.4g}"


def _vec(v: np.ndarray) -> str:
    return "(" + ", ".join(_num(float(x)) for x in v) + ")"


def describe_wrenches(W: np.ndarray, centre: np.ndarray, scale: float, planar: bool = False,
                      tol: float = 1e-6) -> list[str]:
    """Readable names of a subspace of wrenches ``[moment about the centre; force]``
    (columns, normalised units): couples first, then forces with their lines of action."""
    q = W.shape[1]
    if q == 0:
        return []
    W = _orth(W)
    Fp, Mp = W[3:], W[:3]
    nf = _null(Fp, 1e-7)  # combinations with no force: couples
    couples = _orth(Mp @ nf) if nf.shape[1] else np.zeros((3, 0))
    out = []
    if couples.shape[1]:
        out.append(_axis_words(couples, "moment"))
    forces = _orth(Fp)
    if forces.shape[1] >= 2 and not couples.shape[1]:
        # do all the force lines pass through one point?  m_i = r × F_i  for every basis wrench
        A = np.concatenate([-np.array([[0, -f[2], f[1]], [f[2], 0, -f[0]], [-f[1], f[0], 0]]) for f in Fp.T])
        r, *_ = np.linalg.lstsq(A, Mp.T.reshape(-1), rcond=None)
        if np.linalg.norm(A @ r - Mp.T.reshape(-1)) < 1e-7:
            out.append(f"{_axis_words(forces, 'force')} through {_vec(centre + scale * r)}")
            return out
    if forces.shape[1]:
        # aligned basis when the force subspace contains coordinate axes
        proj = forces @ forces.T
        dirs = [_E[k] for k in range(3) if abs(proj[k, k] - 1.0) < 1e-6]
        if len(dirs) != forces.shape[1]:
            dirs = [forces[:, i] for i in range(forces.shape[1])]
        for d in dirs:
            d = d * np.sign(d[np.argmax(np.abs(d))])
            alpha = np.linalg.lstsq(Fp, d, rcond=None)[0]
            m = Mp @ alpha
            if couples.shape[1]:
                m = m - couples @ (couples.T @ m)
            pitch = float(d @ m)
            r = np.cross(d, m)  # foot of the line of action (normalised, relative to the centre)
            name = next((_AXIS_NAMES[k] for k in range(3) if abs(abs(d[k]) - 1) < 1e-9), _vec(d))
            # is the line's position arbitrary? (couples perpendicular to d span 2 dimensions)
            perp = couples - np.outer(d, d @ couples) if couples.shape[1] else couples
            loc_free = perp.shape[1] and np.linalg.matrix_rank(perp, tol=1e-6) >= 2
            wrench = abs(pitch) > max(1e-6, 10 * tol)
            text = f"{'wrench' if wrench else 'force'} along {name}"
            if not loc_free:
                text += f" through {_vec(centre + scale * r)}"
            if wrench:
                text += f" with pitch {_num(pitch * scale)} (force plus moment about it)"
            out.append(text)
    return [o for o in out if o]


def _contour_reason(sysm: _System, idx: int, Wj: np.ndarray) -> str:
    """Why contour ``idx`` has redundant constraints (``Wj``: its redundant wrenches, 6 × q)."""
    q = Wj.shape[1]
    if q == 0:
        return ""
    cols = sorted({c for c, _ in sysm.factors[idx]})
    types = {sysm.joints[sysm.col_joint[c]].type for c in cols}
    if sysm.planar and types <= {"P"}:
        return "translations only: the moment about z repeats"
    if sysm.planar:
        return ("metric constraint: a constraint repeated only under these exact dimensions "
                "(a duplicated link, coaxial or coincident joints)")
    tw = sysm.twists[cols]
    lower_rot = [c for c in cols if sysm.joints[sysm.col_joint[c]].type in ("R", "C", "H")
                 and np.linalg.norm(sysm.twists[c, :3]) > 0.5]
    all_rot = [c for c in cols if np.linalg.norm(sysm.twists[c, :3]) > 0.5]
    if len(lower_rot) >= 2:
        axes = sysm.twists[lower_rot, :3]
        counts = (np.abs(axes @ axes.T) > 1 - 1e-9).sum(axis=1)
        k = int(np.argmax(counts))
        if counts[k] >= 2:
            d = axes[k]
            # split the redundant wrenches: out-of-plane (force ∥ d, moments ⊥ d) vs in-plane
            P = np.concatenate([np.outer(d, d) @ Wj[:3], (np.eye(3) - np.outer(d, d)) @ Wj[3:]])
            in_plane = int(np.linalg.matrix_rank(P, tol=1e-6)) if P.size else 0
            out_plane = q - in_plane
            if out_plane > 0:
                dname = next((_AXIS_NAMES[i] for i in range(3) if abs(abs(d[i]) - 1) < 1e-6), _vec(d))
                n_par = int(counts[k])
                if n_par == len(all_rot):
                    text = (f"parallel axes (all along {dname}): the contour moves in parallel planes, so "
                            f"{out_plane} of its out-of-plane constraints repeat")
                else:
                    text = (f"parallel axes ({n_par} of the contour's {len(all_rot)} rotation axes along {dname}): "
                            f"the other pairs free part of the out-of-plane motion, {out_plane} out-of-plane "
                            f"constraint(s) repeat")
                if in_plane:
                    text += (f"; and {in_plane} metric constraint(s) in the plane (coaxial, coincident or "
                             "duplicated links)")
                return text
    rot = tw[np.linalg.norm(tw[:, :3], axis=1) > 0.5]
    tra = tw[np.linalg.norm(tw[:, :3], axis=1) <= 0.5][:, 3:]
    if len(rot):
        w = rot[:, :3]
        # concurrent axes: every rotation axis through one point, no slides
        v = rot[:, 3:]
        # p × w = v for a common point p:  -[w]× p = v
        A = np.concatenate([-np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]]) for x in w])
        sol, *_ = np.linalg.lstsq(A, v.reshape(-1), rcond=None)
        if len(tra) == 0 and np.linalg.norm(A @ sol - v.reshape(-1)) < 1e-6 and "S" not in types:
            return "concurrent axes (a spherical loop): the forces through the common point repeat"
    elif len(tra):
        return "translations only: the moments repeat"
    return ("special geometry: the pair axes satisfy a metric condition that a generic contour "
            "would not (e.g. Bennett's linkage, equal or coaxial links)")


# --------------------------------------------------------------------------- analysis
def _actuated_columns(sysm: _System) -> tuple[list[int], list[str]]:
    """Columns driven by the declared actuators (C: the slide; multi-freedom pairs: all)."""
    cols, names = [], []
    for k, j in enumerate(sysm.joints):
        if not j.actuated:
            continue
        cs = list(np.flatnonzero(sysm.col_joint == k))
        if j.type == "C":
            cs = cs[1:]
        cols.extend(cs)
        names.append(j.id)
    return cols, names


def _gauss_newton_step(M: np.ndarray, err: np.ndarray, tol: float) -> np.ndarray:
    """Least-norm step ``δ`` with ``M δ ≈ err``: truncated SVD with the rank tolerance
    (near-null directions left alone) for small systems; for large ones the damped
    least-norm step ``Mᵀ (M Mᵀ + tol² I)⁻¹ err`` by a sparse LU (banded for chains)."""
    if M.shape[1] <= DENSE_MAX_FREEDOMS:
        u, sv, vt = np.linalg.svd(M, full_matrices=False)
        keep = sv > tol
        return vt[keep].T @ ((u[:, keep].T @ err) / sv[keep])
    from scipy.sparse import csc_matrix, identity
    from scipy.sparse.linalg import spsolve

    A = csc_matrix(M)
    return A.T @ spsolve((A @ A.T + tol * tol * identity(M.shape[0], format="csc")).tocsc(), err)


def _follow(sysm: _System, N: np.ndarray, tol: float, rank0: int, samples: int = 3,
            step: float = 0.05, seed: int = 0) -> tuple[int | None, list[str]]:
    """Rank at nearby assembled configurations along random null-space directions."""
    rng = np.random.default_rng(seed)
    notes = []
    ranks = []
    returned = 0
    for _ in range(samples):
        d = N @ rng.standard_normal(N.shape[1])
        d *= step / max(np.max(np.abs(d)), 1e-300)
        theta = d.copy()
        ok = False
        for _it in range(60):
            M, err = sysm.closure(theta)
            if np.linalg.norm(err) < max(1e-11, 10.0 * tol * step):
                ok = True
                break
            theta = theta - _gauss_newton_step(M, err, tol)
        if not ok:
            continue
        if np.max(np.abs(theta)) < 0.2 * step:
            returned += 1
            continue
        M, _ = sysm.closure(theta)
        ranks.append(_reduce(sysm, M, tol).rank)
    if not ranks:
        if returned:
            notes.append("the instantaneous motions do not extend to finite motions (a shaky configuration)")
            return rank0 + N.shape[1], notes  # no finite motion: rank 'full'
        notes.append("the motion could not be followed numerically (closure did not converge)")
        return None, notes
    return max(ranks), notes


def analyze_rank(mech: Mechanism, planar: bool | None = None, tol: float | None = None,
                 check_singular: bool = True, seed: int = 0,
                 progress: Callable[[str], None] | None = None) -> RankAnalysis:
    """Screw-theory rank analysis of ``mech`` at its assembled configuration.

    ``planar`` defaults to the file's kind (a planar file is analysed with planar
    motion, 3 equations per contour; see :func:`as_spatial` for the 3-D picture).
    ``progress`` is called with the name of each stage as it starts (``"contours"``,
    ``"rank"``, ``"idle"``, ``"singularity"``). BLAS runs on one thread meanwhile: the
    method makes many small decompositions, which threads only slow down (and on a
    loaded machine by 10-50x). Raises :class:`InsufficientGeometry` when a joint lacks
    the geometry its twists need.

    Examples
    --------
    >>> import mechsyn as ms
    >>> ra = ms.analyze_rank(ms.examples.load("bennett"))    # mobile although Grübler says -2
    >>> ra.mobility, ra.redundant_constraints
    (1, 3)
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _analyze_rank(mech, planar, tol, check_singular, seed, progress or (lambda stage: None))


def _analyze_rank(mech: Mechanism, planar: bool | None, tol: float | None, check_singular: bool, seed: int,
                  progress: Callable[[str], None]) -> RankAnalysis:
    planar = mech.kind == "planar" if planar is None else planar
    progress("contours")
    sysm = _build_system(mech, planar)
    lam, K, F = sysm.lam, len(sysm.contours), sysm.twists.shape[0]
    tol = _default_tolerance(mech, sysm) if tol is None else tol
    M, _ = sysm.closure(np.zeros(F))
    notes: list[str] = []
    progress("rank")
    red = _reduce(sysm, M, tol)
    near = _near_singular_note(red.singular_values, tol, F, lam * K, red.rank, notes)
    mobility, redundant, N = F - red.rank, lam * K - red.rank, red.null
    contours = _contour_ranks(sysm, red, tol)
    if sum(c.redundant for c in contours) != redundant:  # borderline singular values: say so
        notes.append(f"per-contour counts ({', '.join(str(c.redundant) for c in contours)}) and the total "
                     f"{redundant} differ at this tolerance: a singular value is close to it")
    progress("idle")
    acols, anames = _actuated_columns(sysm)
    Z0 = _null(N[acols], tol) if mobility and acols else np.eye(mobility)
    idle, _, idle_notes = find_idle_mobilities(_idle_inputs(mech, sysm, N, Z0), tol) if mobility else ([], None, [])
    notes.extend(idle_notes)
    useful = mobility - len(idle)
    determined, anote = _actuation(sysm, N, Z0, acols, anames, len(idle), tol)
    singular, finite = False, (0 if mobility == 0 else None)
    if check_singular and mobility > 0:
        progress("singularity")
        singular, finite, contours = _singularity(sysm, N, tol, red.rank, len(idle), contours, notes, seed)
    sv = red.singular_values
    return RankAnalysis(
        motion="planar" if planar else "spatial", mobility=mobility, useful_mobility=useful,
        idle_mobilities=idle, redundant_constraints=redundant, contours=contours, drives_needed=useful,
        actuated=anames, actuation_determined=determined, actuation_note=anote, singular=singular,
        finite_mobility=finite, tolerance=float(tol), length_scale=float(sysm.scale), pair_freedoms=F,
        equations=lam * K, rank=red.rank, smallest_singular_values=sorted(float(x) for x in sv)[: min(4, len(sv))],
        near_singular=near, notes=notes,
    )


def _default_tolerance(mech: Mechanism, sysm: _System) -> float:
    """``max(1e-6, min(1e-3, 50 ε / L))`` with ``ε`` the rounding of the file's coordinates."""
    return max(1e-6, min(1e-3, 50.0 * _input_rounding(mech) / sysm.scale))


def _near_singular_note(sv: np.ndarray, tol: float, F: int, equations: int, rank: int, notes: list[str]) -> bool:
    """Singular values between the tolerance and ``1e-2``: a near-singularity, said in ``notes``."""
    small = sv[(sv > tol) & (sv < 1e-2)]
    if small.size:
        k = small.size
        notes.append(f"near-singular: singular value(s) {', '.join(f'{x:.2g}' for x in small)} above the tolerance "
                     f"{tol:.2g} but small; if the geometry is meant to be special (typed with few decimals), "
                     f"--tol {float(small.max()) * 2:.1g} gives mobility {F - rank + k} and {equations - rank + k} "
                     f"redundant constraint(s)")
    return bool(small.size)


def _contour_ranks(sysm: _System, red: _Reduction, tol: float) -> list[ContourRank]:
    """Redundant constraints per contour (sequential) and their directions: the rows of
    contour k reduced against the row space of contours 1..k-1; combinations c of its rows
    whose residual vanishes are its redundant constraints, c being the contour's
    self-stress wrench [moment about the centre; force]."""
    lam = sysm.lam
    contours: list[ContourRank] = []
    for k in range(len(sysm.contours)):
        inc, u_k = red.increments[k], red.left[k]
        qk = lam - inc
        part = u_k[:, inc:]
        dirs: list[str] = []
        Wj = np.zeros((6, 0))
        if qk > 0:
            if sysm.planar:
                Wj = np.zeros((6, part.shape[1]))
                Wj[PLANAR_ROWS] = part
            else:
                Wj = part
            dirs = describe_wrenches(Wj, sysm.centre, sysm.scale, sysm.planar, tol)
        contours.append(ContourRank(index=k + 1, joints=list(sysm.contours[k]), redundant=qk,
                                    directions=dirs, reason=_contour_reason(sysm, k, Wj)))
    return contours


def _actuation(sysm: _System, N: np.ndarray, Z0: np.ndarray, acols: list[int], anames: list[str], idle: int,
               tol: float) -> tuple[bool | None, str]:
    """Whether the drives determine the motion (every motion left with them at rest is
    idle), and the sentence that says so."""
    if not anames:
        return None, ""
    mobility = N.shape[1]
    uncontrolled = Z0.shape[1] - idle
    if uncontrolled:
        return False, (f"the drives at {', '.join(anames)} leave {uncontrolled} useful motion(s) undetermined: "
                       f"{mobility - idle} drive(s) needed")
    ra = _rank(N[acols], tol) if mobility else 0
    if ra < len(acols):
        locked = [j.id for k, j in enumerate(sysm.joints) if j.actuated and mobility
                  and np.max(np.abs(N[sysm.col_joint == k]), initial=0.0) <= tol]
        return True, (f"the drives at {', '.join(anames)} determine the motion but {len(acols) - ra} of them "
                      "are not independent (redundant actuation: the drives fight each other)"
                      + (f"; the mechanism locks the drive(s) at {', '.join(locked)}: they cannot move"
                         if locked else ""))
    return True, f"the drives at {', '.join(anames)} determine the motion"


def _singularity(sysm: _System, N: np.ndarray, tol: float, rank: int, idle: int, contours: list[ContourRank],
                 notes: list[str], seed: int) -> tuple[bool, int | None, list[ContourRank]]:
    """Singular when the rank at nearby assembled configurations is larger; the finite
    mobility there, and the contours' reasons amended."""
    F, equations = sysm.twists.shape[0], sysm.lam * len(sysm.contours)
    r_near, fnotes = _follow(sysm, N, tol, rank, seed=seed)
    notes.extend(fnotes)
    if r_near is None:
        return False, None, contours
    finite = F - r_near
    if r_near == rank:
        return False, finite, contours
    notes.append(f"singular configuration: {N.shape[1]} instantaneous freedom(s) but {max(finite, 0)} "
                 f"finite one(s) at nearby assembled configurations; away from it "
                 f"{max(finite - idle, 0)} drive(s) and {equations - r_near} redundant constraint(s)")
    lead = "singular configuration (pairs lined up): "
    if equations - r_near == 0:
        lead += "every redundant constraint vanishes at nearby configurations"
        return True, finite, [replace(c, reason=lead) if c.redundant else c for c in contours]
    lead += f"{r_near - rank} redundant constraint(s) vanish at nearby configurations; otherwise "
    return True, finite, [replace(c, reason=lead + c.reason) if c.redundant else c for c in contours]


# --------------------------------------------------------------------------- formulas side by side
@dataclass(frozen=True)
class Comparison:
    """One formula's answer next to the rank method's, with why they differ."""

    quantity: str
    formula: str
    formula_value: float | int | None
    rank_value: float | int | None
    agree: bool
    why: str

    def to_dict(self) -> dict[str, Any]:
        return {"quantity": self.quantity, "formula": self.formula, "formula_value": self.formula_value,
                "rank_value": self.rank_value, "agree": self.agree, "why": self.why}


def _q_reasons(ra: RankAnalysis) -> str:
    parts = []
    for c in ra.contours:
        if c.redundant:
            parts.append(f"contour {c.index}: {c.redundant}, {c.reason.split(':')[0]}")
    return "; ".join(parts)


def _idle_words(ra: RankAnalysis) -> str:
    return ", ".join(f"{i.link or '?'} ({' '.join(i.joints)})" for i in ra.idle_mobilities)


def compare_with_formulas(fa: Any, ra: RankAnalysis) -> list[Comparison]:
    """Each formula of ``fa`` (:class:`~mechsyn.structure.analysis.StructuralAnalysis`)
    next to the rank answer ``ra``, with one line on why they differ.

    Identities used: Malyshev's ``W = F - 6K`` and Chebyshev's ``W = F - 3K`` equal
    ``m - q`` (instantaneous mobility minus redundant constraints), and Ozol's
    ``q = W + λK - f`` is the rank's ``q`` exactly when ``W`` is the instantaneous mobility.
    """
    out: list[Comparison] = []
    m, u, q = ra.mobility, ra.useful_mobility, ra.redundant_constraints
    idle = len(ra.idle_mobilities)
    planar = ra.motion == "planar"
    reasons = _q_reasons(ra)
    idle_txt = f"; it includes {idle} idle mobility(ies): {_idle_words(ra)}" if idle else ""
    main = (("chebyshev", "Chebyshev W = 3n - 2p5 - p4 (planar)") if planar
            else ("malyshev", "Malyshev W = 6n - Σ i·p_i (spatial)"))
    f = fa.formulas.get(main[0])
    if f is not None and f.value is not None:
        w = f.value
        if w == m:
            why = "agree: no constraint is redundant" + idle_txt
        else:
            why = (f"W = m - q = {m} - {q} = {m - q}: the formula counts every constraint as independent, "
                   f"{q} are redundant ({reasons})" + idle_txt)
        out.append(Comparison("mobility", main[1], w, m, w == m, why))
    if not planar:
        f = fa.formulas.get("somov_malyshev")
        if f is not None and f.value is not None:
            w = f.value
            s_idle = fa.idle_mobilities
            if w == m:
                why = "agree: the per-contour S_Σ + G_Σ matches the redundant constraints the rank method finds"
            elif w == u:
                why = (f"W equals the useful mobility {u}: S_Σ = {fa.structural_redundancy} nets "
                       f"{s_idle} idle mobility(ies) against redundant constraints; the rank method counts "
                       f"{q} redundant constraint(s) and {idle} idle mobility(ies) apart (m = {m} = {u} + {idle})")
            else:
                bad = []
                for rc, fc in zip(ra.contours, fa.contours):
                    fq = max(fc.S, 0) + fc.T
                    if fq != rc.redundant:
                        bad.append(f"contour {rc.index}: S + T = {fq:g}, rank {rc.redundant}"
                                   + (f" ({rc.reason.split(':')[0]})" if rc.reason else ""))
                why = ("the per-contour counts assume generic geometry (each contour's pairs independent): "
                       + ("; ".join(bad) if bad else f"S_Σ + G_Σ = {fa.structural_redundancy + fa.constructive_redundancy:g}"
                          f" vs rank q = {q}") + idle_txt)
            out.append(Comparison("mobility", "Somov-Malyshev W = 6n - Σ i·p_i + S_Σ + G_Σ (003, spatial)", w, m, w == m, why))
    f = fa.formulas.get("ozol_redundant")
    if f is not None and f.value is not None:
        w_used = fa.declared_mobility if fa.declared_mobility is not None else fa.mobility
        why = ("agree" if f.value == q else
               f"Ozol's q = W + {3 if planar else 6}K - f used W = {w_used:g}; with the rank's instantaneous "
               f"mobility m = {m} (idle included) it gives q = {q}")
        if f.value == q and q:
            why = f"agree: {reasons}"
        out.append(Comparison("redundant constraints", f"Ozol q = W + {3 if planar else 6}K - f (002, {ra.motion})", f.value, q, f.value == q, why))
    if fa.contours and len(fa.contours) == len(ra.contours) and not planar:
        for fc, rc in zip(fa.contours, ra.contours):
            sj = max(fc.S, 0) + fc.T
            agree = sj == rc.redundant
            why = "agree" if agree else (
                f"the rank method finds {rc.redundant}" + (f": {rc.reason}" if rc.reason else "")
                + (f" (formula: S = {fc.S}, T = {fc.T:g})"))
            if not agree and rc.redundant < sj:
                why += ("; S_j counts freedoms, not their directions: with this geometry the pairs' "
                        "freedoms absorb the constraints it counts as redundant")
            if agree and rc.redundant:
                why = f"agree: {', '.join(rc.directions)}"
            out.append(Comparison(f"redundant constraints, contour {fc.index}", "003: max(S_j, 0) + T_j",
                                  sj, rc.redundant, agree, why))
    f_idle = fa.idle_mobilities
    if not planar:
        out.append(Comparison(
            "idle mobilities", "003: Σ max(-S_j, 0)", f_idle, idle, f_idle == idle,
            "agree" + (f": {_idle_words(ra)}" if idle else "") if f_idle == idle else
            (f"the rank method finds {idle}: {_idle_words(ra) or 'none'}"
             + ("; the per-contour count misses idle motions that a contour's redundant constraints mask"
                if idle > f_idle else "; the per-contour count assumes a generic geometry"))))
    h = fa.degrees_of_mobility
    why = "agree" if h == ra.drives_needed else (
        f"drives needed = useful mobility = {ra.drives_needed} (rank); the rule H = n - Σ A_j is "
        "topological and misses special geometry" + (f" (exclusive-link reading: {fa.degrees_of_mobility_exclusive})"
                                                      if fa.degrees_of_mobility_exclusive != h else ""))
    out.append(Comparison("drives", "003: H = n - Σ A_j", h, ra.drives_needed, h == ra.drives_needed, why))
    return out


# --------------------------------------------------------------------------- remedies re-checked
@dataclass(frozen=True)
class RemedyCheck:
    """The rank method's verdict on a remedy variant."""

    accepted: bool
    reason: str
    rank: RankAnalysis | None
    geometry: dict[str, dict[str, list[float]]]

    def to_dict(self) -> dict[str, Any]:
        r = self.rank
        return {"accepted": self.accepted, "reason": self.reason, "geometry": self.geometry,
                "rank": None if r is None else {
                    "mobility": r.mobility, "useful_mobility": r.useful_mobility,
                    "idle_mobilities": [i.to_dict() for i in r.idle_mobilities],
                    "redundant_constraints": r.redundant_constraints,
                    "redundant_by_contour": r.redundant_by_contour,
                    "redundant_directions": r.redundant_directions}}


def _candidate_dirs(mech: Mechanism, j: Joint) -> list[np.ndarray]:
    p = _pad3(j.point)
    out: list[np.ndarray] = []
    for other in mech.joints:
        if other is j or other.point is None or not set(other.links) & set(j.links):
            continue
        d = _pad3(other.point) - p
        if np.linalg.norm(d) > 1e-9:
            out.append(_unit(d))
    out += [e for e in _E]
    uniq: list[np.ndarray] = []
    for d in out:
        if all(abs(abs(d @ e) - 1) > 1e-9 for e in uniq):
            uniq.append(d)
    return uniq


def _variant_geometry(original: Mechanism, variant: Mechanism) -> list[tuple[Mechanism, dict[str, dict[str, list[float]]]]]:
    """Geometric realisations of a remedy variant: changed pairs at the same point with the
    same axis; directions a new pair needs (sphere-with-pin's blocked rotation, a line
    contact's line) tried among the directions to the neighbouring joints and x, y, z."""
    import itertools

    old = {j.id: j for j in original.joints}
    choices: list[list[tuple[Joint, dict[str, list[float]]]]] = []
    for j in variant.joints:
        o = old[j.id]
        if o.type == j.type and o.pair_class == j.pair_class:
            choices.append([(o, {})])
            continue
        base = replace(j, point=o.point, axis=o.axis, axis2=o.axis2, normal=o.normal, pitch=None, ratio=None)
        opts: list[tuple[Joint, dict[str, list[float]]]] = []
        if j.type == "S_pin" and (o.axis is None or o.axis2 is None):
            if o.point is not None:
                for d in _candidate_dirs(original, o):
                    opts.append((replace(base, normal=d, axis=None, axis2=None), {"normal": [float(x) for x in d]}))
        elif j.type == "line_contact" and base.axis is None and base.normal is not None:
            n = _unit(_pad3(base.normal))
            for e in _E:
                ln = np.cross(n, e)
                if np.linalg.norm(ln) > 1e-6:
                    ln = _unit(ln)
                    opts.append((replace(base, axis=ln), {"axis": [float(x) for x in ln]}))
        elif j.type == "U" and o.axis is not None and o.axis2 is None:
            for d in _candidate_dirs(original, o):
                a2 = np.cross(_pad3(o.axis), d)
                if np.linalg.norm(a2) > 1e-6:
                    opts.append((replace(base, axis2=_unit(a2)), {"axis2": [float(x) for x in _unit(a2)]}))
        else:
            g = {}
            if base.point is not None:
                g["point"] = [float(x) for x in base.point]
            if base.axis is not None and j.type not in ("S",):
                g["axis"] = [float(x) for x in base.axis]
            opts.append((base, g))
        choices.append(opts or [(base, {})])
    combos = itertools.islice(itertools.product(*choices), 64)
    out = []
    for combo in combos:
        joints = tuple(c[0] for c in combo)
        geo = {j.id: c[1] for j, c in zip(joints, combo) if c[1] and (old[j.id].type != j.type)}
        out.append((replace(variant, joints=joints), geo))
    return out


def check_remedy(original: Mechanism, variant: Mechanism, base: RankAnalysis, metric_left: float = 0.0,
                 tol: float | None = None) -> RemedyCheck:
    """Re-check a remedy variant (paper 003's class changes) with the rank method.

    Accepted when, for some realisation of the new pairs at the old pairs' points and
    axes, the useful mobility is unchanged, no idle mobility is left and no more
    redundant constraints remain than the metric constraints the formulas admit
    (``metric_left``, which class changes cannot remove).
    """
    old = {j.id: j for j in original.joints}
    moved = [j for j in variant.joints if j.actuated and j.type != old[j.id].type
             and not (old[j.id].type == "P" and j.type == "C")]
    if moved:
        return RemedyCheck(False, "rejected by the rank method: " + "; ".join(
            f"the driven pair {j.id} would become {j.type} ({j.freedom} freedoms): a drive sets one coordinate"
            for j in moved), None, {})
    best: tuple[tuple[int, int, int], RankAnalysis, dict[str, Any]] | None = None
    for mech, geo in _variant_geometry(original, variant):
        try:
            r = analyze_rank(mech, tol=tol if tol is not None else base.tolerance, check_singular=False)
        except InsufficientGeometry as exc:
            return RemedyCheck(True, f"not checked: {exc.message}", None, {})
        lost_drive = int(base.actuation_determined is True and r.actuation_determined is False)
        score = (abs(r.useful_mobility - base.useful_mobility) + lost_drive, len(r.idle_mobilities),
                 max(0, r.redundant_constraints - int(round(metric_left))))
        if best is None or score < best[0]:
            best = (score, r, geo)
        if score == (0, 0, 0):
            break
    assert best is not None
    score, r, geo = best
    if score == (0, 0, 0):
        extra = (f"; {r.redundant_constraints} metric constraint(s) remain, as the formulas say"
                 if r.redundant_constraints else "")
        return RemedyCheck(True, f"confirmed: useful mobility {r.useful_mobility}, no idle mobility, "
                                 f"no redundant constraint{extra}", r, geo)
    why = []
    if score[0] and r.useful_mobility != base.useful_mobility:
        why.append(f"changes the useful mobility from {base.useful_mobility} to {r.useful_mobility}")
    elif score[0]:
        why.append(f"the drives at {', '.join(r.actuated)} no longer determine the motion")
    if score[1]:
        why.append(f"leaves {len(r.idle_mobilities)} idle mobility(ies): {_idle_words(r)}")
    if score[2]:
        locs = "; ".join(f"contour {c.index}: {', '.join(c.directions)}" for c in r.contours if c.redundant)
        why.append(f"leaves {r.redundant_constraints} redundant constraint(s) ({locs})")
    return RemedyCheck(False, "rejected by the rank method: " + "; ".join(why), r, geo)


# --------------------------------------------------------------------------- report
def rank_summary_lines(ra: RankAnalysis) -> list[str]:
    """The rank answer in a few plain lines (terminal and Markdown reports)."""
    lines = [
        f"{ra.motion} motion: F = {ra.pair_freedoms} pair freedoms, {ra.equations} loop-closure equations, "
        f"rank {ra.rank} (tolerance {ra.tolerance:.2g}, length scale {ra.length_scale:.4g})",
        f"instantaneous mobility m = {ra.pair_freedoms} - {ra.rank} = {ra.mobility} = {ra.useful_mobility} useful"
        f" + {len(ra.idle_mobilities)} idle",
        f"redundant constraints q = {ra.equations} - {ra.rank} = {ra.redundant_constraints}"
        + (f" (by contour: {', '.join(map(str, ra.redundant_by_contour))})" if ra.contours else ""),
        f"drives needed: {ra.drives_needed}" + (f"; {ra.actuation_note}" if ra.actuation_note else ""),
    ]
    for i in ra.idle_mobilities:
        lines.append(f"idle mobility: {i.description}")
    if ra.singular:
        lines.append(f"SINGULAR configuration: finite mobility nearby {ra.finite_mobility} "
                     f"(instantaneous {ra.mobility})")
    elif ra.finite_mobility is not None:
        lines.append(f"not singular: finite mobility at nearby assembled configurations {ra.finite_mobility}")
    return lines


def rank_to_markdown(ra: RankAnalysis, comparisons: list[Comparison] | None = None, level: int = 2) -> str:
    h = "#" * level
    out = [f"{h} Rank method (screw theory)", ""] + [f"- {x}" for x in rank_summary_lines(ra)]
    if any(c.redundant for c in ra.contours):
        out += ["", "| contour | joints | redundant | directions | why |", "|---|---|---|---|---|"]
        for c in ra.contours:
            out.append(f"| {c.index} | {' '.join(c.joints)} | {c.redundant} | {'; '.join(c.directions)} | {c.reason} |")
    if comparisons:
        out += ["", f"{h}# Formulas and rank side by side", "", "| quantity | formula | formula | rank | why |",
                "|---|---|---|---|---|"]
        for c in comparisons:
            fv = "n/a" if c.formula_value is None else f"{c.formula_value:g}"
            out.append(f"| {c.quantity} | {c.formula} | {fv} | {c.rank_value} | {c.why} |")
    if ra.notes:
        out += [""] + [f"- note: {n}" for n in ra.notes]
    return "\n".join(out) + "\n"
