"""The explicit Topology (issue 37, item 2): what a sweep reuses across geometries is one
immutable object built from the mechanism's topology, held by every system and plan of
it, and the one bounded LRU cache of the kinematics package is keyed by it."""

from __future__ import annotations

import numpy as np
import pytest

from kinematics_helpers import fourbar
from mechsyn.kinematics import analysis, topology
from mechsyn.kinematics.analysis import cached_plan, compile_plan, input_grid, simulate
from mechsyn.kinematics.system import build_system
from mechsyn.kinematics.topology import CACHE, LRUCache, Topology, topology_of


def test_same_topology_other_dimensions_is_one_topology_and_reuses_its_products():
    """Two mechanisms with the same links, joints and drives and other dimensions have
    equal Topologies (the same hash); a plan of one refilled with the other's numbers
    holds it, and what the topology decides (the engines' programs) is built once."""
    m = fourbar()
    other = m.with_joint_points({"C": m.joint("C").point + [0.2, -0.1], "D": m.joint("D").point + [0.3, 0.0]})
    T1, T2 = topology_of(m), topology_of(other)
    assert T1 == T2 and hash(T1) == hash(T2) and T1 is not T2
    kp = compile_plan(m, inputs=("A",))
    kp2 = kp.refilled(other)
    assert kp.topology == kp2.topology == T1 and build_system(other).topology == T1
    assert kp2.groups is kp.groups  # the decomposition: the topology's
    built = []
    first = T1.product("a test's product", lambda: built.append(1) or "built", kp.groups)
    again = T2.product("a test's product", lambda: built.append(2) or "again", kp2.groups)
    assert (first, again, built) == ("built", "built", [1])


def test_another_topology_is_not_equal():
    m = fourbar()
    assert topology_of(m) != topology_of(m, {"A": "locked"})  # the VLL modes compiled are part of it
    assert topology_of(m) != topology_of(m, prescribed=("A",))
    with pytest.raises(AttributeError):
        topology_of(m).key = ()  # immutable


def test_the_cache_is_bounded_and_forgets_the_least_recently_used():
    """Filled past its size, the LRU keeps ``maxsize`` entries: the oldest unused goes,
    one read since stays."""
    c = LRUCache(4)
    T = topology_of(fourbar())
    for k in range(4):
        c.put((T, k), k)
    assert c.get((T, 0)) == 0  # used: the most recent now
    for k in range(4, 10):
        c.put((T, k), k)
    assert len(c) == 4 and c.get((T, 1)) is None
    assert [c.get((T, k)) for k in (6, 7, 8, 9)] == [6, 7, 8, 9]


def test_the_kinematics_cache_stays_bounded_filled_past_its_size(monkeypatch):
    """Simulating more geometries than the cache holds leaves it at its size (and the
    answers right: a plan pushed out is compiled again)."""
    small = LRUCache(6)
    monkeypatch.setattr(analysis, "CACHE", small)
    monkeypatch.setattr(topology, "CACHE", small)
    m = fourbar()
    grid = {"A": input_grid(0, 90, 30)}
    first = simulate(m, grid, points=["C"]).point("C")
    for k in range(20):
        simulate(m.with_joint_points({"D": m.joint("D").point + [0.01 * (k + 1), 0.0]}), grid)
    assert len(small) == small.maxsize
    assert np.array_equal(simulate(m, grid, points=["C"]).point("C"), first)


def test_a_geometry_change_never_returns_the_old_geometrys_answer():
    """The same mechanism object whose joint point array is changed in place, and a new
    mechanism of the same topology, are answered for their own numbers (compared with a
    system built anew), never from the plan cached for the old geometry."""
    m = fourbar()
    grid = {"A": input_grid(0, 120, 15)}
    old = simulate(m, grid, points=["C"]).point("C")
    moved = m.with_joint_points({"D": m.joint("D").point + [0.4, 0.1]})
    new = simulate(moved, grid, points=["C"]).point("C")
    fresh = analysis.KinematicPlan(moved, build_system(moved), None).simulate(grid, points=["C"], method="newton")
    assert not np.allclose(new, old, equal_nan=True)
    ok = ~np.isnan(new[:, 0])
    assert ok.sum() > 5 and np.allclose(new[ok], fresh.point("C")[ok], atol=1e-9)
    kp = cached_plan(m, inputs=("A",))
    m.joint("D").point[0] += 0.4  # the same object, its numbers changed in place
    m.joint("D").point[1] += 0.1
    try:
        assert cached_plan(m, inputs=("A",)) is not kp
        assert np.allclose(simulate(m, grid, points=["C"]).point("C")[ok], new[ok], atol=1e-12)
    finally:
        m.joint("D").point[0] -= 0.4
        m.joint("D").point[1] -= 0.1


def test_topology_pickles_and_repr():
    import pickle

    T = topology_of(fourbar())
    assert pickle.loads(pickle.dumps(T)) == T
    assert isinstance(T, Topology) and repr(T).startswith("Topology(3 moving links")
    assert CACHE.maxsize == 256


def test_a_studio_drag_reuses_the_topology(monkeypatch):
    """The studio's simulate of a dragged mechanism (parsed anew from the page's dict at
    each step) builds no constraint system and nothing of the topology again: its plan is
    refilled from what the topology keeps, and the cache gains only entries keyed by the
    new numbers."""
    from kinematics_helpers import fourbar_dict
    from mechsyn.web import _service

    _service.simulate(fourbar_dict(g=4.0), steps=36)  # the first step: the topology is built
    puts, built = [], []
    put = CACHE.put
    monkeypatch.setattr(CACHE, "put", lambda key, value: (puts.append(key), put(key, value))[1])
    monkeypatch.setattr(analysis, "build_system", lambda *a, **k: built.append(a) or build_system(*a, **k))
    out = [_service.simulate(fourbar_dict(g=g), steps=36) for g in (4.05, 4.1, 4.15)]
    assert not built and puts and all(not isinstance(k[0], Topology) for k in puts)
    assert all(o["points"] != out[0]["points"] for o in out[1:])  # each step its own numbers
