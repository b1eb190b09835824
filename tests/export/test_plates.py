"""Link plates: the DXF read back has hole spacings equal to the link lengths."""

from __future__ import annotations

import itertools
from pathlib import Path

import ezdxf  # the `cad` extra, in the `test` extra
import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.export.plates import link_plates, plate_outline
from mechsyn.io import load_mechanism

ROOT = Path(__file__).resolve().parents[2]


def _link_lengths(mech, link):
    """Distances between the distinct joint points of ``link`` in the file."""
    pts = []
    for j in mech.joints_of(link):
        if j.type == "R" and not any(np.allclose(j.point, p, atol=1e-12) for p in pts):
            pts.append(np.asarray(j.point, float))
    return sorted(float(np.linalg.norm(a - b)) for a, b in itertools.combinations(pts, 2))


@pytest.mark.parametrize("src", ["examples/kinematics/crank_rocker.yaml", "examples/pyslvs/jansen.pyslvs",
                                 "examples/pyslvs/watt1.pyslvs"])
def test_dxf_hole_spacing_equals_link_lengths(src, tmp_path, run_cli):
    path = ROOT / src
    if path.suffix == ".pyslvs":
        code, _, err = run_cli("convert", path, "-o", tmp_path / "m.yaml")
        assert code == 0, err
        path = tmp_path / "m.yaml"
    mech = load_mechanism(path)
    out = tmp_path / "parts.dxf"
    code, _, err = run_cli("export", path, "--dxf", out, "--clearance", "0.1")
    assert code == 0, err
    doc = ezdxf.readfile(out)
    msp = doc.modelspace()
    outlines = list(msp.query("LWPOLYLINE[layer=='OUTLINE']"))
    circles = list(msp.query("CIRCLE[layer=='HOLES']"))
    labels = [t.dxf.text for t in msp.query("TEXT[layer=='LABELS']")]
    assert len(outlines) == len(labels) == len(mech.link_names)
    layout = link_plates(mech, clearance=0.1)
    # every hole lies inside exactly one outline; group them per plate by the outline's box
    seen = 0
    for poly, plate in zip(outlines, layout.plates):
        assert poly.closed
        xy = np.array([(p[0], p[1]) for p in poly.get_points("xy")])
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        inside = np.array([(c.dxf.center.x, c.dxf.center.y) for c in circles
                           if np.all(np.array([c.dxf.center.x, c.dxf.center.y]) >= lo)
                           and np.all(np.array([c.dxf.center.x, c.dxf.center.y]) <= hi)])
        for c in circles:
            assert c.dxf.radius == pytest.approx((layout.cut_diameter) / 2, abs=1e-12)
        got = sorted(float(np.linalg.norm(a - b)) for a, b in itertools.combinations(inside, 2))
        want = _link_lengths(mech, plate.link)
        assert len(got) == len(want), plate.link
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
        seen += len(inside)
    assert seen == len(circles)


def test_plates_do_not_overlap_on_the_sheet():
    mech = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    layout = link_plates(mech, width=0.4)
    boxes = []
    for p in layout.plates:
        xy = np.array([(x, y) for x, y, _ in p.outline])
        boxes.append((xy.min(axis=0) - 0.2, xy.max(axis=0) + 0.2))
    for (a0, a1), (b0, b1) in itertools.combinations(boxes, 2):
        assert np.any(a1 <= b0 + 1e-9) or np.any(b1 <= a0 + 1e-9)


def test_outline_is_the_grown_hull():
    pts = np.array([[0.0, 0.0], [10.0, 0.0], [4.0, 6.0]])
    out = plate_outline(pts, 1.5)
    # straight sides lie at 1.5 from the hull edges; the arcs turn a full circle in all
    total = sum(4 * np.arctan(b) for _, _, b in out)
    assert total == pytest.approx(2 * np.pi)
    for x, y, _ in out:
        d = np.linalg.norm(pts - [x, y], axis=1).min()
        assert d == pytest.approx(1.5)


def test_holes_too_big_are_refused(run_cli):
    with pytest.raises(MechsynInputError, match="material"):
        link_plates(load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml"), width=0.2, hole_diameter=0.19)
    code, _, err = run_cli("export", ROOT / "examples/kinematics/crank_rocker.yaml", "--dxf", "x.dxf",
                           "--width", "2", "--hole", "1.5")
    assert code == 2 and "too close" in err


def test_a_point_at_a_hole_gives_a_round_plate_not_nan():
    """cam_polar's follower: its named point F is the centre of its only hole R (and of its
    slide S: the follower is a slider's block)."""
    lay = link_plates(load_mechanism(ROOT / "examples" / "kinematics" / "cam_polar.yaml"), width=3.0,
                      hole_diameter=1.0)
    plate = next(p for p in lay.plates if p.link == "follower")
    outline = np.array(plate.outline)
    assert np.all(np.isfinite(outline))
    centre = plate.holes[0]
    # the follower slides on S: it is the slider's block, a rectangle two widths long round its pin
    assert len(outline) == 4 and np.all(outline[:, 2] == 0)
    assert np.allclose(np.sort(np.abs(outline[:, :2] - centre), axis=0)[-1], [3.0, 1.5])
    assert plate_outline(np.array([[1.0, 2.0], [1.0, 2.0], [1.0, 2.0]]), 2.0) == [(-1.0, 2.0, 1.0), (3.0, 2.0, 1.0)]


def test_a_slider_gets_a_block_and_a_slot_over_its_stroke():
    """The slider-crank (crank 1): the frame's slot spans the stroke, 2 cranks; the slider is
    a rectangular block round its pin. A VLL cylinder's slot spans its limits; a slider that
    no drive turns and no limits bound gets no slot, and the notes say why."""
    lay = link_plates(load_mechanism(ROOT / "examples/textbook/slider_crank.yaml"))
    frame = next(p for p in lay.plates if p.link == "frame")
    ((a, b),) = frame.slots
    assert np.linalg.norm(b - a) == pytest.approx(2.0, rel=1e-6)
    block = next(p for p in lay.plates if p.link == "slider")
    corners = np.array(block.outline)
    assert len(corners) == 4 and np.all(corners[:, 2] == 0)
    assert np.ptp(corners[:, 0]) == pytest.approx(2 * lay.width) and np.ptp(corners[:, 1]) == pytest.approx(lay.width)
    assert block.hole_names == ["C+D"] and any("stroke 2" in n for n in lay.notes)
    vll = link_plates(load_mechanism(ROOT / "examples/fingers/two_phalanx_vll_000.yaml"))
    ((a, b),) = next(p for p in vll.plates if p.slots).slots
    assert np.linalg.norm(b - a) == pytest.approx(10.0, rel=1e-9)  # limits [24, 34]
    fixed = link_plates(load_mechanism(ROOT / "examples/structural/gripper_002_fig1_plane.yaml"))
    assert not any(p.slots for p in fixed.plates)
    assert any("give the joint `limits`" in n for n in fixed.notes)
