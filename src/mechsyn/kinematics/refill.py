"""A new geometry in a compiled topology: the fast path of a drag or a design loop.

Two planar mechanisms with the same :func:`topology_key` (links, joints and their pair
types, drives, VLL modes, prescribed inputs) differ only in numbers: joint points, P
axes, named points. :func:`with_geometry` fills the numbers of one into the constraint
system compiled for the other (link frames, local joint points, drawn angles and slide
coordinates, the length scale), with the results of
:func:`~mechsyn.kinematics.system.build_system` and none of its per-joint dispatch; the
compiled plan of :mod:`mechsyn.kinematics.analysis` keeps the decomposition of the
topology (see docs/kinematics.md, "The fresh-geometry fast path").
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from mechsyn.kinematics.system import Con, PlanarSystem, _axis, _dir_angle, _to_frame
from mechsyn.model.mechanism import Mechanism

__all__ = ["topology_key", "with_geometry"]


def topology_key(mech: Mechanism, vll: dict[str, str] | None = None, prescribed: tuple[str, ...] = ()) -> tuple:
    """What a compiled system depends on besides the numbers of the geometry: the kind,
    the links (frame first), every joint's id, pair type, links, drive, VLL mode, ratio
    and extra attributes, the VLL modes asked for and the prescribed inputs. Two
    mechanisms with the same key differ only in their joint points, P axes and named
    points, so :func:`with_geometry` fills one's numbers into the other's system.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("crank_rocker")
    >>> moved = m.with_joint_points({"C": (3.1, 2.9)})
    >>> topology_key(moved) == topology_key(m)
    True
    """
    joints = tuple((j.id, j.type, j.links, j.actuated, j.vll, j.ratio, repr(j.attrs) if j.attrs else "")
                   for j in mech.joints)
    named = tuple((k, p.link) for k, p in mech.points.items())
    return (mech.kind, mech.ground, mech.link_names, joints, named, tuple(sorted((vll or {}).items())),
            tuple(prescribed))


def with_geometry(T: PlanarSystem, mech: Mechanism) -> PlanarSystem | None:
    """The system of ``mech`` built from ``T``, the system of a mechanism of the same
    :func:`topology_key`: the same constraints, drivers and notes with the numbers of
    ``mech``'s joint points (link frames, local points, drawn angles and slide
    coordinates, length scale), equal to :func:`build_system`'s; None when ``T`` has
    blocks other than R pairs, angles and lines (cams, gears, belts: built anew).

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> from mechsyn.kinematics.system import build_system
    >>> m = ms.examples.load("crank_rocker")
    >>> moved = m.with_joint_points({"C": (3.1, 2.9)})
    >>> S = with_geometry(build_system(m), moved)
    >>> bool(np.array_equal(S.q0, build_system(moved).q0))
    True
    """
    lay = T.cache.get("layout")
    if lay is None:
        lay = T.cache["layout"] = _layout(T)
    if lay is False:
        return None
    first, other, lengths = lay
    joints = mech.joints
    pts = [j.point for j in joints]
    allpts = np.array(pts + [p.at for p in mech.points.values()], float)
    scale = float(max((allpts.max(axis=0) - allpts.min(axis=0)).max(), 1e-9)) if len(allpts) > 1 else 1.0
    nl = len(T.links)
    origin0 = allpts[first] if nl else np.zeros((0, 2))
    angle0 = np.zeros(nl)
    for i, ks in enumerate(other):  # towards the first other joint point (as _link_frames)
        for k in ks:
            d = pts[k] - origin0[i]
            if math.hypot(d[0], d[1]) > 1e-12 * scale:
                angle0[i] = _dir_angle(d)
                break
    cos, sin = np.cos(-angle0).tolist(), np.sin(-angle0).tolist()
    org, ang = origin0.tolist(), angle0.tolist()

    def loc(i: int, p: Any, direction: bool = False) -> np.ndarray:  # S.to_local / to_local_dir
        if i < 0:
            return np.asarray(p, float)
        return _to_frame(cos[i], sin[i], p[0], p[1]) if direction else \
            _to_frame(cos[i], sin[i], p[0] - org[i][0], p[1] - org[i][1])

    cons, drivers = _refilled(T, mech, loc, ang, org)
    q0 = np.empty(3 * nl)
    q0[0::3], q0[1::3], q0[2::3] = origin0[:, 0], origin0[:, 1], angle0
    rows = np.where(lengths, scale, 1.0)
    cols = np.ones(len(q0))
    cols[0::3] = cols[1::3] = scale
    # the engines' programs by topology (regular._program's shapes), shared with T
    cache = {"frames": (cos, sin, org), "programs": T.cache.setdefault("programs", {})}
    return PlanarSystem(mech, T.links, origin0, angle0, cons, drivers, T.n, T.m, q0, scale, vll=dict(T.vll),
                        notes=T.notes, row_scale=rows, col_scale=cols, cache=cache)


def _layout(T: PlanarSystem) -> tuple | bool:
    """Joint indices of every moving link's frame (its first joint, then the others in
    file order), or False when ``T`` cannot be refilled (see :func:`with_geometry`)."""
    mech = T.mech
    if T.n != 3 * len(T.links) or any(c.kind not in ("R", "angle", "line") for c in T.cons):
        return False
    index = {j.id: k for k, j in enumerate(mech.joints)}
    first, other = [], []
    for name in T.links:
        ks = [index[j.id] for j in mech.joints_of(name)]
        first.append(ks[0])
        other.append(ks[1:])
    lengths = np.concatenate([np.full(c.rows, c.kind != "angle") for c in T.cons]) if T.cons else np.zeros(0, bool)
    return first, other, lengths


def _refilled(T: PlanarSystem, mech: Mechanism, loc: Any, ang: list, org: list) -> tuple[tuple, tuple]:
    """``T``'s constraints and drivers with the numbers of ``mech`` (see :func:`_Builder`)."""
    joint = {j.id: j for j in mech.joints}
    drawn = {d.joint: d for d in T.drivers}
    drivers = list(T.drivers)
    cons = []

    def rel(b: int, a: int) -> float:  # phi_b - phi_a drawn (_Builder.angle)
        return float((0.0 if b < 0 else ang[b]) - (0.0 if a < 0 else ang[a]))

    for c in T.cons:
        j = joint[c.joint]
        a, b = c.a, c.b
        if c.kind == "R":
            cons.append(Con("R", c.joint, 2, a, b, sa=loc(a, j.point), sb=loc(b, j.point), role=c.role))
            continue
        if c.kind == "angle":
            if c.role == "drive":
                drivers[c.driver] = replace(drawn[c.joint], assembled=rel(b, a))
            cons.append(replace(c, c0=rel(b, a)) if c.role == "rotation" else c)
            continue
        u = _axis(j)
        u_loc = loc(a, u, direction=True)
        if c.role == "pair":
            cons.append(Con("line", c.joint, 1, a, b, sa=loc(a, j.point), sb=loc(b, j.point),
                            w=np.array([-u_loc[1], u_loc[0]]), role="pair"))
            continue
        o_a = np.zeros(2) if a < 0 else np.asarray(org[a])
        s0 = float(u @ (j.point - o_a))
        if c.driver is not None:
            drivers[c.driver] = replace(drawn[c.joint], assembled=s0)
        cons.append(Con("line", c.joint, 1, a, b, sa=np.zeros(2), sb=loc(b, j.point), w=u_loc,
                        c0=s0 if c.role == "lock" else 0.0, driver=c.driver, role=c.role))
    return tuple(cons), tuple(drivers)
