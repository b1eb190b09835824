"""Paper 002 (paired crank-slider grippers, variable structure): the spec's section 3."""

import pytest

from conftest import EXAMPLES

S = EXAMPLES / "structural"


@pytest.mark.parametrize("fig", [1, 2])
def test_plane_scheme(cli_json, fig):
    d = cli_json("analyze", S / f"gripper_002_fig{fig}_plane.yaml")
    assert d["moving_links"] == 9 and d["links_with_frame"] == 10
    assert d["pairs_by_class"] == {"5": 13}
    assert d["formulas"]["grubler"]["value"] == 1
    assert d["formulas"]["grubler"]["expression"] == "W = 3(10 - 1) - 2·13 - 0 = 1"
    assert d["formulas"]["chebyshev"]["value"] == 1
    assert d["independent_contours"] == 4
    assert d["formulas"]["scheme_check"]["expression"] == "p = N + K - 1: 13 = 10 + 4 - 1 = 13"
    assert d["mobility"] == 1


@pytest.mark.parametrize("fig", [1, 2])
def test_spatial_scheme(cli_json, fig):
    d = cli_json("analyze", S / f"gripper_002_fig{fig}_spatial.yaml")
    q = d["formulas"]["ozol_redundant"]
    assert q["value"] == 11
    assert q["expression"].startswith("q = 1 + 6·4 - 14 = 11")
    # three in each parallelogram contour, two and three in the other two
    assert [c["S"] for c in d["contours"]] == [3, 3, 2, 3]


@pytest.mark.parametrize("fig", [1, 2])
def test_remedy(cli_json, fig):
    d = cli_json("analyze", S / f"gripper_002_fig{fig}_remedy.yaml")
    assert d["pairs_by_class"] == {"3": 8, "4": 1, "5": 4}
    q = d["formulas"]["ozol_redundant"]
    # W = 1 + 5 idle mobilities = 6 (declared in the file, as the paper states it)
    assert q["value"] == 0
    assert q["expression"] == "q = 6 + 6·4 - 30 = 0 (f = 4·1 + 1·2 + 8·3)"


@pytest.mark.parametrize("fig", [1, 2])
def test_clamped_external_constraints(cli_json, fig):
    d = cli_json("analyze", S / f"gripper_002_fig{fig}_spatial.yaml")
    ext = d["states"]["clamped"]["external"]
    assert (ext["S_a"], ext["W_f"], ext["W_rob"], ext["W_a"], ext["S_ai"]) == (11, 1, 0, 6, 1)
    assert ext["external_redundant"]["value"] == 5
    assert ext["external_redundant"]["expression"] == "σ_a = 11 - [(1 - 0) + 6 - 1] = 5"


def test_remedy_clamped_whole_system(cli_json):
    d = cli_json("analyze", S / "gripper_002_fig1_remedy.yaml")
    ext = d["states"]["clamped"]["external"]
    assert ext["S_i"] == 48 and ext["S"] == 59
    assert ext["system_redundant"]["value"] == 0
    assert ext["external_redundant"]["value"] == 5
    pl = d["states"]["clamped_point_line"]["external"]
    assert pl["S_a"] == 6
    assert pl["external_redundant"]["value"] == 0
    # the clamped state is analysed as a whole too: the object is one more moving link
    assert d["states"]["clamped"]["moving_links"] == 10
    assert d["states"]["clamped"]["independent_contours"] == 6
