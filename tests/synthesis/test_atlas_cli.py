"""`mechsyn atlas` and the mechanisms derived from chains (issue 7)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from mechsyn.cli.main import main
from mechsyn.synthesis.chains import synthesize_chains
from mechsyn.synthesis.mechanisms import (
    chain_layout,
    distinct_mechanisms,
    frame_orbits,
    instantaneous_mobility,
    mechanism_dict,
)


def test_six_bar_inversions_watt_2_stephenson_3():
    by_triangles = {}
    for chain in synthesize_chains(6, 1):
        ternaries = [v for v, d in enumerate(chain.degrees()) if d == 3]
        watt = tuple(sorted(ternaries)) in chain.edges  # the two ternary links jointed
        by_triangles["watt" if watt else "stephenson"] = len(frame_orbits(chain))
    assert by_triangles == {"watt": 2, "stephenson": 3}


@pytest.mark.parametrize("n,total", [(4, 1), (6, 5), (8, 71), (10, 1834)])
def test_inversions_by_choice_of_frame(n, total):
    # distinct single-dof mechanisms by choice of frame: 1, 5, 71, 1834 (literature)
    assert sum(len(frame_orbits(c)) for c in synthesize_chains(n, 1)) == total


def test_mechanisms_with_input_are_orbit_representatives():
    four_bar = synthesize_chains(4, 1)[0]
    assert [(m.frame, m.input) for m in distinct_mechanisms(four_bar)] == [(0, 1)]
    for chain in synthesize_chains(6, 1):
        choices = distinct_mechanisms(chain)
        g = chain.graph()
        assert all(m.input in g[m.frame] for m in choices)
        # the equivalent choices add up to every (frame, adjacent input) pair
        assert sum(m.equivalent_frames * m.equivalent_inputs for m in choices) == 2 * len(chain.edges)


def test_layout_is_generic_instantaneous_mobility_equals_gruebler():
    for chain in synthesize_chains(9, 2) + synthesize_chains(8, 1):
        _, points = chain_layout(chain)
        assert instantaneous_mobility(chain.n_links, chain.edges, points) == chain.mobility
        d = np.linalg.norm(points[:, None] - points[None], axis=2) + np.eye(len(points)) * 1e9
        assert d.min() > 1.0


def test_instantaneous_mobility_sees_a_singular_geometry():
    # a four-bar folded flat on a line is singular: mobility 2 at that instant
    edges = [(0, 1), (1, 2), (2, 3), (0, 3)]
    flat = np.array([[0, 0], [1, 0], [2, 0], [3, 0]], dtype=float)
    assert instantaneous_mobility(4, edges, flat) == 2
    assert instantaneous_mobility(4, edges, np.array([[0, 0], [0, 1], [3, 1.5], [3, 0]])) == 1


def test_atlas_json_contract(capsys):
    assert main(["atlas", "--links", "7", "--mobility", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["count"] == 4
    # number synthesis: every solution of the assortment equations is listed
    rows = {r["label"]: r["chains"] for r in data["assortments"]}
    assert rows == {"6B 1Q": 1, "5B 2T": 3}
    assert sum(c["fractionated"] for c in data["chains"]) == 1
    for chain in data["chains"]:
        assert {"assortment", "edges", "degenerate", "fractionated", "planar_graph"} <= set(chain)
        assert sum(chain["assortment"].values()) == 7
        assert len(chain["edges"]) == 8


def test_atlas_table_and_degenerate_listing(capsys):
    assert main(["atlas", "-n", "6", "--include-degenerate", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["count"] == 2 and data["degenerate_listed"] >= 1
    assert main(["atlas", "-n", "6"]) == 0
    assert "4B 2T" in capsys.readouterr().out


def test_atlas_drawing_and_mechanism_files(tmp_path, capsys):
    out = tmp_path / "atlas.png"
    assert main(["atlas", "-n", "6", "--out", str(out), "--mechanisms",
                 str(tmp_path / "m")]) == 0
    assert out.stat().st_size > 10_000
    files = sorted((tmp_path / "m").glob("*.yaml"))
    assert len(files) == 2
    for f in files:
        doc = yaml.safe_load(f.read_text())
        assert doc["kind"] == "planar" and doc["ground"] in doc["links"]
        assert all(j["type"] == "R" and len(j["point"]) == 2 for j in doc["joints"])
        n = len(doc["links"])
        assert 3 * (n - 1) - 2 * len(doc["joints"]) == 1
        assert sum(bool(j.get("actuated")) for j in doc["joints"]) == 1
        index = {name: i for i, name in enumerate(doc["links"])}
        edges = [tuple(index[x] for x in j["links"]) for j in doc["joints"]]
        pts = np.array([j["point"] for j in doc["joints"]])
        assert instantaneous_mobility(n, edges, pts, frame=index[doc["ground"]]) == 1


@pytest.mark.parametrize("args", [["atlas", "-n", "5", "-F", "1"],
                                  ["atlas", "-n", "6", "--out", "x.txt"],
                                  ["atlas", "-n", "6", "-F", "0"]])
def test_atlas_bad_input_exits_2(args, capsys):
    assert main(args) == 2
    assert "error" in capsys.readouterr().err


def test_mechanism_dict_frame_choice():
    chain = synthesize_chains(6, 1)[0]
    doc = mechanism_dict(chain, frame=1, input_link=3)
    assert doc["ground"] == "L1"
    act = [j for j in doc["joints"] if j.get("actuated")]
    assert act[0]["links"] == ["L1", "L3"]


@pytest.mark.parametrize("n,f", [(8, 1), (7, 2)])
def test_mechanism_files_pass_analyze(tmp_path, capsys, n, f):
    """Every chain's mechanism file loads with the model and `mechsyn analyze` finds
    the chain's mobility."""
    from mechsyn.io import load_mechanism

    assert main(["atlas", "-n", str(n), "-F", str(f), "--mechanisms", str(tmp_path)]) == 0
    capsys.readouterr()
    files = sorted(tmp_path.glob("*.yaml"))
    assert len(files) == {8: 16, 7: 4}[n]
    for path in files:
        mech = load_mechanism(path)
        assert mech.n_moving == n - 1
        assert sum(j.actuated for j in mech.joints) == f
        assert main(["analyze", str(path), "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["mobility"] == f
