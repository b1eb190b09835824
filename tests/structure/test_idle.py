"""Idle mobilities of links and link groups (issue 12 §1).

The expected counts come from the mechanisms' geometry, not from the program: each
case's header states Malyshev's or Chebyshev's W and how the instantaneous mobility
splits into useful and idle motions; the idle axes are checked against the joint
centres they must pass through.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.rank import analyze_rank

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def load(rel: str):
    return load_mechanism(EXAMPLES / rel)


def _on_axis(axis: dict, point) -> bool:
    p = np.asarray(point, float)
    p = np.pad(p, (0, 3 - p.size))
    d = p - np.asarray(axis["point"])
    return bool(np.linalg.norm(np.cross(d, axis["direction"])) < 1e-8)


def _joint_point(mech, jid):
    return next(j.point for j in mech.joints if j.id == jid)


def test_gough_stewart_6sps_legs_spin_as_groups():
    mech = load("structural/gough_stewart_6sps.yaml")
    r = analyze_rank(mech)
    assert analyze_structure(mech).formulas["malyshev"].value == r.mobility == 12
    assert (len(r.idle_mobilities), r.useful_mobility, r.drives_needed) == (6, 6, 6)
    assert r.actuation_determined is True and r.redundant_constraints == 0
    for k, i in enumerate(r.idle_mobilities, start=1):
        assert i.family == "group" and i.links == [f"cyl{k}", f"piston{k}"]
        assert i.joints == [f"Sb{k}", f"Sp{k}"]
        # the axis is the leg's S-S line
        assert _on_axis(i.axis, _joint_point(mech, f"Sb{k}")) and _on_axis(i.axis, _joint_point(mech, f"Sp{k}"))


def test_wrist_3sps_s_three_idle_leg_spins():
    mech = load("structural/wrist_3sps_s.yaml")
    r = analyze_rank(mech)
    assert analyze_structure(mech).formulas["malyshev"].value == r.mobility == 6
    assert (r.useful_mobility, len(r.idle_mobilities), r.actuation_determined) == (3, 3, True)
    assert sorted(tuple(i.links) for i in r.idle_mobilities) == [("cyl1", "piston1"), ("cyl2", "piston2"),
                                                                 ("cyl3", "piston3")]


def test_rspsr_leg_spin_and_two_drives():
    mech = load("structural/rspsr_leg.yaml")
    r = analyze_rank(mech)
    assert r.mobility == 3 and r.useful_mobility == 2 and r.actuation_determined is True
    (i,) = r.idle_mobilities
    assert i.links == ["cyl", "piston"] and i.joints == ["B", "C"]
    assert _on_axis(i.axis, _joint_point(mech, "B")) and _on_axis(i.axis, _joint_point(mech, "C"))
    # one drive (the crank) alone leaves the leg's length free: not determined
    d = yaml.safe_load((EXAMPLES / "structural/rspsr_leg.yaml").read_text())
    for j in d["joints"]:
        if j["id"] == "L":
            j.pop("actuated")
    r1 = analyze_rank(mechanism_from_dict(d))
    assert r1.actuation_determined is False and len(r1.idle_mobilities) == 1


@pytest.mark.parametrize("name, useful, idle", [("rusc_leg_spin", 1, 1), ("rusc_leg", 2, 0)])
def test_u_s_leg_spins_only_when_the_u_frees_it(name, useful, idle):
    mech = load(f"structural/{name}.yaml")
    r = analyze_rank(mech)
    assert r.mobility == 2 and (r.useful_mobility, len(r.idle_mobilities)) == (useful, idle)
    for i in r.idle_mobilities:  # the leg's spin moves neither the U's nor the S's centre
        assert i.links == ["leg"]
        assert _on_axis(i.axis, _joint_point(mech, "B")) and _on_axis(i.axis, _joint_point(mech, "C"))


def test_families_overlap_rod_spin_counted_once():
    # the RSSR rod's spin is a one-link group (a) and keeps both centres at rest (b)
    r = analyze_rank(load("textbook/rssr.yaml"))
    assert r.mobility == 2 and len(r.idle_mobilities) == 1 and r.useful_mobility == 1
    # the cam's roller: a one-link group and a centre at rest
    r = analyze_rank(load("textbook/cam_follower.yaml"))
    assert [i.links for i in r.idle_mobilities] == [["roller"]] and r.useful_mobility == 1


def test_geared_rollers_idle_by_centres_only():
    r = analyze_rank(load("structural/cam_two_rollers_geared.yaml"))
    assert (r.mobility, r.useful_mobility) == (2, 1)
    (i,) = r.idle_mobilities
    assert i.family == "centres" and i.links == ["roller1", "roller2"] and i.axis is None
    # the rollers turn in opposite senses at equal rates about their own pins
    a1, a2 = i.axes["roller1"], i.axes["roller2"]
    assert a1["point"][:2] == pytest.approx([0, 1.5]) and a2["point"][:2] == pytest.approx([0.6, 1.5])
    assert r.actuation_determined is True


def test_gear_pair_without_drives_is_the_function_not_idle():
    r = analyze_rank(load("structural/gear_pair.yaml"))
    # both wheels turn in bearings on the frame: a link joined to the frame that moves is
    # the function (family (b) keeps the frame's neighbours at rest), drives declared or not
    assert r.mobility == r.useful_mobility == 1 and not r.idle_mobilities


def test_shoe_group_slide_idle_by_groups_only():
    r = analyze_rank(load("structural/shoe_pair_slide.yaml"))
    assert (r.mobility, r.useful_mobility) == (1, 0)
    (i,) = r.idle_mobilities
    assert i.family == "group" and i.links == ["shoe1", "shoe2"]
    assert i.axis["point"] is None and i.axis["direction"] == pytest.approx([1, 0, 0])
    assert "are locked" in r.actuation_note and "redundant actuation" not in r.actuation_note


def test_five_bar_second_freedom_is_not_idle():
    mech = load("textbook/five_bar_5r.yaml")
    r = analyze_rank(mech)
    assert r.mobility == r.useful_mobility == 2 and not r.idle_mobilities
    d = {"name": "5R, one drive", "kind": "planar", "ground": "frame",
         "links": [l.name for l in mech.links],
         "joints": [{"id": j.id, "type": "R", "links": list(j.links), "point": list(j.point),
                     **({"actuated": True} if j.id == "A" else {})} for j in mech.joints]}
    r1 = analyze_rank(mechanism_from_dict(d))
    assert r1.mobility == r1.useful_mobility == 2 and not r1.idle_mobilities
    assert r1.actuation_determined is False


def test_delta_bars_spin_each_alone():
    r = analyze_rank(load("textbook/delta.yaml"))
    assert (r.mobility, r.useful_mobility, len(r.idle_mobilities)) == (9, 3, 6)
    assert all(i.family == "group" and len(i.links) == 1 and i.links[0].startswith("bar") for i in r.idle_mobilities)


def test_cli_json_rank_section(cli_json):
    d = cli_json("analyze", str(EXAMPLES / "structural/gough_stewart_6sps.yaml"))
    rank = d["rank"]
    assert rank["useful_mobility"] == rank["drives_needed"] == 6 and rank["actuation_determined"] is True
    assert len(rank["idle_mobilities"]) == 6
    assert {"links", "axis", "joints", "family"} <= set(rank["idle_mobilities"][0])
    assert rank["idle_mobilities"][0]["axis"]["direction"]
