"""``mechsyn capability``: the JSON contract, maps, spatial arms, bad inputs (exit 2)."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm_file import load_arm
from mechsyn.capability.measures import exact_limit
from mechsyn.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
PAPER = str(ROOT / "examples" / "capability" / "paper004_3r.yaml")
UR5 = str(ROOT / "examples" / "capability" / "ur5_dh.yaml")
REF = json.loads((Path(__file__).parent / "data" / "paper004_results.json").read_text())


def run_json(capsys, *args):
    code = main(["capability", *args, "--json"])
    out = capsys.readouterr().out
    assert code == 0, out
    return json.loads(out)


def test_point_contract_ignore_limits(capsys):
    r = run_json(capsys, PAPER, "--point", "1300,900", "--direction", "1,0",
                 "--q1", "20:120:20", "--ignore-limits")
    confs = r["configurations"]
    assert len(confs) == 6 and r["rejected"] == []
    for c in confs:
        assert set(c) >= {"q_deg", "exact", "component", "min_norm", "stepped_min_norm", "stepped"}
    assert [c["q_deg"][0] for c in confs] == [20, 40, 60, 80, 100, 120]
    np.testing.assert_allclose([c["q_deg"][1] for c in confs],
                               [98.01, 55.23, 9.59, -28.77, -63.47, -103.10], atol=0.0051)
    assert [c["stepped_min_norm"] for c in confs] == [65, 70, 80, 90, 95, 60]
    assert r["best"]["q_deg"][0] == 80
    if REF:
        for c, t in zip(confs, REF["table1"]):
            assert c["exact"] == pytest.approx(t["ikq"]["Vx_lp"], rel=1e-6)
            assert c["min_norm"] == pytest.approx(t["ikq"]["Vx_mn"], rel=1e-6)
            assert c["stepped"] == t["ikq"]["Vx_step"]
        assert r["best"]["exact"] == pytest.approx(REF["table1"][3]["ikq"]["Vx_lp"], rel=1e-9)
    assert r["continuous_best"]["exact"] >= r["best"]["exact"]
    # the component measure (perpendicular part free) is never below the exact one
    assert all(c["component"] >= c["exact"] for c in confs)


def test_point_respects_limits_and_explains(capsys):
    r = run_json(capsys, PAPER, "--point", "1300,900", "--direction", "0,1", "--q1", "20:120:20")
    assert [c["q_deg"][0] for c in r["configurations"]] == [80, 100, 120]
    assert len(r["rejected"]) == 3 and "q3" in r["rejected"][0]["reason"]
    if REF:
        assert r["best"]["exact"] == pytest.approx(REF["table1"][4]["ikq"]["Vy_lp"], rel=1e-9)


def test_point_branch_measure_and_polytope(capsys):
    r = run_json(capsys, PAPER, "--point", "1500,500", "--direction", "1,0",
                 "--branch", "both", "--measure", "min_norm", "--polytope", "--ignore-limits")
    signs = {np.sign(c["q_deg"][2]) for c in r["configurations"]}
    assert signs == {-1.0, 1.0}
    assert r["best"]["min_norm"] == max(c["min_norm"] for c in r["configurations"])
    poly = r["best_velocity_polytope"]
    assert poly["limit_along_d"] == pytest.approx(r["best"]["exact"], rel=1e-9)
    assert r["best_velocity_ellipse"]["radius_along_d"] <= r["best"]["exact"] + 1e-9


def test_unreachable_point_gives_no_best(capsys):
    r = run_json(capsys, PAPER, "--point", "5000,0", "--direction", "1,0")
    assert r["configurations"] == [] and r["best"] is None and r["continuous_best"] is None


def test_point_rich_table(capsys):
    assert main(["capability", PAPER, "--point", "1300,900", "--direction", "1,0"]) == 0
    out = capsys.readouterr().out
    assert "best" in out and "110.27" in out and "rejected" in out


def test_grid_map_csv_json(tmp_path, capsys):
    png, csvf = tmp_path / "map.png", tmp_path / "grid.csv"
    r = run_json(capsys, PAPER, "--grid", "1300:2100:200,100:900:200", "--direction", "1,0",
                 "--map", str(png), "--csv", str(csvf))
    assert png.stat().st_size > 10_000 and png.read_bytes()[:4] == b"\x89PNG"
    rows = list(csv.reader(csvf.open()))
    assert rows[0][:3] == ["x", "y", "v_max_exact"] and len(rows) == 26
    v = np.array(r["v_max"])
    assert v.shape == (5, 5)
    if REF:  # x ascending, y ascending; the reference lists y descending
        np.testing.assert_allclose(v[:, ::-1], REF["table2"]["-1|all|lp"], rtol=1e-6)
        cell = next(row for row in rows[1:] if row[:2] == ["1300.0", "900.0"])
        assert float(cell[2]) == pytest.approx(REF["table2"]["-1|all|lp"][0][0], rel=1e-12)
    arm = load_arm(PAPER)
    q = np.radians(np.array(r["q_opt"]).reshape(-1, 3))
    np.testing.assert_allclose(exact_limit(arm.jacobian(q), arm.qd_max, (1, 0)), v.ravel(),
                               rtol=1e-12)


def test_grid_text_summary(capsys):
    assert main(["capability", PAPER, "--grid", "1300:1500:100,500:700:100", "--direction",
                 "0,1", "--continuous"]) == 0
    out = capsys.readouterr().out
    assert "9 points" in out and "continuous" in out


def test_grid_interpolated_configuration(capsys):
    r = run_json(capsys, PAPER, "--grid", "1300:1700:50,300:700:50", "--direction", "1,0",
                 "--continuous", "--interpolate", "1425,515")
    it = r["interpolated"]
    assert it["method"] == "cubic" and it["tool_error"] < 1.0  # mm, on a smooth optimum
    arm = load_arm(PAPER)
    q = np.radians(it["q_deg"])
    assert np.linalg.norm(arm.fk(q)[0] - [1425, 515]) == pytest.approx(it["tool_error"])
    v = np.array(r["v_max"])
    assert v.min() - 1 < it["exact"] < v.max() + 1


def test_spatial_dh_arm_point_and_grid(tmp_path, capsys):
    r = run_json(capsys, UR5, "--point", "400,200,300", "--direction", "1,0,0")
    arm = load_arm(UR5)
    assert len(r["configurations"]) >= 4 and r["best"]["exact"] > 0
    q = np.radians(np.array([c["q_deg"] for c in r["configurations"]]))
    np.testing.assert_allclose(arm.fk(q), np.tile([400, 200, 300], (len(q), 1)), atol=1e-3)
    assert r["best"]["exact"] == max(c["exact"] for c in r["configurations"])
    cb = r["continuous_best"]  # local search over the self-motion from the best ones
    assert cb["exact"] >= r["best"]["exact"]
    np.testing.assert_allclose(arm.fk(np.radians(cb["q_deg"])), [[400, 200, 300]], atol=1e-4)
    png = tmp_path / "ur5.png"
    g = run_json(capsys, UR5, "--grid", "300:500:200,0:200:200", "--z", "300",
                 "--direction", "0,0,1", "--map", str(png))
    assert np.all(np.array(g["v_max"]) > 0) and png.exists()


@pytest.mark.parametrize("args", [
    [PAPER, "--point", "1300", "--direction", "1,0"],
    [PAPER, "--point", "1300,900", "--direction", "0,0"],
    [PAPER, "--point", "1300,900", "--direction", "1,0,0"],
    [PAPER, "--point", "a,b", "--direction", "1,0"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--q1", "120:20:20"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--q1", "0:1"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--branch", "sideways"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--measure", "fastest"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--step", "0"],
    [PAPER, "--point", "1300,900", "--grid", "0:1:1,0:1:1", "--direction", "1,0"],
    [PAPER, "--direction", "1,0"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--map", "x.png"],
    [PAPER, "--grid", "1300:2100:200", "--direction", "1,0"],
    [PAPER, "--point", "nan,900", "--direction", "1,0"],
    [UR5, "--grid", "0:100:50,0:100:50", "--direction", "1,0,0"],
    [UR5, "--point", "400,200,300", "--direction", "1,0,0", "--branch", "both"],
    ["/no/such/arm.yaml", "--point", "1,2", "--direction", "1,0"],
    [PAPER, "--point", "1300,900", "--direction", "1,0", "--interpolate", "1,2"],
    [PAPER, "--grid", "1300:1500:100,300:500:100", "--direction", "1,0", "--interpolate", "0,0"],
])
def test_bad_inputs_exit_2(args, capsys):
    assert main(["capability", *args]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.strip()


def test_bad_arm_file_exit_2(tmp_path, capsys):
    bad = tmp_path / "arm.yaml"
    bad.write_text("kind: planar_serial\nlink_lengths: [900, 900]\n"
                   "joint_speed_limits_deg_s: [4]\n")
    assert main(["capability", str(bad), "--point", "1,1", "--direction", "1,0"]) == 2
    err = capsys.readouterr().err
    assert "arm.yaml" in err and "joint_speed_limits_deg_s" in err


def test_long_arm_table_fits_80_columns(capsys, tmp_path, monkeypatch):
    """A 12-joint arm's point table lists the joint values below the measures, wrapped to
    the terminal, instead of one column per joint (a 100-joint arm's table was 2,000 wide)."""
    from mechsyn.cli import render

    monkeypatch.setattr(render.console, "width", 80)
    arm = tmp_path / "arm12.yaml"
    arm.write_text(f"kind: planar_serial\nlink_lengths: {[0.1] * 12}\njoint_speed_limits_deg_s: {[10] * 12}\n")
    assert main(["capability", str(arm), "--direction", "1,0", "--point", "0.3,0.2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) <= 80
    best = [line for line in lines if " best " in f" {line} "]
    assert best and best[0].split()[0].isdigit()  # the best configuration's row, numbered
    listed = [line for line in lines if line.startswith(f"{best[0].split()[0]}: q (deg) = ")]
    assert listed, lines  # its joint values below the table
