"""Rank (screw-theory) structural analysis: spec vectors (003, 002) and textbook mechanisms.

Expected values: paper 003 and 002 as restated in shared/spec/structural.md; textbook
mobilities from Hunt, *Kinematic geometry of mechanisms* (1978) and Gogu, "Mobility of
mechanisms: a critical review", Mech. Mach. Theory 40 (2005): four-bar, slider-crank,
Watt, Stephenson (1), 5R (2), Bennett (1), RSSR (1 + 1 idle), Sarrus (1), 3-RPS (3),
6-UPS (6), Delta with S-S bars (3 + 6 idle).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mechsyn.cli.main import main
from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.compare import check_remedy, compare_with_formulas
from mechsyn.structure.rank import InsufficientGeometry, analyze_rank, as_spatial, pair_twists
from mechsyn.structure.remedies import find_remedies

ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples"


def load(rel: str):
    return load_mechanism(EX / rel)


# ----------------------------------------------------------------------------- paper 003
def test_003_fig3_parallel_axes_idle_spin_and_two_redundant():
    mech = load("structural/robot_actuator_003.yaml")
    r = analyze_rank(mech)
    f = analyze_structure(mech)
    # spec: 4 instantaneous freedoms = 3 useful + 1 idle (link6 spins), 2 redundant constraints
    assert (r.mobility, r.useful_mobility, r.redundant_constraints) == (4, 3, 2)
    assert [(i.link, sorted(i.joints)) for i in r.idle_mobilities] == [("link6", ["D3", "F3"])]
    assert r.redundant_by_contour == [2, 0]
    # contour 1's axes are parallel to z and the cylindrical pair D4 frees the z force
    assert r.redundant_directions[0] == ["moments about x, y"]
    assert "parallel axes" in r.contours[0].reason
    # the paper's S_Σ = 2 - 1 nets the idle mobility against the redundant constraints
    assert f.structural_redundancy == r.redundant_constraints - len(r.idle_mobilities)
    assert f.mobility == r.useful_mobility  # Somov-Malyshev W = 3 is the useful mobility
    # Malyshev's W = m - q exactly (identity F - 6K = m - q)
    assert f.formulas["malyshev"].value == r.mobility - r.redundant_constraints
    # drives: the rank answer equals paper 003's H = 3 (A, D5, G) and they determine the motion
    assert r.drives_needed == f.degrees_of_mobility == 3
    assert r.actuation_determined is True
    assert not r.singular and r.finite_mobility == 4


@pytest.mark.parametrize("name", ["robot_actuator_003_remedy_a.yaml", "robot_actuator_003_remedy_b.yaml"])
def test_003_fig3_remedies_leave_neither_redundancy_nor_idle(name):
    r = analyze_rank(load(f"structural/{name}"))
    assert (r.mobility, r.useful_mobility, r.redundant_constraints, len(r.idle_mobilities)) == (3, 3, 0, 0)


def test_003_fig4_drives_from_rank_and_per_contour_redundancy():
    mech = load("structural/gripper_003.yaml")
    r = analyze_rank(mech)
    f = analyze_structure(mech)
    # spec: drives from the rank method = 1 (the paper's H = 1; the sequential rule gives 0)
    assert r.drives_needed == 1 and r.useful_mobility == 1 and r.actuation_determined
    assert f.degrees_of_mobility != r.drives_needed
    # per-contour: S_j + T_j of the paper (1, 1, 3 + 1, 3 + 1) = the rank's q_j
    assert r.redundant_by_contour == [max(c.S, 0) + c.T for c in f.contours] == [1, 1, 4, 4]
    assert f.mobility == r.mobility == 1
    # contour 3's fourth redundant constraint is the in-plane metric one (P coaxial with F)
    assert "metric" in r.contours[2].reason


def test_003_fig4_remedy():
    r = analyze_rank(load("structural/gripper_003_remedy.yaml"))
    assert (r.mobility, r.redundant_constraints, len(r.idle_mobilities)) == (1, 0, 0)


# ----------------------------------------------------------------------------- paper 002
@pytest.mark.parametrize("fig", ["fig1", "fig2"])
def test_002_spatial_scheme_eleven_redundant(fig):
    mech = load(f"structural/gripper_002_{fig}_spatial.yaml")
    r = analyze_rank(mech)
    f = analyze_structure(mech)
    # spec: q = 11: three in each parallelogram, two and three in the other contours
    assert r.redundant_constraints == f.formulas["ozol_redundant"].value == 11
    assert r.redundant_by_contour == [3, 3, 2, 3]
    assert r.useful_mobility == r.mobility == 1


@pytest.mark.parametrize("fig", ["fig1", "fig2"])
def test_002_remedy_six_equals_one_plus_five_idle(fig):
    mech = load(f"structural/gripper_002_{fig}_remedy.yaml")
    r = analyze_rank(mech)
    f = analyze_structure(mech)
    # spec: W = 6 = 1 + 5 idle (four S-S rods spin, the slider turns in its cylindrical pair)
    assert r.mobility == mech.mobility == 6
    assert r.useful_mobility == 1
    assert sorted(i.link for i in r.idle_mobilities) == ["rocker5", "rocker9", "rod2", "rod6", "slider1"]
    assert r.redundant_constraints == f.formulas["ozol_redundant"].value == 0
    assert r.actuation_determined is True


@pytest.mark.parametrize("fig", ["fig1", "fig2"])
def test_002_plane_scheme(fig):
    mech = load(f"structural/gripper_002_{fig}_plane.yaml")
    r = analyze_rank(mech)
    assert r.mobility == analyze_structure(mech).formulas["grubler"].value == 1
    assert r.redundant_constraints == 0
    # in 3-D, each of the four planar contours repeats its three out-of-plane constraints
    s = analyze_rank(as_spatial(mech))
    assert s.redundant_by_contour == [3, 3, 3, 3]


def test_002_states_without_geometry_are_reported_not_guessed():
    mech = load("structural/gripper_002_fig1_remedy.yaml").in_state("clamped")
    with pytest.raises(InsufficientGeometry, match="generic"):
        analyze_rank(mech)


# ----------------------------------------------------------------------------- planar textbook
@pytest.mark.parametrize("name, m", [
    ("fourbar", 1), ("slider_crank", 1), ("watt_sixbar", 1), ("stephenson_sixbar", 1), ("five_bar_5r", 2),
])
def test_planar_textbook_mobility_equals_chebyshev(name, m):
    mech = load(f"textbook/{name}.yaml")
    r = analyze_rank(mech)
    assert r.mobility == r.useful_mobility == m == analyze_structure(mech).formulas["chebyshev"].value
    assert r.redundant_constraints == 0 and not r.singular
    assert r.drives_needed == len(mech.actuated_joints) and r.actuation_determined


def test_double_parallelogram_metric_constraint():
    mech = load("textbook/double_parallelogram.yaml")
    r = analyze_rank(mech)
    cheb = analyze_structure(mech).formulas["chebyshev"].value
    assert cheb == 0 and r.mobility == 1 and r.redundant_constraints == 1
    assert cheb == r.mobility - r.redundant_constraints
    # the repeated constraint is a force along the cranks' direction (0.5, 1.5)
    d = r.redundant_directions[1][0]
    assert d.startswith("force along (0.3162, 0.9487, 0)")
    assert "metric" in r.contours[1].reason
    # a slightly longer third crank breaks the metric constraint: a structure
    data = json.loads(json.dumps({
        "name": "x", "kind": "planar", "ground": "frame", "links": ["frame", "c1", "c2", "c3", "cp"],
        "joints": [{"id": "A1", "type": "R", "links": ["frame", "c1"], "point": [0, 0]},
                   {"id": "B1", "type": "R", "links": ["c1", "cp"], "point": [0.5, 1.5]},
                   {"id": "A2", "type": "R", "links": ["frame", "c2"], "point": [2, 0]},
                   {"id": "B2", "type": "R", "links": ["c2", "cp"], "point": [2.5, 1.5]},
                   {"id": "A3", "type": "R", "links": ["frame", "c3"], "point": [4, -0.3]},
                   {"id": "B3", "type": "R", "links": ["c3", "cp"], "point": [4.5, 1.5]}]}))
    r2 = analyze_rank(mechanism_from_dict(data))
    assert r2.mobility == 0 and r2.redundant_constraints == 0


def test_cam_roller_spin_is_idle():
    r = analyze_rank(load("textbook/cam_follower.yaml"))
    assert [i.link for i in r.idle_mobilities] == ["roller"]
    assert r.useful_mobility == 1


def test_planar_fourbar_as_spatial_three_redundant():
    r = analyze_rank(as_spatial(load("textbook/fourbar.yaml")))
    assert r.mobility == 1 and r.redundant_constraints == 3
    assert r.redundant_directions == [["moments about x, y", "force along z"]]


def test_fourbar_rank_velocity_ratio_matches_finite_motion():
    """The null vector's rocker/crank rate ratio against finite differences of the
    closed-form four-bar position (independent method)."""
    mech = load("textbook/fourbar.yaml")
    r = analyze_rank(mech)
    assert r.mobility == 1
    from mechsyn.structure.rank import _build_system, _null

    sysm = _build_system(mech, True)
    M, _ = sysm.closure(np.zeros(4))
    n = _null(M, 1e-9)[:, 0]
    ratio = n[3] / n[0]  # joint D (rocker-frame) against A (frame-crank)
    A, B, C, D = (np.array(j.point, float) for j in mech.joints)
    a, b, c = np.linalg.norm(B - A), np.linalg.norm(C - B), np.linalg.norm(D - C)
    th0 = np.arctan2(*(B - A)[::-1])

    def coupler_point(th, branch):
        Bp = A + a * np.array([np.cos(th), np.sin(th)])
        d = np.linalg.norm(D - Bp)
        ang = np.arctan2(*(D - Bp)[::-1])
        ang_c = np.arccos((b * b + d * d - c * c) / (2 * b * d))
        return Bp + b * np.array([np.cos(ang + branch * ang_c), np.sin(ang + branch * ang_c)])

    branch = 1 if np.linalg.norm(coupler_point(th0, 1) - C) < 1e-9 else -1
    assert np.linalg.norm(coupler_point(th0, branch) - C) < 1e-9

    def rocker(th):
        return np.arctan2(*(coupler_point(th, branch) - D)[::-1])

    h = 1e-6
    fd = (rocker(th0 + h) - rocker(th0 - h)) / (2 * h)
    # joint D's rate is the frame relative to the rocker (links [rocker, frame]): -ω_rocker
    assert -ratio == pytest.approx(fd, rel=1e-6)


def test_folded_fourbar_is_singular():
    r = analyze_rank(load("textbook/fourbar_folded.yaml"))
    assert r.mobility == 2 and r.singular and r.finite_mobility == 1


def test_dead_centre_crank_does_not_determine_motion():
    r = analyze_rank(load("textbook/fourbar_dead_centre.yaml"))
    assert r.mobility == 1 and not r.singular
    assert r.actuation_determined is False


# ----------------------------------------------------------------------------- spatial textbook
def test_bennett_mobility_one_malyshev_minus_two():
    mech = load("textbook/bennett.yaml")
    r = analyze_rank(mech)
    f = analyze_structure(mech)
    assert f.formulas["malyshev"].value == -2
    assert r.mobility == 1 and r.redundant_constraints == 3
    assert "special geometry" in r.contours[0].reason
    # the motion is finite: the rank stays 3 at nearby assembled configurations
    assert not r.singular and r.finite_mobility == 1
    why = compare_with_formulas(f, r)[0]
    assert not why.agree and "3 are redundant" in why.why


def test_bennett_typed_with_four_decimals_still_moves():
    r = analyze_rank(load("textbook/bennett_4dp.yaml"))
    assert r.tolerance > 1e-6  # raised for coordinates written with 4 decimals
    assert r.mobility == 1 and r.redundant_constraints == 3 and not r.singular


def test_generic_spatial_4r_is_a_structure():
    r = analyze_rank(load("textbook/spatial_4r_generic.yaml"))
    assert r.mobility == 0 and r.redundant_constraints == 2


def test_rssr_rod_spin_idle():
    mech = load("textbook/rssr.yaml")
    r = analyze_rank(mech)
    assert analyze_structure(mech).formulas["malyshev"].value == r.mobility == 2
    assert r.useful_mobility == 1
    assert [(i.link, sorted(i.joints)) for i in r.idle_mobilities] == [("rod", ["B", "C"])]


def test_sarrus():
    mech = load("textbook/sarrus.yaml")
    r = analyze_rank(mech)
    assert analyze_structure(mech).formulas["malyshev"].value == 0
    assert r.mobility == 1 and r.redundant_constraints == 1 and not r.singular


@pytest.mark.parametrize("name, m, useful", [("rps3", 3, 3), ("stewart_6ups", 6, 6), ("delta", 9, 3)])
def test_parallel_platforms(name, m, useful):
    mech = load(f"textbook/{name}.yaml")
    r = analyze_rank(mech)
    assert r.mobility == m == analyze_structure(mech).formulas["malyshev"].value
    assert r.useful_mobility == useful and r.redundant_constraints == 0
    assert r.actuation_determined is True


# ----------------------------------------------------------------------------- pairs, remedies
def _joint(**kw):
    data = {"name": "t", "kind": "spatial", "ground": "a", "links": ["a", "b"],
            "joints": [{"id": "J", "links": ["a", "b"], **kw}]}
    return mechanism_from_dict(data).joints[0]


def test_pair_twists():
    h = pair_twists(_joint(type="H", point=[1, 0, 0], axis=[0, 0, 1], pitch=0.5), False)
    np.testing.assert_allclose(h, [[0, 0, 1, 0, -1, 0.5]])
    u = pair_twists(_joint(type="U", point=[0, 0, 0], axis=[1, 0, 0], axis2=[0, 1, 0]), False)
    assert u.shape == (2, 6)
    assert pair_twists(_joint(type="point_contact", point=[0, 0, 0], normal=[0, 0, 1]), False).shape == (5, 6)
    with pytest.raises(InsufficientGeometry, match="axis2"):
        pair_twists(_joint(type="U", point=[0, 0, 0], axis=[1, 0, 0]), False)
    with pytest.raises(InsufficientGeometry, match="generic"):
        pair_twists(_joint(type="generic", **{"class": 3}, point=[0, 0, 0]), False)


def test_gear_given_by_ratio():
    data = {"name": "gears", "kind": "planar", "ground": "frame", "links": ["frame", "g1", "g2"],
            "joints": [{"id": "O1", "type": "R", "links": ["frame", "g1"], "point": [0, 0]},
                       {"id": "O2", "type": "R", "links": ["frame", "g2"], "point": [3, 0]},
                       {"id": "M", "type": "gear", "links": ["g1", "g2"], "ratio": -2}]}
    r = analyze_rank(mechanism_from_dict(data))
    assert r.mobility == 1 and r.redundant_constraints == 0


def test_remedies_rechecked_by_rank():
    mech = load("structural/robot_actuator_003.yaml")
    base = analyze_rank(mech)
    rem = find_remedies(mech, max_variants=10)
    checks = [check_remedy(mech, r.mechanism, base, r.analysis.metric_constraints) for r in rem]
    assert any(c.accepted for c in checks)
    # two cylindrical pairs with parallel axes in contour 1 leave its moments redundant
    rejected = [c for c in checks if not c.accepted]
    assert rejected and all("rejected by the rank method" in c.reason for c in rejected)
    # the paper's remedy a (B -> S, D3 -> S_pin) is confirmed
    a = [c for r, c in zip(rem, checks) if {x.joint for x in r.changes} == {"B", "D3"}
         and {x.new_type for x in r.changes} == {"S", "S_pin"}]
    assert a and a[0].accepted


# ----------------------------------------------------------------------------- command line
def test_cli_json_keeps_keys_and_adds_rank(capsys):
    path = str(EX / "structural/robot_actuator_003.yaml")
    assert main(["analyze", path, "--json", "--method", "formulas"]) == 0
    old = json.loads(capsys.readouterr().out)
    assert main(["analyze", path, "--json"]) == 0
    new = json.loads(capsys.readouterr().out)
    assert set(old) <= set(new)
    rank = new["rank"]
    for key in ("mobility", "useful_mobility", "idle_mobilities", "redundant_constraints", "redundant_by_contour",
                "redundant_directions", "drives_needed", "actuation_determined", "singular", "tolerance"):
        assert key in rank
    assert new["mobility"] == rank["useful_mobility"] == 3
    assert [{k: i[k] for k in ("link", "joints", "links", "family")} for i in rank["idle_mobilities"]] == [
        {"link": "link6", "joints": ["F3", "D3"], "links": ["link6"], "family": "group"}]
    assert old["rank"] is None


def test_cli_as_spatial_and_remedies(capsys):
    assert main(["analyze", str(EX / "textbook/fourbar.yaml"), "--as-spatial", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["rank"]["redundant_constraints"] == 3 and d["formulas"]["malyshev"]["value"] == -2
    assert main(["analyze", str(EX / "structural/robot_actuator_003.yaml"), "--remedies", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["remedies"] and d["remedies_rejected"]
    assert all(r["rank_check"]["reason"].startswith("rejected") for r in d["remedies_rejected"])


def test_cli_text_report(capsys):
    assert main(["analyze", str(EX / "textbook/bennett.yaml")]) == 0
    out = capsys.readouterr().out
    assert "Rank method" in out and "side by side" in out


def test_cli_bad_inputs(tmp_path, capsys):
    assert main(["analyze", str(EX / "textbook/fourbar.yaml"), "--method", "magic"]) == 2
    assert main(["analyze", str(EX / "textbook/fourbar.yaml"), "--tol", "5"]) == 2
    f = tmp_path / "nogeo.yaml"
    f.write_text("name: x\nkind: planar\nground: f\nlinks: [f, a, b, c]\njoints:\n"
                 "  - {id: A, type: R, links: [f, a]}\n  - {id: B, type: R, links: [a, b]}\n"
                 "  - {id: C, type: R, links: [b, c]}\n  - {id: D, type: R, links: [c, f]}\n")
    assert main(["analyze", str(f), "--method", "rank"]) == 2
    err = capsys.readouterr().err
    assert "joint A" in err and "point" in err
    assert main(["analyze", str(f), "--json"]) == 0  # formulas only by default
    assert json.loads(capsys.readouterr().out)["rank"] is None


def _unit(v):
    v = np.asarray(v, float)
    return (v / np.linalg.norm(v)).tolist()


def test_spherical_fourbar_concurrent_axes():
    """Spherical 4R (all axes through the origin): Malyshev -2, mobility 1, three forces
    through the centre repeat (Hunt 1978)."""
    axes = [_unit([1, 0, 0.3]), _unit([0.2, 1, 0.4]), _unit([-0.8, 0.3, 1]), _unit([0.1, -0.7, 0.9])]
    links = ["frame", "a", "b", "c"]
    mech = mechanism_from_dict({
        "name": "spherical 4R", "kind": "spatial", "ground": "frame", "links": links,
        "joints": [{"id": f"J{k}", "type": "R", "links": [links[k], links[(k + 1) % 4]],
                    "point": (2 * np.array(axes[k])).tolist(), "axis": axes[k]} for k in range(4)]})
    r = analyze_rank(mech)
    assert analyze_structure(mech).formulas["malyshev"].value == -2
    assert (r.mobility, r.redundant_constraints) == (1, 3)
    assert r.redundant_directions == [["forces along x, y, z through (0, 0, 0)"]]
    assert r.contours[0].reason.startswith("concurrent axes")


def test_bennett_typed_with_two_decimals_is_flagged_near_singular():
    import yaml

    d = yaml.safe_load((EX / "textbook/bennett.yaml").read_text())
    for j in d["joints"]:
        j["point"] = [round(x, 2) for x in j["point"]]
        j["axis"] = [round(x, 2) for x in j["axis"]]
    r = analyze_rank(mechanism_from_dict(d))
    # two decimals are taken as exact: a generic 4R (a structure), but the small singular
    # value is reported with the tolerance that recovers Bennett's mobility
    assert r.mobility == 0 and r.near_singular
    assert any("gives mobility 1" in n for n in r.notes)


def test_markdown_report_has_rank_and_comparison(capsys):
    assert main(["analyze", str(EX / "structural/gripper_003.yaml"), "--markdown", "--remedies"]) == 0
    out = capsys.readouterr().out
    assert "## Rank method (screw theory)" in out and "side by side" in out
    assert "Remedies re-checked by the rank method" in out and "rejected by the rank method" in out


def test_planetary_gear_train_given_by_ratios():
    """Sun, planet on a carrier, ring: a 2-freedom differential (Chebyshev 3·4 - 2·4 - 2 = 2);
    one drive at the sun does not determine it."""
    d = {"name": "planetary", "kind": "planar", "ground": "frame",
         "links": ["frame", "sun", "carrier", "planet", "ring"],
         "joints": [{"id": "Os", "type": "R", "links": ["frame", "sun"], "point": [0, 0], "actuated": True},
                    {"id": "Oc", "type": "R", "links": ["frame", "carrier"], "point": [0, 0]},
                    {"id": "Or", "type": "R", "links": ["frame", "ring"], "point": [0, 0]},
                    {"id": "Op", "type": "R", "links": ["carrier", "planet"], "point": [3, 0]},
                    {"id": "M1", "type": "gear", "links": ["sun", "planet"], "ratio": -2},
                    {"id": "M2", "type": "gear", "links": ["planet", "ring"], "ratio": 0.25}]}
    mech = mechanism_from_dict(d)
    r = analyze_rank(mech)
    assert r.mobility == analyze_structure(mech).formulas["chebyshev"].value == 2
    assert r.redundant_constraints == 0 and r.actuation_determined is False
    # fixing the ring (a third R pair between ring and frame would be redundant; instead drive it)
    d["joints"][2]["actuated"] = True
    assert analyze_rank(mechanism_from_dict(d)).actuation_determined is True
