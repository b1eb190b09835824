"""The result of spatial kinematics (:func:`mechsyn.kinematics.spatial.simulate_spatial`):
the :class:`~mechsyn.kinematics.analysis.Simulation` interface (``point``, ``link``,
``to_dict``, a summary, a table, ``plot``, ``animate``) for motions in 3-D.

Units: inputs in degrees (R, H) or the file's length unit (P), measured from the drawn
assembly; link rotations as matrices, angular velocities in rad/s, angular accelerations
in rad/s^2; points in the file's length unit (per s, per s^2).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn.kinematics.simulation import Motion, rows

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
    ``R`` (N, 3, 3) by SciPy's :class:`~scipy.spatial.transform.Rotation` (through the
    quaternion: accurate up to the half turn); NaN rows stay NaN.

    Examples
    --------
    >>> c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    >>> np.round(rotation_vectors(np.array([[[c, -s, 0], [s, c, 0], [0, 0, 1.0]]])), 9).tolist()
    [[0.0, 0.0, 30.0]]
    """
    from scipy.spatial.transform import Rotation  # (lazy: a sweep does not need it)

    R = np.asarray(R, float)
    out = np.full((len(R), 3), np.nan)
    ok = np.isfinite(R).all(axis=(1, 2))
    if ok.any():
        out[ok] = Rotation.from_matrix(R[ok]).as_rotvec(degrees=True)
    return out


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
    _animate = "spatial:animate_spatial"

    links: dict[str, LinkPose]
    joints: dict[str, np.ndarray]
    residual: np.ndarray
    singular_ratio: np.ndarray
    length_scale: float
    rank: int
    idle: int
    #: how each row was reached: 0 not, 1 moving from the drawn assembly, 2 the same going the
    #: other way round (the R input modulo 360), 3 by re-assembly (another assembly)
    reached: np.ndarray
    engine: str = "spatial"
    method: str = "spatial continuation"
    model: Any = field(default=None, repr=False, metadata={"json": False})
    #: the drives held at their drawn value (driven in the file, no input given)
    held: tuple[str, ...] = ()
    #: per input joint, its value at the drawn assembly (deg, length): the input's zero is the
    #: joint's zero (see the file format), so the drawn assembly is at this value
    zero: dict[str, float] = field(default_factory=dict)

    def _summary(self) -> list[tuple[str, str]]:
        ok = self.assembled
        res = float(np.nanmax(self.residual)) if ok.any() else float("nan")
        rows = [("mechanism", self.mechanism), ("engine", f"{self.engine} ({self.method})")]
        for j, x in self.inputs.items():
            unit = self.input_unit(j)
            zero = self.zero.get(j, 0.0)
            frm = "from the drawn assembly" if zero == 0.0 else f"drawn at {zero:.6g}"
            rows.append(("input", f"{j}: {len(x)} values, {x[0]:.6g} to {x[-1]:.6g} {unit} ({frm}), "
                                  f"speed {self.speeds[j]:g}" if len(x) else f"{j}: none"))
        if self.held:
            rows.append(("held", ", ".join(self.held) + " (driven in the file, no input: at the drawn value)"))
        unit = self.input_unit(self.main_input)
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
        head = f"{self.main_input} {self.input_unit(self.main_input)}"
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

    def columns(self, motion: bool = True) -> dict[str, np.ndarray]:
        """:meth:`Motion.columns` (a link's translation and rates by component), then how
        each row was reached (``reached``: see the field), the residual, every joint value
        (``joint_<id>``: deg or length) and every link's orientation as a rotation vector
        (``<link>_rx_deg`` ...: axis times angle from the drawn assembly,
        :func:`rotation_vectors`)."""
        cols = super().columns(motion)
        cols.update(reached=self.reached, residual=self.residual)
        cols.update({f"joint_{j}": v for j, v in self.joints.items()})
        for name, lp in self.links.items() if motion else ():
            cols.update(zip((f"{name}_r{c}_deg" for c in "xyz"), rotation_vectors(lp.rotation).T))
        return cols

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
            "reached": self.reached.tolist(),
            "held": list(self.held), "zero": {k: float(v) for k, v in self.zero.items()},
            "units": {"input": "deg (R, H, C/turn, U) from the joint's zero, or length (P, C)", "angular_velocity": "rad/s",
                      "angular_acceleration": "rad/s^2", "residual": "fraction of length_scale"},
        }
