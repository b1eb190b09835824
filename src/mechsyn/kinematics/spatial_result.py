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

from mechsyn.kinematics.simulation import Motion, rows
from mechsyn.results import csv_cell

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


def rotation_vectors(R: np.ndarray) -> np.ndarray:
    """Rotation vectors (N, 3; axis times angle in deg, the angle in [0, 180]) of rotations
    ``R`` (N, 3, 3); NaN rows stay NaN. The angle is ``atan2(sin θ, cos θ)`` from the skew
    part and the trace; the axis is the skew part's direction up to a quarter turn and,
    beyond it, the leading column of ``(R + Rᵀ)/2 - cos θ I = (1 - cos θ) a aᵀ`` signed by the
    skew part (accurate up to the half turn).

    Examples
    --------
    >>> c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    >>> np.round(rotation_vectors(np.array([[[c, -s, 0], [s, c, 0], [0, 0, 1.0]]])), 9).tolist()
    [[0.0, 0.0, 30.0]]
    """
    R = np.asarray(R, float)
    v = np.stack([R[:, 2, 1] - R[:, 1, 2], R[:, 0, 2] - R[:, 2, 0], R[:, 1, 0] - R[:, 0, 1]], axis=1)
    c = 0.5 * (np.trace(R, axis1=1, axis2=2) - 1)
    sn = 0.5 * np.linalg.norm(v, axis=1)
    ang = np.arctan2(sn, c)
    out = np.zeros_like(v)
    with np.errstate(invalid="ignore", divide="ignore"):
        small = c >= 0
        out[small] = v[small] / np.where(sn[small] > 0, 2 * sn[small], 1.0)[:, None]
        big = (c < 0)
        if big.any():
            B = 0.5 * (R[big] + np.swapaxes(R[big], 1, 2)) - c[big, None, None] * np.eye(3)
            r = np.arange(int(big.sum()))
            k = np.argmax(np.diagonal(B, axis1=1, axis2=2), axis=1)
            a = B[r, :, k]
            a = a / np.linalg.norm(a, axis=1)[:, None]
            out[big] = a * np.where((a * v[big]).sum(axis=1) < 0, -1.0, 1.0)[:, None]
    out = out * ang[:, None]
    out[~np.isfinite(c)] = np.nan
    return np.degrees(out)


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
    #: how each row was reached: 0 not, 1 moving from the drawn assembly, 2 the same going the
    #: other way round (the R input modulo 360), 3 by re-assembly (another assembly)
    reached: np.ndarray | None = None
    #: the drives held at their drawn value (driven in the file, no input given)
    held: tuple[str, ...] = ()
    #: per input joint, its value at the drawn assembly (deg, length): the input's zero is the
    #: joint's zero (see the file format), so the drawn assembly is at this value
    zero: dict[str, float] = field(default_factory=dict)

    def working_ranges(self) -> list[list[float]]:
        """Runs of consecutive assembled rows as ``[first, last]`` values of the main input,
        each end at a dead point refined to ``1e-6`` of the step (the event's input)."""
        vals = self.inputs[self.main_input]
        ok = np.asarray(self.assembled, bool)
        ends = {(e["last"], e["index"]): float(e["input"][self.main_input]) for e in self.events
                if e["kind"] == "dead point" and "last" in e}
        out, k, N = [], 0, len(ok)
        while k < N:
            if not ok[k]:
                k += 1
                continue
            j = k
            while j + 1 < N and ok[j + 1]:
                j += 1
            out.append([ends.get((k, k - 1), float(vals[k])), ends.get((j, j + 1), float(vals[j]))])
            k = j + 1
        return out

    def _summary(self) -> list[tuple[str, str]]:
        ok = self.assembled
        res = float(np.nanmax(self.residual)) if ok.any() else float("nan")
        rows = [("mechanism", self.mechanism), ("engine", f"{self.engine} ({self.method})")]
        for j, x in self.inputs.items():
            unit = _unit(self.input_types[j])
            zero = self.zero.get(j, 0.0)
            frm = "from the drawn assembly" if zero == 0.0 else f"drawn at {zero:.6g}"
            rows.append(("input", f"{j}: {len(x)} values, {x[0]:.6g} to {x[-1]:.6g} {unit} ({frm}), "
                                  f"speed {self.speeds[j]:g}" if len(x) else f"{j}: none"))
        if self.held:
            rows.append(("held", ", ".join(self.held) + " (driven in the file, no input: at the drawn value)"))
        unit = _unit(self.input_types[self.main_input])
        wr = self.working_ranges()
        rows += [("assembled", f"{int(np.count_nonzero(ok))} of {len(ok)}"),
                 ("working range", "; ".join(f"{a:.7g} to {b:.7g}" for a, b in wr) + f" {unit} ({self.main_input})"
                  if wr else "none"),
                 ("closure", f"largest residual {res:.2g} of the length scale {self.length_scale:.4g}"),
                 ("rank", f"{self.rank} (idle motions with the drives at rest: {self.idle})"),
                 ("joints", ", ".join(self.joints) or "-"),
                 ("points", ", ".join(self.points) or "-"), ("links", ", ".join(self.links) or "-")]
        if self.events:
            main = self.main_input
            rows.append(("events", "; ".join(f"{e['kind']} at {main}={e['input'][main]:.7g}" for e in self.events[:6])
                         + (f"; {len(self.events) - 6} more" if len(self.events) > 6 else "")))
        rows += [("note", n) for n in self.notes]
        return rows

    def table(self, points: list[str] | None = None, rows: int = 13, width: int = 80) -> str:
        """The joint values (deg, lengths), then point positions, at ``rows`` evenly spread
        inputs, as many columns as fit ``width`` (coordinates under ``1e-10`` of the length
        scale print as 0; link orientations and rates are in ``--csv`` and ``--json``)."""
        x = self.inputs[self.main_input]
        fit = max(1, (width - 8) // 11)
        cols: list[tuple[str, np.ndarray]] = [(j, v) for j, v in self.joints.items() if j != self.main_input][:fit]
        njoints = len(cols)
        names = list(points or sorted(self.points, key=lambda n: -self._travel(n)))
        shown = 0
        for name in names:
            if len(cols) + 3 > fit:
                break
            P = np.where(np.abs(self.point(name)) < 1e-10 * self.length_scale, 0.0, self.point(name))
            cols += [(f"{name}.{c}", P[:, k]) for k, c in enumerate("xyz")]
            shown += 1
        ks = np.unique(np.linspace(0, len(x) - 1, min(rows, len(x))).round().astype(int))
        head = f"{self.main_input} {_unit(self.input_types[self.main_input])}"
        lines = [f"{head:>8}" + "".join(f" {h:>10}" for h, _ in cols)]
        for k in ks:
            vals = "".join(f" {'-':>10}" if not np.isfinite(v[k]) else f" {v[k]:>10.4g}" for _, v in cols)
            lines.append(f"{x[k]:>8.4g}" + vals)
        others = len([j for j in self.joints if j != self.main_input])
        if len(ks) < len(x) or shown < len(names) or njoints < others:
            lines.append(f"({len(ks)} of {len(x)} rows, {njoints} of {others} joints, {shown} of {len(names)} "
                         "points; --csv: all, link poses too)")
        return "\n".join(lines)

    def _travel(self, name: str) -> float:
        """How far point ``name`` moves over the sweep (the diagonal of its path's box)."""
        P = self.point(name)[self.assembled]
        return float(np.linalg.norm(np.ptp(P, axis=0))) if len(P) else 0.0

    def csv(self) -> str:
        """Every row: the inputs, assembled, how the row was reached (``reached``: see the
        field), residual, every joint value (``joint_<id>``: deg or length), every link's
        orientation as a rotation vector (``<link>_rx_deg`` ...: axis times angle from the
        drawn assembly, :func:`rotation_vectors`) and translation, every point's x, y, z."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        links = {n: (rotation_vectors(lp.rotation), lp.translation) for n, lp in self.links.items()}
        w.writerow([csv_cell(f"input_{j}") for j in self.inputs] + ["assembled", "reached", "residual"]
                   + [csv_cell(f"joint_{j}") for j in self.joints]
                   + [csv_cell(f"{n}_{c}") for n in links for c in ("rx_deg", "ry_deg", "rz_deg", "tx", "ty", "tz")]
                   + [csv_cell(f"{n}_{c}") for n in self.points for c in "xyz"])
        reached = self.reached if self.reached is not None else self.assembled.astype(int)

        def num(v: float) -> str:
            return "" if not np.isfinite(v) else repr(float(v))

        for k in range(len(self.assembled)):
            row = [repr(float(v[k])) for v in self.inputs.values()] + [int(self.assembled[k]), int(reached[k])]
            row.append(num(self.residual[k]))
            row += [num(v[k]) for v in self.joints.values()]
            for rv, t in links.values():
                row += [num(c) for c in rv[k]] + [num(c) for c in t[k]]
            for pm in self.points.values():
                row += [num(c) for c in pm.position[k]]
            w.writerow(row)
        return buf.getvalue()

    def input_unit(self, joint: str) -> str:
        """The unit of input ``joint``'s values: ``"length"`` (P) or ``"deg"`` (R, H, U)."""
        return _unit(self.input_types[joint])

    def to_dict(self, rates: bool = True) -> dict[str, Any]:
        """:meth:`Motion.to_dict` and the spatial fields: ``joints`` (every pair's value from
        its zero), ``residual``, ``length_scale``, ``rank``, ``idle``, ``reached``, ``held``,
        ``zero`` and the units."""
        ok = np.asarray(self.assembled, bool)
        return {
            **super().to_dict(rates),
            "joints": {j: rows(v, ok) for j, v in self.joints.items()},
            "residual": rows(self.residual, ok), "length_scale": float(self.length_scale),
            "rank": int(self.rank), "idle": int(self.idle),
            "reached": (self.reached if self.reached is not None else ok.astype(int)).tolist(),
            "held": list(self.held), "zero": {k: float(v) for k, v in self.zero.items()},
            "units": {"input": "deg (R, H, C/turn, U) from the joint's zero, or length (P, C)", "angular_velocity": "rad/s",
                      "angular_acceleration": "rad/s^2", "residual": "fraction of length_scale"},
        }

    def animate(self, fig: Any = None, **kwargs: Any) -> Any:
        """The mechanism moving over the sweep in 3-D: a Matplotlib ``FuncAnimation``."""
        from mechsyn.plot.spatial import animate_spatial

        return animate_spatial(self, fig=fig, **kwargs)
