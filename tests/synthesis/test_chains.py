"""Number and topological synthesis of planar kinematic chains (issue 7)."""

from __future__ import annotations

import itertools
import json

import networkx as nx
import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.chains import (
    chain_certificate,
    is_degenerate,
    is_fractionated,
    link_assortments,
    read_chain_stream,
    rigid_subchain,
    synthesize_chains,
    synthesize_chains_to_file,
)

# Literature counts (OEIS A233288; Tuttle 1996): (links, mobility) ->
# (chains, chains with a non-planar graph, chains not fractionated)
COUNTS = {
    (4, 1): (1, 0, 1),
    (6, 1): (2, 0, 2),
    (8, 1): (16, 0, 16),
    (10, 1): (230, 11, 230),
    (5, 2): (1, 0, 1),
    (7, 2): (4, 0, 3),
    (9, 2): (40, 0, 35),
}


@pytest.mark.parametrize("n,f", sorted(COUNTS))
def test_counts_match_literature(n, f):
    chains = synthesize_chains(n, f)
    count, nonplanar, not_fractionated = COUNTS[(n, f)]
    assert len(chains) == count
    assert sum(not c.planar_graph for c in chains) == nonplanar
    assert sum(not c.fractionated for c in chains) == not_fractionated
    assert len({c.certificate for c in chains}) == count  # pairwise non-isomorphic


@pytest.mark.slow
@pytest.mark.parametrize("n,f,count,nonplanar,not_frac", [(12, 1, 6856, 938, 6856),
                                                          (11, 2, 839, None, 753)])
def test_counts_12_links_and_11_links_mobility_2(n, f, count, nonplanar, not_frac):
    chains = synthesize_chains(n, f)
    assert len(chains) == count
    if nonplanar is not None:
        assert sum(not c.planar_graph for c in chains) == nonplanar
    assert sum(not c.fractionated for c in chains) == not_frac


def test_chain_properties_checked_independently():
    """Every 10-link chain: Gruebler mobility 1, simple, degree >= 2, no rigid subset
    (all-subsets test), flags equal to networkx's planarity and articulation points."""
    for c in synthesize_chains(10, 1):
        g = c.graph()
        assert 3 * (c.n_links - 1) - 2 * g.number_of_edges() == 1
        assert len(set(c.edges)) == len(c.edges)
        assert min(d for _, d in g.degree()) >= 2
        assert rigid_subchain(c.edges, c.n_links) is None
        assert nx.check_planarity(g)[0] == c.planar_graph
        assert is_fractionated(c.edges) == c.fractionated
        deg = c.degrees()
        assert {d: deg.count(d) for d in set(deg)} == c.assortment


def test_degenerate_flags_agree_with_all_subsets_test():
    chains = synthesize_chains(8, 1, include_degenerate=True)
    assert sum(not c.degenerate for c in chains) == 16
    assert any(c.degenerate for c in chains)
    for c in chains:
        assert c.degenerate == is_degenerate(c.edges, c.n_links)


def _brute_force(n, f):
    """Every simple graph with n vertices, min degree 2, connected, bridgeless and
    Gruebler mobility f, up to isomorphism (nauty certificates): independent of the
    contracted-graph enumeration."""
    j = (3 * (n - 1) - f) // 2
    pairs = list(itertools.combinations(range(n), 2))
    certs = {}
    for chosen in itertools.combinations(range(len(pairs)), j):
        deg = [0] * n
        for k in chosen:
            a, b = pairs[k]
            deg[a] += 1
            deg[b] += 1
        if min(deg) < 2:
            continue
        edges = [pairs[k] for k in chosen]
        g = nx.Graph(edges)
        if not nx.is_connected(g) or nx.has_bridges(g):
            continue
        certs.setdefault(chain_certificate(edges, n), edges)
    return certs


@pytest.mark.slow
@pytest.mark.parametrize("n,f", [(6, 1), (7, 2)])
def test_enumeration_equals_brute_force(n, f):
    brute = _brute_force(n, f)
    ours = synthesize_chains(n, f, include_degenerate=True)
    assert {c.certificate for c in ours} == set(brute)
    for c in ours:
        assert c.degenerate == is_degenerate(brute[c.certificate], n)


def test_cospectral_chains_are_distinguished():
    """Two 10-link chains with the same adjacency spectrum are both listed: the
    canonical form (nauty) separates what spectra (or degree sequences) cannot."""
    chains = synthesize_chains(10, 1)
    by_spectrum = {}
    for c in chains:
        spec = tuple(np.round(np.linalg.eigvalsh(nx.to_numpy_array(c.graph())), 8))
        by_spectrum.setdefault(spec, []).append(c)
    pairs = [v for v in by_spectrum.values() if len(v) > 1]
    assert pairs, "the 10-link atlas contains cospectral chains"
    for group in pairs:
        a, b = group[:2]
        assert not nx.is_isomorphic(a.graph(), b.graph())
        assert a.certificate != b.certificate


def test_certificate_is_a_canonical_form():
    edges = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (4, 5), (5, 2)]
    perm = [3, 5, 0, 1, 4, 2]
    relabelled = [(perm[a], perm[b]) for a, b in edges]
    assert chain_certificate(edges, 6) == chain_certificate(relabelled, 6)
    # the classic cospectral pair: K_{1,4} and C_4 + K_1, not isomorphic
    star = [(0, 1), (0, 2), (0, 3), (0, 4)]
    square = [(0, 1), (1, 2), (2, 3), (3, 0)]
    assert np.allclose(np.linalg.eigvalsh(_adjacency(star, 5)),
                       np.linalg.eigvalsh(_adjacency(square, 5)))
    assert chain_certificate(star, 5) != chain_certificate(square, 5)


def _adjacency(edges, n):
    g = nx.Graph(edges)
    g.add_nodes_from(range(n))
    return nx.to_numpy_array(g, nodelist=range(n))


def test_degeneracy_hand_made_cases():
    # a triangle inside a chain: rigid three-link sub-chain
    watt_with_triangle = [(0, 1), (1, 2), (2, 0), (2, 3), (3, 4), (4, 0)]
    assert rigid_subchain(watt_with_triangle) == (0, 1, 2)
    # no triangle, but K_{2,3} (5 links, 6 joints: 3*4 - 2*6 = 0) is rigid: the kind of
    # sub-chain a triangle heuristic lets through (Pyslvs's 4 extra 10-link chains)
    k23 = [(0, 2), (0, 3), (0, 4), (1, 2), (1, 3), (1, 4)]
    chain = k23 + [(2, 5), (5, 6), (6, 7), (7, 8), (8, 9), (9, 3), (4, 6)]
    g = nx.Graph(chain)
    assert sum(nx.triangles(g).values()) == 0
    assert 3 * (g.number_of_nodes() - 1) - 2 * g.number_of_edges() == 1
    assert set(rigid_subchain(chain)) == {0, 1, 2, 3, 4}
    # Watt and Stephenson six-bars and the four-bar are not degenerate
    assert not is_degenerate([(0, 1), (1, 2), (2, 3), (3, 0)])
    watt = [(0, 1), (0, 2), (0, 3), (1, 4), (2, 4), (3, 5), (4, 5)]
    assert not is_degenerate(watt)
    # two joints between the same two links: rigid pair
    assert is_degenerate([(0, 1), (0, 1)], 2)


def test_link_assortments_number_synthesis():
    assert link_assortments(4, 1) == [{2: 4}]
    assert {2: 4, 3: 2} in link_assortments(6, 1)
    eight = link_assortments(8, 1)
    for a in ({2: 4, 3: 4}, {2: 5, 3: 2, 4: 1}, {2: 6, 4: 2}):
        assert a in eight
    for a in eight:
        assert sum(a.values()) == 8
        assert sum(d * c for d, c in a.items()) == 2 * 10
    realised = {tuple(sorted(c.assortment.items())) for c in synthesize_chains(8, 1)}
    assert realised == {((2, 4), (3, 4)), ((2, 5), (3, 2), (4, 1)), ((2, 6), (4, 2))}


@pytest.mark.parametrize("n,f", [(5, 1), (1, 1), (6, 0)])
def test_bad_requests(n, f):
    with pytest.raises(MechsynInputError):
        synthesize_chains(n, f)


def test_stream_and_resume(tmp_path):
    path = tmp_path / "chains.jsonl"
    full = synthesize_chains_to_file(path, 9, 2)
    assert len(full) == 40
    lines = path.read_text().splitlines()
    # simulate an interrupted run: keep the first completed assortment and a torn line
    dones = [i for i, l in enumerate(lines) if '"done"' in l]
    cut = dones[-2]
    path.write_text("\n".join(lines[: cut + 2]) + "\n" + lines[cut + 2][:7])
    partial = read_chain_stream(path)
    assert 0 < len(partial) < 40
    calls = []
    resumed = synthesize_chains_to_file(path, 9, 2, progress=calls.append)
    assert [c.certificate for c in resumed] == [c.certificate for c in full]
    assert len(read_chain_stream(path)) == 40
    with pytest.raises(MechsynInputError):
        synthesize_chains_to_file(path, 10, 1)
    assert all(json.loads(l) for l in path.read_text().splitlines())
