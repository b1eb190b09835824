"""Planar kinematics and force analysis.

Modules: ``analysis`` (:func:`simulate`, :func:`forces`: the entry points), ``system``
(link poses and constraint equations, analytic Jacobian), ``solve`` (Newton continuation,
velocities, accelerations), ``dyads`` (closed-form Assur dyads, vectorised), ``forces``
(kinetostatics), ``derived`` (transmission angle, mechanical advantage, Grashof, path
extent, straightness). Paper 001's belt drive is :mod:`mechsyn.belt`. Figures and the
animation: :mod:`mechsyn.plot.kinematics`.

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from typing import Any

__all__ = ["simulate", "forces", "input_grid", "compile_plan", "cached_plan", "KinematicPlan"]


def __getattr__(name: str) -> Any:  # lazy: importing the package stays cheap
    if name in __all__:
        from mechsyn.kinematics import analysis

        return getattr(analysis, name)
    raise AttributeError(name)
