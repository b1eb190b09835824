"""The topology of a planar mechanism: what a sweep reuses across its geometries.

Two planar mechanisms with the same :func:`topology_key` (links, joints and their pair
types, drives, VLL modes, prescribed inputs) differ only in numbers: joint points, P axes,
named points. A :class:`Topology` is that key made an immutable value (equal and hashed
by the key), built once from the mechanism's topology and held by everything of that
topology: every :class:`~mechsyn.kinematics.system.PlanarSystem` built or refilled for it
(``S.topology``), so every :class:`~mechsyn.kinematics.analysis.KinematicPlan`
(``kp.topology``). A drag in the studio and a synthesis candidate hold it through the
plan they refill (:meth:`~mechsyn.kinematics.analysis.KinematicPlan.refilled`).

What the topology alone decides (the engines' programs of a decomposition, the refill
layout, the shape of the inputs and named points) is built once per topology and kept in
the one cache of the kinematics package, :data:`CACHE`: a bounded LRU keyed by the
:class:`Topology` (with the name of the product and, where it depends on a decomposition,
that decomposition). A geometry-dependent answer is never kept under a topology alone:
the compiled plans are kept under the mechanism and its geometry's numbers
(:func:`mechsyn.kinematics.analysis.cached_plan`), a decomposition under the topology and
which of its joints coincide (the only geometry it depends on).

Examples
--------
>>> import mechsyn as ms
>>> m = ms.examples.load("crank_rocker")
>>> moved = m.with_joint_points({"C": (3.1, 2.9)})
>>> topology_of(m) == topology_of(moved), topology_of(m) == topology_of(ms.examples.load("slider_crank"))
(True, False)
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from typing import Any

from mechsyn.model.mechanism import Mechanism

__all__ = ["CACHE", "LRUCache", "Topology", "topology_key", "topology_of"]


def topology_key(mech: Mechanism, vll: dict[str, str] | None = None, prescribed: tuple[str, ...] = ()) -> tuple:
    """What a compiled system depends on besides the numbers of the geometry: the kind,
    the links (frame first), every joint's id, pair type, links, drive, VLL mode, ratio
    and extra attributes, the named points' links, the VLL modes asked for and the
    prescribed inputs. Two mechanisms with the same key differ only in their joint
    points, P axes and named points, so
    :func:`~mechsyn.kinematics.refill.with_geometry` fills one's numbers into the
    other's system.

    Examples
    --------
    >>> import mechsyn as ms
    >>> m = ms.examples.load("crank_rocker")
    >>> moved = m.with_joint_points({"C": (3.1, 2.9)})
    >>> topology_key(moved) == topology_key(m), topology_key(m) == topology_key(m, {"A": "locked"})
    (True, False)
    """
    joints = tuple([(j.id, j.type, j.links, j.actuated, j.vll, j.ratio, repr(j.attrs) if j.attrs else "")
                    for j in mech.joints])
    named = tuple([(k, p.link) for k, p in mech.points.items()]) if mech.points else ()
    return (mech.kind, mech.ground, tuple([link.name for link in mech.links]), joints, named,
            tuple(sorted(vll.items())) if vll else (), tuple(prescribed))


class Topology:
    """The topology of a planar mechanism (:func:`topology_key`) as an immutable value:
    two topologies are equal, and hash equal, when their keys are. What a sweep builds
    from it alone is kept in :data:`CACHE` by :meth:`product`.

    Examples
    --------
    >>> import mechsyn as ms
    >>> T = topology_of(ms.examples.load("crank_rocker"))
    >>> T.product("links", lambda: T.key[2]), T.key[3][0][:2]
    (('frame', 'crank', 'coupler', 'rocker'), ('A', 'R'))
    """

    __slots__ = ("key", "_hash")

    def __init__(self, key: tuple) -> None:
        object.__setattr__(self, "key", key)
        object.__setattr__(self, "_hash", hash(key))

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"a Topology is immutable (tried to set {name!r})")

    def __eq__(self, other: object) -> bool:
        return self is other or (isinstance(other, Topology) and self._hash == other._hash and self.key == other.key)

    def __hash__(self) -> int:
        return self._hash

    def __repr__(self) -> str:
        joints = " ".join(f"{j[0]}:{j[1]}" for j in self.key[3])
        return f"Topology({len(self.key[2]) - 1} moving links; {joints})"

    def __reduce__(self) -> tuple:
        return Topology, (self.key,)

    def product(self, name: Hashable, build: Callable[[], Any], plan: Any = None) -> Any:
        """``build()``, what this topology alone (and the decomposition ``plan``, when one
        is given: its steps, links and joints, no number) decides, built once and kept in
        :data:`CACHE` under ``(self, name)`` (``plan`` by identity: a decomposition is
        an object of the sweeps that share it)."""
        key = (self, name) if plan is None else (self, name, id(plan))
        hit = CACHE.get(key)
        if hit is None or hit[0] is not plan:
            hit = (plan, build())
            CACHE.put(key, hit)
        return hit[1]


class LRUCache:
    """A bounded mapping that forgets its least recently used entry past ``maxsize``
    (thread-safe: the studio's server answers from several threads).

    Examples
    --------
    >>> c = LRUCache(2)
    >>> c.put("a", 1); c.put("b", 2); c.get("a"); c.put("c", 3)
    1
    >>> c.get("b"), c.get("a"), len(c)
    (None, 1, 2)
    """

    def __init__(self, maxsize: int) -> None:
        self.maxsize = maxsize
        self._data: OrderedDict = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: Hashable) -> Any:
        """The value kept under ``key`` (made the most recently used), else None."""
        with self._lock:
            value = self._data.get(key)
            if value is not None:
                self._data.move_to_end(key)
            return value

    def put(self, key: Hashable, value: Any) -> None:
        """Keep ``value`` under ``key``, forgetting the least recently used entries past
        :attr:`maxsize`."""
        with self._lock:
            self._data[key] = value
            self._data.move_to_end(key)
            while len(self._data) > self.maxsize:
                self._data.popitem(last=False)

    def clear(self) -> None:
        with self._lock:
            self._data.clear()

    def __len__(self) -> int:
        return len(self._data)


#: The kinematics package's one cache, at most 256 entries: what a topology decides, under
#: ``(Topology, name[, id(plan)])`` (:meth:`Topology.product`: the engines' programs, the
#: refill layout, the decompositions, the template a new geometry is refilled from); the
#: compiled plans of the last mechanisms simulated, under ``("plan", id(mechanism),
#: VLL modes, prescribed inputs, the geometry's numbers)``
#: (:func:`~mechsyn.kinematics.analysis.cached_plan`); the input grids of the last sweeps,
#: under ``("input grid", shape, dtype)`` (:func:`~mechsyn.kinematics.engines.drawn_row`).
#: A geometry-dependent answer is never kept under a topology alone.
CACHE = LRUCache(256)


def topology_of(mech: Mechanism, vll: dict[str, str] | None = None, prescribed: tuple[str, ...] = ()) -> Topology:
    """The :class:`Topology` of ``mech`` with the VLL modes ``vll`` and the prescribed
    inputs ``prescribed``."""
    return Topology(topology_key(mech, vll, prescribed))
