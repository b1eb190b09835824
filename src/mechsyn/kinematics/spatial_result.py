"""The result of spatial kinematics (:func:`mechsyn.kinematics.spatial.simulate_spatial`):
the :class:`~mechsyn.kinematics.analysis.Simulation` interface (``point``, ``link``,
``to_dict``, a summary, a table, ``plot``, ``animate``) for motions in 3-D.

Units: inputs in degrees (R, H) or the file's length unit (P), measured from the drawn
assembly; link rotations as matrices, angular velocities in rad/s, angular accelerations
in rad/s^2; points in the file's length unit (per s, per s^2).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn.kinematics.simulation import Motion, PointMotion

__all__ = ["SpatialSimulation", "LinkPose"]


@dataclass
class LinkPose:
    """A link's displacement from the drawn assembly, ``x = rotation @ x0 + translation``,
    and its angular velocity and acceleration (rad/s, rad/s^2), each over the sweep."""

    rotation: np.ndarray              # (N, 3, 3)
    translation: np.ndarray           # (N, 3)
    angular_velocity: np.ndarray      # (N, 3)
    angular_acceleration: np.ndarray  # (N, 3)

    def to_dict(self) -> dict[str, Any]:
        return {"rotation": self.rotation, "translation": self.translation,
                "angular_velocity": self.angular_velocity, "angular_acceleration": self.angular_acceleration}


def _unit(t: str) -> str:
    return "length" if t == "P" else "deg"


@dataclass(repr=False, kw_only=True)
class SpatialSimulation(Motion):
    """Motion of a spatial mechanism over a sweep of its drives.

    ``s.point("P")`` gives (N, 3) positions, ``s.link("platform").rotation`` (N, 3, 3)
    rotations, ``s.joints["R2"]`` the rotation (deg) or slide of a pair from the drawn
    assembly (a C or H pair's slide under ``"<id>/slide"``), ``s.residual`` the closure residual of every row in units of
    ``s.length_scale``; ``print(s)`` a summary, ``s.table()`` the points row by row,
    ``s.plot()`` a 3-D view, ``s.animate()`` the motion.

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = ms.simulate(ms.examples.load("bennett"), {"R1": ms.input_grid(0, 360, 10)})
    >>> s.engine, s.point("R2").shape, int(s.assembled.sum())
    ('spatial', (37, 3), 37)
    """

    _plot = "spatial:plot_spatial"

    links: dict[str, LinkPose]
    joints: dict[str, np.ndarray]
    residual: np.ndarray
    singular_ratio: np.ndarray
    length_scale: float
    rank: int
    idle: int
    engine: str = "spatial"
    method: str = "spatial continuation"
    model: Any = field(default=None, repr=False, metadata={"json": False})

    def _summary(self) -> list[tuple[str, str]]:
        x = self.inputs[self.main_input]
        unit = _unit(self.input_types[self.main_input])
        ok = self.assembled
        res = float(np.nanmax(self.residual)) if ok.any() else float("nan")
        rows = [("mechanism", self.mechanism), ("engine", f"{self.engine} ({self.method})"),
                ("input", f"{self.main_input}: {len(x)} values, {x[0]:g} to {x[-1]:g} {unit} from the drawn assembly"
                 if len(x) else "none"),
                ("assembled", f"{int(np.count_nonzero(ok))} of {len(ok)}"),
                ("closure", f"largest residual {res:.2g} of the length scale {self.length_scale:.4g}"),
                ("rank", f"{self.rank} (idle motions with the drives at rest: {self.idle})"),
                ("points", ", ".join(self.points) or "-"), ("links", ", ".join(self.links) or "-")]
        if self.events:
            rows.append(("events", "; ".join(f"{e['kind']} at row {e['index']}" for e in self.events[:6])
                         + (f"; {len(self.events) - 6} more" if len(self.events) > 6 else "")))
        rows += [("note", n) for n in self.notes]
        return rows

    def table(self, points: list[str] | None = None, rows: int = 13, width: int = 80) -> str:
        """Point positions at ``rows`` evenly spread inputs, as many points as fit ``width``
        (coordinates under ``1e-10`` of the length scale print as 0)."""
        x = self.inputs[self.main_input]
        names = list(points or sorted(self.points, key=lambda n: -self._travel(n)))
        cols: list[tuple[str, np.ndarray]] = []
        for name in names:
            if 8 + 11 * (len(cols) + 3) > width:
                break
            P = np.where(np.abs(self.point(name)) < 1e-10 * self.length_scale, 0.0, self.point(name))
            cols += [(f"{name}.{c}", P[:, k]) for k, c in enumerate("xyz")]
        ks = np.unique(np.linspace(0, len(x) - 1, min(rows, len(x))).round().astype(int))
        head = f"{self.main_input} {_unit(self.input_types[self.main_input])}"
        lines = [f"{head:>8}" + "".join(f" {h:>10}" for h, _ in cols)]
        for k in ks:
            vals = "".join(f" {'-':>10}" if not np.isfinite(v[k]) else f" {v[k]:>10.4g}" for _, v in cols)
            lines.append(f"{x[k]:>8.4g}" + vals)
        shown = len(cols) // 3
        if len(ks) < len(x) or shown < len(names):
            lines.append(f"({len(ks)} of {len(x)} rows, {shown} of {len(names)} points; --json or --csv for all)")
        return "\n".join(lines)

    def _travel(self, name: str) -> float:
        """How far point ``name`` moves over the sweep (the diagonal of its path's box)."""
        P = self.point(name)[self.assembled]
        return float(np.linalg.norm(np.ptp(P, axis=0))) if len(P) else 0.0

    def csv(self) -> str:
        """Every row: the inputs, assembled, residual, every point's x, y, z."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow([f"input_{j}" for j in self.inputs] + ["assembled", "residual"]
                   + [f"{n}_{c}" for n in self.points for c in "xyz"])
        for k in range(len(self.assembled)):
            row = [repr(float(v[k])) for v in self.inputs.values()] + [int(self.assembled[k])]
            row.append("" if not np.isfinite(self.residual[k]) else repr(float(self.residual[k])))
            for pm in self.points.values():
                row += ["" if not np.isfinite(c) else repr(float(c)) for c in pm.position[k]]
            w.writerow(row)
        return buf.getvalue()

    def to_dict(self) -> dict[str, Any]:
        ok = self.assembled

        def mask(a: np.ndarray) -> list:
            return [v if good else None for v, good in zip(np.asarray(a, float).tolist(), ok)]

        main = self.main_input
        return {
            "mechanism": self.mechanism, "engine": self.engine, "method": self.method,
            "input": {"joint": main, "values": self.inputs[main], "unit": _unit(self.input_types[main]),
                      "speed": self.speeds[main]},
            "inputs": {j: {"values": v, "type": self.input_types[j], "unit": _unit(self.input_types[j]),
                           "speed": self.speeds[j]} for j, v in self.inputs.items()},
            "assembled": ok,
            "points": {n: {k: mask(v) for k, v in pm.to_dict().items()} for n, pm in self.points.items()},
            "links": {n: {k: mask(v) for k, v in lp.to_dict().items()} for n, lp in self.links.items()},
            "joints": {j: mask(v) for j, v in self.joints.items()}, "working_ranges": self.working_ranges(),
            "residual": mask(self.residual), "length_scale": self.length_scale,
            "rank": self.rank, "idle": self.idle, "events": self.events, "notes": self.notes,
            "units": {"input": "deg (R, H) or length (P) from the drawn assembly", "angular_velocity": "rad/s",
                      "angular_acceleration": "rad/s^2", "residual": "fraction of length_scale"},
        }

    def animate(self, fig: Any = None, **kwargs: Any) -> Any:
        """The mechanism moving over the sweep in 3-D: a Matplotlib ``FuncAnimation``."""
        from mechsyn.plot.spatial import animate_spatial

        return animate_spatial(self, fig=fig, **kwargs)
