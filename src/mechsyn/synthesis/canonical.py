"""Canonical forms and automorphisms of vertex-coloured graphs: bliss (igraph) or nauty.

The atlas of kinematic chains needs three things of a small vertex-coloured graph: a
*certificate* (equal for two graphs iff they are isomorphic by a colour-preserving map),
*generators* of its automorphism group, and the group's *orbits* on the vertices. Two
back ends give them:

* ``"igraph"`` (default): python-igraph's interface to bliss (Junttila and Kaski 2007),
  with wheels for Linux, macOS and Windows;
* ``"pynauty"`` (optional, ``pip install pynauty``; no Windows wheels): nauty (McKay and
  Piperno 2014).

Both give the same isomorphism classes, groups and orbits; the certificates themselves
differ (each is a canonical labelling of its own). Choose with :func:`set_backend` or
the environment variable ``MECHSYN_GRAPH_BACKEND``.

References
----------
T. Junttila and P. Kaski, "Engineering an efficient canonical labeling tool for large
and sparse graphs", Proc. 9th Workshop on Algorithm Engineering and Experiments
(ALENEX), SIAM, 135-149, 2007.

B. D. McKay and A. Piperno, "Practical graph isomorphism, II", Journal of Symbolic
Computation 60, 94-112, 2014.

Examples
--------
>>> square = [(0, 1), (1, 2), (2, 3), (3, 0)]
>>> certificate(4, square) == certificate(4, [(0, 2), (2, 1), (1, 3), (3, 0)])
True
>>> orbits(4, square, colours=[0, 1, 1, 1])
[0, 1, 2, 1]
"""

from __future__ import annotations

import functools
import os
import threading
from collections.abc import Sequence

BACKENDS = ("igraph", "pynauty")
_state = {"backend": os.environ.get("MECHSYN_GRAPH_BACKEND", "igraph")}

__all__ = ["BACKENDS", "NATIVE_LOCK", "get_backend", "set_backend", "preload", "certificate", "generators",
           "orbits"]

#: One process-wide lock around every call into bliss (igraph) and nauty: neither is
#: documented as thread-safe, and bliss aborts the whole process (SIGABRT) on an error
#: raised while another thread is inside it (issue 27: a bad chain sent to the studio
#: while its atlas list ran killed the server).
NATIVE_LOCK = threading.RLock()


def get_backend() -> str:
    """The back end in use (``"igraph"`` unless changed)."""
    return _state["backend"]


def set_backend(name: str) -> str:
    """Use ``name`` (one of :data:`BACKENDS`) from now on; returns the previous one.

    Raises ``ImportError`` with the install hint if its package is missing."""
    if name not in BACKENDS:
        raise ValueError(f"unknown graph back end {name!r}; one of {', '.join(BACKENDS)}")
    _module(name)
    old, _state["backend"] = _state["backend"], name
    return old


def _module(name: str):
    try:
        if name == "igraph":
            import igraph

            return igraph
        import pynauty

        return pynauty
    except ImportError:
        from mechsyn._extras import missing

        package = "python-igraph" if name == "igraph" else "pynauty"
        raise missing(package if name == "igraph" else "pynauty", f"the graph back end {name!r}") from None


def preload() -> None:
    """Import the back end in use now (before local worker processes are forked, which
    then inherit it: igraph's import, with the Matplotlib it loads, costs each process
    about a second)."""
    _module(get_backend())


def _check_colours(n: int, colours: Sequence[int] | None) -> None:
    """One colour per vertex, else ``ValueError`` (bliss aborts the process on a colour
    vector of another length)."""
    if colours is not None and len(colours) != n:
        raise ValueError(f"{len(colours)} colours for {n} vertices")


def _colour_classes(n: int, colours: Sequence[int] | None) -> list[int]:
    """Colours as small integers 0..k-1 in order of first value (both back ends)."""
    _check_colours(n, colours)
    if colours is None:
        return [0] * n
    order = {c: i for i, c in enumerate(sorted(set(colours)))}
    return [order[c] for c in colours]


def _nauty_graph(n: int, edges, colours):
    pynauty = _module("pynauty")
    adj: dict[int, list[int]] = {v: [] for v in range(n)}
    for a, b in edges:
        if not (0 <= a < n and 0 <= b < n):
            raise ValueError(f"edge {(a, b)!r} names a vertex outside 0..{n - 1}")
        if a != b:
            adj[a].append(b)
    classes: dict[int, set[int]] = {}
    for v, c in enumerate(colours):
        classes.setdefault(c, set()).add(v)
    colouring = [classes[c] for c in sorted(classes)] if len(classes) > 1 else []
    return pynauty.Graph(n, directed=False, adjacency_dict=adj, vertex_coloring=colouring)


def _igraph(n: int, edges):
    """igraph's C graph (``GraphBase``: the Python ``Graph`` wrapper's set-up costs more
    than bliss on these small graphs), loops left out."""
    ig = _module("igraph")
    g = ig.GraphBase(n, edges if all(a != b for a, b in edges) else
                     [(a, b) for a, b in edges if a != b])
    if g.vcount() != n:  # igraph adds the vertices an edge names beyond n - 1
        raise ValueError(f"an edge names a vertex outside 0..{n - 1}")
    return g


@functools.lru_cache(maxsize=1)
def _moves_to_index() -> bool:
    """True when igraph's ``permute_vertices(p)`` sends vertex ``v`` to ``p[v]`` (0.10,
    0.11), False when vertex ``p[i]`` becomes ``i`` (1.0): probed once on a tiny graph."""
    with NATIVE_LOCK:
        h = _igraph(3, [(0, 1)]).permute_vertices([2, 0, 1])
    return sorted(h.get_edgelist()[0]) == [0, 2]


def certificate(n: int, edges: Sequence[tuple[int, int]],
                colours: Sequence[int] | None = None) -> bytes:
    """Canonical certificate of a simple graph on ``0..n-1`` (edges undirected, no
    loops) with vertex ``colours``: equal iff the graphs are isomorphic by a map that
    keeps the colours (compare certificates of one back end only)."""
    col = _colour_classes(n, colours)
    if get_backend() == "pynauty":
        with NATIVE_LOCK:
            return _module("pynauty").certificate(_nauty_graph(n, edges, col))
    moves = _moves_to_index()
    with NATIVE_LOCK:
        g = _igraph(n, edges)
        order = g.canonical_permutation(color=col if colours is not None else None)
        # permute_vertices(canonical_permutation()) is canonical in every igraph version; the
        # colours travel with the vertices, and igraph 1.0 reversed the meaning of the
        # permutation vector (0.10/0.11: vertex v goes to order[v]; 1.0: the vertex at i is order[i])
        canonical = g.permute_vertices(order)
    flat = bytes(v for e in sorted(tuple(sorted(e)) for e in canonical.get_edgelist()) for v in e)
    if colours is None:
        labels = b""
    elif moves:
        new = [0] * n
        for v, i in enumerate(order):
            new[i] = col[v]
        labels = bytes(new)
    else:
        labels = bytes(col[v] for v in order)
    return bytes([n & 255, n >> 8, len(labels) > 0]) + labels + flat


def generators(n: int, edges: Sequence[tuple[int, int]],
               colours: Sequence[int] | None = None) -> list[list[int]]:
    """Generators of the colour-preserving automorphism group, each a list ``g`` with
    vertex ``v`` mapped to ``g[v]`` (the identity group: an empty list)."""
    col = _colour_classes(n, colours)
    with NATIVE_LOCK:
        if get_backend() == "pynauty":
            gens = _module("pynauty").autgrp(_nauty_graph(n, edges, col))[0]
        else:
            gens = _igraph(n, edges).automorphism_group(color=col)
    identity = list(range(n))
    return [list(map(int, g)) for g in gens if list(g) != identity]


def orbits(n: int, edges: Sequence[tuple[int, int]],
           colours: Sequence[int] | None = None) -> list[int]:
    """Orbit of every vertex under the automorphism group, as the smallest vertex of
    its orbit (the same labels from both back ends)."""
    parent = list(range(n))

    def find(x: int) -> int:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for g in generators(n, edges, colours):
        for v, w in enumerate(g):
            a, b = find(v), find(w)
            if a != b:
                parent[max(a, b)] = min(a, b)
    return [find(v) for v in range(n)]
