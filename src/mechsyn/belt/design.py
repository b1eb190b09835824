"""Dimensions of paper 001's belt manipulator and the belt's design constants.

Frame: origin at A0, y along the axis of the technological machine. In the design
position lever 1 lies on +y, A = (0, a), the belt runs straight up from
B0 = (r, a - b0) to the tangent point B = (r, a), C = (-c, a) and H = (-c, a + h).

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
from numpy.typing import NDArray

from mechsyn.errors import MechsynInputError

Array = NDArray[np.float64]

__all__ = ["BeltDesign", "design_constants"]


def design_constants(a: float, c: float, r: float) -> tuple[float, float, float]:
    """Initial free belt length b0, frame length l0 and frame angle α0 (radians).

    Paper 001, equations (1)-(3)::

        b0 = a c / (c + r)          (1)  (exactly the condition y''_C(0) = 0)
        l0 = sqrt((a - b0)^2 + r^2) (2)
        α0 = arccos(r / l0)         (3)
    """
    b0 = a * c / (c + r)
    l0 = math.hypot(a - b0, r)
    alpha0 = math.acos(r / l0)
    return b0, l0, alpha0


@dataclass(frozen=True)
class BeltDesign:
    """Dimensions of the manipulator: lever a = |A0 A|, hand offsets c, h, pulley radius r.

    C = A + (-c, 0) and H = C + (0, h) in the design position (paper 001, fig. 1).

    Examples
    --------
    >>> import mechsyn as ms
    >>> d = ms.BeltDesign(a=500, c=350, h=100, r=75)      # paper 001's example
    >>> round(d.b0, 3), round(d.l0, 3)                    # the paper's values
    (411.765, 115.804)
    """

    a: float
    c: float
    h: float
    r: float

    def __post_init__(self) -> None:
        for name in ("a", "c", "h", "r"):
            value = getattr(self, name)
            if not isinstance(value, (int, float)) or not math.isfinite(value):
                raise MechsynInputError(f"{name} must be a finite number, got {value!r}",
                                        field=name)
        if self.a <= 0:
            raise MechsynInputError(f"lever length a must be positive, got {self.a:g}",
                                    field="a", hint="A must lie on +y above A0")
        if self.r <= 0:
            raise MechsynInputError(f"pulley radius r must be positive, got {self.r:g}",
                                    field="r")
        if self.c <= 0:
            raise MechsynInputError(
                f"c must be positive (C to the left of A), got {self.c:g}", field="c",
                hint="with c <= 0 the free belt length b0 = a c/(c + r) is not positive",
            )

    @property
    def b0(self) -> float:
        return design_constants(self.a, self.c, self.r)[0]

    @property
    def l0(self) -> float:
        return design_constants(self.a, self.c, self.r)[1]

    @property
    def alpha0(self) -> float:
        """Angle of the frame line A0 B0 to x, radians."""
        return design_constants(self.a, self.c, self.r)[2]

    @property
    def B0(self) -> Array:
        """Belt anchor on the frame: l0 (cos α0, sin α0) = (r, a - b0)."""
        return np.array([self.r, self.a - self.b0])

    def to_dict(self) -> dict[str, float]:
        return {"a": self.a, "c": self.c, "h": self.h, "r": self.r,
                "b0": self.b0, "l0": self.l0, "alpha0_deg": math.degrees(self.alpha0)}


