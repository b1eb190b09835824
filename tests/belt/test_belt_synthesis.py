"""Paper 001: synthesis of the primary chain and the belt from H0, Hf, φ_of, A0, r."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mechsyn.errors import MechsynInputError
from mechsyn.belt import BeltDesign, analyze
from mechsyn.belt import synthesize_belt


def _positions(design: BeltDesign, phi_of: float, A0=(0.0, 0.0)):
    s = analyze(design, [0.0, phi_of])
    return tuple(s.H[0] + A0), tuple(s.H[1] + A0)


@pytest.mark.parametrize("phi_deg", [-73.0, -60.0, -30.0, 20.0, 60.0])
def test_recovers_paper_design(phi_deg):
    design = BeltDesign(500.0, 350.0, 100.0, 75.0)
    phi = math.radians(phi_deg)
    A0 = (1200.0, -300.0)                      # machine frame: A0 anywhere
    H0, Hf = _positions(design, phi, A0)
    res = synthesize_belt(H0, Hf, phi, 75.0, A0=A0)
    got = res.design
    assert (got.a, got.c, got.h) == pytest.approx((500.0, 350.0, 100.0), rel=1e-9)
    # and so b0, l0, α0 to the paper's digits
    assert round(got.b0, 3) == 411.765
    assert round(got.l0, 3) == 115.804
    assert round(math.degrees(got.alpha0), 3) == 49.635
    assert all(res.checks.values())
    assert res.to_dict()["Hf_miss"] < 1e-6


@settings(max_examples=40, deadline=None)
@given(a=st.floats(200, 1500), c=st.floats(50, 800), h=st.floats(-300, 300),
       r=st.floats(10, 150), phi_deg=st.floats(-70, -5))
def test_recovers_random_designs(a, c, h, r, phi_deg):
    design = BeltDesign(a, c, h, r)
    phi = math.radians(phi_deg)
    s = analyze(design, np.linspace(0.0, phi, 50))
    if not np.all(s.valid):
        return                                   # the belt itself cannot make this motion
    H0, Hf = _positions(design, phi)
    dx = H0[0] - (Hf[0] * math.cos(phi) + Hf[1] * math.sin(phi))
    dy = H0[1] - (-Hf[0] * math.sin(phi) + Hf[1] * math.cos(phi))
    if abs(dy) < 1e-6 * max(abs(dx), 1.0):
        return                                   # bisector parallel to y: A undetermined
    res = synthesize_belt(H0, Hf, phi, r)
    assert res.design.a == pytest.approx(a, rel=1e-6)
    assert res.design.c == pytest.approx(c, rel=1e-9)
    assert res.design.h == pytest.approx(h, rel=1e-6, abs=1e-6 * a)


def test_construction_points_are_geometric():
    res = synthesize_belt((-350.0, 600.0), (300.0, 560.0), math.radians(-55.0), 75.0)
    A = np.array([0.0, res.design.a])
    # A is equidistant from H0 and Hf(1) and lies on the y axis (lever 1's design line)
    assert np.linalg.norm(A - res.H0) == pytest.approx(np.linalg.norm(A - res.Hf1), rel=1e-12)
    assert np.linalg.norm(res.Hf1) == pytest.approx(np.linalg.norm(res.Hf), rel=1e-12)
    # belt and lever parallel in the design position, B0 = (r, a - b0)
    np.testing.assert_allclose(res.design.B0, [75.0, res.design.a - res.design.b0])
    assert res.checks["lever_and_belt_parallel_at_design"]


@pytest.mark.parametrize("kwargs, field", [
    (dict(H0=(-350, 600), Hf=(-350, 600), phi_of=0.0, r=75), "phi"),
    (dict(H0=(-350, 600), Hf=(-350, 600), phi_of=0.5, r=-1), "r"),
    (dict(H0=(-350, 600), Hf=(300, 600), phi_of=math.radians(-50), r=75), "a0"),
    (dict(H0=(350, 600), Hf=(500, 100), phi_of=math.radians(-50), r=75), "h0"),
    (dict(H0=(-350, 600), Hf=(-350, 600), phi_of=math.radians(30), r=75), None),
    (dict(H0=(-350, 600), Hf=(math.nan, 600), phi_of=0.5, r=75), None),
])
def test_bad_inputs(kwargs, field):
    with pytest.raises(MechsynInputError) as err:
        synthesize_belt(**kwargs)
    if field:
        assert err.value.field == field


def test_slack_belt_rejected():
    # a huge pulley: A passes within r of B0 during the motion
    design = BeltDesign(300.0, 50.0, 0.0, 200.0)
    s = analyze(design, np.linspace(0, math.radians(-170), 400))
    assert not np.all(s.valid)
    H0 = (-50.0, 300.0)
    phi = math.radians(-170)
    # Hf(1) on the circle of radius 50 about A = (0, 300): the bisector passes through A
    xf1, yf1 = 50.0 * math.cos(0.3), 300.0 + 50.0 * math.sin(0.3)
    Hf = (xf1 * math.cos(phi) - yf1 * math.sin(phi), xf1 * math.sin(phi) + yf1 * math.cos(phi))
    with pytest.raises(MechsynInputError, match="slack"):
        synthesize_belt(H0, Hf, phi, 200.0)
