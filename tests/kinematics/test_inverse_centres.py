"""Issue 40: inverse kinematics by the same engines, and instant centres (Kennedy)."""

from __future__ import annotations

from itertools import combinations

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.analysis import drawn_inputs, simulate
from mechsyn.kinematics.centres import instant_centres
from mechsyn.kinematics.inverse import posed, simulate_inverse


def test_five_bar_tool_follows_a_line_and_the_forward_simulation_agrees():
    m = ms.load("five_bar_5r")
    path = np.column_stack([np.linspace(2.0, 2.6, 7), np.linspace(3.5, 3.1, 7)])
    r = simulate_inverse(m, "tool", path)
    assert r.ok and r.boundary is None
    s = simulate(m, r.inputs, points=["tool"])
    assert s.point("tool") == pytest.approx(path, abs=1e-8)


def test_out_of_reach_stops_at_the_workspace_boundary():
    m = ms.load("five_bar_5r")
    r = simulate_inverse(m, "tool", [[2.0, 3.6], [2.0, 40.0]])
    assert r.reached.tolist() == [True, False] and r.boundary == 1
    assert "workspace boundary" in r.message
    # the nearest reach is on the boundary: the distal links (2.5 + 2.5 from the proximal tips) nearly straight
    assert np.linalg.norm(r.nearest[1] - [2.0, 40.0]) > 30


def test_drives_must_match_the_point():
    with pytest.raises(MechsynInputError, match="drive"):
        simulate_inverse(ms.examples.load("crank_rocker"), "M", [[1.0, 2.0]])


@pytest.mark.slow
def test_delta_platform_point_by_three_drives():
    d = ms.load("delta")
    u0 = drawn_inputs(d)
    p0 = simulate(d, {k: [v] for k, v in u0.items()}, points=["S1a2"]).point("S1a2")[0]
    target = p0 + [0.05, -0.03, -0.1]
    r = simulate_inverse(d, "S1a2", [target])
    assert r.ok
    s = simulate(d, {k: v for k, v in r.inputs.items()}, points=["S1a2", "S2a2"])
    assert s.point("S1a2")[0] == pytest.approx(target, abs=1e-7)
    # a translating platform: the other platform joint moved by the same vector
    assert s.point("S2a2")[0] - simulate(d, {k: [v] for k, v in u0.items()}, points=["S2a2"]).point("S2a2")[0] == \
        pytest.approx([0.05, -0.03, -0.1], abs=1e-6)
    new = posed(d, simulate(d, r.inputs, points=None), 0)
    assert new.joint("S1a2").point == pytest.approx(target, abs=1e-7)


def _collinear(p, q, r, tol):
    u, w = np.subtract(q, p), np.subtract(r, p)
    return abs(u[0] * w[1] - u[1] * w[0]) <= tol * np.linalg.norm(u) * np.linalg.norm(w)


@pytest.mark.parametrize("name, angle", [("crank_rocker", None), ("crank_rocker", 150.0), ("watt_sixbar", None)])
def test_kennedy_three_centres_on_a_line(name, angle):
    m = ms.load(name)
    inputs = None if angle is None else {"A": angle}
    cs = {c.links: c for c in instant_centres(m, inputs)}
    links = m.link_names
    n = len(links)
    assert len(cs) == n * (n - 1) // 2
    checked = 0
    for a, b, c in combinations(links, 3):
        pts = [cs[tuple(x)].point for x in ((a, b), (b, c), (a, c))]
        if all(p is not None for p in pts) and np.ptp(pts, axis=0).max() > 1e-9:
            assert _collinear(*pts, 1e-7), (a, b, c)
            checked += 1
    assert checked >= 4
    # the primary centres are the R joints
    for c in cs.values():
        if c.joint:
            assert c.point == pytest.approx(posed_point(m, c.joint, inputs), abs=1e-9)


def posed_point(m, jid, inputs):
    u = drawn_inputs(m)
    u.update(inputs or {})
    return simulate(m, {k: [v] for k, v in u.items()}, points=[jid]).point(jid)[0]


def test_velocity_ratio_is_the_distance_ratio():
    m = ms.examples.load("crank_rocker")
    cs = {c.links: c for c in instant_centres(m)}
    p12, p14, p24 = cs[("frame", "crank")].point, cs[("frame", "rocker")].point, cs[("crank", "rocker")].point
    # ω4/ω2 = P12P24 / P14P24, signed: same sense when P24 is outside P12-P14
    ratio = np.linalg.norm(p24 - p12) / np.linalg.norm(p24 - p14)
    assert abs(cs[("crank", "rocker")].ratio) == pytest.approx(ratio, rel=1e-9)


def test_slider_centre_at_infinity_perpendicular_to_the_guide():
    s = ms.load("slider_crank")
    c = next(c for c in instant_centres(s, {"A": 60.0}) if c.links == ("frame", "slider"))
    assert c.point is None and abs(c.direction[0]) == pytest.approx(0.0, abs=1e-9)
