"""``mechsyn synth path|function|motion`` through the command line."""

import json

import numpy as np
import pytest
from dimsynth_data import public_cases, public_data  # noqa: F401  (fixtures)
import yaml

from mechsyn.cli.main import main
from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.path import PathCase, evaluate_design


@pytest.fixture()
def p2_file(tmp_path, public_data):
    f = tmp_path / "p2.json"
    f.write_text(json.dumps(public_data["cases"][0]))
    return f


def test_synth_path_json_contract(p2_file, tmp_path, capsys, public_data):
    out, png = tmp_path / "mech.yaml", tmp_path / "p.png"
    code = main(["synth", "path", str(p2_file), "--seed", "2", "--time-limit", "20", "--restarts", "2",
                 "--json", "--out", str(out), "--plot", str(png)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("error", "design", "assembled_at_all_targets", "seconds"):
        assert key in data
    assert data["assembled_at_all_targets"] is True
    assert set(data["design"]) == {"r1", "r2", "r3", "r4", "rcx", "rcy"}
    case = PathCase.from_dict(public_data["cases"][0])
    assert data["error"] == evaluate_design(case, data["design"])["error"]
    assert data["error"] < 1e-3
    assert png.stat().st_size > 1000
    # the mechanism file reproduces the coupler point at target 1
    mech = yaml.safe_load(out.read_text())
    assert mech["kind"] == "planar" and [j["id"] for j in mech["joints"]] == ["A", "B", "C", "D"]
    pts = {j["id"]: np.array(j["point"]) for j in mech["joints"]}
    d = data["design"]
    assert np.linalg.norm(pts["D"] - pts["A"]) == pytest.approx(d["r1"])
    assert np.linalg.norm(pts["B"] - pts["A"]) == pytest.approx(d["r2"])
    assert np.linalg.norm(pts["C"] - pts["B"]) == pytest.approx(d["r3"])
    assert np.linalg.norm(pts["D"] - pts["C"]) == pytest.approx(d["r4"])
    pose = fourbar_position(d["r1"], d["r2"], d["r3"], d["r4"], np.pi / 6, rcx=d["rcx"], rcy=d["rcy"])
    assert np.allclose(mech["points"]["P"]["at"], pose.C)
    # other tools take it: the model loads it and analyze finds one degree of freedom
    from mechsyn.io import load_mechanism

    m = load_mechanism(out)
    assert m.n_moving == 3 and m.joint("A").actuated and m.points["P"].link == "coupler"
    capsys.readouterr()
    assert main(["analyze", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["formulas"]["chebyshev"]["value"] == 1
    # and the project's general simulator, driving joint A through the prescribed angles,
    # moves point P through the targets with the same error (independent kinematics)
    assert main(["simulate", str(out), "-i", "A=30,45,60,75,90", "--points", "P", "--json"]) == 0
    sim = json.loads(capsys.readouterr().out)
    assert all(sim["assembled"])
    got = np.array(sim["points"]["P"]["position"])
    sim_error = float(np.sum((got - np.array(public_data["cases"][0]["targets"])) ** 2))
    assert sim_error == pytest.approx(data["error"], rel=1e-6)


def test_synth_path_collection_needs_case(tmp_path, capsys, public_data):
    f = tmp_path / "all.json"
    f.write_text(json.dumps(public_data))
    assert main(["synth", "path", str(f)]) == 2
    assert "--case" in capsys.readouterr().err


@pytest.mark.parametrize("content, args", [
    ("{not json", []),
    ('{"targets": [[0, 0]], "timing": {"type": "later"}}', []),
    (None, ["--time-limit", "-1"]),
])
def test_synth_path_bad_input_exits_2(tmp_path, p2_file, capsys, content, args):
    f = p2_file
    if content is not None:
        f = tmp_path / "bad.json"
        f.write_text(content)
    assert main(["synth", "path", str(f), *args]) == 2
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err


def test_synth_path_missing_file(capsys):
    assert main(["synth", "path", "/nonexistent/case.json"]) == 2


def test_synth_function(tmp_path, capsys):
    phi = np.radians([40.0, 75.0, 115.0])
    psi = np.degrees(fourbar_position(4.0, 1.5, 3.5, 3.0, phi).theta4)
    out = tmp_path / "f.yaml"
    code = main(["synth", "function", "--phi", "40,75,115", "--psi", ",".join(f"{v:.12f}" for v in psi),
                 "--ground", "4", "--json", "--out", str(out)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    assert data["verified"] and data["design"]["r2"] == pytest.approx(1.5, rel=1e-9)
    assert yaml.safe_load(out.read_text())["links"] == ["frame", "crank", "coupler", "rocker"]
    assert main(["synth", "function", "--phi", "1,2", "--psi", "1,2,3"]) == 2


def test_synth_motion(tmp_path, capsys):
    pose = fourbar_position(4.0, 1.5, 3.5, 3.0, np.radians([30, 60, 95, 130, 170]))
    P = np.column_stack([pose.A, np.degrees(pose.theta3)])
    f = tmp_path / "poses.json"
    f.write_text(json.dumps({"poses": P.tolist()}))
    png = tmp_path / "m.png"
    assert main(["synth", "motion", str(f), "--json", "--plot", str(png), "--out", str(tmp_path / "m.yaml")]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["verified_count"] >= 1 and data["solutions"][0]["verified"]
    assert png.exists()
    three = ",".join(f"{v:.12g}" for v in P[:3].ravel())
    assert main(["synth", "motion", "--poses", three, "--circle-points", "0,0,3.5,0", "--json"]) == 0
    sol = json.loads(capsys.readouterr().out)["solutions"][0]
    assert sol["verified"] and sol["r1"] == pytest.approx(4.0)
    assert main(["synth", "motion", "--poses", "1,2"]) == 2
