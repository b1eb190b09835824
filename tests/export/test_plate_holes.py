"""Every cut hole lies inside its plate's outline, read back from the written SVG and DXF.

The outlines are read as a cutter would: the SVG path's arcs through the SVG 1.1 endpoint
parametrisation (implementation notes F.6.5, written out here, not taken from mechsyn), the
DXF polylines through ezdxf's own path flattening. Each hole's circle must lie inside the
region bounded by its outline, with material round it: the centre inside, its distance to
the outline at least the hole's radius.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import ezdxf  # the `cad` extra, in the `test` extra
import numpy as np
import pytest
from ezdxf import path as dxf_path

import mechsyn as ms
from mechsyn.errors import MechsynInputError
from mechsyn.export.plates import link_plates
from mechsyn.io.convert import load_any

ROOT = Path(__file__).resolve().parents[2]
NS = {"s": "http://www.w3.org/2000/svg"}


def _planar_examples() -> list[str]:
    names = [e.name for e in ms.examples.list() if e.kind == "mechanism"]
    names = [n for n in names if ms.examples.load(n).kind == "planar"]
    return names + [f"pyslvs/{p.name}" for p in sorted((ROOT / "examples" / "pyslvs").glob("*.pyslvs"))]


def _file(name: str) -> Path:
    return ROOT / "examples" / name if name.startswith("pyslvs/") else ms.examples.path(name)


def _arc_points(p0, p1, r: float, large: int, sweep: int, n: int = 400) -> np.ndarray:
    """Points of an SVG circular arc from p0 to p1 (SVG 1.1 F.6.5, rx = ry = r, no rotation)."""
    x1p, y1p = (p0[0] - p1[0]) / 2, (p0[1] - p1[1]) / 2
    if x1p == y1p == 0:  # F.6.2: an arc between identical points is omitted
        return np.array([p0, p1], float)
    r = max(r, math.hypot(x1p, y1p))  # F.6.6: a radius too small is scaled up
    num = r * r * r * r - r * r * (y1p * y1p + x1p * x1p)
    coef = math.sqrt(max(0.0, num / (r * r * (y1p * y1p + x1p * x1p))))
    if large == sweep:
        coef = -coef
    cxp, cyp = coef * y1p, -coef * x1p
    cx, cy = cxp + (p0[0] + p1[0]) / 2, cyp + (p0[1] + p1[1]) / 2
    t1 = math.atan2((y1p - cyp) / r, (x1p - cxp) / r)
    t2 = math.atan2((-y1p - cyp) / r, (-x1p - cxp) / r)
    dt = t2 - t1
    if sweep == 0 and dt > 0:
        dt -= 2 * math.pi
    elif sweep == 1 and dt < 0:
        dt += 2 * math.pi
    t = t1 + dt * np.linspace(0.0, 1.0, n)
    return np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t)])


def _svg_outline(d: str) -> np.ndarray:
    """The polygon of a path made of M, L, A and Z commands (absolute), arcs finely sampled."""
    tokens = re.findall(r"[MLAZ]|-?[\d.]+(?:e-?\d+)?", d)
    pts: list[np.ndarray] = []
    i, cur = 0, None
    while i < len(tokens):
        c = tokens[i]
        if c in "ML":
            cur = np.array([float(tokens[i + 1]), float(tokens[i + 2])])
            pts.append(cur[None])
            i += 3
        elif c == "A":
            r, _, _, large, sweep, x, y = (float(v) for v in tokens[i + 1:i + 8])
            end = np.array([x, y])
            pts.append(_arc_points(cur, end, r, int(large), int(sweep))[1:])
            cur = end
            i += 8
        else:
            assert c == "Z", d
            i += 1
    return np.vstack(pts)


def _inside(poly: np.ndarray, q) -> bool:
    """Ray casting: is ``q`` inside the closed polygon ``poly``?"""
    x, y = poly[:, 0], poly[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    crosses = (y > q[1]) != (yn > q[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        xs = x + (q[1] - y) * (xn - x) / (yn - y)
    return bool(np.count_nonzero(crosses & (q[0] < xs)) % 2)


def _distance_to_boundary(poly: np.ndarray, q) -> float:
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", np.asarray(q) - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300),
                0.0, 1.0)
    return float(np.min(np.linalg.norm(a + t[:, None] * ab - q, axis=1)))


def _assert_hole_in(poly: np.ndarray, centre, radius: float, what: str) -> None:
    scale = float(np.ptp(poly, axis=0).max())
    assert _inside(poly, centre), f"{what}: hole at {tuple(centre)} outside its outline"
    gap = _distance_to_boundary(poly, centre)
    assert gap >= radius - 1e-6 * scale, f"{what}: hole of radius {radius:g} cuts the outline ({gap:g} from it)"


def _assert_slot_in(poly: np.ndarray, slot: np.ndarray, what: str) -> None:
    """Every point of a slot's outline inside the plate's, none on it."""
    scale = float(np.ptp(poly, axis=0).max())
    for q in slot[:: max(1, len(slot) // 200)]:
        assert _inside(poly, q) and _distance_to_boundary(poly, q) > 1e-6 * scale, f"{what}: slot cuts the outline"


def _export(run_cli, name: str, tmp_path: Path, *extra: str) -> tuple[Path, Path] | None:
    svg, dxf = tmp_path / "p.svg", tmp_path / "p.dxf"
    code, _, err = run_cli("export", _file(name), "--svg", svg, "--dxf", dxf, *extra)
    if code != 0 and "give the plate width" in err:  # no link with two pins: size the plates from the span
        mech = load_any(_file(name))
        pts = np.array([j.point for j in mech.joints if j.point is not None], float)[:, :2]
        width = 0.1 * float(np.ptp(pts, axis=0).max() or 1.0)
        code, _, err = run_cli("export", _file(name), "--svg", svg, "--dxf", dxf, "--width", str(width))
    if code != 0 and "no points to place the holes" in err:
        return None
    assert code == 0, err
    return svg, dxf


@pytest.mark.parametrize("name", _planar_examples())
def test_every_hole_lies_inside_its_plate_in_svg_and_dxf(name, run_cli, tmp_path):
    files = _export(run_cli, name, tmp_path, "--clearance", "0.0")
    if files is None:
        with pytest.raises(MechsynInputError, match="no points"):
            link_plates(load_any(_file(name)))
        return
    svg, dxf = files
    root = ET.fromstring(svg.read_text())
    groups = root.findall("s:g/s:g", NS)
    assert groups
    n_holes = 0
    n_slots = 0
    for g in groups:
        (path,) = [p for p in g.findall("s:path", NS) if p.get("stroke") == "#000"]
        poly = _svg_outline(path.get("d"))
        for slot in (p for p in g.findall("s:path", NS) if p.get("stroke") == "#d00"):  # a slider's guide
            _assert_slot_in(poly, _svg_outline(slot.get("d")), f"{name} SVG plate {g.get('id')}")
            n_slots += 1
        for c in g.findall("s:circle", NS):  # holes (red) and point marks (green)
            centre = (float(c.get("cx")), float(c.get("cy")))
            _assert_hole_in(poly, centre, float(c.get("r")), f"{name} SVG plate {g.get('id')}")
            n_holes += 1
    msp = ezdxf.readfile(dxf).modelspace()
    outlines = [np.array([(v.x, v.y) for v in dxf_path.make_path(e).flattening(1e-6)])
                for e in msp.query("LWPOLYLINE[layer=='OUTLINE']")]
    assert len(outlines) == len(groups)
    slots = [np.array([(v.x, v.y) for v in dxf_path.make_path(e).flattening(1e-6)])
             for e in msp.query("LWPOLYLINE[layer=='SLOTS']")]
    assert len(slots) == n_slots
    for slot in slots:
        owners = [poly for poly in outlines if _inside(poly, slot[0])]
        assert len(owners) == 1, f"{name} DXF: a slot inside {len(owners)} outlines"
        _assert_slot_in(owners[0], slot, f"{name} DXF")
    circles = list(msp.query("CIRCLE[layer=='HOLES' | layer=='POINTS']"))
    assert len(circles) == n_holes
    for c in circles:
        centre = (c.dxf.center.x, c.dxf.center.y)
        owners = [poly for poly in outlines if _inside(poly, centre)]
        assert len(owners) == 1, f"{name} DXF: hole at {centre} inside {len(owners)} outlines"
        _assert_hole_in(owners[0], centre, c.dxf.radius, f"{name} DXF")


def test_the_svg_reader_sees_a_hole_outside_a_mirrored_arc():
    """The check can fail: an end arc bulging inwards (sweep flag flipped) leaves the hole out."""
    right = _svg_outline("M 0 1 L 4 1 A 1 1 0 0 0 4 -1 L 0 -1 A 1 1 0 0 0 0 1 Z")
    wrong = _svg_outline("M 0 1 L 4 1 A 1 1 0 0 1 4 -1 L 0 -1 A 1 1 0 0 1 0 1 Z")
    assert _distance_to_boundary(right, (4.0, 0.0)) == pytest.approx(1.0, abs=1e-4)
    assert _inside(right, (4.0, 0.0)) and _inside(right, (4.9, 0.0))
    assert not _inside(wrong, (4.5, 0.0)) and not _inside(wrong, (-0.5, 0.0))
