"""Idle mobilities of links and of link groups (issue 12 §1; derivation in docs/rank.md).

With every drive at rest, the mechanism's remaining instantaneous motions form the
subspace ``Z0`` of the null space of the loop-closure matrix. An **idle** motion is

(a) a motion of one link or of a connected group of links moving as ONE rigid body
    (one twist ``t``) while every other link stays, that moves no named point; or
(b) a motion in which every link joined to the frame stays at rest, every S, U and
    S_pin centre and every named point stays at rest, every R, C and H axis stays in
    place as a line (whatever point of it the file gives), every slide (P) keeps its
    direction and every plane pair (E) its plane, and no output turns (a link joined to
    one neighbour only keeps its place on it). Nothing in this family depends on which
    point of an axis the file writes. When the file declares no drive, a motion carried
    through a higher pair (the contact point's velocity along the contact normal not
    zero: a cam turning its follower) is the function, not idle (a note says so).

The idle count is the dimension of the span of both families (they overlap: a rod
spinning between two ball joints is in both); the useful mobility is ``m`` minus it.
A group (or link) joined to one neighbour only is an output: its motion is the function,
never idle (a door on its hinges, the last link of an open chain). A five-bar's second
freedom is not idle: with one crank at rest the other three links move with different
twists and move joint centres.

The functions here work on arrays only: the link twists per basis motion
(``links × 6 × d``, normalised units, see :mod:`mechsyn.structure.rank`), the joint
graph, and the points that must stay at rest.

References
----------
Hunt, K. H. (1978). *Kinematic Geometry of Mechanisms*. Oxford University Press.
Gogu, G. (2005). Mobility of mechanisms: a critical review. *Mechanism and Machine
Theory*, 40(9), 1068-1097.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["IdleMobility", "IdleInputs", "find_idle_mobilities", "screw_axis", "MAX_GROUP_LINKS"]

#: Largest link group searched for family (a) motions (groups beyond it are reported).
MAX_GROUP_LINKS = 6
_MAX_GROUPS = 20000


@dataclass(frozen=True)
class IdleMobility:
    """An idle mobility: the links it moves, its axis, the pairs whose rates it uses.

    ``link`` is the moved links joined with ``+`` (one name for a single link);
    ``family`` is ``"group"`` (one rigid body: a link or a connected group of links),
    ``"centres"`` (family (b): the links joined to the frame at rest, every joint axis in
    place and every ball centre and named point at rest, links turning with different
    twists) or ``"cancelling"`` (pair rates that cancel: no link moves).
    ``axis`` is the common screw axis of the moved links (``direction``, ``point`` (None
    for a slide), ``pitch`` (length per radian; None for a slide)), or None when the
    links move with different twists; ``axes`` gives each link's.
    """

    link: str
    joints: list[str]
    description: str
    links: list[str] = field(default_factory=list)
    family: str = "group"
    axis: dict[str, Any] | None = None
    axes: dict[str, dict[str, Any]] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "joints": self.joints, "description": self.description,
                "links": self.links, "family": self.family, "axis": self.axis, "axes": self.axes}


@dataclass
class IdleInputs:
    """What :func:`find_idle_mobilities` needs, in normalised units.

    ``A``: twists of the moving links per basis motion of ``Z0`` (``n × 6 × d``, ``[ω; v]``
    with ``v`` the velocity of the point at the origin); ``rates``: pair rates per basis
    motion (``F × d``); ``col_joint``: joint index of each rate; ``links``: moving link
    names (rows of ``A``); ``edges``: per joint ``(link a, link b)`` as indices into
    ``links`` or ``-1`` for the frame; ``centres``: ``(link index, point)`` that must stay
    at rest in family (b) (lower-pair centres on moving links); ``named``: ``(link index,
    point)`` of the named points; ``contacts``: ``(link index, point, normal)`` of the
    higher pairs; ``joint_ids``: joint names; ``drives``: whether drives are declared
    (``Z0`` is then the motion left with them at rest).
    """

    A: np.ndarray
    rates: np.ndarray
    col_joint: np.ndarray
    links: list[str]
    edges: list[tuple[int, int]]
    centres: list[tuple[int, np.ndarray]]
    named: list[tuple[int, np.ndarray]]
    contacts: list[tuple[int, np.ndarray, np.ndarray]]
    joint_ids: list[str]
    centre: np.ndarray
    scale: float
    drives: bool = True
    lines: list[tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list)
    slides: list[tuple[int, np.ndarray]] = field(default_factory=list)
    planes: list[tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list)


def _skew(p: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -p[2], p[1]], [p[2], 0.0, -p[0]], [-p[1], p[0], 0.0]])


def _point_velocity(Al: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Velocity of point ``p`` of a link with twists ``Al`` (6 × d): ``v + ω × p`` (3 × d)."""
    return Al[3:] - _skew(p) @ Al[:3]


def _null_basis(rows: np.ndarray, d: int, tol: float) -> np.ndarray:
    if rows.shape[0] == 0:
        return np.eye(d)
    _, s, vt = np.linalg.svd(rows, full_matrices=rows.shape[0] < d)  # vt is d × d either way
    return vt[int(np.sum(s > tol)):].T


def _orth(a: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    if a.size == 0:
        return a.reshape(a.shape[0], 0)
    u, s, _ = np.linalg.svd(a, full_matrices=False)
    return u[:, : int(np.sum(s > tol))]


def screw_axis(tw: np.ndarray, centre: np.ndarray, scale: float) -> dict[str, Any]:
    """The screw axis of a normalised twist ``[ω; v]``: direction, a point on it (the
    foot of the perpendicular from the centre of the joint points) and pitch, in the file's
    units; a pure slide has ``point`` and ``pitch`` None.

    Examples
    --------
    A turn about the z axis through (1, 0, 0), lengths in units of 2 from the origin:

    >>> import numpy as np
    >>> screw_axis(np.array([0, 0, 1.0, 0, -0.5, 0]), centre=np.zeros(3), scale=2.0)
    {'direction': [0.0, 0.0, 1.0], 'point': [1.0, 0.0, 0.0], 'pitch': 0.0}
    """
    w, v = tw[:3], tw[3:]
    nw = float(np.linalg.norm(w))
    if nw < 1e-9 * max(1.0, float(np.linalg.norm(v))):
        d = v / np.linalg.norm(v)
        d = d * np.sign(d[np.argmax(np.abs(d))])
        return {"direction": _clean(d), "point": None, "pitch": None}
    d = w / nw
    sgn = np.sign(d[np.argmax(np.abs(d))])
    r = np.cross(w, v) / nw ** 2
    pitch = float(w @ v) / nw ** 2 * scale
    return {"direction": _clean(d * sgn), "point": _clean(centre + scale * r), "pitch": _clean1(pitch)}


def _clean1(x: float) -> float:
    return 0.0 if abs(x) < 1e-9 else round(float(x), 10)


def _clean(v: np.ndarray) -> list[float]:
    return [_clean1(x) for x in v]


def _connected_groups(nodes: list[int], adj: dict[int, set[int]], k_max: int,
                      cap: int) -> tuple[list[tuple[int, ...]], bool]:
    """Connected node sets of up to ``k_max`` nodes, smallest first; True when larger
    connected sets exist (or ``cap`` sets were reached) and were left out."""
    out: list[tuple[int, ...]] = []
    level = {frozenset([v]) for v in nodes}
    for size in range(1, k_max + 1):
        nxt: set[frozenset[int]] = set()
        for g in sorted(level, key=sorted):
            out.append(tuple(sorted(g)))
            if len(out) >= cap:
                return out, True
            for v in g:
                nxt.update(g | {w} for w in adj[v] if w not in g)
        if size == k_max:
            return out, bool(nxt)
        level = nxt
        if not level:
            break
    return out, False


def _components(nodes: list[int], adj: dict[int, set[int]]) -> list[list[int]]:
    """Connected components (sorted node lists) of the graph ``adj`` on ``nodes``."""
    seen: set[int] = set()
    out = []
    for v in nodes:
        if v in seen:
            continue
        comp, stack = [], [v]
        seen.add(v)
        while stack:
            u = stack.pop()
            comp.append(u)
            for w in adj[u] - seen:
                seen.add(w)
                stack.append(w)
        out.append(sorted(comp))
    return out


def _describe(links: list[str], joints: list[str], axis: dict[str, Any] | None, family: str) -> str:
    who = links[0] if len(links) == 1 else " and ".join([", ".join(links[:-1]), links[-1]])
    pairs = f" (pairs {', '.join(joints)})" if joints else ""
    if family == "cancelling":
        return f"joint rates of {', '.join(joints)} cancel: no link moves (coaxial or duplicated pairs)"
    if axis is None:
        return (f"{who} turn with different twists, each about its own joint axis (every joint axis in place), "
                f"the links joined to the frame at rest{pairs}")
    together = "" if len(links) == 1 else " together as one body"
    if axis["point"] is None:
        return f"{who} slide{'s' if len(links) == 1 else ''}{together} along {_vec(axis['direction'])}{pairs}"
    spin = "spins" if len(links) == 1 else "spin"
    pitch = f" with pitch {axis['pitch']:.4g}" if axis["pitch"] else ""
    return f"{who} {spin}{together} about the axis along {_dir(axis['direction'])} through {_vec(axis['point'])}{pitch}{pairs}"


def _num(x: float) -> str:
    x = 0.0 if abs(x) < 5e-10 else x
    return f"{x:.4g}"


def _vec(v: list[float]) -> str:
    return "(" + ", ".join(_num(float(x)) for x in v) + ")"


def _dir(v: list[float]) -> str:
    for k, name in enumerate("xyz"):
        if abs(abs(v[k]) - 1.0) < 1e-6:
            return name
    return _vec(v)


def _family_b_rows(inp: IdleInputs, neighbours: dict[int, set[int]]) -> list[np.ndarray]:
    """The linear conditions (rows, each ``k × d``) of family (b).

    A line through ``p`` along unit ``a`` stays in place under a twist ``[ω; v]`` exactly
    when ``ω ∥ a`` and the velocity of ``p`` is along ``a``: ``(I - aaᵀ) ω = 0`` and
    ``(I - aaᵀ) v(p) = 0``. Both hold for every point ``p + s a`` of the line
    (``v(p + s a) = v(p) + s ω × a``), so the rows do not depend on the point written."""
    A = inp.A
    rows = [_point_velocity(A[li], p) for li, p in inp.centres + inp.named]
    for li, p, a in inp.lines:
        P = np.eye(3) - np.outer(a, a)
        rows += [P @ A[li, :3], P @ _point_velocity(A[li], p)]
    for li, a in inp.slides:
        rows.append((np.eye(3) - np.outer(a, a)) @ A[li, :3])
    for li, p, nrm in inp.planes:
        rows += [(np.eye(3) - np.outer(nrm, nrm)) @ A[li, :3], (nrm @ _point_velocity(A[li], p))[None]]
    for i in range(A.shape[0]):
        if -1 in neighbours[i]:
            rows.append(A[i])  # joined to the frame: at rest
        elif len(neighbours[i]) < 2:
            (other,) = neighbours[i] or {-1}
            rows.append(A[i] - A[other])
    return rows


def find_idle_mobilities(inp: IdleInputs, tol: float) -> tuple[list[IdleMobility], np.ndarray, list[str]]:
    """Idle mobilities (families (a) and (b), module docstring) of the motions ``Z0``.

    Returns the idle mobilities (a basis of the span of both families: first pair rates
    that cancel, then rigid groups smallest first, then what only family (b) adds), their
    basis in ``Z0`` coordinates (``d × idle``) and notes (e.g. a group search cut short).
    """
    A = inp.A
    n, _, d = A.shape
    notes: list[str] = []
    if d == 0:
        return [], np.zeros((0, 0)), notes
    # motions that move no link at all (pair rates cancelling): idle, family (b) trivially
    flat = A.reshape(n * 6, d)
    Zn = _null_basis(flat, d, tol) if n else np.eye(d)
    basis = Zn.copy()
    found: list[tuple[str, list[int], np.ndarray]] = [("cancelling", [], Zn[:, i]) for i in range(Zn.shape[1])]

    neighbours: dict[int, set[int]] = {i: set() for i in range(n)}
    for a, b in inp.edges:
        if a >= 0:
            neighbours[a].add(b)
        if b >= 0:
            neighbours[b].add(a)

    # -- family (a): rigid groups, by Gram matrices (d × d) of the constraint rows
    gram = np.einsum("lrm,lrn->lmn", A, A)
    g_all = gram.sum(axis=0)
    moving = [i for i in range(n) if np.linalg.norm(A[i]) > tol]
    movable = set(moving)
    adj = {i: {w for w in neighbours[i] if w in movable} for i in moving}
    named_on: dict[int, list[np.ndarray]] = {}
    for li, p in inp.named:
        named_on.setdefault(li, []).append(p)
    components = _components(moving, adj)
    if d == 1:  # the one motion moves every movable link: the only candidate is all of them
        groups, truncated = [tuple(c) for c in components if len(components) == 1], False
    else:
        groups, truncated = _connected_groups(moving, adj, MAX_GROUP_LINKS, _MAX_GROUPS)
        groups += [tuple(c) for c in components if len(c) > MAX_GROUP_LINKS]  # large rigid sub-assemblies
    for g in groups:
        if basis.shape[1] >= d:
            break
        outside = set().union(*(neighbours[i] for i in g)) - set(g)
        if len(outside) < 2:
            continue  # joined to one neighbour only: an output, its motion is the function
        g0 = g[0]
        S = g_all - gram[list(g)].sum(axis=0)
        for i in g[1:]:
            D = A[i] - A[g0]
            S = S + D.T @ D
        for i in g:
            for p in named_on.get(i, []):
                V = _point_velocity(A[i], p)
                S = S + V.T @ V
        evals, evecs = np.linalg.eigh(S)
        z = evecs[:, evals < tol * tol]
        if not z.shape[1]:
            continue
        z = z - basis @ (basis.T @ z)
        z = _orth(z)
        for i in range(z.shape[1]):
            found.append(("group", list(g), z[:, i]))
        basis = np.concatenate([basis, z], axis=1)
    if truncated and basis.shape[1] < d:
        notes.append(f"idle motions of link groups larger than {MAX_GROUP_LINKS} links were not searched: "
                     "family (b) (frame's neighbours at rest, joint axes in place) still counts them when they keep to it")

    # -- family (b): the frame's neighbours at rest, joint axes in place, ball centres and
    # named points at rest, nothing transmitted through a higher pair, outputs in place
    rows = _family_b_rows(inp, neighbours)
    Zb = _null_basis(np.concatenate(rows, axis=0) if rows else np.zeros((0, d)), d, tol)
    if not inp.drives and inp.contacts and Zb.shape[1]:
        # no drive declared: a motion carried through a cam or gear contact (a gear train's,
        # a cam's) is taken as the function, not as idle; say so when that decides
        rows += [(nrm @ _point_velocity(A[li], p))[None] for li, p, nrm in inp.contacts]
        Zc = _null_basis(np.concatenate(rows, axis=0), d, tol)
        if Zc.shape[1] < Zb.shape[1]:
            notes.append(f"{Zb.shape[1] - Zc.shape[1]} motion(s) keep every joint centre at rest but pass through "
                         "a cam, gear or belt contact: with no drive declared they are taken as the function, not "
                         "idle; declare the drives (actuated: true) to classify them")
        Zb = Zc
    if Zb.shape[1]:
        zb = _orth(Zb - basis @ (basis.T @ Zb))
        for i in range(zb.shape[1]):
            found.append(("centres", [], zb[:, i]))
        basis = np.concatenate([basis, zb], axis=1)

    out = [_idle_record(inp, fam, g, z, tol) for fam, g, z in found]
    return out, basis, notes


def _idle_record(inp: IdleInputs, family: str, group: list[int], z: np.ndarray, tol: float) -> IdleMobility:
    rates = inp.rates @ z
    scale_z = max(float(np.max(np.abs(rates))), 1e-300)
    jidx = sorted({int(inp.col_joint[c]) for c in np.flatnonzero(np.abs(rates) > 1e-6 * scale_z)})
    joints = [inp.joint_ids[k] for k in jidx]
    tw = inp.A @ z  # n × 6
    big = float(np.max(np.linalg.norm(tw, axis=1))) if tw.size else 0.0
    moved = group or [i for i in range(len(inp.links)) if np.linalg.norm(tw[i]) > max(tol, 1e-6 * big)]
    axes = {inp.links[i]: screw_axis(tw[i], inp.centre, inp.scale) for i in moved}
    names = [inp.links[i] for i in moved]
    axis: dict[str, Any] | None = None
    if moved:
        t0 = tw[moved[0]]
        if all(np.linalg.norm(tw[i] - t0) <= 1e-6 * max(1.0, np.linalg.norm(t0)) for i in moved):
            axis = axes[names[0]]
    if family == "centres" and axis is not None:
        family = "group"  # one rigid body after all (a group larger than the search went)
    return IdleMobility(link="+".join(names), joints=joints, description=_describe(names, joints, axis, family),
                        links=names, family=family, axis=axis, axes=axes)
