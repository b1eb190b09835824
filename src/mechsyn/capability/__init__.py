"""mechsyn.capability: velocity capability of serial arms under joint speed limits.

Paper 004 (mobility of a redundant planar manipulator), done exactly and vectorised:

* :mod:`~mechsyn.capability.arm` -- forward kinematics, Jacobians, inverse kinematics
  over the self-motion;
* :mod:`~mechsyn.capability.arm_file` -- arm files (planar_serial, dh, urdf), validated
  with pydantic (imported on first use of ``load_arm`` or ``arm_from_dict``);
* :mod:`~mechsyn.capability.measures` -- exact directional speed limit (closed form over
  the velocity zonotope), largest component, minimum-norm limit, the paper's stepping,
  velocity polytope and ellipse;
* :mod:`~mechsyn.capability.maps` -- best configuration over the self-motion, maps over
  grids, interpolation of the optimal configuration (figures: :mod:`mechsyn.plot.capability`).

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from mechsyn.capability.arm import SerialArm, ik_numeric, ik_planar_3r
from mechsyn.capability.maps import (
    CapabilityMap, capability_map, continuous_best, interpolate_configuration,
    measure_gradient, measure_values, refine_over_self_motion, self_motion,
)
from mechsyn.capability.measures import (
    MEASURES, VelocityEllipse, VelocityPolytope, all_measures, component_limit,
    exact_limit, exact_limit_lp, min_norm_limit, min_norm_rates, optimal_rates, stepped_limit,
    velocity_ellipse, velocity_polytope,
)

__all__ = [
    "SerialArm", "arm_from_dict", "ik_numeric", "ik_planar_3r", "load_arm",
    "CapabilityMap", "capability_map", "continuous_best", "interpolate_configuration",
    "measure_gradient", "measure_values", "refine_over_self_motion", "self_motion",
    "MEASURES", "VelocityEllipse", "VelocityPolytope", "all_measures", "component_limit",
    "exact_limit", "exact_limit_lp", "min_norm_limit", "min_norm_rates", "optimal_rates", "stepped_limit",
    "velocity_ellipse", "velocity_polytope",
]


def __getattr__(name: str):
    """``load_arm`` and ``arm_from_dict`` load the file module (and pydantic) on first use."""
    if name in ("load_arm", "arm_from_dict"):
        from mechsyn.capability import arm_file

        return getattr(arm_file, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
