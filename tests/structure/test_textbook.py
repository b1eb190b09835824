"""Textbook mechanisms: their known mobility and structure."""

import pytest

from conftest import EXAMPLES

T = EXAMPLES / "textbook"


@pytest.mark.parametrize(
    "name, W, K",
    [("fourbar", 1, 1), ("slider_crank", 1, 1), ("watt_sixbar", 1, 2), ("stephenson_sixbar", 1, 2),
     ("five_bar_5r", 2, 1), ("cam_follower", 2, 1)],
)
def test_mobility(cli_json, name, W, K):
    d = cli_json("analyze", T / f"{name}.yaml")
    # issue 3: with geometry the top-level mobility is the rank method's useful mobility (the
    # cam's roller spin is idle: 2 - 1); the formulas' W is kept under mobility_formulas.
    assert d.get("mobility_formulas", d["mobility"]) == W
    assert d["mobility"] == W - len(d["rank"]["idle_mobilities"])
    assert d["formulas"]["chebyshev"]["value"] == W
    assert d["formulas"]["grubler"]["value"] == W
    assert d["independent_contours"] == K


def test_fourbar_as_space_mechanism_has_three_redundant_constraints(cli_json):
    d = cli_json("analyze", T / "fourbar.yaml")
    # Malyshev: 6·3 - 5·4 = -2; the per-contour count gives S = 3, W = 1
    assert d["formulas"]["malyshev"]["value"] == -2
    assert d["structural_redundancy"] == 3
    assert d["formulas"]["somov_malyshev"]["value"] == 1


def test_cam_roller_is_a_redundant_link(cli_json):
    d = cli_json("analyze", T / "cam_follower.yaml")
    # Chebyshev W = 2: one useful mobility and the roller's spin; Z = 1 redundant link
    assert d["redundant_links"] == 1


def test_contours_chosen_when_not_given(cli_json):
    d = cli_json("analyze", T / "watt_sixbar.yaml")
    assert d["contours_chosen_by_program"] is True
    assert all(not c["from_file"] for c in d["contours"])
    assert any("chosen by the program" in n for n in d["notes"])
    # every chosen contour is a closed loop of the file's joints
    assert sorted(len(c["joints"]) for c in d["contours"]) == [4, 4]
