"""Pyslvs mechanism expressions: parsing, conversion both ways, mobility, simulation."""

from __future__ import annotations

import math
import re
import sys
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
    ("M[J[RP, A[1], P[0, 0], A[2], L[ground, a]]]", "second slot angle"),
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
  J[RP, A[0.0], color[(10, 200, 30)], P[40.0, 0.0], L[ground, link_2]],
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


# --------------------------------------------------------------------------- Pyslvs' own form (issue 26)
def _pyslvs_num(v: float) -> str:
    """A number as Pyslvs' VPoint.expr writes it: four decimals, trailing zeros dropped."""
    return f"{v:.4f}".rstrip("0").rstrip(".")


def _slider_crank(angle: float, kind: str, color: str, offset: float = 5.0) -> str:
    """A slider-crank whose slot runs at ``angle`` degrees, written as Pyslvs writes it
    (``J[type, A[deg], color[...], P[x, y], L[...]]``), with a coupler point. ``kind``
    RP: the coupler's pin slides in the frame's slot; P: a block slides on the frame and
    the coupler turns on it at a second point of the block."""
    a = math.radians(angle)
    u, n = np.array([math.cos(a), math.sin(a)]), np.array([-math.sin(a), math.cos(a)])
    crank = np.array([10.0 * math.cos(a + 1.0), 10.0 * math.sin(a + 1.0)])
    # the slider on the slot line s * u + offset * n, 40 from the crank pin
    d = crank - offset * n
    s = float(d @ u + math.sqrt(40.0 ** 2 - (d @ n) ** 2))
    slider = s * u + offset * n
    coupler_pt = (crank + slider) / 2 + 8.0 * n
    def j(t, xy, links, c="Blue"):
        head = f"{t}, A[{angle}]" if t != "R" else "R"
        return f"J[{head}, color[{c}], P[{_pyslvs_num(xy[0])}, {_pyslvs_num(xy[1])}], L[{links}]]"
    pts = [j("R", (0.0, 0.0), "ground, link_1", "Green"), j("R", crank, "link_1, link_2")]
    if kind == "RP":
        pts.append(j("RP", slider, "ground, link_2", color))
    else:  # P: the block (link_3) slides on the frame; the coupler turns on it
        pts += [j("P", slider, "ground, link_3", color), j("R", slider + 3.0 * n, "link_2, link_3")]
    pts.append(j("R", coupler_pt, "link_2", "Red"))
    return "M[" + ", ".join(pts) + "]"


PYSLVS_FORM = [pytest.param(_slider_crank(a, k, c), id=f"{k}-{a:g}deg")
               for a, k, c in [(0.0, "RP", "Green"), (30.0, "RP", "Orange"), (90.0, "RP", "dark-blue"),
                               (-45.0, "RP", "(10, 200, 30)"), (135.0, "P", "Green"), (30.0, "P", "Red"),
                               (0.0, "P", "Orange")]]


@pytest.mark.parametrize("text", PYSLVS_FORM)
def test_expressions_as_pyslvs_writes_them_round_trip(text, tmp_path, run_cli):
    """Type, A[...], color[...], P[...], L[...] (Pyslvs' grammar): read, moved, written back
    in the same order with the same joints, angles, colours and coupler point."""
    expr = parse_expression(text)
    assert all(j.angle is not None for j in expr.joints if j.type != "R") and not expr.notes
    src = tmp_path / "m.pyslvs"
    src.write_text(text)
    _convert(run_cli, src, tmp_path / "m.yaml", "--input", "0,1")
    mech = load_mechanism(tmp_path / "m.yaml")
    assert analyze_structure(mech).mobility == 1
    sim = simulate(mech, {"P0": np.arange(0.0, 360.0, 30.0)}, points=[f"P{len(expr.joints) - 1}"])
    assert sim.assembled.all(), sim.events
    _convert(run_cli, tmp_path / "m.yaml", tmp_path / "back.pyslvs")
    written = (tmp_path / "back.pyslvs").read_text()
    # the slot angle right after the type, as Pyslvs writes it
    sliders = [line for line in written.splitlines() if line.strip().startswith(("J[P,", "J[RP,"))]
    assert sliders and all(re.match(r"\s*J\[(RP|P), A\[[-0-9.e]+\], color\[", line) for line in sliders)
    again = parse_expression(written)
    assert [(j.type, j.links, j.color) for j in again.joints] == [(j.type, j.links, j.color) for j in expr.joints]
    assert [j.angle for j in again.joints] == pytest.approx([j.angle for j in expr.joints], abs=1e-9)
    np.testing.assert_allclose([(j.x, j.y) for j in again.joints], [(j.x, j.y) for j in expr.joints], atol=1e-9)


def test_slot_angle_read_in_either_place():
    pyslvs = "M[J[R, P[0, 0], L[ground, a]], J[RP, A[30], color[Green], P[5, 0], L[ground, a]]]"
    older = "M[J[R, P[0, 0], L[ground, a]], J[RP, color[Green], P[5, 0], A[30], L[ground, a]]]"
    assert parse_expression(pyslvs).joints == parse_expression(older).joints
    assert parse_expression(pyslvs).joints[1].angle == 30.0


def test_slider_without_angle_gets_pyslvs_default_and_says_so():
    e = parse_expression("M[J[R, P[0, 0], L[ground, a]], J[RP, P[5, 0], L[ground, a]]]")
    assert e.joints[1].angle == 0.0
    data, notes = expression_to_data(e)
    assert any("point 1" in n and "slot angle" in n for n in notes)


def test_block_comments_and_trailing_commas_of_pyslvs():
    e = parse_expression("#[ a block comment\nJ[R, P[9, 9], L[x]]\n#] end\n"
                         "M[J[R, P[0, 0], L[ground, a,]], J[R, P[1, 0], L[a]],]")
    assert [j.links for j in e.joints] == [("ground", "a"), ("a",)]


def test_examples_are_written_in_pyslvs_order():
    for path in PYSLVS:
        for line in path.read_text().splitlines():
            if line.strip().startswith(("J[P,", "J[RP,")):
                assert re.match(r"\s*J\[(RP|P), A\[", line), f"{path.name}: {line}"


def _ladder(k: int) -> str:
    """k four-bars side by side (every third a slider-crank with a slot at 30 deg), each
    with a coupler point, in Pyslvs' form: about 290 bytes and 3 links a loop."""
    out = ["M["]
    for i in range(k):
        x, c, r, q = 100.0 * i, f"crank_{i}", f"coupler_{i}", f"rocker_{i}"
        out += [f"  J[R, color[Green], P[{x}, 0.0], L[ground, {c}]],",
                f"  J[R, color[Blue], P[{x + 10.0}, 20.0], L[{c}, {r}]],"]
        if i % 3 == 2:
            out.append(f"  J[RP, A[30.0], color[Orange], P[{x + 60.0}, 30.0], L[ground, {r}]],")
        else:
            out += [f"  J[R, color[Blue], P[{x + 60.0}, 40.0], L[{r}, {q}]],",
                    f"  J[R, color[Green], P[{x + 70.0}, 0.0], L[ground, {q}]],"]
        out.append(f"  J[R, color[Red], P[{x + 30.0}, 50.0], L[{r}]],")
    return "\n".join(out + ["]"]) + "\n"


def _steps(fn, *args) -> int:
    """Python lines run by ``fn(*args)`` in mechsyn.io.pyslvs (a count, not a time)."""
    import mechsyn.io.pyslvs as mod

    count = 0

    def tracer(frame, event, arg):
        nonlocal count
        if frame.f_code.co_filename != mod.__file__:
            return None
        count += event == "line"
        return tracer

    sys.settrace(tracer)
    try:
        fn(*args)
    finally:
        sys.settrace(None)
    return count


def test_conversion_is_linear_in_the_file():
    """Four times the loops, about four times the work both ways (a scan of joints x joints,
    as before issue 26, makes it sixteen)."""
    def both(k):
        data, _ = expression_to_data(parse_expression(_ladder(k)))
        return lambda: data_to_expression(mechanism_to_dict(load_mechanism_dict(data)))

    small, large = 30, 120
    fwd = _steps(lambda k: expression_to_data(parse_expression(_ladder(k))), large) / \
        _steps(lambda k: expression_to_data(parse_expression(_ladder(k))), small)
    back = _steps(both(large)) / _steps(both(small))
    assert fwd < 4.5 and back < 4.5, (fwd, back)  # measured 4.0 and 4.0; before: 5.5 and 14.7


def load_mechanism_dict(data):
    from mechsyn.io import mechanism_from_dict

    return mechanism_from_dict(data)


@pytest.mark.slow
def test_large_generated_file_converts_and_keeps_its_mobility(tmp_path, run_cli):
    """620 loops (1,860 links, 180 KB): converted both ways, mobility = its cranks."""
    src = tmp_path / "big.pyslvs"
    src.write_text(_ladder(620))
    assert src.stat().st_size > 149_000
    _convert(run_cli, src, tmp_path / "big.yaml")
    mech = load_mechanism(tmp_path / "big.yaml")
    assert analyze_structure(mech).mobility == len(mech.actuated_joints) == 620
    _convert(run_cli, tmp_path / "big.yaml", tmp_path / "back.pyslvs")
    assert parse_expression((tmp_path / "back.pyslvs").read_text()).joints == parse_expression(_ladder(620)).joints


def test_link_limit_is_checked_before_the_conversion(monkeypatch):
    import mechsyn.io.pyslvs as mod
    from mechsyn.limits import set_limit

    def never(*args, **kwargs):
        raise AssertionError("the conversion ran before the limit was checked")

    monkeypatch.setattr(mod, "_ground_cranks", never)
    set_limit("links", 100)
    try:
        with pytest.raises(MechsynInputError, match="limit") as info:
            expression_to_data(parse_expression(_ladder(40)), source="big.pyslvs")
    finally:
        set_limit("links", None)
    assert "MECHSYN_LIMIT_LINKS" in str(info.value)


def test_rp_point_of_three_links_is_one_pin_not_a_zero_length_block(tmp_path, run_cli):
    """Pyslvs' RP point on L[ground, L2, L3]: L2 and L3 turn on one pin that slides in the
    frame's slot. Made as a block with one pin (L3 turns on L2 there): it loads, moves,
    and writes back as the same RP point."""
    text = ("M[J[R, color[Green], P[0.0, 0.0], L[ground, L1]], J[R, color[Green], P[-2.0, 20.0], L[L1, L2]], "
            "J[RP, A[0.0], color[Orange], P[40.0, 0.0], L[ground, L2, L3]], "
            "J[R, color[Blue], P[70.0, 30.0], L[L3, L4]], J[R, color[Green], P[90.0, 0.0], L[ground, L4]]]")
    src = tmp_path / "rp3.pyslvs"
    src.write_text(text)
    _convert(run_cli, src, tmp_path / "m.yaml", "--input", "0,1")
    mech = load_mechanism(tmp_path / "m.yaml")
    assert analyze_structure(mech).mobility == 1
    assert mech.joint("P2_1").links == ("block2", "L2") and mech.joint("P2_2").links == ("L2", "L3")
    sim = simulate(mech, {"P0": np.arange(90.0, 131.0, 10.0)}, points=["P2_1"])
    assert sim.assembled.all() and np.allclose(sim.points["P2_1"].position[:, 1], 0.0, atol=1e-9)  # in the slot
    _convert(run_cli, tmp_path / "m.yaml", tmp_path / "back.pyslvs")
    back = parse_expression((tmp_path / "back.pyslvs").read_text())
    assert [(j.type, j.links) for j in back.joints] == [(j.type, j.links) for j in parse_expression(text).joints]


def test_slider_input_drives_its_travel_both_ways():
    """Pyslvs' input (i, i) on a slider point drives the slider along its slot."""
    e = parse_expression("M[J[RP, A[0.0], color[Green], P[0.0, 0.0], L[ground, L2]], "
                         "J[R, color[Green], P[50.0, 0.0], L[ground, L1]], "
                         "J[R, color[Green], P[25.0, 27.0], L[L1, L2]]]")
    data, _ = expression_to_data(e, inputs=[(0, 0)])
    assert [j["id"] for j in data["joints"] if j.get("actuated")] == ["P0"]
    from mechsyn.io import mechanism_from_dict

    mech = mechanism_from_dict(data)
    assert mech.joint("P0").type == "P" and analyze_structure(mech).mobility == 1
    assert data_to_expression(mechanism_to_dict(mech)).inputs == [(0, 0)]
    with pytest.raises(MechsynInputError, match="no slider"):
        expression_to_data(e, inputs=[(1, 1)])
