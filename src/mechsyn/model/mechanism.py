"""The mechanism model: links, kinematic pairs (joints), points, contours, states.

A :class:`Mechanism` is immutable; it is usually built from a file by
:func:`mechsyn.io.load_mechanism`. Its link graph (:meth:`Mechanism.graph`) is a
NetworkX multigraph whose nodes are link names and whose edges are the joints.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.pairs import PAIR_KINDS

if TYPE_CHECKING:  # NetworkX is imported by graph() only: reading and analysing a file need not load it
    import networkx as nx

    # The facade methods below return the upper layers' results: named here for the types only;
    # the methods import their module when called (the facade edges of tests/test_layout.py).
    from mechsyn.kinematics.analysis import Simulation
    from mechsyn.kinetostatics.analysis import ForceAnalysis
    from mechsyn.structure.report import StructureReport
    from mechsyn.web.widget import MechanismWidget

Kind = Literal["planar", "spatial"]
VLLMode = Literal["active", "passive", "locked"]


@dataclass(frozen=True)
class Link:
    """A rigid body. ``attrs`` holds the file's extra attributes (mass, inertia, ...)."""

    name: str
    attrs: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Joint:
    """A kinematic pair between two links; ``links[1]`` moves relative to ``links[0]``.

    ``pair_class`` is the class ``i`` used by the formulas: the spatial class for a
    spatial mechanism, and 5 (lower) or 4 (higher) for a planar one (Chebyshev's p5, p4).
    """

    id: str
    type: str
    links: tuple[str, str]
    pair_class: int
    point: np.ndarray | None = None
    axis: np.ndarray | None = None
    axis2: np.ndarray | None = None
    normal: np.ndarray | None = None
    pitch: float | None = None
    ratio: float | None = None
    actuated: bool = False
    vll: VLLMode | None = None
    limits: tuple[float, float] | None = None
    attrs: dict[str, Any] = field(default_factory=dict)
    higher_override: bool | None = None

    @property
    def freedom(self) -> int:
        """Relative freedoms of the pair, ``f = 6 - i``."""
        return 6 - self.pair_class

    @property
    def is_higher(self) -> bool:
        """Line or point contact (``m = 4`` in paper 003)."""
        if self.higher_override is not None:
            return self.higher_override
        return PAIR_KINDS[self.type].higher

    @property
    def m(self) -> int:
        """Paper 003's ``m``: 5 for a lower pair, 4 for a higher pair."""
        return 4 if self.is_higher else 5

    def other(self, link: str) -> str:
        a, b = self.links
        return b if link == a else a

    def with_class(self, pair_class: int, type: str | None = None) -> "Joint":
        return replace(self, pair_class=pair_class, type=type or self.type)


@dataclass(frozen=True)
class PointSpec:
    """A named point fixed on ``link``, given by its coordinates ``at`` in the assembly."""

    link: str
    at: np.ndarray


@dataclass(frozen=True)
class ExternalSpec:
    """Paper 002's external-constraint quantities of a state (see ``structure.external``).

    ``S_a`` defaults to the sum of the classes of the state's added contacts and ``W_f``
    to the mechanism's own mobility.
    """

    W_rob: int = 0
    S_ai: int = 0
    W_a: int = 6
    S_a: int | None = None
    W_f: int | None = None


@dataclass(frozen=True)
class StateSpec:
    """A state of a variable-structure mechanism (paper 002): what it adds to the base."""

    name: str
    description: str = ""
    add_links: tuple[Link, ...] = ()
    add_joints: tuple[Joint, ...] = ()
    contours: tuple[tuple[str, ...], ...] | None = None
    external: ExternalSpec | None = None
    mobility: int | None = None


@dataclass(frozen=True, eq=False, repr=False)
class Mechanism:
    """A mechanism: links (frame included), joints, named points, contours, states.

    ``print(m)`` shows its joints as a table (links joined, pair type and class, drives);
    ``m.analyze()``, ``m.simulate(A=(0, 360, 1))`` and ``m.forces(...)`` run the analyses;
    ``m.to_dict()`` gives the file-format data (``mechsyn.save(m, path)`` writes it).

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("fourbar")
    >>> m
    <Mechanism 'Four-bar linkage': planar, 4 links (frame 'frame'), 4 joints, p5 = 4>
    >>> s = m.simulate(A=(0, 90, 45))
    >>> s.assembled.tolist(), s.point("M").shape
    ([True, True, True], (3, 2))

    Attributes
    ----------
    name : str
        The file's name.
    kind : str
        ``"planar"`` or ``"spatial"``.
    ground : str
        The frame link's name.
    links : tuple of Link
        Every link, frame included, in file order.
    joints : tuple of Joint
        The kinematic pairs in file order.
    points : dict of str to PointSpec
        Named points fixed on links.
    contours : tuple of tuple of str, or None
        Independent contours as ordered joint-id lists, when the file gives them (paper
        003's per-contour results depend on their order).
    states : dict of str to StateSpec
        Variable-structure states (paper 002), by name.
    mobility : int or None
        The actual mobility W declared in the file (idle mobilities included), used by
        formulas that need W when no other source is better.
    source : str or None
        The file it was read from.
    """

    name: str
    kind: Kind
    ground: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    points: dict[str, PointSpec] = field(default_factory=dict)
    contours: tuple[tuple[str, ...], ...] | None = None
    states: dict[str, StateSpec] = field(default_factory=dict)
    mobility: int | None = None
    source: str | None = None
    attrs: dict[str, Any] = field(default_factory=dict)

    # -- look-ups -------------------------------------------------------------------
    @property
    def link_names(self) -> tuple[str, ...]:
        return tuple(link.name for link in self.links)

    @property
    def moving_links(self) -> tuple[str, ...]:
        """Names of the moving links (frame excluded)."""
        return tuple(n for n in self.link_names if n != self.ground)

    @property
    def n_moving(self) -> int:
        """Paper notation ``n``: number of moving links."""
        return len(self.links) - 1

    @property
    def dim(self) -> int:
        """Coordinates of a point: 2 (planar) or 3 (spatial)."""
        return 2 if self.kind == "planar" else 3

    def link(self, name: str) -> Link:
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)

    def joint(self, joint_id: str) -> Joint:
        for joint in self.joints:
            if joint.id == joint_id:
                return joint
        raise KeyError(joint_id)

    def joints_of(self, link: str) -> tuple[Joint, ...]:
        return tuple(j for j in self.joints if link in j.links)

    @property
    def actuated_joints(self) -> tuple[Joint, ...]:
        return tuple(j for j in self.joints if j.actuated)

    @property
    def has_geometry(self) -> bool:
        """Every joint has a point (axes default where the kind allows)."""
        return bool(self.joints) and all(j.point is not None for j in self.joints)

    def graph(self) -> nx.MultiGraph:
        """Link graph: nodes are link names, each joint an edge keyed by its id."""
        import networkx as nx

        g = nx.MultiGraph()
        g.add_nodes_from(self.link_names)
        for j in self.joints:
            g.add_edge(j.links[0], j.links[1], key=j.id, joint=j)
        return g

    def pairs_by_class(self) -> dict[int, int]:
        """``{class i: p_i}`` for the classes present, ascending."""
        counts: dict[int, int] = {}
        for j in self.joints:
            counts[j.pair_class] = counts.get(j.pair_class, 0) + 1
        return dict(sorted(counts.items()))

    # -- display --------------------------------------------------------------------
    def __repr__(self) -> str:
        pbc = ", ".join(f"p{k} = {v}" for k, v in self.pairs_by_class().items()) or "no pairs"
        name = self.name if len(self.name) <= 80 else self.name[:77] + "..."
        return (f"<Mechanism {name!r}: {self.kind}, {len(self.links)} links (frame {self.ground!r}), "
                f"{len(self.joints)} joints, {pbc}>")

    def _rows(self) -> list[tuple[str, ...]]:
        return [(j.id, j.type, str(j.pair_class), f"{j.links[0]} - {j.links[1]}",
                 "drive" if j.actuated else (f"VLL {j.vll}" if j.vll else "")) for j in self.joints]

    def __str__(self) -> str:
        head = ("joint", "type", "class", "links", "")
        rows = [head, *self._rows()]
        widths = [max(len(r[k]) for r in rows) for k in range(len(head))]
        lines = [repr(self)[1:-1]]
        lines += ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        if self.points:
            lines.append("  points: " + ", ".join(f"{k} on {p.link}" for k, p in self.points.items()))
        if self.states:
            lines.append("  states: " + ", ".join(self.states))
        return "\n".join(lines)

    def _repr_markdown_(self) -> str:
        out = [f"**{self.name}** ({self.kind}, frame `{self.ground}`)", "",
               "| joint | type | class | links | |", "|---|---|---|---|---|"]
        out += ["| " + " | ".join(r) + " |" for r in self._rows()]
        return "\n".join(out)

    def to_dict(self) -> dict[str, Any]:
        """The file-format data (what :func:`mechsyn.save` writes)."""
        from mechsyn.io.load import mechanism_to_dict

        return mechanism_to_dict(self)

    # -- analyses (the library's entry points, as methods) ---------------------------
    def analyze(self, method: str | None = None, remedies: bool = False, **kwargs: Any) -> StructureReport:
        """Structural analysis: :func:`mechsyn.analyze` (formulas, rank method, remedies)."""
        from mechsyn.structure.report import analyze

        return analyze(self, method=method, remedies=remedies, **kwargs)

    def simulate(self, inputs: dict[str, Any] | None = None, *, points: list[str] | None = None,
                 speeds: dict[str, float] | None = None, vll: dict[str, str] | None = None,
                 method: str = "auto", **joint_inputs: Any) -> Simulation:
        """Kinematics over a sweep: :func:`mechsyn.simulate`, inputs given per joint.

        Each input is ``(start, stop, step)`` (a tuple: a range, ends included) or the values
        themselves (a list or array); degrees for R joints, lengths for P joints:
        ``m.simulate(A=(0, 360, 1))`` or ``m.simulate({"A": np.linspace(0, 90, 7)})``.
        """
        from mechsyn.kinematics.analysis import input_grid, simulate  # one import statement per call

        return simulate(self, _inputs(inputs, joint_inputs, input_grid), speeds=speeds, points=points, vll=vll,
                        method=method)

    def forces(self, inputs: dict[str, Any] | None = None, *, gravity: tuple[float, float] = (0.0, 0.0),
               static: bool = False, speeds: dict[str, float] | None = None, vll: dict[str, str] | None = None,
               method: str = "auto", **joint_inputs: Any) -> ForceAnalysis:
        """Joint reactions and drive efforts over a sweep: :func:`mechsyn.forces`, inputs as
        in :meth:`simulate`."""
        from mechsyn.kinetostatics import forces

        return forces(self, _inputs(inputs, joint_inputs), speeds=speeds, gravity=gravity, static=static,
                      vll=vll, method=method)

    # -- variants -------------------------------------------------------------------
    def with_joints(self, joints: tuple[Joint, ...], name: str | None = None) -> "Mechanism":
        return replace(self, joints=joints, name=name or self.name)

    def with_joint_points(self, points: dict[str, Any]) -> "Mechanism":
        """The same mechanism with some joints moved (``{joint id: (x, y)}``): only
        numbers change (no parsing, no validation of the structure), so a simulation of
        the result reuses the compiled program of every mechanism of the same topology
        (:class:`mechsyn.kinematics.topology.Topology`). Named points keep their drawn positions. An unknown joint
        or a point that is not ``dim`` finite numbers raises
        :class:`~mechsyn.errors.MechsynInputError`.

        Examples
        --------
        >>> import mechsyn as ms
        >>> m = ms.examples.load("crank_rocker")
        >>> m.with_joint_points({"C": (3.1, 2.9)}).joint("C").point.tolist()
        [3.1, 2.9]
        """
        joints = list(self.joints)
        index = {j.id: k for k, j in enumerate(joints)}
        dim = self.dim
        for jid, p in points.items():
            k = index.get(jid)
            if k is None:
                raise MechsynInputError(f"no joint {jid!r}", source=self.source, field="joints",
                                        hint=f"joints are: {', '.join(index)}")
            try:
                arr = np.array(p, float)
                if arr.shape != (dim,):  # (a reshape costs twice the copy: only when needed)
                    arr = arr.reshape(dim)
            except (TypeError, ValueError):
                arr = np.full(dim, np.nan)
            if not all(map(math.isfinite, arr.tolist())):
                raise MechsynInputError(f"the point of joint {jid} must be {dim} finite numbers, not {p!r}",
                                        source=self.source, field=f"joints.{jid}.point",
                                        hint="give e.g. (x, y) in the file's length unit")
            joints[k] = fields_replaced(joints[k], point=arr)
        return fields_replaced(self, joints=tuple(joints))

    def widget(self, root: str = ".") -> MechanismWidget:
        """This mechanism in mechsyn studio's editor as a Jupyter widget (``mechsyn[web,notebook]``);
        the widget's ``mechanism`` follows every edit (see :mod:`mechsyn.web.widget`)."""
        from mechsyn.web.widget import MechanismWidget

        return MechanismWidget(self, root=root)

    def in_state(self, state: str) -> "Mechanism":
        """The mechanism with a state's added bodies and contacts (paper 002)."""
        spec = self.states[state]
        contours = spec.contours
        if contours is None and self.contours is not None and not spec.add_joints:
            contours = self.contours
        return replace(
            self,
            name=f"{self.name} [{state}]",
            links=self.links + spec.add_links,
            joints=self.joints + spec.add_joints,
            contours=contours,
            states={},
            mobility=spec.mobility if spec.mobility is not None else (
                self.mobility if not spec.add_joints else None),
        )


def _inputs(inputs: dict[str, Any] | None, joint_inputs: dict[str, Any],
            input_grid: Any = None) -> dict[str, np.ndarray]:
    """Joint -> values: a tuple ``(start, stop, step)`` is a range with both ends, anything
    else the values themselves (``input_grid``: :func:`mechsyn.kinematics.analysis.input_grid`,
    imported here when not given)."""
    if input_grid is None:
        from mechsyn.kinematics.analysis import input_grid

    out: dict[str, np.ndarray] = {}
    for jid, v in ({**inputs, **joint_inputs} if inputs else joint_inputs).items():
        if isinstance(v, tuple):
            if len(v) != 3:
                raise MechsynInputError(f"{jid}: a range is (start, stop, step), got {v!r}", field="inputs",
                                        hint="give a list or an array for explicit values")
            start, stop, step = map(float, v)
            if step == 0 or (stop - start) * step < 0:
                raise MechsynInputError(f"{jid}: step {step:g} does not lead from {start:g} to {stop:g}",
                                        field="inputs")
            out[jid] = input_grid(start, stop, step)
        else:
            out[jid] = np.atleast_1d(np.asarray(v, float))
    return out


def fields_replaced(obj: Any, **changes: Any) -> Any:
    """``dataclasses.replace(obj, **changes)`` for a frozen dataclass without
    ``__post_init__`` or init-only fields (a :class:`Joint`, a :class:`Mechanism`, the
    kinematics' constraint blocks and systems), by copying the instance's fields: a few
    hundred nanoseconds instead of the generated ``__init__``'s microseconds, which a
    fresh geometry paid per joint, constraint and driver on every call of a drag. The
    names are checked against the class's fields, and a class with a ``__post_init__``
    (whose checks this would skip) is refused.

    Examples
    --------
    >>> from dataclasses import replace
    >>> j = Joint("A", "R", ("frame", "crank"), 5, point=np.zeros(2))
    >>> moved = fields_replaced(j, point=np.ones(2))
    >>> moved.point.tolist(), j.point.tolist(), moved.links == replace(j, point=np.ones(2)).links
    ([1.0, 1.0], [0.0, 0.0], True)
    """
    cls = type(obj)
    names = _FIELD_NAMES.get(cls)
    if names is None:  # once per class: its fields, or None when it checks them in __post_init__
        names = _FIELD_NAMES[cls] = None if hasattr(cls, "__post_init__") else frozenset(obj.__dataclass_fields__)
    if names is None or not changes.keys() <= names:
        bad = next((k for k in changes if k not in obj.__dataclass_fields__), None)
        raise TypeError(f"{cls.__name__} has no field {bad!r}" if bad else
                        f"{cls.__name__} checks its fields in __post_init__: use dataclasses.replace")
    new = object.__new__(cls)
    fields = new.__dict__
    fields.update(obj.__dict__)
    fields.update(changes)
    return new


#: The field names of each class :func:`fields_replaced` has copied (None: it has a
#: ``__post_init__``, refused).
_FIELD_NAMES: dict[type, frozenset | None] = {}


