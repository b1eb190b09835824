"""Contracted multigraphs of planar kinematic chains, the first step of the enumeration in
:mod:`mechsyn.synthesis.chains`.

A chain that is not a single loop contracts to a multigraph on its links of degree >= 3
(its *contracted graph*); each edge is a binary chain (a path of binary links) between
two of them, and a loop an edge from a link to itself. :func:`contracted_graphs` lists
the contracted multigraphs of a link assortment up to isomorphism (canonical certificates
of the multigraph with each edge subdivided, :mod:`mechsyn.synthesis.canonical`);
:func:`edge_automorphisms` gives the permutations of the edges by the graph's automorphism
group; the masks test, vectorised over distributions of the binary links on the edges,
which chains are simple (:func:`simple_mask`) and which degenerate
(:func:`degenerate_mask`, with the proof that the test on the contracted graph is the
complete one).

Examples
--------
>>> # two ternary links and four binary ones: the theta graph of the Watt and Stephenson
>>> # six-bars (binary links on its three edges 0, 2, 2 and 1, 1, 2)
>>> [cg.edges for cg in contracted_graphs([3, 3], n_binary=4, allow_loops=True)]
[((0, 1), (0, 1), (0, 1))]

The method and the chain counts it reproduces (OEIS A233288; Tuttle 1996) are described
in :mod:`mechsyn.synthesis.chains`.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache

import networkx as nx
import numpy as np

from mechsyn.synthesis import canonical

__all__ = ["ContractedGraph", "contracted_graphs", "edge_automorphisms", "compositions", "degenerate_mask",
           "simple_mask", "orbit_representatives", "expand", "has_bridge", "is_fractionated_contracted"]


@dataclass(frozen=True)
class ContractedGraph:
    """A contracted multigraph: vertices 0..m-1 (links of degree >= 3), edges (u, v)
    with u <= v (u == v: a loop), in a fixed order."""

    degrees: tuple[int, ...]
    edges: tuple[tuple[int, int], ...]


# ------------------------------------------------------------- contracted multigraphs


def _subdivided(m: int, edges: Sequence[tuple[int, int]]) -> tuple[int, list, list[int]]:
    """The multigraph with every edge subdivided by an edge vertex (coloured apart):
    vertex count, simple edges and colours for :mod:`mechsyn.synthesis.canonical`."""
    simple = []
    for k, (u, v) in enumerate(edges):
        simple.append((m + k, u))
        if v != u:
            simple.append((m + k, v))
    return m + len(edges), simple, [0] * m + [1] * len(edges)


def contracted_graphs(
    high_degrees: Sequence[int], n_binary: int, allow_loops: bool, degenerate_too: bool = False
) -> list[ContractedGraph]:
    """All connected multigraphs with the given degrees, up to isomorphism.

    Labelled generation (each vertex's partners in non-decreasing order; among untouched
    vertices of equal degree only the first is tried, which loses no isomorphism class),
    pruned by the binary links that a non-degenerate chain needs (``k`` parallel edges
    need ``2 k - 2`` binaries, a loop needs 3; with ``degenerate_too`` what a simple graph
    needs: ``k - 1`` and 2), then one representative per nauty certificate of the
    subdivided multigraph.
    """
    loop_cost, parallel_cost = (2, 1) if degenerate_too else (3, 2)
    degrees = tuple(sorted(high_degrees, reverse=True))
    m = len(degrees)
    if m == 0:
        return []
    residual = list(degrees)
    mult: dict[tuple[int, int], int] = {}
    found: dict[bytes, ContractedGraph] = {}
    edges: list[tuple[int, int]] = []

    def connected() -> bool:
        parent = list(range(m))

        def find(x: int) -> int:
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for u, v in edges:
            parent[find(u)] = find(v)
        root = find(0)
        return all(find(x) == root for x in range(m))

    def rec(i: int, last: int, budget: int) -> None:
        while i < m and residual[i] == 0:
            i += 1
            last = i
        if i == m:
            if connected():
                key = canonical.certificate(*_subdivided(m, edges))
                if key not in found:
                    found[key] = ContractedGraph(degrees, tuple(edges))
            return
        seen_fresh: set[int] = set()
        for j in range(last, m):
            if j == i:
                if not allow_loops or residual[i] < 2:
                    continue
                cost = loop_cost
            else:
                if residual[j] == 0:
                    continue
                if residual[j] == degrees[j] and j > i:  # untouched vertex
                    if degrees[j] in seen_fresh:
                        continue
                    seen_fresh.add(degrees[j])
                k = mult.get((i, j), 0)
                cost = parallel_cost if k >= 1 else 0
            if cost > budget:
                continue
            residual[i] -= 1
            residual[j] -= 1
            mult[(i, j)] = mult.get((i, j), 0) + 1
            edges.append((i, j))
            rec(i, j, budget - cost)
            edges.pop()
            mult[(i, j)] -= 1
            residual[i] += 1
            residual[j] += 1

    rec(0, 0, n_binary)
    return list(found.values())


def edge_automorphisms(cg: ContractedGraph) -> np.ndarray:
    """The automorphism group of the multigraph acting on its edges, all elements.

    nauty's generators of the subdivided multigraph, restricted to the edge vertices,
    closed under composition (the restriction is a homomorphism). Rows are
    permutations ``g`` with the orbit of a labelling ``x`` being ``{x[g]}``.
    """
    m, ne = len(cg.degrees), len(cg.edges)
    gens = canonical.generators(*_subdivided(m, cg.edges))
    identity = tuple(range(ne))
    perms = {tuple(int(g[m + k]) - m for k in range(ne)) for g in gens}
    perms.discard(identity)
    group = {identity}
    frontier = [identity]
    while frontier:
        nxt = []
        for a in frontier:
            for g in perms:
                c = tuple(a[g[k]] for k in range(ne))
                if c not in group:
                    group.add(c)
                    nxt.append(c)
        frontier = nxt
    return np.array(sorted(group), dtype=np.intp).reshape(-1, ne)


@lru_cache(maxsize=256)
def compositions(total: int, parts: int) -> np.ndarray:
    """All ways to write ``total`` as an ordered sum of ``parts`` non-negative ints."""
    if parts == 0:
        return np.zeros((1 if total == 0 else 0, 0), dtype=np.int64)
    bars = np.array(list(itertools.combinations(range(total + parts - 1), parts - 1)),
                    dtype=np.int64).reshape(-1, parts - 1)
    left = np.concatenate([np.full((len(bars), 1), -1), bars], axis=1)
    right = np.concatenate([bars, np.full((len(bars), 1), total + parts - 1)], axis=1)
    return right - left - 1


def degenerate_mask(cg: ContractedGraph, dist: np.ndarray) -> np.ndarray:
    """Which binary-link distributions give a degenerate chain (vectorised).

    Proof of equivalence with the all-subsets test. Write ``g(S) = 2 e(S) - 3 |S| + 3``;
    ``S`` is rigid iff ``g(S) >= 0``. Take ``S`` rigid and minimal. A binary link of
    ``S`` with at most one neighbour in ``S`` can be dropped (``g`` does not decrease,
    and ``|S| >= 2`` is kept since a rigid ``S`` has at least 3 links in a simple graph),
    so a minimal rigid ``S`` is a set ``T`` of links of degree >= 3 plus whole binary
    chains between them. A binary chain with ``c`` links adds ``c`` links and ``c + 1``
    joints, changing ``g`` by ``2 - c``; the best choice takes the chains with ``c <= 2``.
    Hence the chain is degenerate iff for some ``T`` with ``|T| >= 2``
    ``sum over edges inside T of max(0, 2 - c_e) >= 3 |T| - 3``, or a loop has ``c <= 2``.
    """
    m, ne = len(cg.degrees), len(cg.edges)
    gain = np.maximum(0, 2 - dist)
    bad = np.zeros(len(dist), dtype=bool)
    loops = [k for k, (u, v) in enumerate(cg.edges) if u == v]
    if loops:
        bad |= (dist[:, loops] <= 2).any(axis=1)
    subsets = [t for t in range(1, 1 << m) if bin(t).count("1") >= 2]
    if subsets:
        inside = np.array(
            [[1 if ((t >> u) & 1 and (t >> v) & 1) else 0 for (u, v) in cg.edges]
             for t in subsets], dtype=np.int64,
        ).reshape(len(subsets), ne)
        need = np.array([3 * bin(t).count("1") - 3 for t in subsets], dtype=np.int64)
        bad |= ((gain @ inside.T) >= need).any(axis=1)
    return bad


def simple_mask(cg: ContractedGraph, dist: np.ndarray) -> np.ndarray:
    """Distributions that give a simple graph: no two joints between the same links."""
    ok = np.ones(len(dist), dtype=bool)
    groups: dict[tuple[int, int], list[int]] = {}
    for k, e in enumerate(cg.edges):
        groups.setdefault(e, []).append(k)
    for (u, v), ks in groups.items():
        if u == v:
            ok &= (dist[:, ks] >= 2).all(axis=1)  # a loop needs a triangle at least
        elif len(ks) > 1:
            ok &= (dist[:, ks] == 0).sum(axis=1) <= 1
    return ok


def orbit_representatives(dist: np.ndarray, group: np.ndarray, base: int) -> np.ndarray:
    """One distribution per orbit of the edge group: the lexicographically largest image."""
    if len(dist) == 0 or len(group) == 1:
        return dist
    weights = base ** np.arange(dist.shape[1] - 1, -1, -1, dtype=np.int64)
    codes_self = dist @ weights
    keep = np.ones(len(dist), dtype=bool)
    chunk = max(1, 2_000_000 // max(1, len(group) * dist.shape[1]))
    for s in range(0, len(dist), chunk):
        block = dist[s:s + chunk]
        images = block[:, group]  # (b, |G|, E)
        codes = images @ weights  # (b, |G|)
        keep[s:s + chunk] = codes.max(axis=1) == codes_self[s:s + chunk]
    return dist[keep]


def expand(cg: ContractedGraph, counts: Sequence[int]) -> list[tuple[int, int]]:
    """The chain's joints: each contracted edge becomes a path through its binaries."""
    m = len(cg.degrees)
    nxt = m
    out: list[tuple[int, int]] = []
    for (u, v), c in zip(cg.edges, counts):
        prev = u
        for _ in range(int(c)):
            out.append((prev, nxt))
            prev = nxt
            nxt += 1
        out.append((prev, v))
    return [(a, b) if a < b else (b, a) for a, b in out]


def has_bridge(cg: ContractedGraph) -> bool:
    g = nx.MultiGraph()
    g.add_nodes_from(range(len(cg.degrees)))
    g.add_edges_from(cg.edges)
    return nx.has_bridges(g) if g.number_of_edges() else False


def is_fractionated_contracted(cg: ContractedGraph) -> bool:
    """Cut link of the expanded chain: a cut vertex of the contracted multigraph, or a
    vertex with a loop and other edges (binary links never cut a bridgeless chain)."""
    m = len(cg.degrees)
    if m == 1:
        return sum(1 for u, v in cg.edges if u == v) >= 2
    g = nx.Graph()
    g.add_nodes_from(range(m))
    g.add_edges_from((u, v) for u, v in cg.edges if u != v)
    if any(True for _ in nx.articulation_points(g)):
        return True
    return any(u == v for u, v in cg.edges)
