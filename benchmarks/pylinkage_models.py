"""pylinkage models of mechsyn mechanisms, for benchmarks/kinematics_simulate.py (issue 30).

pylinkage (https://github.com/HugoFara/pylinkage, numba) is never a mechsyn dependency:
this module is imported only when it is importable (``pip install pylinkage numba`` in a
virtual environment of its own, with mechsyn's ``src`` on ``PYTHONPATH``).

A model is read from the mechanism mechsyn loaded from its YAML file, never retyped:

* joints drawn at one point that share a link are one pin (a double joint such as the
  Jansen leg's knee, written as two joints of two links each);
* the ground pins are :class:`pylinkage.components.Ground`, the driven R joint a
  :class:`pylinkage.actuators.Crank` whose output is another pin of the crank link;
* then, until every pin is placed, a pin with two placed pins on one of its links is a
  :class:`pylinkage.dyads.FixedDyad` (a rigid link: distance and angle from the drawing),
  and a pin with placed pins on two of its links an :class:`pylinkage.dyads.RRRDyad`
  (two distances; the drawn position is its hint, so pylinkage starts on the drawn branch
  and keeps the solution nearest the previous row);
* named points are FixedDyads on two placed pins of their link.

Anything else (a P joint, two drives, a pin no dyad reaches) raises :class:`NotExpressible`
naming what pylinkage's dyads cannot say.

Row ``k`` of :func:`run` is the crank at ``start + k * step`` (pylinkage moves the crank by
one step before it writes a row, so the crank is built at ``start - step``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


class NotExpressible(ValueError):
    """The mechanism has no pylinkage model of drivers, RRR and fixed dyads."""


@dataclass(frozen=True)
class Model:
    """The topology of a pylinkage model: which pin is solved how, in order.

    ``pins``: pin name -> the mechsyn joint ids drawn there (the first names the pin);
    ``ground``: pins on the frame; ``crank``: (anchor pin, output pin); ``steps``:
    ``("fixed" | "rrr", name, anchor1, anchor2)`` in solving order, named points last;
    ``names``: every pin and named point in pylinkage's component order;
    ``drive``: the driven joint's id (mechsyn's input).
    """

    pins: dict
    ground: tuple
    crank: tuple
    steps: tuple
    names: tuple
    drive: str
    points: dict  # named point -> link


def _pins(mech, tol: float) -> dict[str, list]:
    """Joints drawn at one point that share a link, merged into one pin."""
    pins: dict[str, list] = {}
    for j in mech.joints:
        if j.type != "R":
            raise NotExpressible(f"joint {j.id} is a {j.type} pair: only R pairs are modelled here")
        p = np.asarray(j.point, float)[:2]
        for name, members in pins.items():
            q = np.asarray(mech.joint(name).point, float)[:2]
            links = {lk for m in members for lk in mech.joint(m).links}
            if np.linalg.norm(p - q) <= tol and links & set(j.links):
                members.append(j.id)
                break
        else:
            pins[j.id] = [j.id]
    return pins


def model_of(mech) -> Model:
    """The pylinkage model of ``mech`` (planar, R pairs, one driven joint on the frame)."""
    if mech.kind != "planar":
        raise NotExpressible(f"{mech.kind} mechanism: pylinkage is planar")
    pts = np.array([np.asarray(j.point, float)[:2] for j in mech.joints])
    pins = _pins(mech, 1e-9 * float(np.ptp(pts, axis=0).max()))
    links = {p: {lk for m in ms for lk in mech.joint(m).links} for p, ms in pins.items()}
    drives = [j for j in mech.joints if j.actuated]
    if len(drives) != 1 or mech.ground not in drives[0].links:
        raise NotExpressible("pylinkage's Crank needs exactly one driven joint on the frame")
    anchor = next(p for p, ms in pins.items() if drives[0].id in ms)
    crank_link = next(lk for lk in drives[0].links if lk != mech.ground)
    ground = tuple(p for p in pins if mech.ground in links[p])
    out = next((p for p in pins if p not in ground and crank_link in links[p]), None)
    if out is None:
        raise NotExpressible(f"the crank link {crank_link} carries no moving joint")
    placed, steps = list(ground) + [out], []
    todo = [p for p in pins if p not in placed] + [f"point:{n}" for n in mech.points]
    while todo:
        for p in todo:
            mine = {mech.points[p[6:]].link} if p.startswith("point:") else links[p]
            on = {lk: [q for q in placed if lk in links[q]] for lk in sorted(mine)}
            rigid = next((qs for qs in on.values() if len(qs) >= 2), None)
            pair = [qs[0] for qs in on.values() if qs]
            if rigid is not None:
                steps.append(("fixed", p, rigid[0], rigid[1]))
            elif len(pair) >= 2 and pair[0] != pair[1] and not p.startswith("point:"):
                steps.append(("rrr", p, pair[0], pair[1]))
            else:
                continue
            placed.append(p)
            links.setdefault(p, mine)
            todo.remove(p)
            break
        else:
            raise NotExpressible(f"no RRR or fixed dyad places {', '.join(todo)}")
    return Model(pins, ground, (anchor, out), tuple(steps), tuple(placed), drives[0].id,
                 {n: s.link for n, s in mech.points.items()})


def drawn_points(mech, model: Model, moved: dict | None = None) -> dict[str, np.ndarray]:
    """Pin and named point -> drawn (x, y), with the joints of ``moved`` ({id: (x, y)}) moved."""
    moved = moved or {}
    P = {p: np.asarray(moved.get(ms[0], mech.joint(ms[0]).point), float)[:2] for p, ms in model.pins.items()}
    for n, s in mech.points.items():
        P[f"point:{n}"] = np.asarray(s.at, float)[:2]
    return P


def crank_angle(model: Model, P: dict) -> float:
    """The drawn crank angle (radians from +x), mechsyn's input of an R drive."""
    d = P[model.crank[1]] - P[model.crank[0]]
    return math.atan2(d[1], d[0])


def build(model: Model, P: dict, start: float, step: float):
    """A pylinkage Linkage for the drawn points ``P``, its crank at ``start - step`` (radians),
    turning by ``step`` per row at 1 rad/s (velocities per unit crank speed)."""
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRRDyad
    from pylinkage.simulation import Linkage

    comp = {p: Ground(float(P[p][0]), float(P[p][1]), name=p) for p in model.ground}
    a, o = model.crank
    crank = Crank(comp[a], float(np.linalg.norm(P[o] - P[a])), angular_velocity=step,
                  initial_angle=start - step, name=o)
    comp[o] = crank
    anchor = {o: crank.output}
    for kind, p, q1, q2 in model.steps:
        A1, A2 = anchor.get(q1, comp.get(q1)), anchor.get(q2, comp.get(q2))
        if kind == "rrr":
            comp[p] = RRRDyad(A1, A2, float(np.linalg.norm(P[p] - P[q1])), float(np.linalg.norm(P[p] - P[q2])),
                              x=float(P[p][0]), y=float(P[p][1]), name=p)
        else:
            d, r = P[q2] - P[q1], P[p] - P[q1]
            comp[p] = FixedDyad(A1, A2, float(np.hypot(*r)), math.atan2(r[1], r[0]) - math.atan2(d[1], d[0]), name=p)
    lk = Linkage([comp[n] for n in model.names], name="mechsyn model")
    lk.set_input_velocity(crank, omega=1.0)
    return lk


def run(lk, n: int):
    """``compile`` and ``step_fast_with_kinematics``: positions, velocities, accelerations
    of every component, each ``(n, components, 2)``."""
    lk.compile()
    return lk.step_fast_with_kinematics(iterations=n)


def fresh(model: Model, P: dict, start: float, step: float, n: int):
    """What pylinkage charges for a new geometry: build, compile, kinematics."""
    return run(build(model, P, start, step), n)
