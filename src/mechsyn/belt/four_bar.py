"""The hinged four-bar A0-A-B-B0 equivalent to paper 001's belt manipulator (up to second
derivatives in the design position), the comparison of the two, and both as mechanism
files for the general planar solver.

References
----------
.. [1] Paper 001 (seed 001), the belt manipulator: the reference in :mod:`mechsyn.belt`.
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from mechsyn.belt.design import BeltDesign
from mechsyn.belt.kinematics import analyze
from mechsyn.belt.straightness import tangent_deviation, translation_range, translation_travel
from mechsyn.kinematics.groups import circle_circle

Array = NDArray[np.float64]

__all__ = ["FourBarState", "belt_mechanism_dict", "compare_with_four_bar",
           "equivalent_four_bar", "four_bar_mechanism_dict"]


@dataclass
class FourBarState:
    """Hinged four-bar A0-A-B-B0 equivalent (up to second derivatives) to the belt
    mechanism in its design position: crank A0A = a, coupler AB = r (link 2, carrying C
    and H), rocker BB0 = b0, frame A0B0 = l0, right angle at B in the design position.
    NaN where it cannot be assembled."""

    dphi: Array
    A: Array
    B: Array
    theta: Array
    C: Array
    H: Array
    valid: NDArray[np.bool_]


def equivalent_four_bar(design: BeltDesign, dphi: ArrayLike) -> FourBarState:
    """Positions of the equivalent four-bar over ``dphi`` (rad), assembly branch of the
    design position (B to the right of the line A B0 ... i.e. as in paper 001's fig. 1).

    B is the intersection of the circles (A, r) and (B0, b0); θ = angle of AB to x.
    """
    dphi = np.atleast_1d(np.asarray(dphi, dtype=float))
    a, c, h, r = design.a, design.c, design.h, design.r
    b0 = design.b0
    B0 = design.B0
    A = np.stack([-a * np.sin(dphi), a * np.cos(dphi)], axis=-1)
    D = B0[None, :] - A
    # the RRR kernel: B = A + f D + sign g R90 D (circles (A, r) and (B0, b0))
    f, g2, _ = circle_circle(D[:, 0], D[:, 1], r**2, b0**2)
    with np.errstate(invalid="ignore"):
        perp = np.sqrt(g2)
    # the branch sign from the design position: A=(0,a), B=(r, a) on which side of A B0
    D0 = B0 - np.array([0.0, a])
    f0, _, _ = circle_circle(float(D0[0]), float(D0[1]), r**2, b0**2)
    Bdesign = np.array([0.0, a]) + f0 * D0
    sign = 1.0 if (np.array([r, a]) - Bdesign) @ np.array([-D0[1], D0[0]]) > 0 else -1.0
    B = A + f[:, None] * D + (sign * perp)[:, None] * np.stack([-D[:, 1], D[:, 0]], axis=-1)
    AB = B - A
    theta = np.arctan2(AB[:, 1], AB[:, 0])
    st, ct = np.sin(theta), np.cos(theta)
    C = A + c * np.stack([-ct, -st], axis=-1)
    H = C + h * np.stack([-st, ct], axis=-1)
    return FourBarState(dphi=dphi, A=A, B=B, theta=theta, C=C, H=H,
                        valid=np.isfinite(perp))


def compare_with_four_bar(
    design: BeltDesign,
    dphi_range: tuple[float, float],
    translation_tol: float = math.radians(3.0),
    samples: int = 4001,
) -> dict[str, object]:
    """Belt mechanism against its equivalent hinged four-bar A0-A-B-B0 (paper 001's claim
    that the belt version is better), over the same lever rotations Δφ in ``dphi_range``.

    For each mechanism and for C and H: the Δφ interval where it can be assembled
    (the belt: d > r; the four-bar: the circles (A, r), (B0, b0) meet), the horizontal
    extent of the path, the largest distances above and below the design tangent line
    on the machine side (Δφ <= 0) and on the other side (Δφ >= 0), and the travel of the
    point while link 2 stays within ±``translation_tol`` of its design attitude. Lengths
    as the design's; angles in degrees.
    """
    lo, hi = float(min(dphi_range)), float(max(dphi_range))
    grid = np.union1d(np.linspace(lo, hi, samples), [0.0] if lo < 0 < hi else [])
    belt = analyze(design, grid)
    fb = equivalent_four_bar(design, grid)
    zero = analyze(design, [0.0])
    out: dict[str, object] = {}
    for name, valid, theta, pts in (
        ("belt", belt.valid, belt.theta, {"C": belt.C, "H": belt.H}),
        ("four_bar", fb.valid, fb.theta, {"C": fb.C, "H": fb.H}),
    ):
        entry: dict[str, object] = {}
        if np.any(valid):
            entry["assembled_dphi_deg"] = [float(np.degrees(grid[valid].min())),
                                           float(np.degrees(grid[valid].max()))]
        else:
            entry["assembled_dphi_deg"] = None
        states = analyze if name == "belt" else equivalent_four_bar
        tlo, thi = translation_range(design, lo, hi, translation_tol,
                                     theta_of=lambda g, f=states: f(design, g).theta)
        for p in ("C", "H"):
            P = pts[p]
            P0 = (zero.C if p == "C" else zero.H)[0]
            T0 = (zero.C1 if p == "C" else zero.H1)[0]
            dev = tangent_deviation(P, P0, T0)
            neg, pos = (grid <= 0) & valid, (grid >= 0) & valid
            rec: dict[str, object] = {
                "extent_x": float(np.ptp(P[valid, 0])) if np.any(valid) else None}
            for side, sel in (("machine_side", neg), ("other_side", pos)):
                rec[side] = ({"max_positive_deviation": float(max(dev[sel].max(), 0.0)) + 0.0,
                              "max_negative_deviation": float(max(-dev[sel].min(), 0.0)) + 0.0}
                             if np.any(sel) else None)
            rec["translation_length"] = translation_travel(
                lambda g, f=states, p=p: getattr(f(design, g), p)[:, 0], tlo, thi)
            rec["translation_dphi_deg"] = [math.degrees(tlo), math.degrees(thi)]
            entry[p] = rec
        out[name] = entry
    out["translation_tol_deg"] = math.degrees(translation_tol)
    return out




def four_bar_mechanism_dict(design: BeltDesign, name: str | None = None) -> dict[str, object]:
    """The equivalent four-bar A0-A-B-B0 of the design position as a mechanism-file dict
    (issue 2's YAML/JSON format, for the general planar solver): frame, lever (A0 A),
    hand (A B, carrying C and H: link 2 with its pulley) and rocker (B B0, the belt's free
    run frozen at b0). The belt mechanism itself differs from it beyond second order."""
    a, c, h, r = design.a, design.c, design.h, design.r
    b0 = design.b0
    return {
        "name": name or f"equivalent four-bar of the belt manipulator a={a:g} c={c:g} "
                        f"h={h:g} r={r:g}",
        "kind": "planar",
        "ground": "frame",
        "links": ["frame", "lever", "hand", "rocker"],
        "joints": [
            {"id": "A0", "type": "R", "links": ["frame", "lever"], "point": [0.0, 0.0],
             "actuated": True},
            {"id": "A", "type": "R", "links": ["lever", "hand"], "point": [0.0, a]},
            {"id": "B", "type": "R", "links": ["hand", "rocker"], "point": [r, a]},
            {"id": "B0", "type": "R", "links": ["rocker", "frame"], "point": [r, a - b0]},
        ],
        "points": {"C": {"link": "hand", "at": [-c, a]},
                   "H": {"link": "hand", "at": [-c, a + h]}},
    }


def belt_mechanism_dict(design: BeltDesign, name: str | None = None) -> dict[str, object]:
    """The belt manipulator itself as a mechanism-file dict for the general planar solver,
    in the design position: frame, lever (A0 A, driven at A0), hand (link 2 with its
    pulley, C and H) and a ``belt`` pair from the frame (anchor B0 = (r, a - b0)) to the
    hand's pulley centred on A, wrapped counter-clockwise. A0's input is the lever's
    direction: 90° + Δφ (``examples/belt/paper001_mechanism.yaml`` for the paper's numbers).
    """
    a, c, h, r = design.a, design.c, design.h, design.r
    B0 = [float(x) for x in design.B0]
    return {
        "name": name or f"belt manipulator a={a:g} c={c:g} h={h:g} r={r:g}",
        "kind": "planar",
        "ground": "frame",
        "links": ["frame", "lever", "hand"],
        "joints": [
            {"id": "A0", "type": "R", "links": ["frame", "lever"], "point": [0.0, 0.0],
             "actuated": True},
            {"id": "A", "type": "R", "links": ["lever", "hand"], "point": [0.0, a]},
            {"id": "W", "type": "belt", "links": ["frame", "hand"], "point": [0.0, a],
             "anchor": B0, "radius": r, "wrap": "ccw"},
        ],
        "points": {"C": {"link": "hand", "at": [-c, a]},
                   "H": {"link": "hand", "at": [-c, a + h]},
                   "B0": {"link": "frame", "at": B0}},
    }
