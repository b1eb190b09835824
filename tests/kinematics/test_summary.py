"""The kinematics summary (mechsyn.kinematics.summary): strokes, rocker ranges, time ratios,
against closed forms of the textbook linkages (Uicker, Pennock, Shigley, sec. 1.10)."""

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics.summary import is_full_turn, motion_summary


def summary(name, values=None):
    m = ms.examples.load(name)
    drive = next(j for j in m.joints if j.actuated)
    x = np.arange(0, 360, 2.0) if values is None else values
    return m, motion_summary(m, ms.simulate(m, {drive.id: x}))


def lengths(m):
    return {link: float(np.linalg.norm(m.joints_of(link)[0].point - m.joints_of(link)[1].point)) for link in m.link_names}


def test_crank_rocker_range_and_time_ratio_are_the_closed_forms():
    m, s = summary("crank_rocker")
    L = lengths(m)
    a, b, c, d = L["crank"], L["coupler"], L["rocker"], L["frame"]
    # extreme positions: crank and coupler in line, stretched (b + a) and folded (b - a)
    ext = np.degrees(np.arccos((d**2 + (b + a) ** 2 - c**2) / (2 * d * (b + a))))
    fold = np.degrees(np.arccos((d**2 + (b - a) ** 2 - c**2) / (2 * d * (b - a))))
    r = s["rockers"]["rocker"]
    assert s["full_turn"] and not r["full_turn"]
    assert r["min"]["input"] == pytest.approx(ext, abs=1e-3) and r["max"]["input"] == pytest.approx(180 + fold, abs=1e-3)
    # the rocker's angles there: its pin on the circle of radius b +/- a around the crank pivot
    swing = lambda L2: np.degrees(np.arccos((c**2 + d**2 - L2**2) / (2 * c * d)))  # noqa: E731
    assert r["range"] == pytest.approx(abs(swing(b + a) - swing(b - a)), abs=1e-3)
    t = r["time_ratio"]
    assert t["forward"] == pytest.approx(180 + fold - ext, abs=1e-3)
    assert t["ratio"] == pytest.approx((180 + fold - ext) / (180 - fold + ext), abs=1e-4)


def test_slider_crank_stroke_is_twice_the_crank_with_extreme_positions():
    m, s = summary("slider_crank")
    sl = s["sliders"]["D"]
    crank = np.linalg.norm(m.joint("B").point - m.joint("A").point)
    assert sl["stroke"] == pytest.approx(2 * crank, rel=1e-9)
    assert [sl["min"]["input"], sl["max"]["input"]] == [pytest.approx(180.0, abs=1e-6), pytest.approx(0.0, abs=1e-6)]
    assert sl["max"]["point"][0] - sl["min"]["point"][0] == pytest.approx(2 * crank)
    assert sl["time_ratio"]["ratio"] == pytest.approx(1.0, abs=1e-9)  # in line: no quick return


def test_a_sweep_of_part_of_a_turn_has_no_time_ratio_and_a_crank_turns_fully():
    _, s = summary("crank_rocker", np.arange(0, 180, 2.0))
    assert not s["full_turn"] and s["rockers"]["rocker"]["time_ratio"] is None
    assert is_full_turn(np.linspace(0, 360, 181), "R") and not is_full_turn(np.linspace(0, 360, 181), "P")
    _, s = summary("jansen_leg")
    assert all(not r["full_turn"] for r in s["rockers"].values()) and s["full_turn"]
