"""Screws of kinematic pairs and the linear algebra of the rank method.

The unit twists ``[ω; v]`` each pair permits at the assembled configuration
(:func:`pair_twists`; ``v`` is the velocity of the point at the origin), a planar file
seen in 3-D (:func:`as_spatial`), exponentials of twists, rank and null spaces (one dense
SVD, or contour by contour for large mechanisms: :func:`_eliminate`), and readable names
of wrench subspaces (:func:`describe_wrenches`). The analysis that uses them is
:mod:`mechsyn.structure.rank`.

References
----------
Hunt, K. H. (1978). *Kinematic Geometry of Mechanisms*. Oxford University Press.
Davies, T. H. (1981). Kirchhoff's circulation law applied to multi-loop kinematic chains.
*Mechanism and Machine Theory*, 16(3), 171-183.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Joint, Mechanism

__all__ = ["InsufficientGeometry", "pair_twists", "missing_geometry", "as_spatial", "describe_wrenches",
           "PLANAR_ROWS"]

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

    Examples
    --------
    A planar slider (P pair along x) permits one translation:

    >>> import mechsyn as ms
    >>> slider = ms.examples.load("slider_crank").joint("D")
    >>> pair_twists(slider, planar=True).tolist()
    [[0.0, 0.0, 0.0, 1.0, 0.0, 0.0]]
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
        t = _spatial_contact(joint, "use class 2 (the belt's instantaneous line contact along z)")
        if a is None:
            a = z
        joint = replace(joint, normal=n)
    if planar:
        return _planar_twists(joint, t, p, a, mech)
    if t in ("cam", "gear"):
        t = _spatial_contact(joint, "use class 2 (line contact, with axis) or 1 (point contact)")
    if t != "P" and p is None:
        raise _need(joint, "point", "give point: [x, y, z]")
    if t in ("line_contact", "point_contact"):
        return _contact_twists(joint, t, p, a)
    return _lower_pair_twists(joint, t, p, a)


def _spatial_contact(joint: Joint, hint: str) -> str:
    """A spatial cam, gear or belt as the contact its class stands for (2: line, 1: point)."""
    if joint.pair_class in (1, 2):
        return "line_contact" if joint.pair_class == 2 else "point_contact"
    raise InsufficientGeometry(f"joint {joint.id}: a spatial {joint.type} of class {joint.pair_class} "
                               "has unknown permitted motions", field=f"joints[{joint.id}]", hint=hint)


def _planar_twists(joint: Joint, t: str, p: np.ndarray | None, a: np.ndarray | None,
                   mech: Mechanism | None) -> np.ndarray:
    """Twists of a pair of a planar file, embedded in the plane ``z = 0``."""
    z = np.array([0.0, 0.0, 1.0])
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


def _lower_pair_twists(joint: Joint, t: str, p: np.ndarray | None, a: np.ndarray | None) -> np.ndarray:
    """Twists of a spatial lower pair (R, P, H, C, U, S, S_pin, E)."""
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
    what = {"R": "the rotation axis", "P": "the sliding direction", "H": "the screw axis",
            "C": "the cylinder axis", "E": "the normal of the contact plane"}
    if t in what and a is None:
        raise _need(joint, "axis", f"give axis: {what[t]}")
    if t == "R":
        return np.array([_rot(p, a)])
    if t == "P":
        return np.array([_tr(a)])
    if t == "H":
        h = joint.pitch or 0.0
        return np.array([_rot(p, a) + _tr(h * a)])
    if t == "C":
        return np.array([_rot(p, a), _tr(a)])
    if t == "U":
        if a is None or joint.axis2 is None:
            raise _need(joint, "axis and axis2", "give axis (fixed in the first link) and axis2 (in the second)")
        return np.array([_rot(p, a), _rot(p, _unit(_pad3(joint.axis2)))])
    if t == "E":
        t1, t2 = _perp_basis(a)
        return np.array([_rot(p, a), _tr(t1), _tr(t2)])
    raise _need(joint, "known twists", "use a catalogue pair type")


def _contact_twists(joint: Joint, t: str, p: np.ndarray, a: np.ndarray | None) -> np.ndarray:
    """Twists of a spatial line or point contact."""
    if t == "line_contact":
        if joint.normal is None or a is None:
            raise _need(joint, "normal and axis", "give normal (contact normal) and axis (contact line)")
        n = _unit(_pad3(joint.normal))
        lin = _unit(a - n * (a @ n))
        return np.array([_rot(p, n), _rot(p, lin), _tr(lin), _tr(np.cross(lin, n))])
    if joint.normal is None:
        raise _need(joint, "normal", "give normal: the contact normal")
    t1, t2 = _perp_basis(_unit(_pad3(joint.normal)))
    return np.array([_rot(p, e) for e in _E] + [_tr(t1), _tr(t2)])


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
        wxv = cross_rows(wr, vr)
        p = np.einsum("nij,nj->ni", np.eye(3) - R, wxv) + wr * np.sum(wr * vr, axis=1, keepdims=True) * t[:, None]
        idx = np.flatnonzero(rotating)
        g[idx, :3, :3] = R
        g[idx, :3, 3] = p
    return g


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of two (n, 3) arrays: ``np.cross(a, b)``'s numbers (the same
    operations), without its axis handling, which costs more than the product for a few rows.

    >>> cross_rows(np.array([[1.0, 0, 0]]), np.array([[0.0, 1, 0]]))
    array([[0., 0., 1.]])
    """
    return np.stack([a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
                     a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]], axis=1)


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


def _eliminate(blocks: list[np.ndarray], cols: list[np.ndarray], lam: int, tol: float, F: int) -> _Reduction:
    """Rank and null space contour by contour, touching only each contour's columns.

    ``blocks[k]`` are contour ``k``'s ``λ`` rows on its columns ``cols[k]``. The motions
    the contours seen so far allow are kept as orthonormal parameter vectors: a pair freedom
    no contour has met yet, or a combination ``Σ z_i P_i`` of earlier parameters. Contour
    ``k`` meets only the parameters that move its columns: the SVD of ``B P_J``
    (``λ × |J|``) gives its new independent equations (the sequential reading), its
    redundant ones (left null vectors, as in :func:`_reduce_dense`) and the combinations of
    ``P_J`` it leaves free. A parameter keeps its values only on the columns a later
    contour touches, plus its recipe; the null space is expanded from the recipes at the
    end. For a chain of loops ``|J|`` stays small and the work grows linearly with the
    contours (a dense SVD grows with their cube).
    """
    last = np.full(F, -1)  # the last contour that touches each column
    for k, ck in enumerate(cols):
        last[ck] = k
    live_unit: set[int] = set(range(F))  # parameter c < F: the unit vector of column c
    values: dict[int, dict[int, float]] = {}  # combined parameter -> values on columns still in use
    recipe: dict[int, tuple[list[int], np.ndarray]] = {}  # combined parameter -> (parents, coefficients)
    touch: list[set[int]] = [{c} for c in range(F)]
    next_id = F
    incs, lefts, svs = [], [], []
    for k, (B, ck) in enumerate(zip(blocks, cols)):
        J = sorted(set().union(*(touch[c] for c in ck)))
        if not J:  # every freedom of the contour is already locked
            incs.append(0)
            lefts.append(np.eye(lam))
            svs.append(np.zeros(lam))
            continue
        pos = {int(c): i for i, c in enumerate(ck)}
        PJ = np.zeros((len(ck), len(J)))
        for i, pid in enumerate(J):
            if pid < F:
                PJ[pos[pid], i] = 1.0
            else:
                for c, x in values[pid].items():
                    if c in pos:
                        PJ[pos[c], i] = x
        u, sv, vt = np.linalg.svd(B @ PJ, full_matrices=True)
        s_full = np.zeros(lam)
        s_full[: sv.size] = sv
        inc = int(np.sum(s_full > tol))
        incs.append(inc)
        lefts.append(u)
        svs.append(s_full)
        if inc == 0:
            continue
        Z = vt[inc:].T
        merged: dict[int, np.ndarray] = {}  # column still in use -> values of the J parameters there
        for i, pid in enumerate(J):
            if pid < F:
                live_unit.discard(pid)
                touch[pid].discard(pid)
                if last[pid] > k:
                    merged.setdefault(pid, np.zeros(len(J)))[i] = 1.0
            else:
                for c, x in values.pop(pid).items():
                    touch[c].discard(pid)
                    if last[c] > k:
                        merged.setdefault(c, np.zeros(len(J)))[i] = x
        for j in range(Z.shape[1]):
            vals = {c: float(row @ Z[:, j]) for c, row in merged.items()}
            big = max((abs(x) for x in vals.values()), default=0.0)
            values[next_id] = {c: x for c, x in vals.items() if abs(x) > 1e-15 * big}
            recipe[next_id] = (J, Z[:, j].copy())
            for c in values[next_id]:
                touch[c].add(next_id)
            next_id += 1
    N = _expand(sorted(live_unit), sorted(values), recipe, F)
    sv_all = np.concatenate(svs) if svs else np.zeros(0)
    return _Reduction(F - N.shape[1], N, incs, lefts, sv_all)


def _expand(units: list[int], combined: list[int], recipe: dict[int, tuple[list[int], np.ndarray]],
            F: int) -> np.ndarray:
    """The null space (``F × m``) from the surviving parameters: unit columns, and combined
    parameters expanded through their recipes (coefficients pushed from the newest
    parameter down to the pair freedoms, all surviving parameters at once)."""
    m = len(units) + len(combined)
    N = np.zeros((F, m))
    for i, c in enumerate(units):
        N[c, i] = 1.0
    if not combined:
        return N
    coef: dict[int, np.ndarray] = {}
    for i, pid in enumerate(combined, start=len(units)):
        coef[pid] = np.zeros(m)
        coef[pid][i] = 1.0
    for pid in sorted(recipe, reverse=True):
        row = coef.pop(pid, None)
        if row is None:
            continue
        parents, z = recipe[pid]
        for parent, zi in zip(parents, z):
            if parent < F:
                N[parent] += zi * row
            elif parent in coef:
                coef[parent] += zi * row
            else:
                coef[parent] = zi * row
    return N


# --------------------------------------------------------------------------- wrenches named
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
