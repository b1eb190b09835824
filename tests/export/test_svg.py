"""SVG drawings: the plates sheet and the mechanism at a pose with its paths."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from mechsyn.export.plates import link_plates
from mechsyn.export.svg import plates_svg
from mechsyn.io import load_mechanism

ROOT = Path(__file__).resolve().parents[2]
NS = {"s": "http://www.w3.org/2000/svg"}


def test_plates_svg_has_one_cut_path_per_plate_and_true_arcs():
    mech = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    layout = link_plates(mech, width=0.4, hole_diameter=0.15, clearance=0.01)
    root = ET.fromstring(plates_svg(layout))
    assert root.get("width").endswith("mm")  # a file without units is cut in mm
    paths = root.findall(".//s:path", NS)
    assert len(paths) == len(layout.plates)
    for p in paths:
        arcs = re.findall(r"A ([\d.]+) ([\d.]+)", p.get("d"))
        assert arcs and all(float(a) == pytest.approx(0.2, abs=1e-6) for a, _ in arcs)
    holes = [c for c in root.findall(".//s:circle", NS) if c.get("stroke") == "#d00"]
    assert len(holes) == sum(len(p.holes) for p in layout.plates)
    assert all(float(c.get("r")) == pytest.approx(0.08) for c in holes)
    # hole spacing on the crank plate is the crank length (y flipped, distances kept)
    crank = root.find(".//s:g[@id='crank']", NS)
    c = [(float(e.get("cx")), float(e.get("cy"))) for e in crank.findall("s:circle", NS)]
    assert math.dist(*c) == pytest.approx(1.0, abs=1e-6)


def test_drawing_at_a_pose_with_a_path(run_cli, tmp_path):
    out = tmp_path / "m.svg"
    code, _, err = run_cli("export", ROOT / "examples/kinematics/crank_rocker.yaml", "--drawing", out,
                           "--path", "M", "--sweep", "A=0:360:5", "--pose", "A=90", "--dimensions")
    assert code == 0, err
    root = ET.fromstring(out.read_text())
    line = root.find(".//s:polyline", NS)
    assert len(line.get("points").split()) == 73
    # the crank pin B sits at (0, 1) when the crank is at 90 deg (crank length 1 from A at the origin)
    pins = [(float(c.get("cx")), -float(c.get("cy"))) for c in root.findall(".//s:circle", NS)
            if c.get("fill") == "#fff"]
    assert any(math.dist(p, (0.0, 1.0)) < 1e-5 for p in pins)
    texts = [t.text for t in root.findall(".//s:text", NS)]
    assert "1" in texts and "3" in texts  # crank and rocker lengths written along the bars


def test_drawing_refuses_a_path_without_a_sweep(run_cli, tmp_path):
    code, _, err = run_cli("export", ROOT / "examples/kinematics/crank_rocker.yaml", "--drawing",
                           tmp_path / "m.svg", "--path", "M")
    assert code == 2 and "--sweep" in err
    assert not (tmp_path / "m.svg").exists()
