"""mechsyn.plot: every figure of mechsyn, on Matplotlib.

The computing packages import no Matplotlib; their results draw themselves by calling
here (``sim.plot()``), and the command line saves what these functions return. Each
function draws on the ``ax=`` (one panel) or ``fig=`` (several panels) it is given, or on
a new pyplot figure, and returns it; none writes a file or chooses a backend.

- :mod:`mechsyn.plot.kinematics` -- a simulation: mechanism, point paths, speeds,
  reactions, an animation
- :mod:`mechsyn.plot.belt` -- paper 001's belt manipulator
- :mod:`mechsyn.plot.capability` -- velocity-capability maps (paper 004)
- :mod:`mechsyn.plot.synthesis` -- path, mechanism and Burmester motion synthesis
- :mod:`mechsyn.plot.curves` -- curve synthesis: target and traced paths
- :mod:`mechsyn.plot.atlas` -- atlases of kinematic chains
- :mod:`mechsyn.plot.finger` -- paper 000's fingers and finger designs

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
.. [3] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import importlib
from typing import Any

_WHERE = {
    "animate_simulation": "kinematics", "draw_mechanism": "kinematics", "plot_forces": "kinematics",
    "plot_paths": "kinematics", "plot_simulation": "kinematics",
    "animate_belt": "belt", "draw_belt": "belt", "plot_belt": "belt", "plot_belt_report": "belt",
    "plot_capability_map": "capability",
    "plot_fourbar_path": "synthesis", "plot_mechanism_synthesis": "synthesis",
    "plot_motion_synthesis": "synthesis",
    "draw_chain": "atlas", "plot_atlas": "atlas",
    "plot_candidate": "curves", "plot_curve_result": "curves",
    "plot_finger_design": "finger", "plot_fingers": "finger", "sketch_mechanism": "finger",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(importlib.import_module(f"mechsyn.plot.{_WHERE[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'mechsyn.plot' has no attribute {name!r}")


def __dir__() -> list[str]:
    return list(__all__)
