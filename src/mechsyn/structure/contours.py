"""Independent contours of a mechanism's link graph.

Paper 003's per-contour results depend on the contours and their order, so a file may
give them; otherwise :func:`independent_contours` chooses a set: the file's contours
first, then the shortest fundamental cycles of a breadth-first spanning tree rooted at
the frame, kept when independent over GF(2) (cycle space of the graph).
"""

from __future__ import annotations

from collections import deque

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


def fundamental_cycles(mech: Mechanism, root: str | None = None) -> list[tuple[str, ...]]:
    """Fundamental cycles (ordered joint ids) of a BFS spanning tree rooted at ``root``
    (default: the frame)."""
    root = mech.ground if root is None else root
    adj: dict[str, list[tuple[str, str]]] = {name: [] for name in mech.link_names}
    for j in mech.joints:
        a, b = j.links
        adj[a].append((b, j.id))
        adj[b].append((a, j.id))
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
        cycles.append(_ordered(mech, cycle))
    return cycles


def _ordered(mech: Mechanism, ids: tuple[str, ...]) -> tuple[str, ...]:
    """Order a cycle's joints so that consecutive joints share a link."""
    joints = {j.id: j for j in mech.joints}
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
    pos = {j.id: i for i, j in enumerate(mech.joints)}
    start = min(range(len(order)), key=lambda k: pos[order[k]])
    order = order[start:] + order[:start]
    if len(order) > 2 and pos[order[-1]] < pos[order[1]]:
        order = [order[0]] + order[1:][::-1]
    assert contour_links([joints[j] for j in order]) is not None
    return tuple(order)


def independent_contours(
    mech: Mechanism, given: tuple[tuple[str, ...], ...] | None = None
) -> tuple[list[tuple[str, ...]], list[bool]]:
    """A full set of K independent contours and, for each, whether the file gave it.

    ``given`` defaults to ``mech.contours``. Given contours that depend on earlier ones
    are kept out (a dependent contour carries no new pair).
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
        roots = [mech.ground] + [n for n in mech.link_names if n != mech.ground]
        pool: dict[int, tuple[str, ...]] = {}
        for r, root in enumerate(roots):
            for c in fundamental_cycles(mech, root):
                pool.setdefault(_mask(c, index), c)
        cands = sorted(pool.values(), key=lambda c: (len(c), sorted(index[j] for j in c)))
        for c in cands:
            if len(chosen) == k_total:
                break
            if _insert(basis, _mask(c, index)):
                chosen.append(c)
                from_file.append(False)
    return chosen, from_file
