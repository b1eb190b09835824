"""Paper 001's manipulator with a flexible element (a belt on a pulley), in one place.

Lever 1 pivots on the frame at A0; link 2 (the "hand", carrying the gripper point H)
pivots on lever 1 at A and carries a pulley of radius r centred on A; a belt (toothed
belt, chain, band or rope) pinned to the frame at B0 wraps the pulley. Near the design
position the hand translates almost rectilinearly.

- :mod:`mechsyn.belt.design`        :class:`BeltDesign`, :func:`design_constants` (eqs. 1-3)
- :mod:`mechsyn.belt.kinematics`    :func:`analyze` → :class:`BeltState`, input laws,
  :func:`motion`, :func:`point_motion`, :func:`inverse_input`
- :mod:`mechsyn.belt.straightness`  :func:`path_quality`, :func:`translation_range`, deviations
- :mod:`mechsyn.belt.four_bar`      the equivalent hinged four-bar A0-A-B-B0, mechanism files
- :mod:`mechsyn.belt.synthesis`     :func:`synthesize_belt` (primary chain, then the belt)
- :mod:`mechsyn.belt.case_file`     :class:`BeltCase` files (YAML/JSON), :func:`load_belt_case`
- :mod:`mechsyn.belt.report`        :func:`analyze_case` → :class:`BeltReport` (what
  ``mechsyn belt analyze`` prints)

Names are imported on first use (``import mechsyn.belt`` loads neither SciPy nor pydantic).

Examples
--------
>>> import mechsyn as ms
>>> d = ms.belt.BeltDesign(a=500, c=350, h=100, r=75)
>>> rep = ms.belt.analyze_case(d, ms.belt.phi_range(-73, 85, 1))
>>> round(rep.paths["H"].translation_length)     # hand within ±3° of its design attitude
270

References
----------
.. [1] Paper 001 (seed 001, ``shared/seeds/001_*.txt``): a new basic mechanism with a
   flexible element for a manipulator serving technological machines (in Bulgarian). The
   stored copy has no title page: it gives neither the authors, nor the title, journal or
   year. It builds on [Гълъбов и др. 2012] (Galabov et al., 2012) for the hinged four-bar
   A0-A-B-B0 and on Beyer (1953) and Geronimus (1962) for synthesis by infinitely close
   positions. Its equations are restated, with the OCR's and the paper's slips corrected,
   in ``shared/spec/flexible-manipulator.md``.
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import importlib
from typing import Any

#: public name -> submodule that defines it (imported on first use)
_LAZY: dict[str, str] = {
    "BeltDesign": "design", "design_constants": "design",
    "BeltState": "kinematics", "analyze": "kinematics", "MotionLaw": "kinematics",
    "ConstantSpeedLaw": "kinematics", "TrapezoidalLaw": "kinematics", "TableLaw": "kinematics",
    "PointMotion": "kinematics", "MotionResult": "kinematics", "motion": "kinematics",
    "point_motion": "kinematics", "InverseResult": "kinematics", "inverse_input": "kinematics",
    "PathQuality": "straightness", "path_quality": "straightness",
    "translation_range": "straightness", "tangent_deviation": "straightness",
    "best_line_deviation": "straightness",
    "FourBarState": "four_bar", "equivalent_four_bar": "four_bar",
    "compare_with_four_bar": "four_bar", "four_bar_mechanism_dict": "four_bar",
    "belt_mechanism_dict": "four_bar",
    "BeltSynthesis": "synthesis", "synthesize_belt": "synthesis",
    "BeltCase": "case_file", "load_belt_case": "case_file", "case_inputs": "case_file",
    "motion_law": "case_file",
    "BeltReport": "report", "analyze_case": "report", "phi_range": "report",
}

__all__ = sorted(_LAZY)


def __getattr__(name: str) -> Any:
    if name not in _LAZY:
        raise AttributeError(f"module 'mechsyn.belt' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"mechsyn.belt.{_LAZY[name]}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return list(__all__)
