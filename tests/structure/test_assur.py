"""Assur group decomposition (issue 7): textbook mechanisms, the spec's examples, paper 000."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure.assur import assur_decomposition, group_class

EX = Path(__file__).resolve().parents[2] / "examples"


def _summary(path):
    d = assur_decomposition(load_mechanism(EX / path))
    return d, [(g.group_class, g.order, set(g.links)) for g in d.groups]


def test_four_bar_is_I_plus_dyad():
    d, groups = _summary("textbook/fourbar.yaml")
    assert groups == [(1, 1, {"crank"}), (2, 2, {"coupler", "rocker"})]
    assert d.structural_formula == "I(frame,crank) -> II(coupler,rocker)"
    assert d.mechanism_class == 2


@pytest.mark.parametrize("path", ["textbook/watt_sixbar.yaml", "textbook/stephenson_sixbar.yaml",
                                  "textbook/slider_crank.yaml"])
def test_six_bars_and_slider_crank_are_class_II(path):
    d, groups = _summary(path)
    assert d.mechanism_class == 2
    assert [g[0] for g in groups] == [1] + [2] * (len(groups) - 1)
    assert all(g[1] == 2 for g in groups[1:])
    assert sum(len(g[2]) for g in groups) == load_mechanism(EX / path).n_moving


def test_triad_is_class_III_order_3():
    mech = mechanism_from_dict({
        "name": "triad", "kind": "planar", "ground": "frame",
        "links": ["frame", "crank", "T", "b1", "b2", "b3"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "b1"]},
            {"id": "C", "type": "R", "links": ["b1", "T"]},
            {"id": "D", "type": "R", "links": ["T", "b2"]},
            {"id": "E", "type": "R", "links": ["b2", "frame"]},
            {"id": "F", "type": "R", "links": ["T", "b3"]},
            {"id": "G", "type": "R", "links": ["b3", "frame"]}]})
    d = assur_decomposition(mech)
    assert [(g.group_class, g.order) for g in d.groups] == [(1, 1), (3, 3)]
    assert d.structural_formula == "I(frame,crank) -> III(T,b1,b2,b3)"


def test_class_IV_group_from_its_four_link_contour():
    assert group_class(("a", "b", "c", "d"), [("a", "b"), ("b", "c"), ("c", "d"), ("d", "a")]) == 4
    assert group_class(("a", "b"), [("a", "b")]) == 2


def test_gripper_002_plane_scheme_two_triads():
    """Paper 002 fig. 1 (plane scheme): the slider is the input; each jaw with its rod and
    two rockers is a class III group of order 3 (the jaw is the triad's base link)."""
    d, groups = _summary("structural/gripper_002_fig1_plane.yaml")
    assert groups[0] == (1, 1, {"slider1"})
    assert groups[1:] == [(3, 3, {"rod2", "rocker3", "jaw4", "rocker5"}),
                          (3, 3, {"rod6", "rocker7", "jaw8", "rocker9"})]
    assert d.mechanism_class == 3


def test_two_phalanx_finger_base_000():
    """Paper 000 fig. 2b: W0 = 2 with one drive: the proximal phalanx is an imaginary
    input link; distal phalanx and rod form a dyad; the proximal phalanx and the rod are
    the binary links to make ternary (m0 = 2(W0 - 1) = 2 free leashes)."""
    d, groups = _summary("fingers/two_phalanx_base_000.yaml")
    assert d.mobility == 2
    assert set(d.input_links) == {"crank", "proximal"}
    assert d.imaginary_input_links == ("proximal",)
    assert (2, 2, {"distal", "rod"}) in groups
    assert set(d.leash_candidates) == {"proximal", "rod"}
    assert len(d.leash_candidates) == 2 * (d.mobility - 1)
    assert d.output_links == ("distal",)


def test_cam_follower_higher_pair_replaced():
    d, groups = _summary("textbook/cam_follower.yaml")
    assert d.replaced_higher_pairs and "~K" in d.replaced_higher_pairs[0]
    assert any("~K" in g[2] for g in groups)


def test_structure_cli_json_contract(capsys):
    assert main(["structure", str(EX / "textbook/watt_sixbar.yaml"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["mechanism_class"] == 2
    assert [g["class"] for g in data["groups"]] == [2, 2]
    assert all({"class", "order", "links"} <= set(g) for g in data["groups"])
    assert main(["structure", str(EX / "fingers/two_phalanx_base_000.yaml")]) == 0
    assert "II(distal,rod)" in capsys.readouterr().out


def test_structure_bad_input(capsys, tmp_path):
    assert main(["structure", str(EX / "structural/gripper_003.yaml")]) == 2  # spatial
    assert "planar" in capsys.readouterr().err
    assert main(["structure", str(EX / "textbook/fourbar.yaml"), "--output", "nope"]) == 2
    rigid = mechanism_from_dict({
        "name": "triangle", "kind": "planar", "ground": "f", "links": ["f", "a", "b"],
        "joints": [{"id": "A", "type": "R", "links": ["f", "a"]},
                   {"id": "B", "type": "R", "links": ["a", "b"]},
                   {"id": "C", "type": "R", "links": ["b", "f"]}]})
    with pytest.raises(MechsynInputError):
        assur_decomposition(rigid)


def test_three_phalanx_finger_base_000():
    """W0 = 3 with one drive: two imaginary inputs, the proximal phalanx (on the palm) and
    the distal phalanx (on the middle one, a pair between moving links)."""
    d, groups = _summary("fingers/three_phalanx_base_000.yaml")
    assert d.mobility == 3
    assert set(d.imaginary_input_links) == {"proximal", "distal"}
    assert (2, 2, {"middle", "rod"}) in groups
    assert d.structural_formula.endswith("I(middle,distal)")
