"""Pyslvs mechanism expressions: parsing, conversion both ways, mobility, simulation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.io.pyslvs import (color_rgb, data_to_expression, expression_to_data, parse_expression,
                               pyslvs_text)
from mechsyn.kinematics.analysis import simulate
from mechsyn.structure.analysis import analyze_structure

ROOT = Path(__file__).resolve().parents[2]
PYSLVS = sorted((ROOT / "examples" / "pyslvs").glob("*.pyslvs"))
EX = ROOT / "examples"


def test_a_dozen_classic_linkages():
    names = {p.stem for p in PYSLVS}
    assert len(PYSLVS) >= 12
    assert {"crank_rocker", "slider_crank_rp", "jansen", "jansen_double", "stephenson3", "watt1", "watt2",
            "ball_lifter_double", "ball_lifter_triple"} <= names


def _convert(run_cli, src: Path, dst: Path, *extra: str) -> None:
    code, out, err = run_cli("convert", src, "-o", dst, *extra)
    assert code == 0, err


def _lengths(joints) -> dict[tuple[str, int, int], float]:
    """Distances between every two points on one link (what fixes the geometry)."""
    out = {}
    for a, ja in enumerate(joints):
        for b, jb in enumerate(joints):
            for link in set(ja.links) & set(jb.links):
                if a < b:
                    out[(link, a, b)] = math.hypot(ja.x - jb.x, ja.y - jb.y)
    return out


@pytest.mark.parametrize("path", PYSLVS, ids=lambda p: p.stem)
def test_round_trip_mobility_and_simulation(path, tmp_path, run_cli):
    expr = parse_expression(path.read_text(), str(path))
    yaml_file, back = tmp_path / "m.yaml", tmp_path / "back.pyslvs"
    _convert(run_cli, path, yaml_file)
    mech = load_mechanism(yaml_file)
    # the mobility the Pyslvs example is driven with, and as many drives
    assert analyze_structure(mech).mobility == len(expr.inputs)
    assert len(mech.actuated_joints) == len(expr.inputs)
    # expression -> file -> expression gives the same joints, links and inputs
    _convert(run_cli, yaml_file, back)
    again = parse_expression(back.read_text(), str(back))
    assert [(j.type, j.links) for j in again.joints] == [(j.type, j.links) for j in expr.joints]
    assert [j.angle for j in again.joints] == pytest.approx([j.angle for j in expr.joints], abs=1e-9)
    np.testing.assert_allclose([(j.x, j.y) for j in again.joints], [(j.x, j.y) for j in expr.joints], atol=1e-9)
    assert again.inputs == expr.inputs
    # it simulates: a turn of the crank (two cranks: a part turn each) assembles everywhere
    drives = [j.id for j in mech.actuated_joints]
    if len(drives) == 1:
        inputs = {drives[0]: np.arange(0.0, 361.0, 10.0)}
    else:
        inputs = {d: np.linspace(0.0, 20.0, 11) * (1 if k == 0 else -1) + (0 if k == 0 else 100.0)
                  for k, d in enumerate(drives)}
        inputs = {d: v - v[0] + np.degrees(np.arctan2(*(_pin(expr, k)[::-1])))
                  for k, (d, v) in enumerate(inputs.items())}
    r_points = [i for i, j in enumerate(expr.joints) if j.type == "R" and j.links]
    sim = simulate(mech, inputs, points=[f"P{i}" for i in r_points])
    assert sim.assembled.all(), sim.events
    # every two pins of one link keep their distance at every position
    checked = 0
    for (link, a, b), length in _lengths(expr.joints).items():
        if a in r_points and b in r_points:
            d = np.linalg.norm(sim.points[f"P{a}"].position - sim.points[f"P{b}"].position, axis=1)
            np.testing.assert_allclose(d, length, rtol=1e-9, atol=1e-9)
            checked += 1
    assert checked >= 1


def _pin(expr, k):
    base, drive = expr.inputs[k]
    jb, jd = expr.joints[base], expr.joints[drive]
    return np.array([jd.x - jb.x, jd.y - jb.y])


def test_shared_joints_become_pairs_from_the_frame():
    e = parse_expression((ROOT / "examples/pyslvs/jansen.pyslvs").read_text())
    data, _ = expression_to_data(e)
    by_id = {j["id"]: j for j in data["joints"]}
    assert by_id["P1"]["links"] == ["crank", "j"] and by_id["P1_2"]["links"] == ["crank", "k"]
    assert by_id["P2"]["links"] == ["ground", "bde"] and by_id["P2_2"]["links"] == ["ground", "c"]
    assert data["points"] == {"P7": {"link": "ghi", "at": [-43.160111, -91.756933]}}
    # 7 moving links, 10 lower pairs: W = 3*7 - 2*10 = 1
    assert len(data["links"]) - 1 == 7 and len(data["joints"]) == 10


def test_rp_pin_in_a_turning_guide_follows_the_pin(tmp_path, run_cli):
    """Crank-shaper: the guide pivoted at C always points at the crank pin."""
    src = ROOT / "examples/pyslvs/crank_shaper.pyslvs"
    _convert(run_cli, src, tmp_path / "m.yaml")
    mech = load_mechanism(tmp_path / "m.yaml")
    assert mech.joint("P1").type == "P" and mech.joint("P1").links == ("link_2", "block1")
    assert mech.joint("P1_1").links == ("block1", "link_1")
    theta = np.arange(0.0, 360.0, 15.0)
    sim = simulate(mech, {"P0": theta}, points=["P1_1"])
    e = parse_expression(src.read_text())
    pin = sim.points["P1_1"].position
    r = math.hypot(e.joints[1].x, e.joints[1].y)
    np.testing.assert_allclose(pin, r * np.c_[np.cos(np.radians(theta)), np.sin(np.radians(theta))], atol=1e-9)
    c = np.array([e.joints[2].x, e.joints[2].y])
    expected = np.degrees(np.arctan2(pin[:, 1] - c[1], pin[:, 0] - c[0]))
    got = sim.links["link_2"].angle
    # guide direction minus pin direction is constant (the angle of the slot on the guide)
    diff = got - expected
    drift = np.mod(diff - diff[0] + 180.0, 360.0) - 180.0
    assert np.abs(drift).max() < 1e-9


def test_rp_slider_crank_stroke_is_twice_the_crank(tmp_path, run_cli):
    src = ROOT / "examples/pyslvs/slider_crank_rp.pyslvs"
    _convert(run_cli, src, tmp_path / "m.yaml")
    mech = load_mechanism(tmp_path / "m.yaml")
    sim = simulate(mech, {"P0": np.arange(0.0, 360.0, 0.5)}, points=["P2"])
    x = sim.points["P2"].position[:, 0]
    assert np.ptp(x) == pytest.approx(40.0, abs=1e-4)  # crank 20, no offset
    assert np.allclose(sim.points["P2"].position[:, 1], 0.0, atol=1e-9)


def test_default_drivers_are_ground_cranks():
    text = (ROOT / "examples/pyslvs/five_bar.pyslvs").read_text()
    plain = "\n".join(line for line in text.splitlines() if "inputs" not in line)
    e = parse_expression(plain)
    assert e.inputs == []
    data, notes = expression_to_data(e)
    assert [j["id"] for j in data["joints"] if j.get("actuated")] == ["P0", "P4"]
    assert any("ground cranks" in n for n in notes)
    # crank-rocker: the crank (35), not the rocker (70)
    text = (ROOT / "examples/pyslvs/crank_rocker.pyslvs").read_text()
    e = parse_expression("\n".join(line for line in text.splitlines() if "inputs" not in line))
    data, _ = expression_to_data(e)
    assert [j["id"] for j in data["joints"] if j.get("actuated")] == ["P0"]
    data, _ = expression_to_data(e, inputs=[(3, 2)])
    assert [j["id"] for j in data["joints"] if j.get("actuated")] == ["P3"]


def test_input_option_and_stdout(run_cli, tmp_path):
    src = ROOT / "examples/pyslvs/crank_rocker.pyslvs"
    code, out, err = run_cli("convert", src, "-o", "-", "--to", "yaml", "--input", "3,2")
    assert code == 0, err
    assert "actuated: true" in out and out.index("actuated") > out.index("id: P3")
    code, out, err = run_cli("convert", src, "-o", "-")
    assert code == 2 and "--to" in err


def test_mechsyn_file_to_pyslvs_keeps_plain_sliders(run_cli):
    code, out, err = run_cli("convert", ROOT / "examples/kinematics/inverted_slider_crank.yaml", "-o", "-",
                             "--to", "pyslvs")
    assert code == 0, err
    e = parse_expression(out)
    assert [j.type for j in e.joints] == ["R", "R", "P", "R", "R"]
    assert e.joints[2].links == ("guide", "block")
    assert e.joints[2].angle == pytest.approx(math.degrees(math.atan2(0.381307242813756, -0.924448368800428)))
    assert e.inputs == [(0, 1)]


@pytest.mark.parametrize("text, message", [
    ("M[J[R, P[0, 0], L[ground, a]]", "not closed"),
    ("M[J[X, P[0, 0], L[ground, a]]]", "unknown joint type"),
    ("M[J[RP, P[0, 0], L[ground, a]]]", "slot angle"),
    ("M[J[R, P[0, zero], L[ground, a]]]", "expected a number"),
    ("M[J[R, P[0, 0], L[a, b]]]", "no joint on the frame"),
    ("J[R, P[0, 0]]", "no mechanism expression"),
    ("M[J[R, P[0, 0], L[ground, a, a]]]", "listed twice"),
])
def test_bad_expressions_name_the_problem(text, message):
    with pytest.raises(MechsynInputError, match=message):
        expression_to_data(parse_expression(text, "f.pyslvs"), source="f.pyslvs")


def test_bad_expression_line_and_exit_status(tmp_path, run_cli):
    f = tmp_path / "bad.pyslvs"
    f.write_text("M[\n  J[R, P[0, 0], L[ground, a]],\n  J[R, P[1 0], L[a]],\n]\n")
    code, out, err = run_cli("convert", f, "-o", tmp_path / "m.yaml")
    assert code == 2 and "bad.pyslvs:3" in err and "expected ','" in err
    assert not (tmp_path / "m.yaml").exists()


def test_spatial_and_higher_pairs_are_refused():
    with pytest.raises(MechsynInputError, match="Pyslvs has R, P and RP only"):
        data_to_expression({"name": "x", "ground": "f", "links": ["f", "a", "b"], "joints": [
            {"id": "A", "type": "R", "links": ["f", "a"], "point": [0, 0]},
            {"id": "G", "type": "gear", "links": ["a", "b"], "point": [1, 0]}]})
    with pytest.raises(MechsynInputError, match="spatial"):
        data_to_expression({"name": "x", "kind": "spatial", "ground": "f", "links": ["f"], "joints": []})


COLOURED = """M[
  J[R, color[Red], P[0.0, 0.0], L[ground, link_1]],
  J[R, color[dark-blue], P[10.0, 0.0], L[link_1, link_2]],
  J[RP, color[(10, 200, 30)], P[40.0, 0.0], A[0.0], L[ground, link_2]],
  J[R, color[Orange], P[20.0, 5.0], L[link_2]],
]"""


def test_colours_survive_the_round_trip(tmp_path, run_cli):
    """Pyslvs colours go into the file's ``colors`` block (by the P<i> made from point i)
    and come back on the same points, the non-default ones included."""
    src = tmp_path / "c.pyslvs"
    src.write_text(COLOURED)
    code, _, err = run_cli("convert", src, "-o", tmp_path / "c.yaml")
    assert code == 0, err
    data = yaml.safe_load((tmp_path / "c.yaml").read_text())
    assert data["colors"] == {"P0": "Red", "P1": "dark-blue", "P2": "(10, 200, 30)", "P3": "Orange"}
    code, _, err = run_cli("convert", tmp_path / "c.yaml", "-o", tmp_path / "back.pyslvs")
    assert code == 0, err
    back = parse_expression((tmp_path / "back.pyslvs").read_text())
    assert [j.color for j in back.joints] == ["Red", "dark-blue", "(10, 200, 30)", "Orange"]
    assert [j.color for j in parse_expression(COLOURED).joints] == [j.color for j in back.joints]


def test_colour_edited_in_the_file_is_written_and_a_stale_one_let_go(tmp_path):
    data = yaml.safe_load((EX / "kinematics" / "crank_rocker.yaml").read_text())
    first = data["joints"][0]["id"]
    data["colors"] = {first: "tab:purple"}
    f = tmp_path / "m.yaml"
    f.write_text(yaml.safe_dump(data))
    text, _ = pyslvs_text(mechanism_to_dict(load_mechanism(f)))
    assert text.count("color[tab:purple]") == 1
    data["colors"] = {"nowhere": "Red", first: "Red"}  # e.g. a joint deleted in the studio
    f.write_text(yaml.safe_dump(data))
    assert mechanism_to_dict(load_mechanism(f))["colors"] == {first: "Red"}


def test_colour_names_to_rgb():
    assert color_rgb("Green") == pytest.approx((0, 128 / 255, 0))
    assert color_rgb("brick-red") == color_rgb("firebrick")
    assert color_rgb("(0, 0, 255)") == (0.0, 0.0, 1.0)
    assert color_rgb("(0, 0, 256)") is None and color_rgb("not a colour") is None
