"""``mechsyn belt ...``: JSON contract, example file, output files, bad inputs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from mechsyn.cli.main import main
from mechsyn.belt import BeltDesign, analyze, load_belt_case

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "belt" / "paper001.yaml"
PAPER_ARGS = ["--a", "500", "--c", "350", "--h", "100", "--r", "75"]


def _json(capsys, argv):
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_analyze_json_contract(capsys):
    out = _json(capsys, ["belt", "analyze", *PAPER_ARGS, "--phi", "-73:85:1", "--json"])
    assert round(out["b0"], 3) == 411.765
    assert round(out["l0"], 3) == 115.804
    assert round(out["alpha0_deg"], 3) == 49.635
    rows = out["rows"]
    assert len(rows) == 159
    assert rows[0]["dphi_deg"] == -73.0 and rows[-1]["dphi_deg"] == 85.0
    for key in ("dphi_deg", "dpsi_deg", "beta_deg", "b", "d", "psi1", "psi2"):
        assert isinstance(rows[5][key], float)
    for key in ("C", "H", "C1", "C2", "H1", "H2"):
        assert len(rows[5][key]) == 2
    design_row = rows[73]
    assert design_row["dphi_deg"] == 0.0
    assert design_row["psi1"] == pytest.approx(-1.0)
    assert design_row["H2"] == pytest.approx([500 * 100 / 350, 0.0], abs=1e-9)
    # the spec's path figures from the command
    paths = out["paths"]
    assert paths["C"]["extent_x"] == pytest.approx(1228.5, abs=0.1)
    assert paths["H"]["extent_x"] == pytest.approx(1272.8, abs=0.1)
    assert paths["C"]["max_positive_deviation"] == pytest.approx(44.92, abs=0.01)
    assert paths["H"]["max_positive_deviation"] == pytest.approx(20.94, abs=0.01)
    assert paths["H"]["translation_length"] == pytest.approx(270, abs=1)
    # a row against the library (closed form)
    st = analyze(BeltDesign(500, 350, 100, 75), [math.radians(rows[20]["dphi_deg"])])
    assert rows[20]["H1"] == pytest.approx(st.H1[0].tolist(), rel=1e-12)
    assert out["four_bar_comparison"]["four_bar"]["assembled_dphi_deg"][1] < 40


def test_example_file_reproduces_paper(capsys):
    case = load_belt_case(str(EXAMPLE))
    assert case.design is not None and case.design.a == 500
    out = _json(capsys, ["belt", "analyze", "--file", str(EXAMPLE), "--json"])
    assert round(out["b0"], 3) == 411.765
    assert round(out["paths"]["C"]["extent_x"], -1) == 1230
    assert round(out["paths"]["H"]["extent_x"], -1) == 1270
    assert out["motion"]["law"] == "TrapezoidalLaw"
    assert max(out["motion"]["phid_deg_s"]) == pytest.approx(90.0)
    # options override the file
    out2 = _json(capsys, ["belt", "analyze", "--file", str(EXAMPLE), "--h", "0", "--json"])
    assert out2["paths"]["H"]["extent_x"] == pytest.approx(out["paths"]["C"]["extent_x"])


def test_synthesis_file_and_command(capsys, tmp_path):
    phi = -60.0
    st = analyze(BeltDesign(500, 350, 100, 75), [0.0, math.radians(phi)])
    H0 = [float(v) for v in st.H[0] + [100.0, 50.0]]
    Hf = [float(v) for v in st.H[1] + [100.0, 50.0]]
    out = _json(capsys, ["belt", "synthesize", "--h0", f"{H0[0]!r},{H0[1]!r}",
                         "--hf", f"{Hf[0]!r},{Hf[1]!r}", "--phi", str(phi), "--r", "75",
                         "--a0", "100,50", "--json"])
    assert (out["a"], out["c"], out["h"]) == pytest.approx((500, 350, 100), rel=1e-9)
    assert round(out["b0"], 3) == 411.765 and round(out["alpha0_deg"], 3) == 49.635
    f = tmp_path / "s.yaml"
    f.write_text(f"synthesis: {{h0: [{H0[0]!r}, {H0[1]!r}], hf: [{Hf[0]!r}, {Hf[1]!r}], "
                 f"phi_of_deg: {phi}, r: 75, a0: [100, 50]}}\nphi_deg: {{start: -60, stop: 0}}\n")
    res = _json(capsys, ["belt", "analyze", "--file", str(f), "--json"])
    assert res["design"]["a"] == pytest.approx(500)
    assert res["synthesis"]["c"] == pytest.approx(350)
    assert main(["belt", "synthesize", "--h0", "-350,600", "--hf", "324.6,597.5",
                 "--phi", "-60", "--r", "75"]) == 0
    assert "b0" in capsys.readouterr().out


def test_inverse_command(capsys, tmp_path):
    out = _json(capsys, ["belt", "inverse", *PAPER_ARGS, "--phi", "-73:0:1", "--speed", "1000",
                         "--json", "--csv", str(tmp_path / "inv.csv")])
    # at the design position |H'| = a = 500: φ_dot = 1000/500 rad/s
    assert out["phid_deg_s"][-1] == pytest.approx(math.degrees(2.0), rel=1e-9)
    assert out["duration"] > 0
    lines = (tmp_path / "inv.csv").read_text().splitlines()
    assert lines[0].startswith("dphi_deg,t,") and len(lines) == 75


def test_output_files(capsys, tmp_path):
    csv_path, png = tmp_path / "t.csv", tmp_path / "f.png"
    assert main(["belt", "analyze", *PAPER_ARGS, "--phi", "-73:85:1", "--csv", str(csv_path),
                 "--plot", str(png)]) == 0
    lines = csv_path.read_text().splitlines()
    assert lines[0].split(",")[:3] == ["dphi_deg", "dpsi_deg", "beta_deg"]
    assert len(lines) == 160
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "straight-line quality" in capsys.readouterr().out


@pytest.mark.slow
def test_animation(tmp_path):
    gif = tmp_path / "m.gif"
    assert main(["belt", "analyze", *PAPER_ARGS, "--phi", "-73:85:15", "--animate",
                 str(gif)]) == 0
    from PIL import Image

    with Image.open(gif) as im:
        assert im.n_frames == 11


def _bad(tmp_path):
    bad_yaml = tmp_path / "bad.yaml"
    bad_yaml.write_text("design: {a: 500, c: 350\nphi_deg: [\n")
    unknown = tmp_path / "unknown.yaml"
    unknown.write_text("design: {a: 500, c: 350, h: 100, r: 75, q: 1}\n")
    neg = tmp_path / "neg.yaml"
    neg.write_text("design: {a: 500, c: 350, h: 100, r: -75}\nphi_deg: {start: 0, stop: 1}\n")
    table = tmp_path / "table.csv"
    table.write_text("t,phi\n0,0\n1,1\n1,2\n")
    return [
        (["belt", "analyze", *PAPER_ARGS[:-2], "--r", "0", "--phi", "0:10:1"], "--r"),
        (["belt", "analyze", "--a", "500", "--c", "-5", "--h", "0", "--r", "75",
          "--phi", "0:10:1"], "--c"),
        (["belt", "analyze", "--a", "500", "--c", "350", "--phi", "0:10:1"], "missing"),
        (["belt", "analyze", *PAPER_ARGS], "--phi"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10"], "--phi"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:-1"], "--phi"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:0.5:1"], "--phi"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--segment", "5"], "--segment"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--segment", "50:60"], "segment"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--law", "wobble"], "--law"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--law", "trapezoidal"], "--law"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--omega", "-3"], "--omega"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--law", "table", "--table",
          str(table)], str(table)),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--law", "table", "--table",
          str(tmp_path / "nope.csv")], "nope.csv"),
        (["belt", "analyze", *PAPER_ARGS, "--phi", "0:10:1", "--animate",
          str(tmp_path / "m.avi")], "--animate"),
        (["belt", "analyze", "--file", str(tmp_path / "missing.yaml")], "missing.yaml"),
        (["belt", "analyze", "--file", str(bad_yaml)], "bad.yaml:"),
        (["belt", "analyze", "--file", str(unknown)], "design.q"),
        (["belt", "analyze", "--file", str(neg)], "design.r"),
        (["belt", "analyze", "--a", "100", "--c", "300", "--h", "0", "--r", "200",
          "--phi", "-100:-20:1"], "slack"),
        (["belt", "synthesize", "--h0", "1", "--hf", "0,0", "--phi", "10", "--r", "75"],
         "--h0"),
        (["belt", "synthesize", "--h0", "-350,600", "--hf", "-350,600", "--phi", "0",
          "--r", "75"], "--phi"),
        (["belt", "synthesize", "--h0", "-350,600", "--hf", "300,600", "--phi", "-50",
          "--r", "75"], "--a0"),
        (["belt", "synthesize", "--h0", "-350,600", "--hf", "300,600", "--phi", "-50",
          "--r", "nan"], "--r"),
        (["belt", "inverse", *PAPER_ARGS, "--phi", "-73:0:1", "--speed", "0"], "--speed"),
        (["belt", "inverse", *PAPER_ARGS, "--phi", "-73:0:1", "--speed", "1",
          "--point", "Q"], "--point"),
    ]


def test_bad_inputs_exit_2(capsys, tmp_path):
    for argv, needle in _bad(tmp_path):
        code = main(argv)
        err = capsys.readouterr().err
        assert code == 2, (argv, err)
        assert "Traceback" not in err
        assert needle in err, (argv, err)
    assert not (tmp_path / "m.avi").exists()


def test_table_law_and_reverse_range(capsys, tmp_path):
    table = tmp_path / "law.csv"
    table.write_text("# t, dphi_deg\nt,dphi_deg\n" + "".join(
        f"{t / 10:g},{-73 + 73 * (t / 10) ** 2:g}\n" for t in range(11)))
    out = _json(capsys, ["belt", "analyze", *PAPER_ARGS, "--phi", "-73:0:1", "--law", "table",
                         "--table", str(table), "--samples", "11", "--json"])
    assert out["motion"]["law"] == "TableLaw"
    assert out["motion"]["phid_deg_s"][5] == pytest.approx(2 * 73 * 0.5, rel=1e-9)
    # a range run backwards: the input speed is negative, speeds stay positive
    out = _json(capsys, ["belt", "analyze", *PAPER_ARGS, "--phi", "0:-73:-1", "--json"])
    assert out["rows"][0]["dphi_deg"] == 0.0
    assert out["motion"]["phid_deg_s"][0] == pytest.approx(-60.0)
    assert min(out["motion"]["H"]["speed"]) > 0


def test_partly_slack_range_warns(capsys):
    assert main(["belt", "analyze", "--a", "100", "--c", "300", "--h", "0", "--r", "200",
                 "--phi", "-30:40:1"]) == 0
    assert "slack" in capsys.readouterr().out
    out = _json(capsys, ["belt", "analyze", "--a", "100", "--c", "300", "--h", "0",
                         "--r", "200", "--phi", "-30:40:1", "--json"])
    assert out["rows"][0]["valid"] is False and out["rows"][0]["b"] is None
    assert out["rows"][-1]["valid"] is True


def test_four_bar_file_for_the_planar_solver(capsys, tmp_path):
    from mechsyn.io import load_mechanism

    out = tmp_path / "fb.yaml"
    assert main(["belt", "analyze", *PAPER_ARGS, "--phi", "-10:10:1", "--four-bar-file",
                 str(out), "--json"]) == 0
    capsys.readouterr()
    mech = load_mechanism(str(out))
    bundled = load_mechanism(str(ROOT / "examples" / "belt" / "paper001_four_bar.yaml"))
    for j, k in zip(mech.joints, bundled.joints):
        assert j.id == k.id and j.point == pytest.approx(k.point)
    assert mech.joint("B0").point == pytest.approx([75.0, 500.0 - 500 * 350 / 425])
    assert mech.points["H"].at == pytest.approx([-350.0, 600.0])
    assert main(["analyze", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["mobility"] == 1
