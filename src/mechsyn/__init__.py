"""mechsyn: structural analysis, kinematics and synthesis of mechanisms.

>>> import mechsyn as ms
>>> m = ms.examples.load("crank_rocker")
>>> m.analyze().mobility
1
>>> s = m.simulate(A=(0, 360, 30))
>>> s.point("M").shape
(13, 2)

The names below are imported lazily, on first use: ``import mechsyn`` loads neither
SciPy nor Matplotlib, and nothing draws until a result's ``plot()`` is called.

Subpackages, one per concept:

- :mod:`mechsyn.model`      links, kinematic pairs, the mechanism graph
- :mod:`mechsyn.io`         the mechanism file format (YAML/JSON), validation
- :mod:`mechsyn.structure`  mobility formulas, per-contour analysis, rank method, remedies
- :mod:`mechsyn.kinematics` planar positions, velocities, accelerations, forces
- :mod:`mechsyn.capability` velocity capability of redundant manipulators
- :mod:`mechsyn.synthesis`  structural and dimensional synthesis
- :mod:`mechsyn.belt`       paper 001's manipulator with a belt on a pulley
- :mod:`mechsyn.plot`       every figure (Matplotlib), drawn on the Axes you give
- :mod:`mechsyn.examples`   the example files shipped with the package
- :mod:`mechsyn.cli`        the ``mechsyn`` command line (a thin layer)

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import importlib
from typing import Any

from mechsyn.errors import MechsynError, MechsynInputError

#: public name -> module that defines it (imported on first use)
_LAZY: dict[str, str] = {
    # files
    "load": "mechsyn.io.load", "loads": "mechsyn.io.load", "save": "mechsyn.io.load",
    "load_mechanism": "mechsyn.io.load", "Mechanism": "mechsyn.model.mechanism",
    # structure
    "analyze": "mechsyn.structure.report", "StructureReport": "mechsyn.structure.report",
    "analyze_structure": "mechsyn.structure.analysis", "analyze_rank": "mechsyn.structure.rank",
    "find_remedies": "mechsyn.structure.remedies",
    # kinematics
    "simulate": "mechsyn.kinematics.analysis", "input_grid": "mechsyn.kinematics.analysis",
    "Simulation": "mechsyn.kinematics.analysis",
    # kinetostatics
    "forces": "mechsyn.kinetostatics.analysis", "ForceAnalysis": "mechsyn.kinetostatics.analysis",
    # capability (paper 004)
    "SerialArm": "mechsyn.capability.arm", "load_arm": "mechsyn.capability.arm_file",
    "capability_map": "mechsyn.capability.maps", "CapabilityMap": "mechsyn.capability.maps",
    "capability_at": "mechsyn.capability.point", "PointCapability": "mechsyn.capability.point",
    # synthesis
    "synthesize_chains": "mechsyn.synthesis.chains", "synthesize_fingers": "mechsyn.synthesis.finger.candidates",
    "design_finger": "mechsyn.synthesis.finger.design", "synthesize_path": "mechsyn.synthesis.optimize",
    "synthesize_mechanism": "mechsyn.synthesis.general", "motion_synthesis": "mechsyn.synthesis.exact",
    # paper 001's belt manipulator
    "BeltDesign": "mechsyn.belt.design", "synthesize_belt": "mechsyn.belt.synthesis",
}
_SUBMODULES = ("examples", "plot", "io", "model", "structure", "kinematics", "capability", "synthesis",
               "belt")

__all__ = sorted([*_LAZY, *_SUBMODULES, "MechsynError", "MechsynInputError", "__version__"])


def __getattr__(name: str) -> Any:
    if name == "__version__":  # package metadata: read on first use (importlib.metadata is slow to import)
        from mechsyn._version import __version__ as value
    elif name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
    elif name in _SUBMODULES:
        value = importlib.import_module(f"mechsyn.{name}")
    else:
        raise AttributeError(f"module 'mechsyn' has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return list(__all__)
