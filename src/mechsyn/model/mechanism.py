"""The mechanism model: links, kinematic pairs (joints), points, contours, states.

A :class:`Mechanism` is immutable; it is usually built from a file by
:func:`mechsyn.io.load_mechanism`. Its link graph (:meth:`Mechanism.graph`) is a
NetworkX multigraph whose nodes are link names and whose edges are the joints.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Literal

import networkx as nx
import numpy as np

from mechsyn.model.pairs import PAIR_KINDS

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


@dataclass(frozen=True, eq=False)
class Mechanism:
    """A mechanism: links (frame included), joints, named points, contours, states.

    Attributes
    ----------
    name, kind: the file's name and ``"planar"`` or ``"spatial"``.
    ground: the frame link's name.
    links: every link, frame included, in file order.
    joints: the kinematic pairs in file order.
    points: named points fixed on links.
    contours: independent contours as ordered joint-id lists, when the file gives them
        (paper 003's per-contour results depend on their order).
    states: variable-structure states (paper 002).
    mobility: the actual mobility W declared in the file (idle mobilities included),
        used by formulas that need W when no other source is better.
    source: the file it was read from.
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

    # -- variants -------------------------------------------------------------------
    def with_joints(self, joints: tuple[Joint, ...], name: str | None = None) -> "Mechanism":
        return replace(self, joints=joints, name=name or self.name)

    def widget(self, root: str = "."):
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
