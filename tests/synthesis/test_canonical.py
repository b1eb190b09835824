"""Canonical forms: bliss (python-igraph, the default) and nauty (pynauty) agree."""

from __future__ import annotations

import itertools
import random

import networkx as nx
import pytest

from mechsyn.synthesis import canonical
from mechsyn.synthesis.chains import chain_certificate, synthesize_chains
from mechsyn.synthesis.mechanisms import distinct_mechanisms, frame_orbits

BACKENDS = [b for b in canonical.BACKENDS
            if pytest.importorskip("importlib").util.find_spec(b) is not None]


@pytest.fixture(params=BACKENDS)
def backend(request):
    old = canonical.set_backend(request.param)
    yield request.param
    canonical.set_backend(old)


def _random_graphs(count: int, n: int, seed: int):
    rng = random.Random(seed)
    pairs = list(itertools.combinations(range(n), 2))
    for _ in range(count):
        edges = rng.sample(pairs, rng.randint(n - 1, 2 * n))
        colours = [rng.randint(0, 1) for _ in range(n)]
        yield edges, colours


def test_certificate_equal_iff_isomorphic(backend):
    graphs = list(_random_graphs(60, 6, seed=4))
    rng = random.Random(1)
    for edges, colours in graphs[:20]:  # relabelled copies have the same certificate
        perm = list(range(6))
        rng.shuffle(perm)
        moved = [(perm[a], perm[b]) for a, b in edges]
        moved_colours = [0] * 6
        for v, c in enumerate(colours):
            moved_colours[perm[v]] = c
        assert canonical.certificate(6, edges, colours) == canonical.certificate(6, moved, moved_colours)
    match = nx.algorithms.isomorphism.categorical_node_match("c", None)

    def nxg(edges, colours):
        g = nx.Graph(edges)
        g.add_nodes_from(range(6))
        nx.set_node_attributes(g, dict(enumerate(colours)), "c")
        return g

    for (e1, c1), (e2, c2) in itertools.combinations(graphs, 2):
        same = canonical.certificate(6, e1, c1) == canonical.certificate(6, e2, c2)
        assert same == nx.is_isomorphic(nxg(e1, c1), nxg(e2, c2), node_match=match)


def test_orbits_and_generators(backend):
    square = [(0, 1), (1, 2), (2, 3), (3, 0)]
    assert canonical.orbits(4, square) == [0, 0, 0, 0]
    assert canonical.orbits(4, square, colours=[1, 0, 0, 0]) == [0, 1, 2, 1]
    path = [(0, 1), (1, 2)]
    assert canonical.generators(3, path) == [[2, 1, 0]]
    assert canonical.generators(3, path, colours=[0, 0, 1]) == []


@pytest.mark.skipif(len(BACKENDS) < 2, reason="needs both python-igraph and pynauty")
@pytest.mark.parametrize("links, mobility", [(4, 1), (6, 1), (8, 1), (10, 1), (7, 2), (9, 2)])
def test_both_backends_give_the_same_atlas(links, mobility):
    atlases, certs = {}, {}
    for b in BACKENDS:
        old = canonical.set_backend(b)
        try:
            atlases[b] = synthesize_chains(links, mobility)
            frames = [frame_orbits(c) for c in atlases[b]]
            inputs = [[(m.frame, m.input) for m in distinct_mechanisms(c)] for c in atlases[b][:40]]
            atlases[b] = (atlases[b], frames, inputs)
        finally:
            canonical.set_backend(old)
    (a, fa, ia), (b, fb, ib) = atlases.values()
    assert len(a) == len(b) == {(4, 1): 1, (6, 1): 2, (8, 1): 16, (10, 1): 230,
                                (7, 2): 4, (9, 2): 40}[(links, mobility)]
    assert [c.edges for c in a] == [c.edges for c in b]  # the same chains, same order
    assert fa == fb and ia == ib
    # the certificates differ in form but split any set of graphs into the same classes:
    # the chains plus relabelled copies of each
    rng = random.Random(links)
    graphs = []
    for c in a:
        perm = list(range(links))
        rng.shuffle(perm)
        graphs += [c.edges, [(perm[u], perm[v]) for u, v in c.edges]]
    for name in BACKENDS:
        old = canonical.set_backend(name)
        try:
            certs[name] = [chain_certificate(e, links) for e in graphs]
        finally:
            canonical.set_backend(old)

    def classes(keys):
        groups = {}
        for i, k in enumerate(keys):
            groups.setdefault(k, []).append(i)
        return sorted(groups.values())

    assert classes(certs["igraph"]) == classes(certs["pynauty"])
    assert len(classes(certs["igraph"])) == len(a)


def test_unknown_backend_is_refused():
    with pytest.raises(ValueError):
        canonical.set_backend("nope")
