"""Belt-manipulator case files (YAML or JSON): the design (or its synthesis data) and what
to analyse, validated by a strict schema (unknown keys are errors).

Schema, e.g. ``examples/belt/paper001.yaml``::

  name: Paper 001 example
  design: {a: 500, c: 350, h: 100, r: 75}          # or synthesis: {...} below
  phi_deg: {start: -73, stop: 85, step: 1}
  motion: {law: constant, omega_deg_s: 60}         # trapezoidal: omega_max_deg_s, accel_deg_s2
  paths: {segment_deg: [-73, 0], translation_tol_deg: 3}

  synthesis: {h0: [-350, 600], hf: [324.6, 597.5], phi_of_deg: -60, r: 75, a0: [0, 0]}

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from mechsyn.belt.design import BeltDesign
from mechsyn.belt.kinematics import ConstantSpeedLaw, MotionLaw, TableLaw, TrapezoidalLaw
from mechsyn.belt.report import phi_range
from mechsyn.belt.synthesis import synthesize_belt
from mechsyn.errors import MechsynInputError
from mechsyn.io.files import read_data, read_text

if TYPE_CHECKING:
    from mechsyn.belt.synthesis import BeltSynthesis

__all__ = ["BeltCase", "DesignSpec", "MotionSpec", "PathsSpec", "RangeSpec", "SynthesisSpec",
           "case_inputs", "load_belt_case", "motion_law", "read_motion_table"]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class DesignSpec(_Strict):
    """Dimensions of the mechanism (lengths in any one unit, mm in paper 001)."""

    a: float = Field(gt=0, description="lever 1 length |A0 A|")
    c: float = Field(gt=0, description="x offset of C to the left of A")
    h: float = Field(description="height of H above C")
    r: float = Field(gt=0, description="pulley radius")


class SynthesisSpec(_Strict):
    """Working scene for the synthesis (machine frame, y along the machine's axis)."""

    h0: tuple[float, float] = Field(description="design position of H")
    hf: tuple[float, float] = Field(description="final position of H")
    phi_of_deg: float = Field(description="rotation of lever 1 from H0 to Hf, degrees")
    r: float = Field(gt=0, description="pulley radius")
    a0: tuple[float, float] = Field((0.0, 0.0), description="base point A0")


class RangeSpec(_Strict):
    start: float
    stop: float
    step: float = 1.0


class MotionSpec(_Strict):
    law: Literal["constant", "trapezoidal", "table"] = "constant"
    omega_deg_s: float | None = Field(None, gt=0, description="constant input speed")
    omega_max_deg_s: float | None = Field(None, gt=0, description="trapezoidal: top speed")
    accel_deg_s2: float | None = Field(None, gt=0, description="trapezoidal: acceleration")
    t: list[float] | None = Field(None, description="table: times, s")
    phi_deg: list[float] | None = Field(None, description="table: Δφ at those times, deg")

    @model_validator(mode="after")
    def _complete(self) -> "MotionSpec":
        if self.law == "trapezoidal" and (self.omega_max_deg_s is None
                                          or self.accel_deg_s2 is None):
            raise ValueError("a trapezoidal law needs omega_max_deg_s and accel_deg_s2")
        if self.law == "table" and (self.t is None or self.phi_deg is None):
            raise ValueError("a table law needs t and phi_deg lists")
        return self


class PathsSpec(_Strict):
    segment_deg: tuple[float, float] | None = None
    translation_tol_deg: float = Field(3.0, gt=0)


class BeltCase(_Strict):
    """A belt-manipulator case: the design (or its synthesis data) and what to analyse."""

    name: str = "belt manipulator"
    design: DesignSpec | None = None
    synthesis: SynthesisSpec | None = None
    phi_deg: RangeSpec | None = None
    motion: MotionSpec | None = None
    paths: PathsSpec = PathsSpec()

    @model_validator(mode="after")
    def _one_design(self) -> "BeltCase":
        if (self.design is None) == (self.synthesis is None):
            raise ValueError("give exactly one of 'design' and 'synthesis'")
        return self


def load_belt_case(path: str) -> BeltCase:
    """Read and validate a belt case file (YAML or JSON); MechsynInputError on bad input
    (naming the file, the line of a syntax error, or the offending field)."""
    data, _ = read_data(path, "belt case file")
    if not isinstance(data, dict):
        raise MechsynInputError("expected a mapping (name, design, phi_deg, ...) at the top",
                                source=str(path))
    try:
        return BeltCase.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        loc = ".".join(str(x) for x in first["loc"]) or None
        raise MechsynInputError(first["msg"], source=str(path), field=loc,
                                hint="see docs/belt.md for the file's keys") from None


def read_motion_table(path: str | Path) -> tuple[list[float], list[float]]:
    """Times t (s) and lever rotations Δφ (deg) of a motion table (two columns; a header
    line, ``#`` comments and ``,`` ``;`` tab or blank separators allowed), for a
    :class:`mechsyn.belt.TableLaw` (after converting Δφ to radians).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "law.csv"
    >>> _ = f.write_text("t, dphi_deg\\n0, -73\\n0.5, -20\\n1, 0\\n")
    >>> read_motion_table(f)
    ([0.0, 0.5, 1.0], [-73.0, -20.0, 0.0])
    """
    text = read_text(path, "table")
    t: list[float] = []
    phi: list[float] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.split("#", 1)[0].strip()
        if not s:
            continue
        parts = [p for p in s.replace(";", ",").replace("\t", ",").replace(" ", ",").split(",")
                 if p]
        try:
            vals = [float(p) for p in parts]
        except ValueError:
            if not t:          # a header line
                continue
            raise MechsynInputError(f"expected two numbers, got {line.strip()!r}",
                                    source=str(path), line=lineno) from None
        if len(vals) != 2:
            raise MechsynInputError(f"expected two columns (t, dphi_deg), got {len(vals)}",
                                    source=str(path), line=lineno)
        t.append(vals[0])
        phi.append(vals[1])
    return t, phi


def motion_law(law: str, dphi: NDArray[np.float64], *, omega_deg_s: float | None = None,
               omega_max_deg_s: float | None = None, accel_deg_s2: float | None = None,
               t: Sequence[float] | None = None, phi_deg: Sequence[float] | None = None) -> MotionLaw:
    """The input law named ``law`` over the lever rotations ``dphi`` (radians, first to last),
    from the values of a case file's ``motion`` block (degrees, seconds).

    ``constant`` runs at ``omega_deg_s`` (default 60 °/s); ``trapezoidal`` needs
    ``omega_max_deg_s`` and ``accel_deg_s2``; ``table`` interpolates ``t``, ``phi_deg``.

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.belt.case_file import motion_law
    >>> law = motion_law("trapezoidal", np.radians([-73, 0]), omega_max_deg_s=90, accel_deg_s2=200)
    >>> round(law.duration(), 4)
    1.2611
    """
    start, stop = float(dphi[0]), float(dphi[-1])
    if law == "constant":
        return ConstantSpeedLaw(start, stop, math.radians(60.0 if omega_deg_s is None else omega_deg_s))
    if law == "trapezoidal":
        if omega_max_deg_s is None or accel_deg_s2 is None:
            raise MechsynInputError("the trapezoidal law needs a top speed and an acceleration",
                                    field="omega_max_deg_s" if omega_max_deg_s is None else "accel_deg_s2")
        return TrapezoidalLaw(start, stop, math.radians(omega_max_deg_s), math.radians(accel_deg_s2))
    if law == "table":
        if t is None or phi_deg is None:
            raise MechsynInputError("the table law needs a table of t (s) and Δφ (deg)", field="table")
        return TableLaw(tuple(t), tuple(math.radians(p) for p in phi_deg))
    raise MechsynInputError(f"unknown law {law!r}", field="law", hint="constant, trapezoidal or table")


def case_inputs(case: BeltCase) -> tuple[tuple[BeltDesign | BeltSynthesis, NDArray[np.float64]], dict[str, Any]]:
    """The arguments of :func:`mechsyn.belt.analyze_case` for a case: ``(design, dphi)``
    and the keywords (segment, tolerance, input law, name). A case with synthesis data is
    synthesised first (the report then carries the synthesis).

    Examples
    --------
    >>> import mechsyn as ms
    >>> case = ms.belt.load_belt_case(ms.examples.path("paper001"))
    >>> args, kwargs = ms.belt.case_inputs(case)
    >>> rep = ms.belt.analyze_case(*args, **kwargs)       # == mechsyn belt analyze --file ...
    >>> type(rep.law).__name__, round(rep.paths["C"].extent_x, 1)
    ('TrapezoidalLaw', 1228.5)
    """

    if case.synthesis is not None:
        s = case.synthesis
        design: BeltDesign | BeltSynthesis = synthesize_belt(s.h0, s.hf, math.radians(s.phi_of_deg), s.r, A0=s.a0)
    else:
        design = BeltDesign(**case.design.model_dump())  # type: ignore[union-attr]
    if case.phi_deg is None:
        raise MechsynInputError("the case gives no range of Δφ", field="phi_deg",
                                hint="add phi_deg: {start: -73, stop: 85, step: 1}")
    dphi = phi_range(case.phi_deg.start, case.phi_deg.stop, case.phi_deg.step)
    m = case.motion or MotionSpec()
    law = motion_law(m.law, dphi, omega_deg_s=m.omega_deg_s, omega_max_deg_s=m.omega_max_deg_s,
                     accel_deg_s2=m.accel_deg_s2, t=m.t, phi_deg=m.phi_deg)
    seg = case.paths.segment_deg
    return (design, dphi), {"segment": None if seg is None else tuple(math.radians(v) for v in seg),
                            "translation_tol": math.radians(case.paths.translation_tol_deg),
                            "law": law, "name": case.name}
