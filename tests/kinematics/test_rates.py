"""Velocities and accelerations from the linear solves against finite differences."""

import numpy as np
import pytest

from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.kinematics.solve import assemble, newton
from mechsyn.kinematics.system import build_system

from kinematics_helpers import ex, fourbar  # noqa: F401

CASES = [
    ("kinematics/crank_rocker.yaml", {"A": 37.0}, None),
    ("textbook/slider_crank.yaml", {"A": 200.0}, None),
    ("kinematics/inverted_slider_crank.yaml", {"A": 123.0}, None),
    ("kinematics/cam_roller.yaml", {"O": 140.0}, None),
    ("kinematics/cam_polar.yaml", {"O": 125.0}, None),
    ("textbook/watt_sixbar.yaml", {"A": 80.0}, None),
    ("textbook/stephenson_sixbar.yaml", {"A": 75.0}, None),
    ("textbook/five_bar_5r.yaml", {"A": 110.0, "E": 70.0}, None),
    ("fingers/two_phalanx_vll_000.yaml", {"E": 10.0}, None),
    ("fingers/two_phalanx_vll_000.yaml", {"E": 10.0, "S": 27.5}, {"S": "free"}),
    ("fingers/two_phalanx_vll_000.yaml", {"E": 10.0, "S": 27.5}, {"S": "active"}),
    ("fingers/three_phalanx_vll_000.yaml", {"F": 5.0}, None),
]


def _state(S, values):
    u = np.array([d.assembled for d in S.drivers], float)
    for k, d in enumerate(S.drivers):
        if d.joint in values:
            u[k] = np.radians(values[d.joint]) if d.type == "R" else values[d.joint]
    return u


@pytest.mark.parametrize("rel, values, vll", CASES)
def test_rates_match_finite_differences(ex, rel, values, vll):
    m = ex(rel)
    prescribed = tuple(j for j, mode in (vll or {}).items() if mode == "free")
    S = build_system(m, vll=vll, prescribed=prescribed)
    u = _state(S, values)
    speeds = np.array([1.0 if d.joint in values else 0.0 for d in S.drivers])
    speeds[0] = 1.3  # a non-unit speed for the first input
    if len(speeds) > 1 and speeds[1]:
        speeds[1] = -0.7
    q = assemble(S, u)
    (qd,), (qdd,) = S.rates(q[None], speeds)
    h = 1e-5

    def at(t):
        qq, ok = newton(S, q + t * qd, u + t * speeds)
        assert ok
        return qq

    qp, qm = at(h), at(-h)
    fd_v = (qp - qm) / (2 * h)
    assert np.abs(fd_v - qd).max() <= 1e-6 * max(1.0, np.abs(qd).max())
    (vp,), (_,) = S.rates(qp[None], speeds)
    (vm,), (_,) = S.rates(qm[None], speeds)
    fd_a = (vp - vm) / (2 * h)
    assert np.abs(fd_a - qdd).max() <= 1e-6 * max(1.0, np.abs(qdd).max())


def test_point_rates_closed_form_fourbar_vs_differences():
    """The vectorised closed-form RRR rates against differences of the closed-form positions."""
    m = fourbar()
    h = 1e-4
    x = input_grid(0, 360, 7.5)
    base = simulate(m, {"A": x}, points=["M"], method="assur")
    p = simulate(m, {"A": x + np.degrees(h)}, points=["M"], method="assur")
    n = simulate(m, {"A": x - np.degrees(h)}, points=["M"], method="assur")
    v = base.points["M"].velocity
    a = base.points["M"].acceleration
    fd_v = (p.points["M"].position - n.points["M"].position) / (2 * h)
    fd_a = (p.points["M"].velocity - n.points["M"].velocity) / (2 * h)
    assert np.abs(fd_v - v).max() <= 1e-6 * np.abs(v).max()
    assert np.abs(fd_a - a).max() <= 1e-6 * np.abs(a).max()
    # omega of the coupler and rocker as well
    for link in ("coupler", "rocker"):
        w = base.links[link].angular_velocity
        fd = np.radians(p.links[link].angle - n.links[link].angle) / (2 * h)
        assert np.abs(fd - w).max() <= 1e-6 * np.abs(w).max()


def test_speed_scales_velocity_and_acceleration():
    m = fourbar()
    x = input_grid(0, 90, 15)
    s1 = simulate(m, {"A": x}, points=["M"])
    s2 = simulate(m, {"A": x}, points=["M"], speeds={"A": 2.5})
    assert np.allclose(s2.points["M"].velocity, 2.5 * s1.points["M"].velocity, rtol=1e-12, atol=1e-14)
    assert np.allclose(s2.points["M"].acceleration, 6.25 * s1.points["M"].acceleration, rtol=1e-12, atol=1e-14)
