"""mechsyn: structural analysis, kinematics and synthesis of mechanisms.

Subpackages, one per concept:

- :mod:`mechsyn.model`      links, kinematic pairs, the mechanism graph
- :mod:`mechsyn.io`         the mechanism file format (YAML/JSON), validation
- :mod:`mechsyn.structure`  mobility formulas, per-contour analysis, remedies
- :mod:`mechsyn.kinematics` planar positions, velocities, accelerations, forces
- :mod:`mechsyn.capability` velocity capability of redundant manipulators
- :mod:`mechsyn.synthesis`  structural and dimensional synthesis
- :mod:`mechsyn.cli`        the ``mechsyn`` command line (a thin layer)
"""

__version__ = "0.1.0"

from mechsyn.errors import MechsynError, MechsynInputError  # noqa: E402

__all__ = ["MechsynError", "MechsynInputError", "__version__"]
