"""A new geometry in a compiled topology: the fast path of a drag or a design loop.

Two planar mechanisms with the same
:func:`~mechsyn.kinematics.topology.topology_key` (links, joints and their pair
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
from typing import Any

import numpy as np

from mechsyn.kinematics.plane import to_frame
from mechsyn.kinematics.system import Con, PlanarSystem, frame_points
from mechsyn.model.mechanism import Mechanism, fields_replaced

__all__ = ["joint_points", "point_xy", "with_geometry"]


def with_geometry(T: PlanarSystem, mech: Mechanism) -> PlanarSystem | None:
    """The system of ``mech`` built from ``T``, the system of a mechanism of the same
    :class:`~mechsyn.kinematics.topology.Topology` (which it holds): the same constraints,
    drivers and notes with the numbers of
    ``mech``'s joint points (link frames, local points, drawn angles and slide
    coordinates, length scale), equal to :func:`build_system`'s; None when ``T`` has
    blocks other than R pairs, angles and lines (cams, gears, belts: built anew), a
    point is missing or not finite or a P pair has no axis (:func:`build_system` then
    reports it).

    The numbers are worked out on Python floats from one ``tolist`` of the points (the
    same products, sums and ``arctan2`` as :func:`build_system`'s, so the same bits), and
    the link angles, their cosines and sines are each one NumPy call: a fresh geometry of
    a drag or a design loop costs a few NumPy calls, not a few per joint. What the
    regular pass of a drag does not read is made when first read (:class:`_Refilled`:
    the R pairs' constraint blocks, the links' drawn origins as an array, the scales of
    the rows and columns, these shared by the systems of one topology and one size).

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
    lay = T.topology.product("refill layout", lambda: _layout(T))
    if lay is False:
        return None
    first, other, rowmask, colmask, recipe, scales, kept = lay
    nd, joints = np.ndarray, mech.joints  # a float64 point (the common case) read inline
    pts = [p.tolist() if (p := j.point).__class__ is nd and p.dtype is _FLOAT else point_xy(p) for j in joints]
    if recipe[3] and any(joints[k].axis is None for k in recipe[3]):  # a P pair without axis
        return None
    if mech.points:
        pts += [point_xy(p.at) for p in mech.points.values()]
    xs, ys = [x for x, _ in pts], [y for _, y in pts]
    if not math.isfinite(sum(xs) + sum(ys)):  # a NaN or an infinity (or sums past the float range: built anew)
        return None
    scale = max(max(xs) - min(xs), max(ys) - min(ys), 1e-9) if len(pts) > 1 else 1.0
    org = [pts[k] for k in first]
    angle0 = _frame_angles(pts, org, other, 1e-12 * scale)
    turn = -angle0
    frames, ang = (np.cos(turn).tolist(), np.sin(turn).tolist(), org), angle0.tolist()
    cons, drivers = _refilled(T, mech, recipe, pts, frames, ang)
    q0 = np.array([v for (x, y), a in zip(org, ang) for v in (x, y, a)], float)
    cache = {"frames": frames, "joint_points": pts}
    S = object.__new__(_Refilled)
    fields = S.__dict__
    fields.update(kept)  # T's fields a geometry does not change; cons and origin0 made when first read
    fields.update(mech=mech, angle0=angle0, drivers=drivers, q0=q0, scale=scale, vll=dict(T.vll), cache=cache,
                  topology=T.topology, _pending=(T.cons, cons, recipe[1:], pts, frames), _scales=(scale, rowmask, colmask, scales))
    return S


def _scales_of(scale: float, rowmask: np.ndarray, colmask: np.ndarray, scales: list) -> tuple:
    """The row and column scales of a system of size ``scale`` (:func:`build_system`'s:
    ``scale`` where a row or column is a length, else 1), read only: those of the last
    size made are shared by its topology's systems (``scales``: :func:`_layout`'s; one
    read, one write)."""
    sc = scales[0]
    if sc[0] != scale:
        sc = scales[0] = (scale, np.where(rowmask, scale, 1.0), np.where(colmask, scale, 1.0))
        sc[1].setflags(write=False)
        sc[2].setflags(write=False)
    return sc[1], sc[2]


def joint_points(S: PlanarSystem) -> list:
    """The drawn points of ``S``'s joints (file order; then its named points when ``S``
    was refilled) as ``[x, y]`` lists of floats, kept with the system."""
    pts = S.cache.get("joint_points")
    if pts is None:
        pts = S.cache["joint_points"] = np.array([j.point for j in S.mech.joints], float).reshape(-1, 2).tolist()
    return pts


def _frame_angles(pts: list, org: list, other: list, tol: float) -> np.ndarray:
    """Every link frame's drawn angle (:func:`~mechsyn.kinematics.system._link_frames`):
    towards the first other joint point farther than ``tol`` from the origin, else 0;
    the directions' differences on floats (the numbers of the arrays' subtraction), the
    angles in one ``arctan2`` (the same bits as its call per link)."""
    dx, dy = [], []
    for (ox, oy), ks in zip(org, other):
        ex = ey = 0.0  # arctan2(0, 0) = 0: no other joint point away from the origin
        for k in ks:
            px, py = pts[k]
            if math.hypot(px - ox, py - oy) > tol:
                ex, ey = px - ox, py - oy
                break
        dx.append(ex)
        dy.append(ey)
    return np.arctan2(dy, dx)


def point_xy(p: Any) -> list:
    """A drawn point as ``[x, y]`` floats (one ``tolist`` of a float array); none (None):
    NaN, which :func:`with_geometry` refuses.

    Examples
    --------
    >>> import numpy as np
    >>> point_xy(np.array([1.0, 2.5])), point_xy((3, 4)), point_xy(None)
    ([1.0, 2.5], [3.0, 4.0], [nan, nan])
    """
    if p is None:
        return [math.nan, math.nan]
    return p.tolist() if type(p) is np.ndarray and p.dtype is _FLOAT else np.asarray(p, float).tolist()


_FLOAT = np.dtype(float)


def _layout(T: PlanarSystem) -> tuple | bool:
    """What :func:`with_geometry` needs of ``T``'s topology, or False when ``T`` cannot be
    refilled: the joint indices of every moving link's frame (its first joint, then the
    others in file order), which rows and columns scale with the length, and per
    constraint but the R pairs how its numbers are filled (:func:`_refilled`; the R pairs'
    links and joints for :func:`_r_pairs`); then the row and column
    scales of the last size refilled, ``[(scale, rows, cols)]``, and ``T``'s fields that
    no geometry changes (its links, unknowns, equations and notes)."""
    mech = T.mech
    if T.n != 3 * len(T.links) or any(c.kind not in ("R", "angle", "line") for c in T.cons):
        return False
    index = {j.id: k for k, j in enumerate(mech.joints)}
    first, other = [], []
    for name in T.links:
        ks = [index[j.id] for j in mech.joints_of(name)]
        first.append(ks[0])
        other.append(ks[1:])
    rows = np.concatenate([np.full(c.rows, c.kind != "angle") for c in T.cons]) if T.cons else np.zeros(0, bool)
    cols = np.arange(T.n) % 3 != 2
    recipe = []  # (row, how, constraint, joint index) of every constraint but the R pairs
    for r, c in enumerate(T.cons):
        how = c.kind if c.kind != "angle" else ("drive" if c.role == "drive" else
                                                "rotation" if c.role == "rotation" else "kept")
        if how != "R":
            recipe.append((r, how, c, index[c.joint]))
    pairs = [(i, index[c.joint]) for c in T.cons if c.kind == "R" for i in (c.a, c.b)]  # sa, sb of each R
    kept = {k: v for k, v in T.__dict__.items() if k in ("links", "n", "m", "notes")}
    slides = [k for k, j in enumerate(mech.joints) if j.type == "P"]  # (their axes are read: given?)
    return (first, other, rows, cols, ((len(T.cons), recipe), [i for i, _ in pairs], [k for _, k in pairs], slides),
            [(None,)], kept)


def _refilled(T: PlanarSystem, mech: Mechanism, recipe: list, pts: list, frames: tuple,
              ang: list) -> tuple[list, tuple]:
    """``T``'s constraints and drivers with the numbers of ``mech``: a drive's or a P
    pair's drawn relative angle, a line's local points, direction and drawn slide
    coordinate (see :class:`~mechsyn.kinematics.system._Builder`; ``recipe``:
    :func:`_layout`'s); an R pair's block is None, made when the system's constraints
    are first read (:func:`_r_pairs`)."""
    count, recipe = recipe[0]
    drivers = list(T.drivers)
    cons: list = [None] * count

    def rel(b: int, a: int) -> float:  # phi_b - phi_a drawn (_Builder.angle)
        return (0.0 if b < 0 else ang[b]) - (0.0 if a < 0 else ang[a])

    for r, how, c, k in recipe:  # (the R pairs are not visited: None)
        if how == "drive":
            drivers[c.driver] = fields_replaced(drivers[c.driver], assembled=rel(c.b, c.a))
            cons[r] = c
        elif how == "rotation":
            cons[r] = fields_replaced(c, c0=rel(c.b, c.a))
        elif how == "kept":
            cons[r] = c
        else:
            cons[r] = _line(c, mech.joints[k], frames, drivers)
    return cons, tuple(drivers)


def _r_pairs(T_cons: tuple, cons: list, pairs: tuple, pts: list, frames: tuple) -> tuple:
    """The constraints ``cons`` of :func:`_refilled` with every R pair's block (None there)
    made from ``T``'s (``T_cons``) with its local points ``sa``, ``sb`` (``pairs``: the
    links and joints of :func:`_layout`)."""
    links, joints = pairs[:2]
    block = iter(frame_points(frames, links, [pts[k] for k in joints]))
    return tuple(fields_replaced(t, sa=np.array(next(block)), sb=np.array(next(block))) if c is None else c
                 for c, t in zip(cons, T_cons))


def _line(c: Con, j: Any, frames: tuple, drivers: list) -> Con:
    """A line constraint of the P pair ``j`` refilled (its driver's drawn value set in
    ``drivers``), by :meth:`PlanarSystem.to_local`'s arithmetic."""
    cos, sin, org = frames
    a, b = c.a, c.b

    def loc(i: int, p: Any, direction: bool = False) -> np.ndarray:  # S.to_local / to_local_dir
        if i < 0:
            return np.asarray(p, float)
        return to_frame(cos[i], sin[i], p[0], p[1]) if direction else \
            to_frame(cos[i], sin[i], p[0] - org[i][0], p[1] - org[i][1])

    u = np.asarray(j.axis, float)  # given: build_system refuses a P pair without axis
    u_loc = loc(a, u, direction=True)
    if c.role == "pair":
        return Con("line", c.joint, 1, a, b, sa=loc(a, j.point), sb=loc(b, j.point),
                   w=np.array([-u_loc[1], u_loc[0]]), role="pair")
    o_a = np.zeros(2) if a < 0 else np.asarray(org[a])
    s0 = float(u @ (j.point - o_a))
    if c.driver is not None:
        drivers[c.driver] = fields_replaced(drivers[c.driver], assembled=s0)
    return Con("line", c.joint, 1, a, b, sa=np.zeros(2), sb=loc(b, j.point), w=u_loc,
               c0=s0 if c.role == "lock" else 0.0, driver=c.driver, role=c.role)


class _Refilled(PlanarSystem):
    """A system made by :func:`with_geometry`: a :class:`PlanarSystem` whose constraint
    blocks (the R pairs', :func:`_r_pairs`), drawn link origins ``origin0`` and row and
    column scales (:func:`_scales_of`, for the size it was refilled with) are made when
    first read (the regular pass and the drawn checks of a drag never read them;
    Newton's continuation, the rank tests and the forces do, once per system). Its
    fields read, copy, pickle and replace as a built system's (a test).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.system import build_system
    >>> m = ms.examples.load("crank_rocker")
    >>> moved = m.with_joint_points({"C": (3.1, 2.9)})
    >>> S = with_geometry(build_system(m), moved)
    >>> "cons" in S.__dict__, [c.kind for c in S.cons], "cons" in S.__dict__
    (False, ['R', 'angle', 'R', 'R', 'R'], True)
    """

    def __getattr__(self, name: str) -> Any:  # only a field not yet in the instance's __dict__
        fields = self.__dict__
        pending = fields.get("_pending")
        if pending is None or name not in ("cons", "origin0"):
            raise AttributeError(name)
        template, cons, pairs, pts, frames = pending
        if "cons" not in fields:  # (one given to fields_replaced stays)
            fields["cons"] = _r_pairs(template, cons, pairs, pts, frames)
        if "origin0" not in fields:
            fields["origin0"] = np.array(frames[2], float).reshape(-1, 2)
        fields.pop("_pending", None)  # (a thread reading at the same time made the same)
        return fields[name]

    def _scale(self, k: int) -> np.ndarray:
        fields, name = self.__dict__, ("_row_scale", "_col_scale")[k]
        if name not in fields:  # (one given, None too, stays)
            fields.setdefault(name, _scales_of(*fields["_scales"])[k])
        return fields[name]

    @property  # type: ignore[override]
    def row_scale(self) -> np.ndarray:
        return self._scale(0)

    @row_scale.setter
    def row_scale(self, value: Any) -> None:  # dataclasses.replace's __init__ (object.__setattr__)
        self.__dict__["_row_scale"] = value

    @property  # type: ignore[override]
    def col_scale(self) -> np.ndarray:
        return self._scale(1)

    @col_scale.setter
    def col_scale(self, value: Any) -> None:
        self.__dict__["_col_scale"] = value
