"""``-o -`` / ``--csv -``: data to stdout, so results pipe into other tools."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_simulate_csv_to_stdout_equals_the_file(run_cli, tmp_path):
    args = ("simulate", EXAMPLES / "kinematics/crank_rocker.yaml", "--input", "A=0:360:30", "--points", "M")
    code, out, err = run_cli(*args, "--csv", "-")
    assert code == 0, err
    code, _, err = run_cli(*args, "--csv", tmp_path / "t.csv")
    assert code == 0, err
    assert out == (tmp_path / "t.csv").read_text()
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0][0] == "input_A" and len(rows) == 14


def test_two_outputs_to_stdout_are_refused(run_cli):
    code, _, err = run_cli("simulate", EXAMPLES / "kinematics/crank_rocker.yaml", "--input", "A=0:360:30",
                           "--csv", "-", "--json")
    assert code == 2 and "two outputs to stdout" in err


def test_analyze_json_to_stdout(run_cli):
    code, out, err = run_cli("analyze", EXAMPLES / "kinematics/crank_rocker.yaml", "--json", "-o", "-")
    assert code == 0, err
    assert json.loads(out)["mobility"] == 1


def test_belt_inverse_csv_pipes(run_cli):
    code, out, err = run_cli("belt", "inverse", "--a", "500", "--c", "350", "--h", "100", "--r", "75",
                             "--phi", "-73:0:1", "--speed", "1000", "--csv", "-")
    assert code == 0, err
    rows = list(csv.reader(io.StringIO(out)))
    assert rows[0][0] == "dphi_deg" and len(rows) == 75
