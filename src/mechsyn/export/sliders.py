"""A slider's parts to cut: the block and the slot of its guide.

Each prismatic (P) joint joins a *guide* (the frame when the frame is one of its links,
else the link with more joints) and a *block* (the other link). On the sheet of
:func:`mechsyn.export.plates.link_plates` the block is a rectangle along the slide axis
round its pins, and the guide's plate gets a slot along the axis, as wide as a cut hole,
over the block's stroke: the block's pin at the joint point runs in it. The stroke is the
joint's ``limits`` (of its coordinate, from the drawn value) when the file gives them, else the range the block travels relative to
the guide when the first drive turns a full turn (simulated on the file's branch).

Examples
--------
>>> import mechsyn as ms
>>> (s,) = slider_parts(ms.examples.load("slider_crank"))
>>> s.joint, s.guide, s.block, [round(v, 4) for v in s.stroke]   # a stroke of 2 cranks
('D', 'frame', 'slider', [-1.6226, 0.3774])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism

__all__ = ["SliderPart", "slider_parts"]


@dataclass(frozen=True)
class SliderPart:
    """One P joint's parts: ``guide`` and ``block`` links, the drawn slide ``point`` and unit
    ``axis``, and the ``stroke`` (min, max displacement of the block along the axis from the
    drawn position; None when unknown, said in ``note``)."""

    joint: str
    guide: str
    block: str
    point: np.ndarray
    axis: np.ndarray
    stroke: tuple[float, float] | None
    note: str = ""

    @property
    def slot(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The slot's two end centres in the drawn configuration (None without a stroke)."""
        if self.stroke is None:
            return None
        return self.point + self.stroke[0] * self.axis, self.point + self.stroke[1] * self.axis


def slider_parts(mech: Mechanism) -> list[SliderPart]:
    """The parts of every P joint of a planar mechanism with joint points (see the module doc)."""
    joints = [j for j in mech.joints if j.type == "P" and j.point is not None and j.axis is not None]
    if not joints:
        return []
    degree = {name: len(mech.joints_of(name)) for name in mech.link_names}
    sweep = None
    out = []
    for j in joints:
        a, b = j.links
        guide = a if a == mech.ground or (b != mech.ground and degree[a] >= degree[b]) else b
        block = b if guide == a else a
        axis = np.asarray(j.axis, float)[:2]
        axis = axis / np.linalg.norm(axis)
        point = np.asarray(j.point, float)[:2]
        if j.limits is not None:  # the coordinate of the second link: the block's, or the guide's (minus)
            c0 = _drawn_coordinate(mech, j.id)
            if c0 is not None:
                sign = 1.0 if block == b else -1.0
                lo, hi = sorted(sign * (float(v) - c0) for v in j.limits)
                out.append(SliderPart(j.id, guide, block, point, axis, (min(lo, 0.0), max(hi, 0.0))))
                continue
        if sweep is None:
            sweep = _full_turn(mech)
        if isinstance(sweep, str):
            out.append(SliderPart(j.id, guide, block, point, axis, None, f"joint {j.id}: {sweep}: no slot cut; "
                                  "give the joint `limits` for its stroke"))
            continue
        out.append(SliderPart(j.id, guide, block, point, axis, _stroke(sweep, guide, block, point, axis)))
    return out


def _drawn_coordinate(mech: Mechanism, joint: str) -> float | None:
    """The P joint's coordinate in the drawn configuration (the origin its ``limits`` use)."""

    try:
        S = build_system(mech)
    except MechsynInputError:
        return None
    return float(S.coordinate(S.q0[None], joint)[0])


def _full_turn(mech: Mechanism):
    """The simulation of a full turn of the first drive (R) from its drawn value, or why not."""

    try:
        drivers = build_system(mech).drivers
    except MechsynInputError as err:
        return f"the mechanism cannot be simulated ({err.message})"
    if not drivers or drivers[0].type != "R":
        return "no turning drive to sweep"
    d = drivers[0]
    sim = simulate(mech, {d.joint: np.degrees(d.assembled) + np.linspace(0.0, 360.0, 361)})
    if not sim.assembled.any():
        return "the mechanism does not move from its drawn position"
    return sim


def _stroke(sim, guide: str, block: str, point: np.ndarray, axis: np.ndarray) -> tuple[float, float]:
    """The block's displacement along the guide's axis over the assembled steps."""
    S = sim.system
    q = sim.sweep.q[sim.assembled]
    gi, bi = S.index(guide), S.index(block)
    p_block = S.point(q, bi, S.to_local(block, point))
    p_guide = S.point(q, gi, S.to_local(guide, point))
    ax = S.point(q, gi, S.to_local(guide, point + axis)) - p_guide
    s = np.einsum("ij,ij->i", p_block - p_guide, ax)
    return float(min(s.min(), 0.0)), float(max(s.max(), 0.0))
