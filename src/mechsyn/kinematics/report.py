"""The simulation report: a :class:`~mechsyn.kinematics.analysis.Simulation` with the
quantities a designer reads off it (transmission angles, mechanical advantage, Grashof's
class, path extents, straightness of a path segment).

``mechsyn simulate --json`` prints :meth:`SimulationReport.to_dict`. The CSV tables
(``--csv``) are files, not computing: a result's ``csv()``
(:meth:`~mechsyn.kinematics.simulation.Motion.csv`) writes its ``columns()`` with
:func:`mechsyn.results.csv_table`.

References
----------
Transmission angle, mechanical advantage and Grashof's criterion as in
J. J. Uicker, G. R. Pennock, J. E. Shigley, *Theory of Machines and Mechanisms*, 5th ed.,
Oxford University Press, 2017, ch. 1 and 3 (see :mod:`mechsyn.kinematics.derived`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import derived
from mechsyn.kinematics.analysis import Simulation, simulate
from mechsyn.kinematics.simulation import rows
from mechsyn.kinematics.summary import motion_summary
from mechsyn.model.mechanism import Mechanism
from mechsyn.progress import ProgressCallback
from mechsyn.results import to_jsonable

__all__ = ["SimulationReport", "simulation_report", "derived_quantities"]


@dataclass(repr=False)
class SimulationReport(Result):
    """A simulation and its derived quantities.

    ``derived`` holds, where they apply: ``transmission_angle`` (per dyad: values, min,
    max in degrees), ``mechanical_advantage`` (one input: output link and values),
    ``grashof`` (a four-bar of revolute pairs), ``extent`` (bounding box of each reported
    point's path), ``motion`` (planar: the sliders' strokes, the rockers' ranges and the time
    ratios, :func:`mechsyn.kinematics.summary.motion_summary`), ``slides`` (planar: every P
    joint's slide, its rate and acceleration) and ``straightness`` (per point asked for).
    Without the rates (``rates=False``) the mechanical advantage, the motion summary and the
    slides are left out.

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> from mechsyn.kinematics.report import simulation_report
    >>> r = simulation_report(ms.examples.load("crank_rocker"), {"A": np.linspace(0, 360, 13)})
    >>> r.derived["grashof"]["classification"]
    'crank-rocker'
    >>> sorted(r.to_dict())[:4]
    ['assembled', 'derived', 'engine', 'events']
    """

    simulation: Simulation = field(metadata={"json": False})
    derived: dict[str, Any] = field(default_factory=dict)
    #: whether the rates and the quantities made of them are in the report (``to_dict``)
    rates: bool = True

    def to_dict(self) -> dict[str, Any]:
        """The simulation's dict (:meth:`~mechsyn.kinematics.simulation.Motion.to_dict`) with
        the derived quantities under ``derived``: what ``mechsyn simulate --json`` prints and
        the studio draws."""
        return {**self.simulation.to_dict(self.rates), "derived": to_jsonable(self.derived)}

    def plot(self, ax: Any = None, **kwargs: Any) -> Any:
        """Draw the simulation (see :func:`mechsyn.plot.kinematics.plot_simulation`)."""
        return self.simulation.plot(ax=ax, **kwargs)


def _nan_stat(f: Any, values: np.ndarray) -> float | None:
    v = np.asarray(values, float)
    return None if not np.isfinite(v).any() else float(f(v))


def _straightness(sim: Simulation, straight: dict[str, tuple[float, float]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    x = sim.inputs[sim.main_input]
    for name, (a, b) in straight.items():
        if name not in sim.points:
            raise MechsynInputError(f"no reported point {name!r}", field="straight",
                                    hint=f"points: {', '.join(sim.points)}")
        sel = (x >= min(a, b)) & (x <= max(a, b))
        out[name] = {"range": [a, b], **derived.straightness(sim.points[name].position[sel])}
    return out


def derived_quantities(mech: Mechanism, sim: Simulation, output: str | None = None,
                       straight: dict[str, tuple[float, float]] | None = None, rates: bool = True) -> dict[str, Any]:
    """Transmission angles, mechanical advantage, Grashof's class, path extents, the
    sliders' slides and the straightness of path segments of ``sim`` (see
    :class:`SimulationReport`).

    ``output``: the output link of the mechanical advantage (default: the last link
    pivoted on the frame); ``straight``: point name -> (first, last) main input value;
    ``rates=False`` leaves out what is made of the rates (see :class:`SimulationReport`).

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> from mechsyn.kinematics.report import derived_quantities
    >>> m = ms.examples.load("crank_rocker")
    >>> d = derived_quantities(m, ms.simulate(m, {"A": np.linspace(0, 90, 4)}))
    >>> sorted(d)
    ['extent', 'grashof', 'mechanical_advantage', 'motion', 'transmission_angle']
    """
    out: dict[str, Any] = {}
    mu = derived.transmission_angles(sim)
    if mu:
        out["transmission_angle"] = {k: {"values": rows(v), "min": _nan_stat(np.nanmin, v),
                                         "max": _nan_stat(np.nanmax, v)} for k, v in mu.items()}
    out_link = output or derived.default_output_link(mech, list(sim.inputs))
    if rates and out_link is not None and len(sim.inputs) == 1:
        ma = derived.mechanical_advantage(sim, out_link)
        out["mechanical_advantage"] = {"output": out_link, "values": rows(ma)}
    if derived.is_fourbar(mech):
        out["grashof"] = to_jsonable(derived.grashof(mech))
    out["extent"] = {name: derived.path_extent(pm.position) for name, pm in sim.points.items()}
    if mech.kind == "planar" and rates:
        out["motion"] = motion_summary(mech, sim)
        slides = _slides(mech, sim)
        if slides:
            out["slides"] = slides
    if straight:
        out["straightness"] = _straightness(sim, straight)
    return out


def _slides(mech: Mechanism, sim: Simulation) -> dict[str, Any]:
    """Every P joint's slide along its guide, its rate and its acceleration
    (:func:`~mechsyn.kinematics.derived.slide`)."""
    if sim.system is None or sim.sweep is None:
        return {}
    out = {}
    for j in mech.joints:
        if j.type == "P":
            value, rate, acc = derived.slide(sim, j.id, acceleration=True)
            out[j.id] = {"guide": j.links[0], "value": rows(value), "rate": rows(rate), "acceleration": rows(acc)}
    return out


def simulation_report(mech: Mechanism, inputs: dict[str, np.ndarray], *, speeds: dict[str, float] | None = None,
                      points: list[str] | None = None, vll: dict[str, str] | None = None, method: str = "auto",
                      output: str | None = None, straight: dict[str, tuple[float, float]] | None = None,
                      progress: ProgressCallback | None = None, rates: bool = True) -> SimulationReport:
    """Simulate ``mech`` over ``inputs`` (see :func:`mechsyn.simulate`) and derive what a
    designer reads off the motion (see :func:`derived_quantities`).

    Parameters
    ----------
    mech : Mechanism
        The mechanism, with joint points.
    inputs : dict of str to ndarray
        Driven joint id -> values (degrees for R, length for P), all of one length.
    speeds, points, vll, method, progress
        As for :func:`mechsyn.simulate`.
    output : str, optional
        Output link of the mechanical advantage.
    straight : dict of str to (float, float), optional
        Point name -> the main input's range over which to measure straightness.
    rates : bool, default True
        False leaves the rates and what is made of them out of the report (a smaller
        answer, the studio's drag).

    Returns
    -------
    SimulationReport

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> from mechsyn.kinematics.report import simulation_report
    >>> r = simulation_report(ms.examples.load("crank_rocker"), {"A": np.linspace(0, 90, 4)})
    >>> r.simulation.link("crank").angle.round(6).tolist()
    [0.0, 30.0, 60.0, 90.0]
    """
    sim = simulate(mech, inputs, speeds=speeds, points=points, vll=vll, method=method, progress=progress)
    return SimulationReport(sim, derived_quantities(mech, sim, output, straight, rates), rates)
