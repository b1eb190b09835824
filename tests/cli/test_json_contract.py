"""``--json`` is exactly the library report's ``to_dict()``: for each command, the JSON the
command prints equals the JSON of the one library call it makes (both sides through
``mechsyn.results.dumps`` and ``json.loads``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from mechsyn.io import load_mechanism
from mechsyn.results import dumps

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CRANK_ROCKER = EXAMPLES / "kinematics/crank_rocker.yaml"


def same_json(cli_json, args: list, report) -> None:
    """The command's ``--json`` equals ``report.to_dict()`` after a JSON round trip."""
    got = cli_json(*args)
    want = json.loads(dumps(report.to_dict() if hasattr(report, "to_dict") else report))
    assert got == want


def test_simulate_json_is_the_report(cli_json):
    from mechsyn.kinematics.analysis import input_grid
    from mechsyn.kinematics.report import simulation_report

    report = simulation_report(load_mechanism(CRANK_ROCKER), {"A": input_grid(0, 360, 30)},
                               straight={"M": (0.0, 90.0)})
    assert "straightness" in report.derived
    same_json(cli_json, ["simulate", CRANK_ROCKER, "-i", "A=0:360:30", "--straight", "M=0:90"], report)


def test_forces_json_is_the_report(cli_json):
    from mechsyn.kinematics.analysis import input_grid
    from mechsyn.kinetostatics import forces

    fa = forces(load_mechanism(CRANK_ROCKER), {"A": input_grid(0, 360, 45)}, gravity=(0.0, -9.81))
    same_json(cli_json, ["forces", CRANK_ROCKER, "-i", "A=0:360:45", "--gravity", "9.81"], fa)


def test_atlas_json_is_the_report(cli_json):
    from mechsyn.synthesis.atlas import chain_atlas

    report = chain_atlas(7, 2, include_degenerate=True, inputs=True)
    assert report.degenerate_listed > 0
    same_json(cli_json, ["atlas", "-n", "7", "-F", "2", "--include-degenerate", "--inputs"], report)


def _without(d: dict, *keys: str) -> dict:
    return {k: v for k, v in d.items() if k not in keys}


@pytest.mark.slow
def test_synth_path_json_is_the_report(cli_json):
    """Equal but for the wall-clock time (``seconds``), which no two runs share."""
    from mechsyn.synthesis.path import load_cases
    from mechsyn.synthesis.reports import path_synthesis, select_case

    cases = EXAMPLES / "synthesis/path_cases_public.json"
    res = path_synthesis(select_case(load_cases(cases), "P2_kk5_timing"), restarts=1, time_limit=20,
                         min_transmission=25.0)
    got = cli_json("synth", "path", cases, "--case", "P2_kk5_timing", "--restarts", "1", "--time-limit", "20",
                   "--min-transmission-angle", "25")
    assert _without(got, "seconds") == _without(json.loads(dumps(res.to_dict())), "seconds")
    assert got["transmission_angle_min_deg"] == 25.0


def test_synth_motion_json_is_the_report(cli_json):
    from mechsyn.synthesis.reports import motion_report

    poses = json.loads((EXAMPLES / "synthesis/poses_4.json").read_text())["poses"]
    P = np.array(poses, float)
    P[:, 2] = np.radians(P[:, 2])
    same_json(cli_json, ["synth", "motion", EXAMPLES / "synthesis/poses_4.json", "--top", "2"],
              motion_report(P, top=2))


def spy(monkeypatch, module: str, name: str) -> list:
    """Record what the library call ``module.name`` returns when the command makes it (for
    searches whose result depends on the clock: the JSON must be that very result's)."""
    import importlib

    mod = importlib.import_module(module)
    real, seen = getattr(mod, name), []

    def wrapper(*args, **kwargs):
        seen.append(real(*args, **kwargs))
        return seen[-1]

    monkeypatch.setattr(mod, name, wrapper)
    return seen


def test_synth_mechanism_json_is_the_report(cli_json, monkeypatch):
    seen = spy(monkeypatch, "mechsyn.synthesis.reports", "mechanism_synthesis")
    got = cli_json("synth", "mechanism", EXAMPLES / "synthesis/slider_crank_path_case.yaml", "--restarts", "1",
                   "--time-limit", "3")
    assert len(seen) == 1 and got == json.loads(dumps(seen[0].to_dict()))


def test_curves_build_and_synth_curve_json_are_the_reports(cli_json, monkeypatch, tmp_path):
    from mechsyn.synthesis.reports import curve_database

    db = tmp_path / "db"
    got = cli_json("curves", "build", "--links", "4", "--per-topology", "30", "--database", db)
    assert got == json.loads(dumps(curve_database(db, max_links=4, per_topology=30).to_dict()))
    seen = spy(monkeypatch, "mechsyn.synthesis.curves.synthesis", "synthesize_curve")
    t = np.linspace(0, 2 * np.pi, 30, endpoint=False)
    target = tmp_path / "ellipse.json"
    target.write_text(json.dumps({"points": np.c_[3 * np.cos(t), np.sin(t)].tolist(), "closed": True}))
    got = cli_json("synth", "curve", target, "--max-links", "4", "--top", "1", "--time-limit", "3", "--database", db)
    assert len(seen) == 1 and got == json.loads(dumps(seen[0].to_dict()))


ARM = EXAMPLES / "capability/paper004_3r.yaml"


def test_capability_point_json_is_the_report(cli_json):
    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.point import capability_at

    report = capability_at(load_arm(ARM), [1300.0, 900.0], [2.0, 1.0], polytope=True)
    same_json(cli_json, ["capability", ARM, "--point", "1300,900", "--direction", "2,1", "--polytope"], report)


def test_capability_grid_json_is_the_report(cli_json):
    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.maps import capability_grid

    grid = np.arange(900.0, 1301.0, 100.0)
    report = capability_grid(load_arm(ARM), grid, grid, [2.0, 1.0], interpolate=(1050.0, 1010.0))
    assert report.interpolated["q_deg"] is not None
    same_json(cli_json, ["capability", ARM, "--grid", "900:1300:100,900:1300:100", "--direction", "2,1",
                         "--interpolate", "1050,1010"], report)


def test_analyze_json_is_the_report(cli_json):
    from mechsyn.structure.report import analyze

    report = analyze(load_mechanism(CRANK_ROCKER), remedies=True)
    same_json(cli_json, ["analyze", CRANK_ROCKER, "--remedies"], report)


def test_structure_json_is_the_report(cli_json):
    from mechsyn.structure.assur import assur_decomposition

    same_json(cli_json, ["structure", CRANK_ROCKER], assur_decomposition(load_mechanism(CRANK_ROCKER)))


def test_export_json_is_the_plate_layout(cli_json):
    from mechsyn.export.plates import link_plates

    layout = link_plates(load_mechanism(CRANK_ROCKER), width=0.2, clearance=0.01, frame=False)
    same_json(cli_json, ["export", CRANK_ROCKER, "--width", "0.2", "--clearance", "0.01", "--no-frame"], layout)


def test_synth_groups_json_is_the_table(cli_json):
    from mechsyn.synthesis.reports import finger_groups

    same_json(cli_json, ["synth", "groups", "--base-mobility", "3", "--actuators", "1", "--max-links", "6"],
              finger_groups(1, 6, base_mobility=3))


def test_synth_function_json_is_the_result(cli_json):
    from mechsyn.synthesis.exact import freudenstein_synthesis

    r = freudenstein_synthesis(np.radians([30.0, 60.0, 90.0]), np.radians([100.0, 120.0, 135.0]), 2.0)
    same_json(cli_json, ["synth", "function", "--phi", "30,60,90", "--psi", "100,120,135", "--ground", "2"], r)
