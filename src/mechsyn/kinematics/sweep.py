"""What every kinematics engine returns: a :class:`Sweep` (poses and their rates over the
input values, the engine that computed them) and its :class:`Event` records.

An engine (:mod:`mechsyn.kinematics.engines`) fills ``q, qd, qdd`` (N, n) with NaN rows
where the mechanism is not assembled, and lists what happened on the way as events: a
dead point (assembly ends or starts), a reassembly after a gap, a singular configuration
(a change or branch point, rates undefined), the mechanism not assembled at the first
input, a VLL outside its limits. Events are typed records; :meth:`Event.to_dict` is their
JSON form (the keys of the former event dictionaries, in the same order), and an event
reads like that dictionary (``e["kind"]``, ``e.get("input")``).
"""

from __future__ import annotations

import math
import operator
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field, fields
from typing import Any, Literal

import numpy as np

__all__ = ["Sweep", "Event", "EventKind", "by_row", "REGULAR_DISC", "connecting_path",
           "tracking_path", "turns", "driver_kinds"]

#: What an event reports.
EventKind = Literal["dead point", "reassembled", "singular", "not assembled", "branch point", "limit"]


@dataclass(frozen=True, init=False)
class Event(Mapping):
    """One event of a sweep.

    ``index``: the row of the sweep it belongs to; ``input``: the input values where it
    happens (inside an engine a sequence in radians / lengths, in a
    :class:`~mechsyn.kinematics.analysis.Simulation` a mapping joint -> degrees or length);
    ``group``: the Assur group concerned (its joints, e.g. ``"B-C-D"``); ``crossed``: a
    singular point passed between two rows (not at a row); ``before_sweep``: the event lies
    between the drawn configuration and the first row; ``joint``, ``value``: a VLL and its
    length (``limit``); ``last``: the assembled row a refined limit bounds (a dead point of
    the spatial engine, whose ``input`` is then the refined value, not the row's).

    Examples
    --------
    >>> e = Event(3, "dead point", "assembly ends", input={"A": 101.5}, group="B-C-D")
    >>> e["kind"], e.get("crossed"), list(e.to_dict())
    ('dead point', None, ['index', 'kind', 'input', 'group', 'message'])
    """

    index: int
    kind: EventKind
    message: str
    input: Any = None
    group: str | None = None
    crossed: bool | None = None
    before_sweep: bool | None = None
    joint: str | None = None
    value: float | None = None
    last: int | None = None

    def __init__(self, index: int, kind: EventKind, message: str, input: Any = None, group: str | None = None,
                 crossed: bool | None = None, before_sweep: bool | None = None, joint: str | None = None,
                 value: float | None = None, last: int | None = None) -> None:
        # the fields set in one update (a frozen dataclass's __init__ sets them one by one
        # through object.__setattr__: twice the time, and an engine makes events on every sweep)
        self.__dict__.update(index=index, kind=kind, message=message, input=input, group=group, crossed=crossed,
                             before_sweep=before_sweep, joint=joint, value=value, last=last)

    def to_dict(self) -> dict[str, Any]:
        """The JSON form: only the fields that are set, in a fixed order (``index``,
        ``kind`` and ``message`` always; ``value`` with its ``joint``)."""
        d = self.__dict__
        keep = _ALWAYS_WITH_JOINT if d["joint"] is not None else _ALWAYS
        return {k: d[k] for k in _KEYS if k in keep or (d[k] is not None and k != "value")}

    def with_(self, **changes: Any) -> "Event":
        """A copy with some fields changed (``dataclasses.replace`` without its checks:
        an engine makes a few of these per event, on every sweep)."""
        new = object.__new__(Event)
        d = new.__dict__
        d.update(self.__dict__)
        d.update(changes)
        if len(d) != len(_FIELDS):  # a name that is no field added an entry
            raise TypeError(f"Event has no field {next(k for k in changes if k not in _FIELDS)!r}")
        return new

    def __getitem__(self, key: str) -> Any:
        return self.to_dict()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.to_dict())

    def __len__(self) -> int:
        return len(self.to_dict())


_FIELDS = frozenset(f.name for f in fields(Event))
#: The JSON form's keys in their order, and those it always has (:meth:`Event.to_dict`).
_KEYS = ("index", "kind", "input", "joint", "value", "group", "crossed", "message", "before_sweep", "last")
_ALWAYS, _ALWAYS_WITH_JOINT = frozenset({"index", "kind", "message"}), frozenset({"index", "kind", "message", "value"})

def as_event(e: "Event | dict[str, Any]") -> Event:
    """An :class:`Event` from an event or its mapping form (the keys are its fields)."""
    return e if isinstance(e, Event) else Event(**e)


#: The sort key of events: their row (``events.sort(key=by_row)``).
by_row = operator.attrgetter("index")


@dataclass
class Sweep:
    """Result of an engine: poses and their rates at every input value.

    ``q, qd, qdd`` have shape (N, n) with NaN rows where the mechanism is not assembled;
    ``inputs`` (N, n_inputs) in radians (R) or length (P); ``speeds`` the input rates;
    ``engine``: the name of the engine that computed it (:attr:`method`: ``"newton"`` for
    Newton's continuation, else ``"assur"``, the closed form); ``links``: the links' complex states
    (:class:`mechsyn.kinematics.regular.LinkStates`) when the one regular pass computed the
    sweep (every row assembled with finite rates; through folds, from the compiled pass,
    NaN where the poses are), else None; ``rates_ok``: the rows whose
    rates are all finite when the engine knows them (else None: read off ``qd, qdd``);
    ``nan_rows``: every row of ``q`` where the mechanism is not assembled, and of ``qd``,
    ``qdd`` where the rates are not defined, is NaN entirely (so anything computed from
    such a row is NaN there without being set); ``singular_rows``: the assembled rows
    whose rates are not defined, when the engine knows them (else None: read off
    ``assembled`` and ``rates_ok``).
    """

    system: Any
    inputs: np.ndarray
    speeds: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    assembled: np.ndarray
    events: list[Event] = field(default_factory=list)
    links: Any = None
    engine: str = "newton"
    rates_ok: Any = None
    nan_rows: bool = False
    singular_rows: list | None = None

    @property
    def method(self) -> str:
        """``"newton"`` (Newton's continuation) or ``"assur"`` (the closed form of the
        Assur groups)."""
        return "newton" if self.engine == "newton" else "assur"

    @property
    def n(self) -> int:
        return self.q.shape[0]


# --------------------------------------------------------------------------- connecting paths
#: Smallest normalised discriminant of every group over a sweep for which
#: :func:`mechsyn.kinematics.regular.sweep_through_folds` answers without a fold scan (below it
#: :func:`mechsyn.kinematics.tracking.solve_tracked` looks for folds and change points: its
#: candidates are local minima under 0.05).
REGULAR_DISC = 0.05 + 1e-9


def turns(kinds: tuple, u0: list, first: list) -> list:
    """The whole turns (radians; 0 for a P input) between the input values ``first`` and
    the drawn ones ``u0`` (R inputs, ``kinds`` the drivers' types; sequences of floats)."""
    return [2 * math.pi * round((b - a) / (2 * math.pi)) if kind == "R" else 0.0
            for a, b, kind in zip(u0, first, kinds)]


def turned(kinds: tuple, u0: list, first: list) -> list:
    """The first input values ``first`` moved by whole turns (:func:`turns`) to the values
    nearest the drawn ones ``u0``."""
    return [b - t for b, t in zip(first, turns(kinds, u0, first))]


def connecting_path(kinds: tuple, scale: float, u0: list, u1: list, step: float = 1.0,
                    max_rows: int = 4000) -> np.ndarray:
    """Inputs from the drawn values ``u0`` towards ``u1`` (excluded; sequences of floats)
    in steps of at most ``step`` degrees (R) or ``step`` % of the mechanism's size
    ``scale`` (P), ``u0`` the first row: the way every engine reaches a sweep from the
    drawn configuration (the tracked engines by 1-degree steps, Newton's continuation by
    5-degree ones without the first row)."""
    h_r, h_p = math.radians(step), step / 100 * scale
    most = max(abs(b - a) / (h_r if kind == "R" else h_p) for a, b, kind in zip(u0, u1, kinds))
    n = int(min(max_rows, max(1, math.ceil(most))))
    if n == 1:  # the drawn values themselves (t = 0)
        return np.array([u0], float)
    t = np.arange(n) / n
    out = np.empty((n, len(u0)))
    for k, (a, b) in enumerate(zip(u0, u1)):  # u0 + t (u1 - u0), column by column
        np.multiply(t, b - a, out=out[:, k])
        out[:, k] += a
    return out


def driver_kinds(S: Any) -> tuple[tuple, float]:
    """The drivers' types of the planar system ``S`` and the size the connecting paths' P
    steps are measured by."""
    kinds = tuple(d.type for d in S.drivers)
    return kinds, (S.scale if "P" in kinds else 1.0)


def tracking_path(S: Any, first: np.ndarray, u0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The connecting path from the drawn input values to a tracked sweep whose first
    input values are ``first``, and the whole turns ``shift`` the sweep is tracked
    shifted by (R inputs a whole number of turns from the drawn values are the same
    configurations: the sweep is tracked next to the drawn values, so that its rows
    follow each other); ``u0``: the drawn input values when known. Both arrays are
    read-only: a sweep of the same first inputs from the same drawn values (a cached or
    a refilled geometry: the path does not depend on the links) takes them again."""
    a = tuple([float(d.assembled) for d in S.drivers] if u0 is None else u0.tolist())
    kinds, scale = driver_kinds(S)
    b = tuple(first.tolist())
    return S.topology.product(("tracking path", scale, a, b), lambda: _tracking_path(kinds, scale, a, b))


def _tracking_path(kinds: tuple, scale: float, u0: tuple, first: tuple) -> tuple[np.ndarray, np.ndarray]:
    """:func:`tracking_path` of the drivers' types ``kinds`` (the topology's) and the
    size ``scale``, kept as the topology's product with the numbers it depends on."""
    shift = [b - c for b, c in zip(first, turned(kinds, u0, first))]  # the numbers of first - (first - turns)
    path = connecting_path(kinds, scale, list(u0), [b - c for b, c in zip(first, shift)])
    out = path, np.array(shift)
    for x in out:
        x.setflags(write=False)
    return out
