"""Kinetostatic analysis over a sweep: :func:`forces` simulates the mechanism
(:func:`mechsyn.kinematics.analysis.simulate`) and solves the joint reactions and the
drives' balancing efforts at every row (:func:`mechsyn.kinetostatics.reactions.kinetostatics`),
answered as a :class:`ForceAnalysis`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import Simulation, simulate
from mechsyn.kinetostatics.reactions import Reactions, kinetostatics
from mechsyn.model.mechanism import Mechanism
from mechsyn.progress import ProgressCallback
from mechsyn.results import csv_table

__all__ = ["ForceAnalysis", "forces"]


@dataclass(repr=False)
class ForceAnalysis(Result):
    """Joint reactions and balancing efforts over the sweep (see :mod:`mechsyn.kinetostatics.reactions`).

    Examples
    --------
    >>> import mechsyn as ms
    >>> f = ms.examples.load("crank_rocker").forces(A=(0, 360, 90), gravity=(0, -9.81))
    >>> sorted(f.reactions.force), f.reactions.effort_kind["A"]
    (['A', 'B', 'C', 'D'], 'moment')
    """

    _plot = "kinematics:plot_forces"

    def _summary(self) -> list[tuple[str, str]]:
        sim, r = self.simulation, self.reactions
        return [("mechanism", sim.mechanism), ("analysis", "static" if self.static else "kinetostatic"),
                ("gravity", f"({self.gravity[0]:g}, {self.gravity[1]:g})"),
                ("assembled", f"{int(np.count_nonzero(sim.assembled))} of {len(sim.assembled)}"),
                ("joints", ", ".join(r.force) or "-"),
                ("drives", ", ".join(f"{j} ({r.effort_kind[j]})" for j in r.effort) or "-")]

    simulation: Simulation
    reactions: Reactions
    gravity: tuple[float, float]
    static: bool

    def to_dict(self) -> dict[str, Any]:
        sim = self.simulation
        ok = sim.assembled

        def mask(a: np.ndarray) -> list:
            out = np.asarray(a, float).tolist()
            return [v if good else None for v, good in zip(out, ok)]

        main = sim.main_input
        r = self.reactions
        return {
            "mechanism": sim.mechanism,
            "input": {"joint": main, "values": sim.inputs[main], "unit": sim.input_unit(main),
                      "speed": sim.speeds[main]},
            "assembled": ok,
            "static": self.static,
            "gravity": list(self.gravity),
            "joints": {j: {"force": mask(r.force[j]), "magnitude": mask(np.linalg.norm(r.force[j], axis=1)),
                           "moment": mask(r.moment[j])} for j in r.force},
            "drives": {j: {"kind": r.effort_kind[j], "value": mask(r.effort[j])} for j in r.effort},
            "indeterminate": r.indeterminate,
            **({"belts": {j: {"tension": mask(t)} for j, t in r.tension.items()}} if r.tension else {}),
            "notes": self.notes(),
            "events": [e.to_dict() for e in sim.events],
            "method": sim.method,
            "convention": "force: exerted by the joint's first link on its second; drive value: moment (R) "
                          "or force (P) the actuator applies to the second link",
        }


    def columns(self) -> dict[str, np.ndarray]:
        """The inputs, ``assembled``, each joint's reaction (``A_Fx``, ``A_Fy``, ``A_F``
        = |F|, ``A_M``) and each drive's balancing effort, one row per input value."""
        R = self.reactions
        cols = self.simulation.columns(motion=False)
        for j, F in R.force.items():
            cols.update({f"{j}_Fx": F[:, 0], f"{j}_Fy": F[:, 1], f"{j}_F": np.linalg.norm(F, axis=1),
                         f"{j}_M": R.moment[j]})
        for j, e in R.effort.items():
            cols[f"drive_{j}_{R.effort_kind[j]}"] = e
        return cols

    def csv(self) -> str:
        """:meth:`columns` as a CSV table (:func:`mechsyn.results.csv_table`): what
        ``mechsyn forces --csv`` writes.

        Examples
        --------
        >>> import mechsyn as ms
        >>> f = ms.forces(ms.examples.load("crank_rocker"), {"A": ms.input_grid(0, 90, 45)}, static=True)
        >>> f.csv().splitlines()[0].split(",")[:4]
        ['input_A', 'assembled', 'A_Fx', 'A_Fy']
        """
        return csv_table(self.columns())

    def notes(self) -> list[str]:
        """Warnings on the result: belts that would have to push (they go slack)."""
        out = []
        sim = self.simulation
        main = sim.main_input
        lam = self.reactions.lam
        scale = float(np.nanmax(np.abs(lam))) if lam is not None and np.isfinite(lam).any() else 0.0
        for j, t in self.reactions.tension.items():
            bad = np.flatnonzero(sim.assembled & (np.nan_to_num(t) < -1e-9 * scale))
            if len(bad):
                vals = np.asarray(sim.inputs[main], float)[bad]
                out.append(f"belt {j} is in compression (a belt can only pull: it goes slack) at {len(bad)} "
                           f"of the inputs, {main} from {vals.min():g} to {vals.max():g}")
        return out


def forces(mech: Mechanism, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None = None,
           gravity: tuple[float, float] = (0.0, 0.0), static: bool = False, vll: dict[str, str] | None = None,
           method: str = "auto", progress: ProgressCallback | None = None) -> ForceAnalysis:
    """Kinetostatic (or static) analysis over a sweep of the inputs.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("crank_rocker")
    >>> f = ms.forces(m, {"A": ms.input_grid(0, 90, 45)}, static=True, gravity=(0, -9.81))
    >>> f.reactions.effort["A"].shape
    (3,)
    """
    if mech.kind == "spatial":  # spatial kinematics exists, spatial forces do not yet
        raise MechsynInputError("force analysis needs a planar mechanism", source=mech.source, field="kind",
                                hint="simulate gives the motion of a spatial file; forces are computed for planar files only")
    sim = simulate(mech, inputs, speeds=speeds, points=[], vll=vll, method=method, progress=progress)
    sw = sim.sweep
    R = kinetostatics(sim.system, sw.q, None if static else sw.qd, None if static else sw.qdd,
                      gravity=gravity)
    return ForceAnalysis(sim, R, tuple(float(g) for g in gravity), static)
