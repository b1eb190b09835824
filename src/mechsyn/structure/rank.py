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

**Finite mobility.** The local dimension of the configuration space with every drive
free (:mod:`mechsyn.structure.finite`): tangent steps projected back onto the loop
closure (Gauss-Newton on the product-of-exponentials closure) at two shrinking scales
tell whether every instantaneous motion extends to a finite one (a regular
configuration); otherwise the branches through the configuration are found and measured,
and the configuration is **singular** (branches meet) or **shaky** (smooth, with fewer
finite than instantaneous freedoms). Higher pairs are followed as their instantaneously
equivalent chain of lower pairs (the contact surfaces' curvature is not in the file).

Pair twists and the linear algebra live in :mod:`mechsyn.structure.screws`, idle
mobilities in :mod:`mechsyn.structure.idle`, the formulas side by side and the remedy
checks in :mod:`mechsyn.structure.compare`.

References
----------
.. [1] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from mechsyn.model.contour import contour_links
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.progress import ProgressCallback, report
from mechsyn.structure.contours import independent_contours
from mechsyn.structure.drives import excess_drives
from mechsyn.structure.finite import LocalMobility, local_mobility, subgroup_dimension
from mechsyn.structure.idle import IdleInputs, IdleMobility, find_idle_mobilities
from mechsyn.structure.screws import (  # noqa: F401  (re-exported: the names users import from here)
    _AXIS_NAMES,
    PLANAR_ROWS,
    InsufficientGeometry,
    _belt_geometry,
    _eliminate,
    _exp,
    _gear_geometry,
    _null,
    _pad3,
    _rank,
    _reduce_dense,
    _Reduction,
    _unit,
    _vec,
    as_spatial,
    cross_rows,
    describe_wrenches,
    missing_geometry,
    pair_twists,
)

__all__ = [
    "RankAnalysis", "IdleMobility", "ContourRank", "InsufficientGeometry",
    "analyze_rank", "pair_twists", "missing_geometry", "as_spatial", "describe_wrenches",
]

#: Above this many pair freedoms the loop-closure matrix is reduced contour by contour
#: (:func:`_eliminate`) instead of by one dense SVD (``O(F³)``).
DENSE_MAX_FREEDOMS = 120


def _reduce(sysm: "_System", theta: np.ndarray, tol: float) -> _Reduction:
    """Rank and null space of the loop-closure matrix at ``θ``: one dense SVD for small
    systems, contour-by-contour elimination on its blocks above :data:`DENSE_MAX_FREEDOMS`."""
    if sysm.twists.shape[0] <= DENSE_MAX_FREEDOMS:
        return _reduce_dense(sysm.closure(theta)[0], sysm.lam, tol)
    blocks, _ = sysm.closure_blocks(theta)
    return _eliminate(blocks, sysm.contour_columns(), sysm.lam, tol, sysm.twists.shape[0])


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
    shaky: bool = False
    configuration: str = "not checked"
    mobility_reading: str = ""
    excess_drives: list[str] = field(default_factory=list)

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
            "actuation_note": self.actuation_note, "excess_drives": self.excess_drives,
            "length_scale": self.length_scale,
            "pair_freedoms": self.pair_freedoms, "equations": self.equations, "rank": self.rank,
            "smallest_singular_values": self.smallest_singular_values,
            "near_singular": self.near_singular, "notes": self.notes,
            "shaky": self.shaky, "configuration": self.configuration, "mobility_reading": self.mobility_reading,
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
    _cols: list[np.ndarray] | None = None

    @property
    def lam(self) -> int:
        return 3 if self.planar else 6

    def rows(self, mat: np.ndarray) -> np.ndarray:
        return mat[PLANAR_ROWS] if self.planar else mat

    def contour_columns(self) -> list[np.ndarray]:
        """The columns (pair freedoms) each contour's equations touch, sorted."""
        if self._cols is None:
            self._cols = [np.array(sorted({c for c, _ in fac}), dtype=int) for fac in self.factors]
        return self._cols

    def closure_blocks(self, theta: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
        """Per contour, its ``λ`` loop-closure rows on its own columns
        (:meth:`contour_columns`), and the closure error (λK): the loop-closure matrix
        without its zeros (a large mechanism's dense matrix would not fit in memory).

        Every contour's product of exponentials is taken step by step for all contours at
        once (contours padded to the longest one)."""
        F = self.twists.shape[0]
        K = len(self.factors)
        lam = self.lam
        if K == 0:
            return [], np.zeros(0)
        exps = np.concatenate([_exp(self.twists, theta), _exp(self.twists, -theta)])  # + then - sign
        L = max(len(f) for f in self.factors)
        cols = np.full((K, L), -1)
        where = np.zeros((K, L), dtype=int)  # position of the column in the contour's own columns
        signs = np.zeros((K, L))
        for k, (fac, own) in enumerate(zip(self.factors, self.contour_columns())):
            cols[k, : len(fac)] = [c for c, _ in fac]
            where[k, : len(fac)] = np.searchsorted(own, [c for c, _ in fac])
            signs[k, : len(fac)] = [sg for _, sg in fac]
        rows = PLANAR_ROWS if self.planar else np.arange(6)
        blocks = np.zeros((K, lam, L))
        g = np.tile(np.eye(4), (K, 1, 1))
        for t in range(L):
            k = np.flatnonzero(cols[:, t] >= 0)
            c, sg = cols[k, t], signs[k, t]
            xi = self.twists[c] * sg[:, None]
            R, p = g[k, :3, :3], g[k, :3, 3]
            w = np.einsum("kij,kj->ki", R, xi[:, :3])
            v = np.einsum("kij,kj->ki", R, xi[:, 3:]) + cross_rows(p, w)
            blocks[k, :, where[k, t]] = np.concatenate([w, v], axis=1)[:, rows]
            g[k] = g[k] @ exps[np.where(sg > 0, c, c + F)]
        R, p = g[:, :3, :3], g[:, :3, 3]
        e = np.concatenate([0.5 * np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0],
                                             R[:, 1, 0] - R[:, 0, 1]], axis=1), p], axis=1)
        return [blocks[k, :, : len(own)] for k, own in enumerate(self.contour_columns())], e[:, rows].reshape(-1)

    def closure(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Loop-closure twist matrix ``M(θ)`` (λK × F, dense) and the closure error (λK)."""
        blocks, err = self.closure_blocks(theta)
        lam = self.lam
        M = np.zeros((lam * len(blocks), self.twists.shape[0]))
        for k, (B, own) in enumerate(zip(blocks, self.contour_columns())):
            M[lam * k: lam * (k + 1), own] = B
        return M, err

    def sparse_closure(self, blocks: list[np.ndarray]) -> Any:
        """The loop-closure matrix from its blocks, as a SciPy sparse matrix."""
        from scipy.sparse import coo_matrix

        lam = self.lam
        rows = [np.repeat(lam * k + np.arange(lam), len(own)) for k, own in enumerate(self.contour_columns())]
        cols = [np.tile(own, lam) for own in self.contour_columns()]
        return coo_matrix((np.concatenate([B.reshape(-1) for B in blocks]), (np.concatenate(rows),
                          np.concatenate(cols))), shape=(lam * len(blocks), self.twists.shape[0])).tocsc()


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


#: Family (b) of the idle rule: the centres of these pairs stay at rest, the axes of
#: those stay in place as lines (see :mod:`mechsyn.structure.idle`).
_POINT_PAIRS = ("U", "S", "S_pin")
_LINE_PAIRS = ("R", "H", "C")
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

    centres, contacts, lines, slides, planes = [], [], [], [], []
    z = np.array([0.0, 0.0, 1.0])
    for j in mech.joints:
        on = [index[x] for x in j.links if x in index]
        axis = z if (j.axis is None or sysm.planar and j.type != "P") else _unit(_pad3(j.axis))
        if j.type in _POINT_PAIRS and j.point is not None:
            centres += [(i, norm(j.point)) for i in on]
        elif j.type in _LINE_PAIRS and j.point is not None:
            lines += [(i, norm(j.point), axis) for i in on]
        elif j.type == "P" and j.axis is not None:
            slides += [(i, axis) for i in on]
        elif j.type == "E" and j.point is not None:
            planes += [(i, norm(j.point), axis) for i in on]
        elif j.type in _HIGHER_PAIRS:
            pn = _contact(j, mech)
            if pn is not None:
                contacts += [(i, norm(pn[0]), pn[1]) for i in on]
    named = [(index[p.link], norm(p.at)) for p in mech.points.values() if p.link in index]
    edges = [tuple(index.get(x, -1) for x in j.links) for j in mech.joints]
    return IdleInputs(A=LT @ Z0, rates=N @ Z0, col_joint=sysm.col_joint, links=names, edges=edges,  # type: ignore[arg-type]
                      centres=centres, named=named, contacts=contacts, joint_ids=[j.id for j in mech.joints],
                      centre=sysm.centre, scale=sysm.scale, drives=any(j.actuated for j in mech.joints),
                      lines=lines, slides=slides, planes=planes)


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


def _gauss_newton_step(sysm: "_System", theta: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The closure error at ``θ`` and the least-norm step ``δ`` with ``M δ ≈ err``:
    truncated SVD with the rank tolerance (near-null directions left alone) for small
    systems; for large ones the damped step ``Mᵀ (M Mᵀ + tol² I)⁻¹ err`` by a sparse LU
    (banded for chains)."""
    if sysm.twists.shape[0] <= DENSE_MAX_FREEDOMS:
        M, err = sysm.closure(theta)
        u, sv, vt = np.linalg.svd(M, full_matrices=False)
        keep = sv > tol
        return err, vt[keep].T @ ((u[:, keep].T @ err) / sv[keep])
    from scipy.sparse import identity
    from scipy.sparse.linalg import spsolve

    blocks, err = sysm.closure_blocks(theta)
    A = sysm.sparse_closure(blocks)
    return err, A.T @ spsolve((A @ A.T + tol * tol * identity(A.shape[0], format="csc")).tocsc(), err)


def analyze_rank(mech: Mechanism, planar: bool | None = None, tol: float | None = None,
                 check_singular: bool = True, seed: int = 0,
                 progress: ProgressCallback | None = None) -> RankAnalysis:
    """Screw-theory rank analysis of ``mech`` at its assembled configuration.

    ``planar`` defaults to the file's kind (a planar file is analysed with planar
    motion, 3 equations per contour; see :func:`as_spatial` for the 3-D picture).
    ``progress(state)`` (:class:`mechsyn.progress.Progress`) is called as each stage
    starts: stages done of 4, the stage's name (``"contours"``, ``"rank"``, ``"idle"``,
    ``"singularity"``). BLAS runs on one thread meanwhile: the
    method makes many small decompositions, which threads only slow down (and on a
    loaded machine by 10-50x). Raises :class:`InsufficientGeometry` when a joint lacks
    the geometry its twists need.

    Examples
    --------
    >>> import mechsyn as ms
    >>> ra = ms.analyze_rank(ms.examples.load("bennett"))    # mobile although Grübler says -2
    >>> ra.mobility, ra.redundant_constraints
    (1, 3)
    >>> ra.finite_mobility, ra.configuration                # and the motion is finite
    (1, 'regular')
    >>> ms.analyze_rank(ms.examples.load("fourbar_taut")).mobility_reading[:53]
    'shaky: instantaneous mobility 2 but finite mobility 0'

    A spatial RSSR linkage: two instantaneous freedoms, one of them the rod's idle spin
    between its ball joints, about the line B-C (direction (2, 1, 2.2) normalised).

    >>> from mechsyn.io import mechanism_from_dict
    >>> rssr = mechanism_from_dict({"name": "RSSR", "kind": "spatial", "ground": "frame",
    ...     "links": ["frame", "crank", "rod", "rocker"], "joints": [
    ...     {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0, 0], "axis": [0, 0, 1],
    ...      "actuated": True},
    ...     {"id": "B", "type": "S", "links": ["crank", "rod"], "point": [1, 0, 0]},
    ...     {"id": "C", "type": "S", "links": ["rod", "rocker"], "point": [3, 1, 2.2]},
    ...     {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [3, 2, 1], "axis": [1, 0, 0]}]})
    >>> r = analyze_rank(rssr)
    >>> r.mobility, r.useful_mobility, r.actuation_determined
    (2, 1, True)
    >>> [(i.links, i.family, [round(x, 4) for x in i.axis["direction"]]) for i in r.idle_mobilities]
    [(['rod'], 'group', [0.6376, 0.3188, 0.7013])]
    """
    if len(mech.joints) < SMALL_JOINTS:  # BLAS does not thread matrices this small
        return _analyze_rank(mech, planar, tol, check_singular, seed, progress)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        return _analyze_rank(mech, planar, tol, check_singular, seed, progress)


#: Below this many joints :func:`analyze_rank` leaves the BLAS threads alone: its matrices
#: are too small for BLAS to thread, and finding the BLAS libraries (threadpoolctl) would
#: cost more than the analysis of a four-bar.
SMALL_JOINTS = 24


def _analyze_rank(mech: Mechanism, planar: bool | None, tol: float | None, check_singular: bool, seed: int,
                  progress: ProgressCallback | None) -> RankAnalysis:
    planar = mech.kind == "planar" if planar is None else planar
    report(progress, 0, 4, "contours")
    sysm = _build_system(mech, planar)
    lam, K, F = sysm.lam, len(sysm.contours), sysm.twists.shape[0]
    tol = _default_tolerance(mech, sysm) if tol is None else tol
    notes: list[str] = []
    report(progress, 1, 4, "rank")
    red = _reduce(sysm, np.zeros(F), tol)
    near = _near_singular_note(red.singular_values, tol, F, lam * K, red.rank, notes)
    mobility, redundant, N = F - red.rank, lam * K - red.rank, red.null
    contours = _contour_ranks(sysm, red, tol)
    if sum(c.redundant for c in contours) != redundant:  # borderline singular values: say so
        notes.append(f"per-contour counts ({', '.join(str(c.redundant) for c in contours)}) and the total "
                     f"{redundant} differ at this tolerance: a singular value is close to it")
    report(progress, 2, 4, "idle")
    acols, anames = _actuated_columns(sysm)
    Z0 = _null(N[acols], tol) if mobility and acols else np.eye(mobility)
    idle, _, idle_notes = find_idle_mobilities(_idle_inputs(mech, sysm, N, Z0), tol) if mobility else ([], None, [])
    notes.extend(idle_notes)
    useful = mobility - len(idle)
    determined, anote, excess = _actuation(sysm, N, Z0, acols, anames, len(idle), tol)
    lm = LocalMobility(0, 0, "regular", 0, red.rank) if mobility == 0 else \
        LocalMobility(mobility, None, "not checked", None, None)
    if check_singular and mobility > 0:
        report(progress, 3, 4, "singularity")
        lm, contours = _local(sysm, N, tol, red.rank, len(idle), contours, notes, seed)
    drives = useful if lm.finite is None else max(lm.finite - len(idle), 0)  # from the finite mobility
    if lm.finite is not None and drives == 0 and mobility and anames:
        spins = f" besides {_n(len(idle), 'idle motion')}" if idle else ""
        determined, anote = True, (f"the drive(s) at {', '.join(anames)} are locked: the mechanism is rigid "
                                   f"(finite mobility 0{spins}), no drive can move it")
    sv = red.singular_values
    return RankAnalysis(
        motion="planar" if planar else "spatial", mobility=mobility, useful_mobility=useful,
        idle_mobilities=idle, redundant_constraints=redundant, contours=contours, drives_needed=drives,
        actuated=anames, actuation_determined=determined, actuation_note=anote, excess_drives=excess,
        singular=lm.configuration == "singular", shaky=lm.configuration == "shaky", configuration=lm.configuration,
        mobility_reading=mobility_reading(lm.configuration, mobility, lm.finite), finite_mobility=lm.finite, tolerance=float(tol), length_scale=float(sysm.scale), pair_freedoms=F,
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
        shown = ", ".join(f"{x:.2g}" for x in np.sort(small)[:6]) + (f" and {k - 6} more" if k > 6 else "")
        notes.append(f"near-singular: singular value(s) {shown} above the tolerance "
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
               tol: float) -> tuple[bool | None, str, list[str]]:
    """Whether the drives determine the motion (every motion left with them at rest is
    idle), the sentence that says so, and the drives in excess (:func:`excess_drives`)."""
    if not anames:
        return None, "", []
    mobility = N.shape[1]
    uncontrolled = Z0.shape[1] - idle
    locked = [j.id for k, j in enumerate(sysm.joints) if j.actuated and mobility
              and np.max(np.abs(N[sysm.col_joint == k]), initial=0.0) <= tol]
    if uncontrolled:
        if locked:  # a drive at a dead centre: the geometry holds it, the rest moves
            return False, (f"the drive(s) at {', '.join(locked)} are locked at this pose (a dead centre: they cannot "
                           f"move the mechanism here); {uncontrolled} useful motion(s) undetermined"), []
        return False, (f"the drives at {', '.join(anames)} leave {uncontrolled} useful motion(s) undetermined: "
                       f"{mobility - idle} drive(s) needed"), []
    rows = {name: [c for c in acols if sysm.joints[int(sysm.col_joint[c])].id == name] for name in anames}
    excess = excess_drives(N, rows, anames, tol) if mobility else list(anames)
    if excess:
        if mobility and all(d in locked for d in excess):  # the geometry holds them, not the other drives
            return True, (f"the drive(s) at {', '.join(locked)} are locked: the mechanism cannot move them at "
                          "this pose" + (f"; the drives at {', '.join(a for a in anames if a not in locked)} "
                                         "determine the motion" if len(locked) < len(anames) else "")), []
        return True, (f"the drives at {', '.join(anames)} determine the motion but {len(excess)} of them "
                      f"({', '.join(excess)}) {'is' if len(excess) == 1 else 'are'} not independent (redundant actuation: the drives fight each other)"
                      + (f"; the mechanism locks the drive(s) at {', '.join(locked)}: they cannot move"
                         if locked else "")), excess
    return True, f"the drives at {', '.join(anames)} determine the motion", []


def _local(sysm: _System, N: np.ndarray, tol: float, rank: int, idle: int, contours: list[ContourRank],
           notes: list[str], seed: int) -> tuple[LocalMobility, list[ContourRank]]:
    """Finite mobility and kind of configuration (:mod:`mechsyn.structure.finite`), with
    the notes and the contours' reasons amended."""
    F, equations = sysm.twists.shape[0], sysm.lam * len(sysm.contours)
    if not sysm.contours:  # an open chain: every pair freedom is a finite motion
        return LocalMobility(N.shape[1], N.shape[1], "regular", N.shape[1], rank), contours
    if rank in (equations, len(sysm.contours) * subgroup_dimension(sysm.twists)):  # provably regular
        # the loop-closure map (into the subgroup the twists generate: planar or spherical
        # mechanisms in 3-D) has a surjective derivative here, so by the implicit function
        # theorem its zero set is a manifold of dimension F - rank near the pose (finite.py)
        return LocalMobility(N.shape[1], N.shape[1], "regular", N.shape[1], rank), contours

    def null(theta: np.ndarray) -> tuple[int, np.ndarray]:
        red = _reduce(sysm, theta, tol)
        return red.rank, red.null

    lm = local_mobility(lambda th: _gauss_newton_step(sysm, th, tol), null, N, rank, tol, seed=seed)
    notes.extend(lm.notes)
    if lm.configuration in ("regular", "not followed"):
        return lm, contours
    m, r_near = N.shape[1], lm.rank_nearby or rank
    if lm.configuration == "shaky":
        notes.append(f"shaky configuration: {m} instantaneous freedom(s) but {lm.finite} finite one(s): "
                     f"{m - lm.finite} instantaneous motion(s) that no finite motion follows"
                     + (" (the pose is isolated: no other assembly near it)" if lm.finite == 0 else "")
                     + "; no first-order stiffness holds them, so the linkage gives under load")
        return lm, contours
    notes.append(f"singular configuration: {m} instantaneous freedom(s) but {lm.finite} finite one(s); at nearby "
                 f"assembled configurations {max(F - r_near - idle, 0)} drive(s) and {equations - r_near} "
                 "redundant constraint(s)")
    lead = "singular configuration (pairs lined up): "
    if equations - r_near == 0:
        lead += "every redundant constraint vanishes at nearby configurations"
        return lm, [replace(c, reason=lead) if c.redundant else c for c in contours]
    lead += f"{r_near - rank} redundant constraint(s) vanish at nearby configurations; otherwise "
    return lm, [replace(c, reason=lead + c.reason) if c.redundant else c for c in contours]


def mobility_reading(configuration: str, instantaneous: int, finite: int | None) -> str:
    """The kind of configuration in words: which of instantaneous / finite / singular /
    shaky holds.

    >>> mobility_reading("shaky", 2, 0)
    'shaky: instantaneous mobility 2 but finite mobility 0 at a regular configuration (2 instantaneous motion(s) do not extend to finite ones; the configuration space is smooth here)'
    """
    if configuration == "not checked":
        return f"instantaneous mobility {instantaneous}; the finite mobility was not checked"
    if finite is None:
        return f"instantaneous mobility {instantaneous}; the finite mobility is unknown (the motion could not be followed)"
    if configuration == "regular":
        return (f"regular: instantaneous mobility {instantaneous} = finite mobility {finite} (every instantaneous "
                "motion extends to a finite one)")
    if configuration == "singular":
        return (f"singular: instantaneous mobility {instantaneous} but finite mobility {finite} (branches of the "
                "motion meet here)")
    return (f"shaky: instantaneous mobility {instantaneous} but finite mobility {finite} at a regular configuration "
            f"({instantaneous - finite} instantaneous motion(s) do not extend to finite ones; the configuration "
            "space is smooth here)")


# --------------------------------------------------------------------------- report
def _n(k: int, word: str) -> str:
    return f"{k} {word}" + ("" if k == 1 else "s")


def motion_headline(ra: RankAnalysis) -> str:
    """What the mechanism does, first: rigid or moving with how many finite degrees of
    freedom, then the instantaneous count where it differs (shaky or singular), idle motions
    apart.

    Examples
    --------
    >>> import mechsyn as ms
    >>> motion_headline(ms.analyze_rank(ms.examples.load("fourbar_taut")))
    'rigid (finite mobility 0), shaky: 2 instantaneous motions'
    >>> motion_headline(ms.analyze_rank(ms.examples.load("rssr")))
    'moves with 1 degree of freedom (finite; besides 1 idle motion)'
    """
    idle = len(ra.idle_mobilities)
    spins = f"; besides {_n(idle, 'idle motion')}" if idle else ""
    if ra.finite_mobility is None:
        return (f"instantaneous mobility {ra.useful_mobility}{spins.replace(';', ',')} (the finite mobility "
                f"{'was not checked' if ra.configuration == 'not checked' else 'is unknown'})")
    finite = max(ra.finite_mobility - idle, 0)
    if finite == 0:
        head = f"rigid (finite mobility 0{spins})"
        return head + (f", shaky: {_n(ra.useful_mobility, 'instantaneous motion')}" if ra.useful_mobility else "")
    head = f"moves with {_n(finite, 'degree')} of freedom (finite{spins})".replace("degrees of", "degrees of")
    return head + (f", instantaneously {ra.useful_mobility}" if ra.useful_mobility > finite else "")


def rank_summary_lines(ra: RankAnalysis) -> list[str]:
    """The rank answer in a few plain lines (terminal and Markdown reports)."""
    lines = [
        motion_headline(ra)[0].upper() + motion_headline(ra)[1:],
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
    if ra.mobility_reading:  # "SINGULAR: ..." and "SHAKY: ..." stand out; "Regular: ..."
        head, _, rest = ra.mobility_reading.partition(":")
        lines.append((head.upper() if ra.singular or ra.shaky else head.capitalize()) + ":" + rest)
    return lines

