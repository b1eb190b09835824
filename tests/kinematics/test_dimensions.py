"""Issue 40: dimensions typed as design variables, re-assembled on the drawn branch."""

from __future__ import annotations

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.dimensions import dimensions, link_lengths, set_length, set_side, set_slider


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


@pytest.mark.parametrize("link, value", [("rocker", 3.2), ("coupler", 3.0), ("crank", 1.3), ("frame", 4.4)])
def test_one_length_changes_the_others_stay_and_the_branch_is_kept(link, value):
    m = ms.examples.load("crank_rocker")
    new = set_length(m, link, value)
    want = {**link_lengths(m), link: value}
    assert link_lengths(new) == pytest.approx(want, rel=1e-10)
    # the drive keeps its angle, the assembly branch (C on the same side of B-D) is kept
    a, b, c, d = (new.joint(j).point for j in "ABCD")
    a0, b0, c0, d0 = (m.joint(j).point for j in "ABCD")
    if link != "crank":
        assert np.arctan2(*(b - a)[::-1]) == pytest.approx(np.arctan2(*(b0 - a0)[::-1]), abs=1e-12)
    assert np.sign(_cross(b, d, c)) == np.sign(_cross(b0, d0, c0))
    # the file is assembled: the engine accepts it and its drawn pose is row 0
    s = simulate(new, {"A": [float(np.degrees(np.arctan2(*(b - a)[::-1])))]}, points=["C"])
    assert s.point("C")[0] == pytest.approx(c, abs=1e-9)


def test_the_named_point_stays_on_its_link():
    m = ms.examples.load("crank_rocker")
    new = set_length(m, "rocker", 3.2)
    # M keeps its distances to B and C (both on the coupler)
    for j in "BC":
        assert np.linalg.norm(new.points["M"].at - new.joint(j).point) == pytest.approx(
            np.linalg.norm(m.points["M"].at - m.joint(j).point), rel=1e-10)


@pytest.mark.parametrize("value, words", [(0.05, "BD ≤ coupler + rocker"), (7.2, "BD ≥ |coupler - rocker|")])
def test_refused_with_the_violated_condition(value, words):
    m = ms.examples.load("crank_rocker")
    with pytest.raises(MechsynInputError) as e:
        set_length(m, "rocker", value)
    msg = e.value.message
    assert words in msg and f"rocker = {value:g}" in msg and "Grashof" in msg and "\n" not in msg


def test_a_length_past_a_dead_point_on_the_drawn_branch_is_refused():
    # crank-rocker at A = 60: the rocker shortened until B, C, D would fold: the continuation
    # refuses a jump to the other branch (the triangle inequality is what breaks there)
    m = ms.examples.load("crank_rocker")
    bd = np.linalg.norm(m.joint("B").point - m.joint("D").point)
    with pytest.raises(MechsynInputError, match="triangle inequality"):
        set_length(m, "rocker", bd - 3.5 - 1e-3)
    ok = set_length(m, "rocker", bd - 3.5 + 1e-3)
    assert link_lengths(ok)["rocker"] == pytest.approx(bd - 3.5 + 1e-3)


def test_plate_side_keeps_the_other_two_and_jansen_keeps_every_other_length():
    j = ms.examples.load("jansen_leg")
    new = set_side(j, "bde", ("P2", "P3"), 45.0)
    sides = {d.joints: d.value for d in dimensions(new) if d.link == "bde"}
    old = {d.joints: d.value for d in dimensions(j) if d.link == "bde"}
    assert sides[("P2", "P3")] == pytest.approx(45.0)
    assert sides[("P3", "P5")] == pytest.approx(old[("P3", "P5")]) and sides[("P5", "P2")] == pytest.approx(old[("P5", "P2")])
    assert link_lengths(new) == pytest.approx(link_lengths(j), rel=1e-8)
    longer = set_length(j, "crank", 16.0)
    assert link_lengths(longer) == pytest.approx({**link_lengths(j), "crank": 16.0}, rel=1e-8)


def test_slider_offset_and_angle():
    s = ms.load("slider_crank")
    new = set_slider(s, "D", offset=0.3)
    dims = {d.kind: d.value for d in dimensions(new) if d.kind in ("offset", "angle")}
    assert dims["offset"] == pytest.approx(0.3) and dims["angle"] == pytest.approx(0.0, abs=1e-12)
    assert link_lengths(new) == pytest.approx(link_lengths(s))
    turned = set_slider(s, "D", angle=20.0)
    dims = {d.kind: d.value for d in dimensions(turned) if d.kind in ("offset", "angle")}
    assert dims["angle"] == pytest.approx(20.0) and dims["offset"] == pytest.approx(0.0, abs=1e-9)
    assert link_lengths(turned) == pytest.approx(link_lengths(s))


def test_scale_free():
    # the same change on the mechanism scaled by 1000 gives the scaled answer (tolerances relative)
    m = ms.examples.load("crank_rocker")
    from mechsyn.io import mechanism_from_dict, mechanism_to_dict

    d = mechanism_to_dict(m)
    for j in d["joints"]:
        j["point"] = [1000 * c for c in j["point"]]
    for p in d["points"].values():
        p["at"] = [1000 * c for c in p["at"]]
    big = set_length(mechanism_from_dict(d), "rocker", 3200.0)
    small = set_length(m, "rocker", 3.2)
    assert big.joint("C").point == pytest.approx(1000 * small.joint("C").point, rel=1e-9)
