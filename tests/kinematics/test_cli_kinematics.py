"""The simulate / forces commands: JSON contract, files, bad inputs exit 2."""

import json
import re

import numpy as np
import pytest

from mechsyn.cli.main import main

from kinematics_helpers import EX


def run(capsys, *args):
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_json_contract(capsys):
    code, out, _ = run(capsys, "simulate", EX / "kinematics/crank_rocker.yaml", "--input", "A=0:360:1",
                       "--points", "M,C", "--json")
    assert code == 0
    d = json.loads(out)
    assert d["input"]["joint"] == "A"
    assert len(d["input"]["values"]) == 361 and d["input"]["values"][-1] == 360
    assert len(d["assembled"]) == 361 and all(d["assembled"])
    assert set(d["points"]) == {"M", "C"}
    for p in d["points"].values():
        assert set(p) == {"position", "velocity", "acceleration"}
        assert len(p["position"]) == 361 and len(p["position"][0]) == 2
    assert set(d["links"]) == {"crank", "coupler", "rocker"}
    for lk in d["links"].values():
        assert set(lk) == {"angle", "angular_velocity", "angular_acceleration"}
    # unit speed: the crank turns at 1 rad/s, its angle is the input in degrees
    assert np.allclose(d["links"]["crank"]["angular_velocity"], 1.0)
    assert np.allclose(d["links"]["crank"]["angle"], d["input"]["values"])
    assert d["derived"]["grashof"]["classification"] == "crank-rocker"


def test_simulate_json_null_where_not_assembled(capsys):
    code, out, _ = run(capsys, "simulate", EX / "kinematics/triple_rocker.yaml", "--input", "A=0:360:10",
                       "--points", "C", "--json", "--speed", "A=2")
    assert code == 0
    d = json.loads(out)
    k = d["input"]["values"].index(180.0)
    assert d["assembled"][k] is False
    assert d["points"]["C"]["position"][k] is None
    assert d["points"]["C"]["velocity"][k] is None
    assert d["links"]["rocker"]["angle"][k] is None
    assert d["assembled"][0] is True and d["points"]["C"]["position"][0] is not None
    assert d["input"]["speed"] == 2.0
    assert [e["kind"] for e in d["events"]].count("dead point") == 2


def test_simulate_files_and_table(capsys, tmp_path):
    png, gif, csv = tmp_path / "p.png", tmp_path / "a.gif", tmp_path / "t.csv"
    code, out, _ = run(capsys, "simulate", EX / "textbook/slider_crank.yaml", "--input", "A=0:360:30",
                       "--points", "C", "--plot", png, "--animate", gif, "--csv", csv)
    assert code == 0
    assert "point C" in out and "transmission angle" in out
    assert png.stat().st_size > 10000 and gif.stat().st_size > 10000
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("input_A,assembled,C_x,C_y") and len(lines) == 14


def test_forces_json(capsys, tmp_path):
    code, out, _ = run(capsys, "forces", EX / "kinematics/crank_rocker.yaml", "--input", "A=0:360:30",
                       "--gravity", "9.81", "--json", "--plot", tmp_path / "f.png", "--csv", tmp_path / "f.csv")
    assert code == 0
    d = json.loads(out)
    assert set(d["joints"]) == {"A", "B", "C", "D"}
    assert d["drives"]["A"]["kind"] == "moment" and len(d["drives"]["A"]["value"]) == 13
    assert (tmp_path / "f.png").exists() and (tmp_path / "f.csv").exists()
    code, out, _ = run(capsys, "forces", EX / "kinematics/crank_rocker.yaml", "--input", "A=0:90:30", "--static")
    assert code == 0 and "static" in out


def test_vll_option(capsys):
    f = EX / "fingers/two_phalanx_vll_000.yaml"
    code, out, _ = run(capsys, "simulate", f, "--input", "E=0:20:5", "--json")
    assert code == 0 and json.loads(out)["vll"] == {"S": "locked"}
    code, _, err = run(capsys, "simulate", f, "--input", "E=0:20:5", "--vll", "S=free")
    assert code == 2 and "free coordinate" in err
    code, out, _ = run(capsys, "simulate", f, "--input", "E=10,10,10", "--input", "S=27,28,29",
                       "--vll", "S=free", "--json")
    assert code == 0 and all(json.loads(out)["assembled"])


@pytest.mark.parametrize("args, text", [
    (["--input", "Z=0:10:1"], "no joint"),
    (["--input", "B=0:10:1"], "not driven"),
    (["--input", "A=0:10"], "START:STOP:STEP"),
    (["--input", "A=0:10:-1"], "does not lead"),
    (["--input", "A=x,y"], "expected numbers"),
    (["--input", "A"], "START:STOP:STEP"),
    (["--input", "A=0:10:1", "--points", "Q"], "no point or joint"),
    (["--input", "A=0:10:1", "--speed", "B=2"], "which has no input"),
    (["--input", "A=0:10:1", "--speed", "A=fast"], "expected a number"),
    (["--input", "A=0:10:1", "--vll", "A=locked"], "P pair"),
    (["--input", "A=0:10:1", "--method", "magic"], "unknown method"),
    (["--input", "A=0:10:1", "--plot", "x.txt"], ".png"),
    (["--input", "A=0:10:1", "--straight", "M=0"], "START:STOP"),
])
def test_bad_inputs_exit_2(capsys, args, text):
    code, out, err = run(capsys, "simulate", EX / "kinematics/crank_rocker.yaml", *args)
    assert code == 2
    assert text in err
    assert "Traceback" not in err + out


def test_bad_files_exit_2(capsys, tmp_path):
    code, _, err = run(capsys, "simulate", tmp_path / "none.yaml", "--input", "A=0:1:1")
    assert code == 2 and "no such file" in err
    f = tmp_path / "nopoints.yaml"
    f.write_text("name: x\nground: f\nlinks: [f, a]\njoints:\n  - {id: A, type: R, links: [f, a], actuated: true}\n")
    code, _, err = run(capsys, "simulate", f, "--input", "A=0:1:1")
    assert code == 2 and "no point" in err
    f = tmp_path / "cam.yaml"
    f.write_text(re.sub(r", profile: \{[^}]*\}", "", (EX / "textbook/cam_follower.yaml").read_text()))
    code, _, err = run(capsys, "simulate", f, "--input", "O=0:10:1")
    assert code == 2 and "no profile" in err
    f = tmp_path / "offcam.yaml"
    f.write_text((EX / "kinematics/cam_roller.yaml").read_text().replace("radius: 1}", "radius: 1.2}"))
    code, _, err = run(capsys, "simulate", f, "--input", "O=0:10:1")
    assert code == 2 and "not assembled" in err
    f = tmp_path / "spatial.yaml"
    f.write_text("name: x\nkind: spatial\nground: f\nlinks: [f, a]\njoints:\n"
                 "  - {id: A, type: R, links: [f, a], point: [0, 0, 0], axis: [0, 0, 1], actuated: true}\n")
    code, _, err = run(capsys, "simulate", f, "--input", "A=0:1:1")
    assert code == 0  # issue 25: spatial files are simulated (tests/kinematics/test_spatial.py)
    f.write_text(f.read_text().replace("type: R", "type: E"))
    code, _, err = run(capsys, "simulate", f, "--input", "A=0:1:1")
    assert code == 2 and "only R, P, H, C and U" in err
    code, _, err = run(capsys, "forces", EX / "kinematics/crank_rocker.yaml", "--input", "A=0:1:1",
                       "--gravity", "nan")
    assert code == 2


@pytest.mark.parametrize("case", ["kinematics/crank_rocker.yaml", "textbook/fourbar.yaml"])
def test_point_table_numbers_stand_whole_at_80_columns(capsys, case):
    """At 80 columns (captured output: Rich's default width) the point table keeps every
    number on one line, with fewer significant digits if need be, and equals the JSON to
    those digits; positions not assembled say so."""
    from mechsyn.cli.common import console

    assert console.width == 80
    code, out, _ = run(capsys, "simulate", EX / case, "--input", "A=0:360:1")
    assert code == 0
    table = out.split("point M")[1].split("links:")[0]
    rows = [ln for ln in table.splitlines() if ln.startswith("│")]
    assert rows and all(len(ln) <= 80 for ln in table.splitlines())
    code, js, _ = run(capsys, "simulate", EX / case, "--input", "A=0:360:1", "--json")
    d = json.loads(js)
    x = d["input"]["values"]
    for ln in rows:
        cells = [c.strip() for c in ln.strip("│").split("│")]
        assert cells[0] != ""  # no continuation line: nothing was wrapped
        k = x.index(float(cells[0]))
        if cells[1] == "not assembled":
            assert d["assembled"][k] is False
            continue
        p = d["points"]["M"]
        want = [*p["position"][k], *p["velocity"][k], *p["acceleration"][k]]
        got = [float(c) for c in cells[1:]]
        assert np.allclose(got, want, rtol=1e-4, atol=1e-9), (ln, want)
