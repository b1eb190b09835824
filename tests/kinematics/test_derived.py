"""Transmission angle, mechanical advantage, Grashof, path extent, straightness."""

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import derived
from mechsyn.kinematics.analysis import input_grid, simulate

from kinematics_helpers import ex, fourbar  # noqa: F401


@pytest.mark.parametrize("lengths, cls, grashof", [
    ((1.0, 3.5, 3.0, 4.0), "crank-rocker", True),
    ((3.0, 3.5, 3.0, 1.0), "double crank (drag link)", True),
    ((3.0, 1.0, 3.0, 3.5), "double rocker (Grashof)", True),
    ((2.2, 3.0, 2.6, 4.5), "triple rocker (non-Grashof)", False),
    ((2.0, 4.0, 3.0, 3.0), "change point (s + l = p + q)", True),
])
def test_grashof(lengths, cls, grashof):
    a, b, c, g = lengths
    m = fourbar(a=a, b=b, c=c, g=g, theta=75)
    G = derived.grashof(m)
    assert G.classification == cls and G.grashof is grashof
    assert np.isclose(G.s + G.l, sorted(lengths)[0] + sorted(lengths)[3])
    assert np.isclose(G.lengths["crank"], a) and np.isclose(G.lengths["frame"], g)


def test_grashof_needs_fourbar(ex):
    with pytest.raises(MechsynInputError):
        derived.grashof(ex("textbook/watt_sixbar.yaml"))


def test_transmission_angle_law_of_cosines():
    a, b, c, g = 1.0, 3.5, 3.0, 4.0
    sim = simulate(fourbar(), {"A": input_grid(0, 360, 10)})
    mu = derived.transmission_angles(sim)["B-C-D"]
    th = np.radians(sim.inputs["A"])
    BD2 = a ** 2 + g ** 2 - 2 * a * g * np.cos(th)
    ref = np.degrees(np.arccos((b ** 2 + c ** 2 - BD2) / (2 * b * c)))
    assert np.allclose(mu, ref, atol=1e-10)
    # extreme values at theta = 0 and 180 (Norton eq. 4.32)
    assert np.isclose(mu.min(), np.degrees(np.arccos((b ** 2 + c ** 2 - (g - a) ** 2) / (2 * b * c))))
    assert np.isclose(mu.max(), np.degrees(np.arccos((b ** 2 + c ** 2 - (g + a) ** 2) / (2 * b * c))))


def test_slider_crank_transmission_angle(ex):
    sim = simulate(ex("textbook/slider_crank.yaml"), {"A": input_grid(0, 360, 30)})
    mu = derived.transmission_angles(sim)["B-C-D"]
    th = np.radians(sim.inputs["A"])
    l = np.linalg.norm(sim.system.mech.joint("C").point - sim.system.mech.joint("B").point)
    # the rod makes the angle asin(r sin(theta) / l) with the slide: mu = 90 - that
    ref = 90 - np.degrees(np.arcsin(np.abs(np.sin(th)) / l))
    assert np.allclose(mu, ref, atol=1e-9)


def test_mechanical_advantage_is_velocity_ratio():
    sim = simulate(fourbar(), {"A": input_grid(5, 175, 10)})
    ma = derived.mechanical_advantage(sim, "rocker")
    assert np.allclose(ma, np.abs(1.0 / sim.links["rocker"].angular_velocity))
    assert derived.default_output_link(sim.system.mech, ["A"]) == "rocker"


def test_mechanical_advantage_slider(ex):
    sim = simulate(ex("textbook/slider_crank.yaml"), {"A": input_grid(10, 170, 20)}, points=["C"])
    ma = derived.mechanical_advantage(sim, "slider")
    assert np.allclose(ma, np.abs(1.0 / sim.points["C"].velocity[:, 0]), rtol=1e-6)


def test_extent_and_straightness():
    t = np.linspace(0, 2 * np.pi, 361)
    circle = np.stack([2 + np.cos(t), np.sin(t)], 1)
    e = derived.path_extent(circle)
    assert np.isclose(e["width"], 2) and np.isclose(e["height"], 2) and np.isclose(e["x_min"], 1)
    line = np.stack([np.linspace(0, 3, 50), 0.5 * np.linspace(0, 3, 50) + 1], 1)
    assert derived.straightness(line)["max_deviation"] < 1e-12
    bump = line.copy()
    bump[25] += 0.1 * np.array([-0.5, 1]) / np.hypot(0.5, 1)
    assert 0.05 < derived.straightness(bump)["max_deviation"] < 0.1
    # crank tip of the crank-rocker: a circle of radius 1
    sim = simulate(fourbar(), {"A": input_grid(0, 360, 1)}, points=["B"])
    e = derived.path_extent(sim.points["B"].position)
    assert np.isclose(e["width"], 2) and np.isclose(e["height"], 2)
