"""Independent contours of a mechanism's link graph.

Paper 003's per-contour results depend on the contours and their order, so a file may
give them; otherwise :func:`independent_contours` chooses a set: the file's contours
first, then the shortest fundamental cycles of a breadth-first spanning tree rooted at
the frame, kept when independent over GF(2) (cycle space of the graph).

References
----------
.. [1] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import weakref
from collections import deque
from typing import Any

from mechsyn.model.contour import contour_links
from mechsyn.model.mechanism import Mechanism


def cycle_rank(mech: Mechanism) -> int:
    """Number of independent contours ``K = p - N + 1`` (Gokhman: ``K = Σ p_i - n``)."""
    return len(mech.joints) - len(mech.links) + 1


def _mask(ids: tuple[str, ...], index: dict[str, int]) -> int:
    m = 0
    for j in ids:
        m ^= 1 << index[j]
    return m


def _insert(basis: dict[int, int], vec: int) -> bool:
    """Gaussian elimination over GF(2); True when ``vec`` is independent of ``basis``."""
    while vec:
        top = vec.bit_length() - 1
        if top not in basis:
            basis[top] = vec
            return True
        vec ^= basis[top]
    return False


#: Above this many links, candidate contours come from the frame's spanning tree only
#: (each chord's fundamental cycle), not from a spanning tree rooted at every link: the
#: all-roots pool costs ``O(N · K · length)`` and only shortens contours.
ALL_ROOTS_MAX_LINKS = 60


def fundamental_cycles(mech: Mechanism, root: str | None = None,
                       _lookup: tuple[dict, dict, dict] | None = None) -> list[tuple[str, ...]]:
    """Fundamental cycles (ordered joint ids) of a BFS spanning tree rooted at ``root``
    (default: the frame)."""
    root = mech.ground if root is None else root
    adj, joints, pos = _lookup if _lookup is not None else _lookups(mech)
    parent: dict[str, tuple[str, str] | None] = {root: None}
    depth = {root: 0}
    queue = deque([root])
    tree: set[str] = set()
    while queue:
        u = queue.popleft()
        for v, jid in adj[u]:
            if v not in parent:
                parent[v] = (u, jid)
                depth[v] = depth[u] + 1
                tree.add(jid)
                queue.append(v)
    cycles = []
    for j in mech.joints:
        if j.id in tree:
            continue
        a, b = j.links
        # paths up to the common ancestor
        pa, pb = [], []
        x, y = a, b
        while depth[x] > depth[y]:
            u, jid = parent[x]  # type: ignore[misc]
            pa.append(jid)
            x = u
        while depth[y] > depth[x]:
            u, jid = parent[y]  # type: ignore[misc]
            pb.append(jid)
            y = u
        while x != y:
            u, jid = parent[x]  # type: ignore[misc]
            pa.append(jid)
            x = u
            u, jid = parent[y]  # type: ignore[misc]
            pb.append(jid)
            y = u
        # walk: from a up to ancestor (pa), down to b (reversed pb), then the chord b-a
        cycle = tuple(reversed(pa)) + tuple(pb) + (j.id,)
        cycles.append(_ordered(joints, pos, cycle))
    return cycles


def _lookups(mech: Mechanism) -> tuple[dict, dict, dict]:
    """Adjacency (link -> [(other link, joint id)]), joints by id and joint positions: built
    once per mechanism, not per cycle."""
    adj: dict[str, list[tuple[str, str]]] = {name: [] for name in mech.link_names}
    for j in mech.joints:
        a, b = j.links
        adj[a].append((b, j.id))
        adj[b].append((a, j.id))
    return adj, {j.id: j for j in mech.joints}, {j.id: i for i, j in enumerate(mech.joints)}


def _ordered(joints: dict, pos: dict, ids: tuple[str, ...]) -> tuple[str, ...]:
    """Order a cycle's joints so that consecutive joints share a link."""
    remaining = list(ids)
    first = remaining.pop()
    order = [first]
    link = joints[first].links[1]
    while remaining:
        for k, jid in enumerate(remaining):
            if link in joints[jid].links:
                order.append(jid)
                link = joints[jid].other(link)
                remaining.pop(k)
                break
        else:  # pragma: no cover - a fundamental cycle is always a closed walk
            raise RuntimeError("not a cycle")
    # start at the joint nearest the file's order for readability
    start = min(range(len(order)), key=lambda k: pos[order[k]])
    order = order[start:] + order[:start]
    if len(order) > 2 and pos[order[-1]] < pos[order[1]]:
        order = [order[0]] + order[1:][::-1]
    assert contour_links([joints[j] for j in order]) is not None
    return tuple(order)


_CACHE: dict[int, tuple[Any, tuple[list[tuple[str, ...]], list[bool]]]] = {}


def independent_contours(
    mech: Mechanism, given: tuple[tuple[str, ...], ...] | None = None
) -> tuple[list[tuple[str, ...]], list[bool]]:
    """A full set of K independent contours and, for each, whether the file gave it
    (computed once per mechanism object: the formulas and the rank method share them).

    See :func:`choose_contours`.
    """
    if given is not None:
        return choose_contours(mech, given)
    hit = _CACHE.get(id(mech))
    if hit is not None and hit[0]() is mech:
        chosen, from_file = hit[1]
        return list(chosen), list(from_file)
    out = choose_contours(mech)
    key = id(mech)
    _CACHE[key] = (weakref.ref(mech, lambda _r, k=key: _CACHE.pop(k, None)), (list(out[0]), list(out[1])))
    return out


def choose_contours(
    mech: Mechanism, given: tuple[tuple[str, ...], ...] | None = None
) -> tuple[list[tuple[str, ...]], list[bool]]:
    """A full set of K independent contours and, for each, whether the file gave it.

    ``given`` defaults to ``mech.contours``. Given contours that depend on earlier ones
    are kept out (a dependent contour carries no new pair). The program's contours are
    the shortest fundamental cycles of breadth-first spanning trees rooted at every link
    (at the frame only above :data:`ALL_ROOTS_MAX_LINKS` links), kept when independent
    over GF(2).
    """
    given = mech.contours if given is None else given
    index = {j.id: i for i, j in enumerate(mech.joints)}
    k_total = cycle_rank(mech)
    basis: dict[int, int] = {}
    chosen: list[tuple[str, ...]] = []
    from_file: list[bool] = []
    for c in given or ():
        if _insert(basis, _mask(c, index)):
            chosen.append(tuple(c))
            from_file.append(True)
    if len(chosen) < k_total:
        lookup = _lookups(mech)
        if len(mech.link_names) <= ALL_ROOTS_MAX_LINKS:
            roots = [mech.ground] + [n for n in mech.link_names if n != mech.ground]
        else:
            roots = [mech.ground]
        pool: dict[int, tuple[str, ...]] = {}
        for root in roots:
            for c in fundamental_cycles(mech, root, lookup):
                pool.setdefault(_mask(c, index), c)
        cands = sorted(pool.values(), key=lambda c: (len(c), sorted(index[j] for j in c)))
        if not chosen and len(roots) == 1:  # one tree's fundamental cycles are independent
            chosen, from_file = cands[:k_total], [False] * min(k_total, len(cands))
            return chosen, from_file
        for c in cands:
            if len(chosen) == k_total:
                break
            if _insert(basis, _mask(c, index)):
                chosen.append(c)
                from_file.append(False)
    return chosen, from_file
