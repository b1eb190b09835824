"""The result of a kinematic simulation: :class:`Simulation` (every link's angle and rates,
every named point's position and rates over the input values, the events of the sweep),
its parts (:class:`PointMotion`, :class:`LinkMotion`) and the input helpers shared by the
planar and spatial engines (:func:`input_grid`, :func:`resolve_points`).

Kept apart from :mod:`mechsyn.kinematics.analysis` (which runs the engines) so that every
engine, planar or spatial, can build its result without importing the entry point.
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.sweep import Event, Sweep
from mechsyn.limits import limit, limit_hint
from mechsyn.model.mechanism import Mechanism
from mechsyn.results import csv_table

if TYPE_CHECKING:
    from mechsyn.kinematics.system import PlanarSystem

__all__ = ["Motion", "Simulation", "PointMotion", "LinkMotion", "input_grid", "resolve_points", "rows", "is_full_turn"]


@dataclass
class PointMotion:
    position: np.ndarray       # (N, 2)
    velocity: np.ndarray
    acceleration: np.ndarray
    link: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"position": self.position, "velocity": self.velocity, "acceleration": self.acceleration}


@dataclass
class LinkMotion:
    angle: np.ndarray                 # (N,) degrees
    angular_velocity: np.ndarray      # rad/s
    angular_acceleration: np.ndarray  # rad/s^2

    def to_dict(self) -> dict[str, Any]:
        return {"angle": self.angle, "angular_velocity": self.angular_velocity,
                "angular_acceleration": self.angular_acceleration}


@dataclass(repr=False, kw_only=True)
class Motion(Result):
    """What every engine's simulation is (a sweep of the inputs): the inputs, the rows
    where the mechanism is assembled, the named points' and the links' motion, the events
    of the sweep, the engine that ran and its notes.

    Which class fills which field:

    ======================  ==============================  ===============================
    field                   :class:`Simulation` (planar)    ``SpatialSimulation`` (spatial)
    ======================  ==============================  ===============================
    ``points``              (N, 2) positions and rates      (N, 3)
    ``links``               :class:`LinkMotion` (angle)     ``LinkPose`` (rotation matrix)
    ``events``              :class:`~mechsyn.kinematics.sweep.Event`, both
    ``method``              ``"assur"`` or ``"newton"``     ``"spatial continuation"``
    extra fields            ``vll``, ``sweep``, ``system``  ``joints``, ``residual``, ...
    ======================  ==============================  ===============================

    Inputs are in degrees (R) or the file's length unit (P), an input value the same pose
    in every engine; points in the length unit (per s, per s^2); rows not assembled are
    NaN (JSON ``null``).
    """

    mechanism: str
    inputs: dict[str, np.ndarray]         # joint -> values (deg for R, length for P)
    input_types: dict[str, str]
    speeds: dict[str, float]
    assembled: np.ndarray
    points: dict[str, PointMotion]
    links: dict[str, Any]
    engine: str
    method: str
    events: list[Event] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    #: ``"module:function"`` in :mod:`mechsyn.plot` that animates this result.
    _animate: ClassVar[str] = "kinematics:animate_simulation"

    @property
    def main_input(self) -> str:
        return next(iter(self.inputs))

    def input_unit(self, joint: str) -> str:
        """The unit of input ``joint``'s values: ``"deg"`` (R) or ``"length"`` (P)."""
        return _unit(self.input_types[joint])

    def point(self, name: str) -> np.ndarray:
        """Positions (N, 2 or 3) of named point ``name`` over the sweep (NaN where not assembled)."""
        if name not in self.points:
            raise MechsynInputError(f"no point {name!r} in this simulation", field="points",
                                    hint="one of " + (", ".join(self.points) or "none: pass points=[...]"))
        return self.points[name].position

    def link(self, name: str) -> Any:
        """The motion of link ``name`` over the sweep (:class:`LinkMotion`: angle in degrees,
        angular velocity and acceleration; in 3-D a pose)."""
        if name not in self.links:
            raise MechsynInputError(f"no link {name!r} in this simulation", field="link",
                                    hint="one of " + ", ".join(self.links))
        return self.links[name]

    def working_ranges(self) -> list[list[float]]:
        """Runs of consecutive assembled inputs, as [first, last] values of the main input.

        A run that stops at a dead point the engine located between two rows (``events``)
        ends there, not at its last row. A sweep over a whole turn of an R input is a cycle:
        the run through its last row and its first is one range ``[first, last + 360]``
        (``[243.43, 476.57]``: from 243.43 deg through 360 to 116.57 deg).
        """
        vals = np.asarray(self.inputs[self.main_input], float)
        ok = np.asarray(self.assembled, bool)
        n = len(vals)
        dead = [float(e.input[self.main_input]) for e in self.events
                if e.kind == "dead point" and self.main_input in (e.input or {})]

        def located(a: float, b: float, default: float) -> float:
            """The dead point between rows of values a and b (b included), else default."""
            lo, hi = min(a, b), max(a, b)
            inside = [d for d in dead if lo < d <= hi or lo <= d < hi]
            return min(inside, key=lambda d: abs(d - a)) if inside else default

        out = []
        edges = np.flatnonzero(np.diff(np.r_[False, ok, False]))  # each run's first row and the row after it
        for start, end in zip(edges[::2].tolist(), (edges[1::2] - 1).tolist()):
            first = located(vals[start], vals[start - 1], vals[start]) if start > 0 else vals[start]
            last = located(vals[end], vals[end + 1], vals[end]) if end < n - 1 else vals[end]
            out.append([float(first), float(last)])
        if len(out) > 1 and ok[0] and ok[-1] and is_full_turn(vals, self.input_types.get(self.main_input)):
            turn = 360.0 if vals[-1] >= vals[0] else -360.0  # a whole turn: the ends meet
            out[0] = [out[-1][0], out[0][1] + turn]
            out.pop()
        return out

    def columns(self, motion: bool = True) -> dict[str, np.ndarray]:
        """The result as named columns, one row per input value: the inputs, ``assembled``,
        then (``motion``) every point's x, y (z), vx, vy, ..., ax, ... and every link's
        numbers by row (angle, omega, alpha; a 3-D link's translation and rates by
        component): the columns of :meth:`to_pandas` and of :meth:`csv`.

        Examples
        --------
        >>> import mechsyn as ms
        >>> list(ms.examples.load("crank_rocker").simulate(A=(0, 90, 30)).columns())[:5]
        ['input_A', 'assembled', 'M_x', 'M_y', 'M_vx']
        """
        cols: dict[str, Any] = {f"input_{j}": v for j, v in self.inputs.items()}
        cols["assembled"] = self.assembled
        for name, pm in self.points.items() if motion else ():
            for key, arr in (("", pm.position), ("v", pm.velocity), ("a", pm.acceleration)):
                for c, col in zip("xyz", arr.T):
                    cols[f"{name}_{key}{c}"] = col
        for name, lm in self.links.items() if motion else ():
            for key, arr in lm.to_dict().items():
                arr = np.asarray(arr)
                key = _COLUMNS.get(key, key)
                if arr.ndim == 1:
                    cols[f"{name}_{key}"] = arr
                elif arr.ndim == 2:
                    for c, col in zip("xyz", arr.T):
                        cols[f"{name}_{key}_{c}"] = col
        return cols

    def csv(self) -> str:
        """:meth:`columns` as a CSV table (:func:`mechsyn.results.csv_table`): what
        ``mechsyn simulate --csv`` writes.

        Examples
        --------
        >>> import mechsyn as ms
        >>> ms.examples.load("crank_rocker").simulate(A=(0, 90, 30)).csv().splitlines()[0].split(",")[:3]
        ['input_A', 'assembled', 'M_x']
        """
        return csv_table(self.columns())

    def to_pandas(self) -> Any:
        """A :class:`pandas.DataFrame` of :meth:`columns`, one row per input value."""
        from mechsyn._extras import require

        return require("pandas", "Simulation.to_pandas()").DataFrame(self.columns())  # to_dict() needs nothing

    def animate(self, fig: Any = None, **kwargs: Any) -> Any:
        """The mechanism moving over the sweep: a Matplotlib animation that plays when it is a
        notebook cell's value and saves with ``anim.save("m.gif")`` (``.mp4``, ``.html``).

        Without ``fig`` it is drawn on a bare Matplotlib Figure (no pyplot, so a notebook
        shows the player, not a still frame); pass ``fig=plt.figure()`` to play it in a
        Matplotlib window with ``plt.show()``. ``kwargs`` go to the function named in
        ``_animate`` (:func:`mechsyn.plot.kinematics.animate_simulation`: ``max_frames``,
        ``interval``)."""
        module, name = self._animate.split(":")
        draw = getattr(importlib.import_module(f"mechsyn.plot.{module}"), name)
        return draw(self, fig=fig, **kwargs)

    def to_dict(self, rates: bool = True) -> dict[str, Any]:
        """The fields every engine's result shares, as JSON values (lists, ``None`` for a row
        not assembled or not finite): what ``mechsyn simulate --json`` prints and the studio
        draws; a subclass adds its own.

        ``rates=False`` leaves out the velocities and accelerations of the points and links
        (``"rates": false`` says so): a smaller answer, e.g. for the studio's drag.

        Examples
        --------
        >>> import json, mechsyn as ms
        >>> s = ms.examples.load("crank_rocker").simulate(A=(0, 90, 30))
        >>> d = s.to_dict(rates=False)
        >>> d["input"]["type"], sorted(d["points"]["M"]), d["rates"], len(json.dumps(d)) > 0
        ('R', ['position'], False, True)
        """
        ok = np.asarray(self.assembled, bool)
        main = self.main_input

        def kept(parts: dict[str, Any]) -> dict[str, Any]:
            return {k: rows(v, ok) for k, v in parts.items() if rates or k not in _RATES}

        values = {j: rows(v) for j, v in self.inputs.items()}
        return {
            "mechanism": self.mechanism,
            "input": {"joint": main, "type": self.input_types[main], "values": values[main],
                      "unit": self.input_unit(main), "speed": self.speeds[main]},
            "inputs": {j: {"values": v, "type": self.input_types[j], "unit": self.input_unit(j),
                           "speed": self.speeds[j]} for j, v in values.items()},
            "assembled": ok.tolist(),
            "rates": bool(rates),
            "points": {name: kept(pm.to_dict()) for name, pm in self.points.items()},
            "links": {name: kept(lm.to_dict()) for name, lm in self.links.items()},
            "working_ranges": self.working_ranges(),
            "events": [e.to_dict() for e in self.events],
            "method": self.method,
            "engine": self.engine,
            "notes": list(self.notes),
        }


#: The rates among the parts of a point's or a link's motion (left out by ``to_dict(rates=False)``).
_RATES = frozenset({"velocity", "acceleration", "angular_velocity", "angular_acceleration"})


def rows(a: Any, ok: np.ndarray | None = None) -> list:
    """Array ``a`` (N, ...) as JSON values: a list of its rows, ``None`` for a row not
    ``ok`` or with a number that is not finite (JSON has no NaN).

    Examples
    --------
    >>> rows(np.array([[1.0, 2.0], [np.nan, 0.0], [3.0, 4.0]]), np.array([True, True, False]))
    [[1.0, 2.0], None, None]
    """
    a = np.asarray(a, float)
    good = np.isfinite(a).all(axis=tuple(range(1, a.ndim)))
    if ok is not None:
        good &= ok
    out = a.tolist()
    for k in np.flatnonzero(~good).tolist():
        out[k] = None
    return out


#: The table's names of a link's rates (:meth:`Motion.to_pandas`).
_COLUMNS = {"angular_velocity": "omega", "angular_acceleration": "alpha"}


@dataclass(repr=False, kw_only=True)
class Simulation(Motion):
    """Motion of a planar mechanism over a sweep of input values (see the module doc).

    ``s.point("M")`` and ``s.link("coupler").angle`` give the arrays, ``s.to_pandas()`` a
    table, ``s.plot()`` the mechanism and its point paths, ``s.animate()`` the motion.

    Examples
    --------
    >>> import mechsyn as ms
    >>> s = ms.examples.load("crank_rocker").simulate(A=(0, 360, 10))
    >>> s.point("M").shape, bool(s.assembled.all())
    ((37, 2), True)
    """

    _plot = "kinematics:plot_paths"

    links: dict[str, LinkMotion]
    method: str = "newton"
    engine: str = "newton"
    vll: dict[str, str] = field(default_factory=dict)
    sweep: Sweep | None = field(default=None, repr=False)
    system: PlanarSystem | None = field(default=None, repr=False)

    def _summary(self) -> list[tuple[str, str]]:
        x = self.inputs[self.main_input]
        unit = _unit(self.input_types[self.main_input])
        rows = [("mechanism", self.mechanism), ("method", f"{self.method} ({self.engine})"),
                ("input", f"{self.main_input}: {len(x)} values, {x[0]:g} to {x[-1]:g} {unit}" if len(x) else "none"),
                ("assembled", f"{int(np.count_nonzero(self.assembled))} of {len(self.assembled)}"),
                ("points", ", ".join(self.points) or "-"), ("links", ", ".join(self.links) or "-")]
        if self.events:
            rows.append(("events", "; ".join(sorted({str(e.kind) for e in self.events}))))
        return rows

    def animate(self, fig: Any = None, **kwargs: Any) -> Any:
        """:meth:`Motion.animate` (a :class:`~mechsyn.plot.animation.MechanismAnimation`)."""
        return super().animate(fig, bare=True, **kwargs)

    def to_dict(self, rates: bool = True) -> dict[str, Any]:
        d = super().to_dict(rates)
        notes = d.pop("notes")  # (the keys in the order the JSON has always had)
        return {**d, "vll": self.vll, "notes": notes,
                "units": {"angle": "deg", "angular_velocity": "rad/s", "angular_acceleration": "rad/s^2"}}


def _unit(t: str) -> str:
    return "length" if t == "P" else "deg"  # (an angle: R, and a spatial file's H, C/turn, U)


def is_full_turn(values: np.ndarray, input_type: str) -> bool:
    """True when an R input's values cover a whole turn (the last row, one step on, is the
    first again, e.g. 0, 2, ..., 358; or 0 ... 360 with its end repeated).

    Examples
    --------
    >>> import numpy as np
    >>> is_full_turn(np.arange(0, 360, 2.0), "R"), is_full_turn(np.arange(0, 180, 2.0), "R")
    (True, False)
    """
    x = np.asarray(values, float)
    if input_type != "R" or len(x) < 3 or not np.isfinite(x).all():
        return False
    step = float(np.median(np.abs(np.diff(x))))
    return bool(abs(x[-1] - x[0]) + step >= 360.0 * (1 - 1e-9))


def input_grid(start: float, stop: float, step: float) -> np.ndarray:
    """``start, start + step, ..., stop`` (stop included when on the grid).

    More positions than the limit ``sweep_points`` (:mod:`mechsyn.limits`) raise
    :class:`~mechsyn.errors.MechsynInputError` before any memory is taken.

    Examples
    --------
    >>> from mechsyn.kinematics.analysis import input_grid
    >>> input_grid(0.0, 90.0, 30.0).tolist(), input_grid(0.0, 100.0, 30.0).tolist()
    ([0.0, 30.0, 60.0, 90.0], [0.0, 30.0, 60.0, 90.0])
    """
    if not (math.isfinite(start) and math.isfinite(stop) and math.isfinite(step)) or step == 0 \
            or (stop - start) * step < 0:
        raise MechsynInputError(f"no sweep from {start:g} to {stop:g} in steps of {step:g}", field="inputs",
                                hint="e.g. A=0:360:1 on the command line")
    c = (stop - start) / step + 1e-9  # on floats: np.floor's count without three NumPy scalar calls
    count = float(math.floor(c)) + 1.0 if math.isfinite(c) else c + 1.0
    if count > limit("sweep_points"):
        raise MechsynInputError(
            f"{start:g}:{stop:g}:{step:g} is {count:,.0f} positions, more than the limit of "
            f"{limit('sweep_points'):,}", field="inputs",
            hint="use a larger step or a shorter range; " + limit_hint("sweep_points"))
    grid = np.arange(int(count), dtype=float)  # start + step * k in place (exact k: the same numbers)
    grid *= step
    grid += start
    return grid


def resolve_points(mech: Mechanism, names: list[str] | None) -> dict[str, tuple[str, np.ndarray]]:
    """Named points (file ``points`` or joint ids) -> (link, assembled coordinates)."""
    out: dict[str, tuple[str, np.ndarray]] = {}
    if names is None:  # the file's named points, else every joint
        names = list(mech.points) or [j.id for j in mech.joints]
    for name in names:
        if name in mech.points:
            p = mech.points[name]
            out[name] = (p.link, np.asarray(p.at, float))
            continue
        try:
            j = mech.joint(name)
        except KeyError:
            known = list(mech.points) + [j.id for j in mech.joints]
            raise MechsynInputError(f"no point or joint named {name!r}", field="points",
                                    hint=f"known: {', '.join(known)}") from None
        link = j.links[1] if j.links[1] != mech.ground else j.links[0]
        out[name] = (link, np.asarray(j.point, float))
    return out
