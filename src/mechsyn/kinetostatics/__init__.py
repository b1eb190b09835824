"""Kinetostatics: the forces of a planar mechanism in motion, a chapter of its own after
structural and kinematic analysis (Artobolevsky, *Theory of Mechanisms and Machines*).

* ``reactions``: the joint reactions and the drives' balancing moments or forces of given
  poses, rates and accelerations (the constraint equations' Lagrange multipliers:
  :func:`~mechsyn.kinetostatics.reactions.kinetostatics`), the links' masses and the
  file's loads;
* ``analysis``: :func:`forces` over a sweep of the inputs (a kinematic simulation, then
  the reactions at every row), answered as a :class:`ForceAnalysis`.

It sits above :mod:`mechsyn.kinematics`, which it reads (the poses and rates of a sweep,
the constraint system) and which knows nothing of it.
"""

from typing import Any

__all__ = ["forces", "ForceAnalysis"]


def __getattr__(name: str) -> Any:  # lazy: importing the package stays cheap
    if name in __all__:
        from mechsyn.kinetostatics import analysis

        return getattr(analysis, name)
    raise AttributeError(name)
