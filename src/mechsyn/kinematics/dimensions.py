"""A planar mechanism's dimensions as design variables: a bar's length, a plate's side, a
slider guide's offset and angle, each changed with the mechanism re-assembled on the same
branch and every other dimension kept.

The mechanism's links are rigid bodies whose geometry comes from the drawn configuration
(:func:`mechsyn.kinematics.system.build_system`). A new dimension changes the local
coordinates of the joints on one link (a bar's second joint moves along the bar; a
triangle's third joint keeps its two other sides; a guide line turns or shifts about the
link's pivot). The configuration is then followed from the drawn one by Newton
continuation in the dimension (the drives held at their drawn values), the same solver
the sweeps use (:func:`mechsyn.kinematics.solve.newton`): a step that would cross a
singular configuration (the sign of the Jacobian's determinant changes: a fold, the
other assembly branch) is refused, so the result is on the drawn branch or not at all.

Where the mechanism cannot assemble, :class:`~mechsyn.errors.MechsynInputError` says in one
line which dimension violates which condition: the triangle inequality of the dyad that
cannot close (``|a - b| <= d <= a + b``) and, for a four-bar, Grashof's condition.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.kinematics.dimensions import link_lengths, set_length
>>> m = ms.examples.load("crank_rocker")           # frame 4, crank 1, coupler 3.5, rocker 3
>>> new = set_length(m, "rocker", 3.2)
>>> {k: round(v, 9) for k, v in link_lengths(new).items()}
{'frame': 4.0, 'crank': 1.0, 'coupler': 3.5, 'rocker': 3.2}
>>> from mechsyn.errors import MechsynInputError
>>> try:
...     set_length(m, "rocker", 0.05)
... except MechsynInputError as err:
...     print(err.message.split(";")[0])
rocker = 0.05 does not assemble at the drawn input: joints B and D are 3.606 apart but coupler + rocker = 3.5 + 0.05 = 3.55 (triangle inequality BD ≤ coupler + rocker)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.derived import is_fourbar
from mechsyn.kinematics.groups import circle_circle, decompose
from mechsyn.kinematics.plane import cross, perp, to_frame
from mechsyn.kinematics.solve import newton, worst_joint
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism

__all__ = ["Dimension", "dimensions", "link_lengths", "set_length", "set_side", "set_slider"]


@dataclass(frozen=True)
class Dimension:
    """One design variable of a planar mechanism: ``kind`` is ``length`` (a bar, two R
    joints), ``side`` (two joints of a plate of three or more), ``offset`` (the signed
    distance of a slider's guide line from the pivot ``joints[1]`` of its guide link) or
    ``angle`` (the guide's direction, degrees counter-clockwise from x)."""

    link: str
    kind: str
    joints: tuple[str, ...]
    value: float

    def to_dict(self) -> dict[str, Any]:
        return {"link": self.link, "kind": self.kind, "joints": list(self.joints), "value": self.value}


def _xy(p: Any) -> np.ndarray:
    return np.asarray(p, float)[:2]


def _guide(mech: Mechanism, j: Any) -> tuple[str, Any, np.ndarray, float, float]:
    """Slider ``j``'s guide ``(link, pivot, origin, offset, angle)``: its link (the joint's
    first), the pivot its offset is measured from (on the guide link, the drive's R joint,
    else its first R joint; None when it has none), that pivot's place (else the joint's),
    the guide line's signed distance from it and its direction (radians from x)."""
    rs = [x for x in mech.joints_of(j.links[0]) if x.type == "R"]
    piv = ([x for x in rs if x.actuated] or rs or [None])[0]
    u = _xy(j.axis) / np.linalg.norm(_xy(j.axis))
    o = _xy((piv or j).point)
    return j.links[0], piv, o, float(np.array([-u[1], u[0]]) @ (_xy(j.point) - o)), math.atan2(u[1], u[0])


def dimensions(mech: Mechanism) -> list[Dimension]:
    """Every dimension :func:`set_length`, :func:`set_side` and :func:`set_slider` change.

    Examples
    --------
    >>> import mechsyn as ms
    >>> [(d.link, d.kind, round(d.value, 6)) for d in dimensions(ms.examples.load("crank_rocker"))][:2]
    [('frame', 'length', 4.0), ('crank', 'length', 1.0)]
    """
    _planar(mech)
    out: list[Dimension] = []
    for name in mech.link_names:
        places = _places(mech, name)
        if any(j.type not in ("R", "P") for j in mech.joints_of(name)):
            continue
        sides = [(places[k], places[(k + 1) % len(places)]) for k in range(len(places))]  # round the plate
        if len(places) == 2 and not any(j.type == "P" for j in mech.joints_of(name)):
            (a, pa), (b, pb) = sides[0]
            out.append(Dimension(name, "length", (a[0], b[0]), float(np.linalg.norm(pa - pb))))
        elif len(places) >= 3:
            out += [Dimension(name, "side", (a[0], b[0]), float(np.linalg.norm(pa - pb))) for (a, pa), (b, pb) in sides]
    for j in mech.joints:
        if j.type != "P" or j.axis is None:
            continue
        guide, piv, _, e0, a0 = _guide(mech, j)
        out.append(Dimension(guide, "angle", (j.id,), math.degrees(a0)))
        if piv is not None:
            out.append(Dimension(guide, "offset", (j.id, piv.id), e0))
    return out


def link_lengths(mech: Mechanism) -> dict[str, float]:
    """The length of every bar (a link of two R joints, the frame included)."""
    return {d.link: d.value for d in dimensions(mech) if d.kind == "length"}


def _places(mech: Mechanism, link: str) -> list[tuple[tuple[str, ...], np.ndarray]]:
    """The distinct places of ``link``'s R joints (joints drawn on one place, e.g. two links
    pinned to a crank at one pin, are one place): ``[(joint ids, point)]`` in file order."""
    pts = np.array([_xy(j.point) for j in mech.joints if j.point is not None])
    tol = 1e-9 * max(float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 1.0, 1e-300)
    out: list[tuple[list[str], np.ndarray]] = []
    for j in mech.joints_of(link):
        if j.type != "R" or j.point is None:
            continue
        p = _xy(j.point)
        for ids, q in out:
            if np.linalg.norm(p - q) <= tol:
                ids.append(j.id)
                break
        else:
            out.append(([j.id], p))
    return [(tuple(ids), p) for ids, p in out]


def _place_of(mech: Mechanism, link: str, jid: str) -> tuple[str, ...]:
    for ids, _ in _places(mech, link):
        if jid in ids:
            return ids
    raise MechsynInputError(f"joint {jid} is not an R joint of link {link}", field="length")


def _planar(mech: Mechanism) -> None:
    if mech.kind != "planar" or not mech.has_geometry:
        raise MechsynInputError("dimensions are changed on a planar mechanism with joint points",
                                source=mech.source, field="kind")


def _positive(value: float, what: str) -> float:
    v = float(value)
    if not math.isfinite(v) or v <= 0:
        raise MechsynInputError(f"{what} must be a positive number, not {value!r}", field="length",
                                hint="type a length greater than 0")
    return v


# --------------------------------------------------------------------------- the changes
def set_length(mech: Mechanism, link: str, length: float) -> Mechanism:
    """``mech`` with bar ``link`` (two R joints, the frame included) ``length`` long,
    re-assembled on the drawn branch with every other dimension kept: the bar's second
    joint (file order) moves along the bar, in the bar's own frame.

    Raises :class:`~mechsyn.errors.MechsynInputError` (one line) where it cannot assemble.
    """
    _planar(mech)
    bar = [d for d in dimensions(mech) if d.link == link and d.kind == "length"]
    if not bar:
        raise MechsynInputError(f"link {link} is not a bar of two R joints", field="length",
                                hint="type a plate's sides with set_side, a slider's guide with set_slider")
    L = _positive(length, f"the length of {link}")
    a, b = bar[0].joints
    return _apply(mech, link, f"{link} = {L:.6g}", _moved_along(mech, link, a, b, L))


def set_side(mech: Mechanism, link: str, joints: tuple[str, str], length: float) -> Mechanism:
    """``mech`` with the side ``joints`` of plate ``link`` ``length`` long: the second joint
    moves along the side; a triangle's third joint keeps its two other sides (on the same
    side of the changed one); the joints of a larger plate keep their places on it."""
    _planar(mech)
    L = _positive(length, f"side {'–'.join(joints)} of {link}")
    places = _places(mech, link)
    on = [j for ids, _ in places for j in ids]
    if len(joints) != 2 or not set(joints) <= set(on) or _place_of(mech, link, joints[0]) == _place_of(
            mech, link, joints[1]):
        raise MechsynInputError(f"{'–'.join(map(str, joints))} is not a side of link {link}", field="length",
                                hint=f"its joints are {', '.join(on)}")
    a, b = joints
    moves = _moved_along(mech, link, a, b, L)
    if len(places) == 3:
        third = next(ids for ids, _ in places if a not in ids and b not in ids)
        c = third[0]
        pa, pb, pc = (_xy(mech.joint(x).point) for x in (a, b, c))
        pc_new = _third(pa, pb, pc, moves[b])
        moves.update({x: pc_new for x in third})
        if pc_new is None:
            raise MechsynInputError(f"side {a}–{b} of {link} = {L:.6g} breaks the triangle inequality with its "
                                    f"sides {a}–{c} = {np.linalg.norm(pc - pa):.6g} and {b}–{c} = "
                                    f"{np.linalg.norm(pc - pb):.6g}", field="length")
    return _apply(mech, link, f"side {a}–{b} of {link} = {L:.6g}", moves)


def set_slider(mech: Mechanism, joint: str, *, offset: float | None = None,
               angle: float | None = None) -> Mechanism:
    """``mech`` with the guide of P joint ``joint`` at ``offset`` (signed distance from the
    guide link's pivot, :class:`Dimension`) and ``angle`` (degrees), either left as drawn
    when None; the slider block turns with its guide."""
    _planar(mech)
    j = mech.joint(joint)
    if j.type != "P":
        raise MechsynInputError(f"joint {joint} is not a slider (P joint)", field="offset")
    guide, piv, o, e0, a0 = _guide(mech, j)
    for v, what in ((offset, "offset"), (angle, "angle")):
        if v is not None and not math.isfinite(float(v)):
            raise MechsynInputError(f"the guide's {what} must be a number, not {v!r}", field=what)
    e1 = e0 if offset is None else float(offset)
    a1 = a0 if angle is None else math.radians(float(angle))
    if offset is not None and piv is None:
        raise MechsynInputError(f"the guide of {joint} has no pivot to measure an offset from", field="offset")
    what = ", ".join(x for x in (f"offset of {joint} = {e1:.6g}" if offset is not None else "",
                                 f"angle of {joint} = {math.degrees(a1):.6g}°" if angle is not None else "") if x)
    return _apply(mech, guide, what or f"guide of {joint}", {}, guide=(joint, o, e0, e1, a0, a1))


def _moved_along(mech: Mechanism, link: str, a: str, b: str, L: float) -> dict[str, np.ndarray]:
    """Every joint on ``link`` at ``b``'s place moved along the line from ``a`` to length ``L``."""
    pa, pb = _xy(mech.joint(a).point), _xy(mech.joint(b).point)
    d = pb - pa
    n = np.linalg.norm(d)
    u = d / n if n > 0 else np.array([1.0, 0.0])
    return {x: pa + L * u for x in _place_of(mech, link, b)}


def _third(pa: np.ndarray, pb: np.ndarray, pc: np.ndarray, pb_new: np.ndarray) -> np.ndarray | None:
    """The third vertex of the triangle ``pa, pb, pc`` when ``pb`` moves to ``pb_new``: the
    point at its distances from ``pa`` and ``pb`` on the same side of the line a→b (the
    RRR group's circle intersection, :func:`~mechsyn.kinematics.groups.circle_circle`),
    None where the circles do not meet."""
    d = pb_new - pa
    side = 1.0 if cross(pb - pa, pc - pa) >= 0 else -1.0
    ra2, rb2 = float((pc - pa) @ (pc - pa)), float((pc - pb) @ (pc - pb))
    f, g2, disc = circle_circle(float(d[0]), float(d[1]), ra2, rb2)
    if not disc >= -1e-12:  # (NaN: a side of zero length)
        return None
    return pa + f * d + side * math.sqrt(max(g2, 0.0)) * perp(d)


# --------------------------------------------------------------------------- solving
#: Continuation: the first step in the dimension (a fraction of the change) and the smallest.
FIRST_STEP, SMALLEST_STEP = 0.125, 1.0 / 512


def _apply(mech: Mechanism, link: str, what: str, moves: dict[str, np.ndarray], guide: tuple | None = None) -> Mechanism:
    """Re-assemble ``mech`` with the joints ``moves`` (new drawn places on ``link``, in the
    drawn configuration) or the slider ``guide`` changed: continuation from the drawn pose."""

    S = build_system(mech)
    u = np.array([d.assembled for d in S.drivers])
    q, ok = newton(S, S.q0, u, max_iter=30)
    if not ok:
        raise MechsynInputError("the drawn configuration does not assemble: move its joints until it does",
                                source=mech.source, field="joints")
    geo = _Geometry(S, link, moves, guide)
    sign = _det_sign(S, q)
    t, dt = 0.0, FIRST_STEP
    while t < 1.0:
        t1 = min(1.0, t + dt)
        St = geo.system(t1)
        q1, ok = newton(St, q, u, max_iter=12)
        flip = ok and sign != 0 and _det_sign(St, q1) == -sign
        if ok and not flip and _rel_move(S, q, q1) < 0.25:
            t, q = t1, q1
            dt = min(2 * dt, FIRST_STEP)
            continue
        dt /= 2
        if dt < SMALLEST_STEP:
            raise MechsynInputError(_why(geo, q, what, folded=flip), source=mech.source, field="length",
                                    hint="type another value (nothing was changed)")
    return geo.mechanism(q)


def _det_sign(S: Any, q: np.ndarray) -> int:
    """The sign of the dimensionless Jacobian's determinant (0: not square, or singular)."""
    J = S.unit_jacobian(S.jacobian(q[None])[0])
    if J.shape[0] != J.shape[1]:
        return 0
    d = float(np.linalg.det(J))
    return 0 if abs(d) < 1e-9 else (1 if d > 0 else -1)


def _rel_move(S: Any, q0: np.ndarray, q1: np.ndarray) -> float:
    """The largest move of a link between two configurations, over the mechanism's size."""
    nl = len(S.links)
    dr = np.abs(q1[:3 * nl] - q0[:3 * nl]).reshape(-1, 3) if nl else np.zeros((0, 3))
    return float(max(dr[:, :2].max(initial=0.0) / S.scale, dr[:, 2].max(initial=0.0)))


class _Geometry:
    """The drawn system with one link's joint places (or a slider's guide) moved a fraction
    ``t`` of the way to the new dimension."""

    def __init__(self, S: Any, link: str, moves: dict[str, np.ndarray], guide: tuple | None) -> None:
        self.S, self.link, self.guide = S, link, guide
        self.i = S.index(link)
        mech = S.mech
        self.old = {j: S.to_local(link, _xy(mech.joint(j).point)) for j in moves}
        self.new = {j: S.to_local(link, np.asarray(p, float)) for j, p in moves.items()}

    def between(self, jid: str, t: float) -> np.ndarray:
        """Moved joint ``jid``'s local point a fraction ``t`` of the way to its new place."""
        return self.old[jid] + t * (self.new[jid] - self.old[jid])

    def local(self, link: str, jid: str, p: np.ndarray | None = None) -> np.ndarray:
        """Joint ``jid``'s drawn point (or the point ``p``) in ``link``'s frame, with the new
        dimension."""
        if link == self.link and jid in self.new:
            return self.new[jid]
        return self.S.to_local(link, _xy(self.S.mech.joint(jid).point if p is None else p))

    def line(self, t: float) -> tuple[np.ndarray, np.ndarray, float]:
        """The guide at ``t``: a point on it and its direction (drawn coordinates), the turn."""
        jid, o, e0, e1, a0, a1 = self.guide
        p = _xy(self.S.mech.joint(jid).point)
        u0 = np.array([math.cos(a0), math.sin(a0)])
        a = a0 + t * (a1 - a0)
        ut = np.array([math.cos(a), math.sin(a)])
        nt = np.array([-ut[1], ut[0]])
        return o + (e0 + t * (e1 - e0)) * nt + float(u0 @ (p - o)) * ut, ut, a - a0

    def system(self, t: float) -> Any:
        S = self.S
        cons = []
        line = self.line(t) if self.guide else None
        for con in S.cons:
            ch: dict[str, Any] = {}
            if con.joint in self.old:
                if con.a == self.i and con.sa is not None:
                    ch["sa"] = self.between(con.joint, t)
                if con.b == self.i and con.sb is not None:
                    ch["sb"] = self.between(con.joint, t)
            elif line is not None and con.joint == self.guide[0]:
                p, ut, turn = line
                ul = S.to_local_dir(self.link, ut)
                if con.kind == "angle" and con.role == "rotation":
                    ch["c0"] = con.c0 + turn
                elif con.kind == "line" and con.role == "pair":
                    ch.update(sa=S.to_local(self.link, p), w=np.array([-ul[1], ul[0]]))
                elif con.kind == "line":
                    ch["w"] = ul
            cons.append(replace(con, **ch) if ch else con)
        return replace(S, cons=tuple(cons), cache={})

    def place(self, q: np.ndarray, link: str, jid: str, p: np.ndarray | None = None) -> np.ndarray:
        """Where the point :meth:`local` of ``link`` is at ``q`` (new geometry)."""
        return self.S.point(q[None], self.S.index(link), self.local(link, jid, p))[0]

    def mechanism(self, q: np.ndarray) -> Mechanism:
        S, mech = self.S, self.S.mech
        joints = []
        line = self.line(1.0) if self.guide else None
        for j in mech.joints:
            a, b = j.links
            ch: dict[str, Any] = {}
            if line is not None and j.id == self.guide[0]:
                p, ut, _ = line
                on = b if S.index(b) >= 0 else a
                ch["point"] = self.place(q, a, j.id, p) if on == a else self.place(q, b, j.id)
                ch["axis"] = _turned(S, q, a, S.to_local_dir(a, ut))
            elif j.point is not None and (S.index(b) >= 0 or S.index(a) >= 0):
                on = b if S.index(b) >= 0 else a
                ch["point"] = self.place(q, on, j.id)
                if j.type == "P" and j.axis is not None:
                    ch["axis"] = _turned(S, q, a, S.to_local_dir(a, _xy(j.axis)))
            joints.append(replace(j, **ch) if ch else j)
        points = {n: replace(ps, at=self.place(q, ps.link, "", ps.at)) for n, ps in mech.points.items()}
        return replace(mech, joints=tuple(joints), points=points)


def _turned(S: Any, q: np.ndarray, link: str, local_dir: np.ndarray) -> np.ndarray:
    """The direction ``local_dir`` of ``link``'s frame at the configuration ``q``."""
    i = S.index(link)
    phi = 0.0 if i < 0 else float(q[3 * i + 2])
    return to_frame(math.cos(phi), math.sin(phi), local_dir[0], local_dir[1])


# --------------------------------------------------------------------------- why not
def _why(geo: _Geometry, q: np.ndarray, what: str, folded: bool) -> str:
    """One line: which dimension breaks which condition (the dyad that cannot close, and
    Grashof's condition of a four-bar), ``q`` the last configuration reached."""
    S, mech = geo.S, geo.S.mech
    worst = _worst_dyad(geo, q)
    text = f"{what} does not assemble at the drawn input"
    if worst is not None:
        (l1, l2, e, g, f), a, b, d = worst
        if d > a + b:
            text += (f": joints {e} and {f} are {d:.4g} apart but {l1} + {l2} = {a:.4g} + {b:.4g} = {a + b:.4g} "
                     f"(triangle inequality {e}{f} ≤ {l1} + {l2})")
        elif d < abs(a - b):
            text += (f": joints {e} and {f} are {d:.4g} apart but |{l1} - {l2}| = {abs(a - b):.4g} "
                     f"(triangle inequality {e}{f} ≥ |{l1} - {l2}|)")
        else:
            worst = None
    if worst is None:
        text += f": the links at joint {_worst_joint(geo, q)} cannot close their loop"
        if folded:
            text += " (the drawn branch passes a dead point before reaching it)"
    if is_fourbar(mech):
        text += "; " + _grashof_words(geo)
    return text


def _worst_joint(geo: _Geometry, q: np.ndarray) -> str:
    """The joint whose equations are furthest from holding with the new dimension at ``q``."""
    St = geo.system(1.0)
    return worst_joint(St, q, np.array([d.assembled for d in St.drivers]))


def _worst_dyad(geo: _Geometry, q: np.ndarray) -> tuple | None:
    """The RRR dyad of the mechanism's decomposition
    (:func:`~mechsyn.kinematics.groups.decompose`) nearest to (or furthest past) its
    triangle inequality with the new dimension: ``((l1, l2, E, G, F), a, b, d)``, the dyad's
    links ``l1, l2`` joined at ``G``, its outer joints ``E, F`` carried by their known links
    at ``q`` ``d`` apart, its sides ``a = EG`` on ``l1`` and ``b = GF`` on ``l2`` (new lengths)."""
    S = geo.S
    plan = decompose(S)
    best, score = None, -np.inf
    for step in plan.steps if plan is not None else ():
        if step.kind != "RRR":
            continue
        (l1, l2), (e, g, f) = (S.links[i] for i in step.links), step.joints
        a, b = _side_len(geo, l1, e, g), _side_len(geo, l2, g, f)
        pe, pf = (geo.place(q, S.mech.joint(j).other(link), j) for j, link in ((e, l1), (f, l2)))
        d = float(np.linalg.norm(pe - pf))
        s = max(d - (a + b), abs(a - b) - d) / S.scale
        if s > score:
            best, score = ((l1, l2, e, g, f), a, b, d), s
    return best


def _side_len(geo: _Geometry, link: str, j1: str, j2: str) -> float:
    """The distance of joints ``j1`` and ``j2`` on ``link`` with the new dimension."""
    return float(np.linalg.norm(geo.local(link, j1) - geo.local(link, j2)))


def _grashof_words(geo: _Geometry) -> str:
    """Grashof's condition of the four-bar with the new dimension, in words."""
    mech = geo.S.mech
    s, p, qq, L = sorted(_side_len(geo, name, *(j.id for j in mech.joints_of(name))) for name in mech.link_names)
    if s + L <= p + qq:
        return f"Grashof holds (s + l = {s + L:.4g} ≤ p + q = {p + qq:.4g}: the shortest link turns fully)"
    return f"non-Grashof (s + l = {s + L:.4g} > p + q = {p + qq:.4g}: no link turns fully)"
