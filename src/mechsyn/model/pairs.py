"""The catalogue of kinematic pairs (Artobolevsky's classes).

The class ``i`` of a pair is the number of relative-motion constraints it imposes
(1..5); its freedom is ``f = 6 - i``. Lower pairs (surface contact) have ``m = 5`` in
paper 003's per-contour formula, higher pairs (line or point contact) ``m = 4``.

In a *planar* mechanism a lower pair (R or P in the plane) counts as ``p5`` and a
higher pair (cam, gear tooth contact) as ``p4`` (Chebyshev's formula).

A **belt** pair (belt, chain, band or rope; paper 001) joins the link its flexible
element is anchored on to the link carrying the pulley it wraps. The inextensible,
non-slipping belt keeps ``b + r·(wrapped angle)`` constant: one constraint on the
relative motion in the plane, so it counts like a higher pair, class 4 (``p4``). Its
instantaneous equivalent is a contact whose normal is the straight belt run through the
tangent point (the tension's line of action): :func:`belt_tangent`.

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class PairKind:
    """One entry of the pair catalogue.

    Attributes
    ----------
    name : str
        Canonical type name used in mechanism files (``R``, ``P``, ...).
    title : str
        The field's name of the pair.
    pair_class : int or None
        Class ``i`` in a spatial mechanism (``None``: given in the file).
    higher : bool
        Line or point contact (``m = 4`` in paper 003) rather than surface contact.
    planar : bool
        May appear in a planar mechanism.
    """

    name: str
    title: str
    pair_class: int | None
    higher: bool
    planar: bool

    @property
    def freedom(self) -> int | None:
        return None if self.pair_class is None else 6 - self.pair_class


PAIR_KINDS: dict[str, PairKind] = {
    k.name: k
    for k in (
        PairKind("R", "revolute", 5, False, True),
        PairKind("P", "prismatic", 5, False, True),
        PairKind("H", "helical", 5, False, False),
        PairKind("C", "cylindrical", 4, False, False),
        PairKind("U", "universal (Hooke)", 4, False, False),
        PairKind("S_pin", "sphere with pin", 4, False, False),
        PairKind("S", "spherical", 3, False, False),
        PairKind("E", "planar (flat)", 3, False, False),
        PairKind("line_contact", "line contact", 2, True, False),
        PairKind("point_contact", "point contact", 1, True, False),
        # Planar higher pairs: p4 in a planar mechanism; in a spatial mechanism a line
        # contact of parallel cylinders (class 2) unless the file gives `class`.
        PairKind("cam", "cam (planar higher pair)", None, True, True),
        PairKind("gear", "gear mesh (planar higher pair)", None, True, True),
        # A flexible element anchored on one link wrapping a pulley on the other: one
        # constraint in the plane (p4, like a higher pair; spatial class 2 by default).
        PairKind("belt", "belt / chain / rope wrapping a pulley (planar, p4)", None, True, True),
        PairKind("generic", "generic pair of a given class", None, False, True),
    )
}

#: Accepted spellings of the pair types (lower-case key -> canonical name).
PAIR_ALIASES: dict[str, str] = {
    **{k.lower(): k for k in PAIR_KINDS},
    "revolute": "R", "hinge": "R", "pin": "R",
    "prismatic": "P", "slider": "P", "sliding": "P",
    "helical": "H", "screw": "H",
    "cylindrical": "C", "cyl": "C",
    "universal": "U", "hooke": "U", "cardan": "U",
    "spherical": "S", "ball": "S", "ball_joint": "S",
    "sphere_with_pin": "S_pin", "s_pin": "S_pin", "spin": "S_pin",
    "planar": "E", "flat": "E", "plane": "E",
    "line": "line_contact", "linecontact": "line_contact",
    "point": "point_contact", "pointcontact": "point_contact",
    "gear_pair": "gear", "tooth": "gear",
    "chain": "belt", "rope": "belt", "band": "belt", "cable": "belt", "belt_wrap": "belt",
    "flexible": "belt",
}


def canonical_pair_type(name: str) -> str | None:
    """Canonical pair type for ``name`` (case-insensitive, aliases accepted), or None."""
    return PAIR_ALIASES.get(str(name).strip().lower().replace("-", "_").replace(" ", "_"))


#: Pair types of each spatial class that a remedy may suggest (paper 003's practice).
SUGGESTED_LOWER = {5: "R", 4: "C", 3: "S"}
SUGGESTED_HIGHER = {2: "line_contact", 1: "point_contact"}


def suggest_type(old_type: str, new_class: int, higher: bool) -> str:
    """A pair type of ``new_class`` close to ``old_type`` (for remedies)."""
    if higher:
        return SUGGESTED_HIGHER.get(new_class, "generic")
    if old_type == "P" and new_class == 4:
        return "C"  # a cylindrical pair along the slide
    if old_type in ("P", "E") and new_class == 3:
        return "E"
    if old_type == "S" and new_class == 4:
        return "S_pin"
    return SUGGESTED_LOWER.get(new_class, "generic")


#: Wrap senses of a belt pair: +1 counter-clockwise, -1 clockwise.
BELT_WRAPS = {"ccw": 1.0, "cw": -1.0}


def belt_tangent(point: np.ndarray, anchor: np.ndarray, radius: float,
                 wrap: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Tangent point ``T``, unit belt direction ``g`` (anchor to ``T``) and free length ``b``
    of a belt from ``anchor`` wrapping a pulley of ``radius`` centred at ``point``.

    With ``D = point - anchor``, ``d = |D|``, ``σ = +1`` (``ccw``) or ``-1`` (``cw``)::

        b = sqrt(d^2 - r^2),  g = (b D - σ r R90 D) / d^2,  T = anchor + b g

    (the belt leaves the anchor along ``g`` and turns round the pulley in the sense
    ``σ``; paper 001: B0 = (r, a - b0), centre (0, a), ``ccw``: T = (r, a), g = (0, 1)).
    Raises ValueError when the anchor is not outside the pulley (d <= r).
    """
    sigma = BELT_WRAPS[wrap]
    D = np.asarray(point, float)[:2] - np.asarray(anchor, float)[:2]
    d2 = float(D @ D)
    if d2 <= radius * radius:
        raise ValueError("the anchor is not outside the pulley: the belt cannot run straight to it")
    b = float(np.sqrt(d2 - radius * radius))
    g = (b * D - sigma * radius * np.array([-D[1], D[0]])) / d2
    return np.asarray(anchor, float)[:2] + b * g, g, b
