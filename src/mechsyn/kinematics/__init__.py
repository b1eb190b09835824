"""Kinematics: positions, velocities and accelerations of planar and spatial mechanisms
(their forces: :mod:`mechsyn.kinetostatics`).

Modules, from the entry points down (docs/architecture.md):

* ``analysis``: :func:`simulate` (``method="auto"`` or an engine's name), the compiled
  plan and its cache;
* ``engines``: ``ENGINES`` (every engine by a unique name), the ``Engine`` protocol and the
  planar engines tried in order (regular pass, tracked chain, tracked groups, Newton), the
  spatial engine last; ``sweep``: ``Sweep`` and ``Event``; ``simulation``: ``Motion``, the
  result every engine fills (``Simulation`` planar, ``SpatialSimulation`` in 3-D);
* ``regular`` (one-pass regular sweep), ``tracking`` (assembly modes through folds and
  change points), ``chain`` (driver-R + RRR chains, closed-form rates), ``positions``
  (generic group steps), ``groups`` (plan, decomposition, the RRR kernel),
  ``solve`` (Newton continuation, assembly, mobility), ``system`` (link poses,
  constraint equations, analytic and dimensionless Jacobian, batched rates);
* ``batch`` (many designs of one topology), ``derived``
  (transmission angle, mechanical advantage, Grashof, path extent, straightness),
  ``report``; ``dyads`` keeps the Assur-group names for callers outside the package.

Paper 001's belt drive is :mod:`mechsyn.belt`. Figures and the animation:
:mod:`mechsyn.plot.kinematics`.

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from typing import Any

__all__ = ["simulate", "input_grid", "compile_plan", "cached_plan", "KinematicPlan", "Motion", "Simulation",
           "ENGINES"]


def __getattr__(name: str) -> Any:  # lazy: importing the package stays cheap
    if name in __all__:
        from mechsyn.kinematics import analysis

        return getattr(analysis, name)
    raise AttributeError(name)
