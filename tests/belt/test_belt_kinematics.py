"""Paper 001 (belt-and-pulley manipulator): closed-form kinematics against the spec.

Where the paper's printed formula is wrong, the code follows the spec
(``flexible-manipulator.md``); the tests below say which.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.belt import (
    BeltDesign,
    ConstantSpeedLaw,
    TableLaw,
    TrapezoidalLaw,
    analyze,
    best_line_deviation,
    design_constants,
    compare_with_four_bar,
    equivalent_four_bar,
    inverse_input,
    motion,
    path_quality,
)

PAPER = BeltDesign(a=500.0, c=350.0, h=100.0, r=75.0)
RANGE = (math.radians(-73.0), math.radians(85.0))


def _vectors():
    # paper 001's reference vectors (shared/spec/data/paper001_vectors.json, copied here)
    return json.loads((Path(__file__).parent / "data" / "paper001_vectors.json").read_text())


def test_design_constants_to_paper_digits():
    # Paper 001: b0 = 411.765 mm, l0 = 115.804 mm, α0 = 49.635° (printed to 3 decimals).
    b0, l0, alpha0 = design_constants(500.0, 350.0, 75.0)
    assert round(b0, 3) == 411.765
    assert round(l0, 3) == 115.804
    assert round(math.degrees(alpha0), 3) == 49.635


def test_design_constants_match_vectors():
    design = _vectors()["design"]
    b0, l0, alpha0 = design_constants(500.0, 350.0, 75.0)
    np.testing.assert_allclose([b0, l0, math.degrees(alpha0)],
                               [design["b0"], design["l0"], design["alpha0_deg"]], rtol=1e-12)


def _columns(st):
    return {
        "dphi_deg": np.degrees(st.dphi), "dpsi_deg": np.degrees(st.dpsi),
        "beta_deg": np.degrees(st.beta), "b": st.b, "d": st.d,
        "psi1": st.psi1, "psi2": st.psi2,
        "xC": st.C[:, 0], "yC": st.C[:, 1], "xH": st.H[:, 0], "yH": st.H[:, 1],
        "xC1": st.C1[:, 0], "yC1": st.C1[:, 1], "xC2": st.C2[:, 0], "yC2": st.C2[:, 1],
        "xH1": st.H1[:, 0], "yH1": st.H1[:, 1], "xH2": st.H2[:, 0], "yH2": st.H2[:, 1],
    }


def test_every_spec_vector_to_1e6_relative():
    data = _vectors()
    table = np.array(data["test_vectors"])
    st = analyze(PAPER, np.radians(table[:, 0]))
    got = _columns(st)
    for j, name in enumerate(data["test_vectors_columns"]):
        want = table[:, j]
        # 1e-6 relative; values that are exactly zero in theory (design position:
        # Δψ, C'', y'_C, ...) are round-off in the file (~1e-13), hence the tiny floor.
        floor = 1e-9 * max(1.0, float(np.max(np.abs(want))))
        np.testing.assert_allclose(got[name], want, rtol=1e-6, atol=floor, err_msg=name)


def test_design_position_identities():
    st = analyze(PAPER, [0.0])
    a, c, h = PAPER.a, PAPER.c, PAPER.h
    assert math.degrees(st.beta[0]) == pytest.approx(90.0, abs=1e-12)
    assert st.psi1[0] == pytest.approx(-1.0, abs=1e-12)     # link 2 translates
    assert st.yG[0] == pytest.approx(a - PAPER.b0, rel=1e-12)
    assert st.psi2[0] == pytest.approx(-a / c, rel=1e-12)
    np.testing.assert_allclose(st.C2[0], [0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(st.H2[0], [a * h / c, 0.0], atol=1e-9)
    assert st.H2[0, 0] == pytest.approx(142.857, abs=5e-4)
    np.testing.assert_allclose(st.B[0], [PAPER.r, a], atol=1e-9)


def test_printed_psi1_is_wrong_at_design_position():
    # The paper's (9) ψ' = 1 - (a/r) cos β is the derivative w.r.t. -Δφ: used directly it
    # gives 1 + ψ' = 2 at the design position, not 0 (link 2 would not translate).
    st = analyze(PAPER, [0.0])
    printed = 1.0 - (PAPER.a / PAPER.r) * math.cos(st.beta[0])
    assert 1.0 + printed == pytest.approx(2.0)
    assert 1.0 + st.psi1[0] == pytest.approx(0.0, abs=1e-12)


def test_beta_equals_printed_equation_7_and_tangent_geometry():
    phi = np.radians(np.linspace(-73, 85, 50))
    st = analyze(PAPER, phi)
    l0, alpha0, r = PAPER.l0, PAPER.alpha0, PAPER.r
    printed = np.arctan(st.b / r) + np.arcsin(l0 * np.cos(alpha0 - phi) / st.d)
    np.testing.assert_allclose(st.beta, printed, rtol=1e-12)
    # the belt runs from B0 to the tangent point B, |B0 B| = b, AB ⟂ belt, |AB| = r
    B0 = PAPER.B0
    np.testing.assert_allclose(np.hypot(*(st.B - B0).T), st.b, rtol=1e-10)
    np.testing.assert_allclose(np.hypot(*(st.B - st.A).T), r, rtol=1e-10)
    dots = np.einsum("ij,ij->i", st.B - st.A, st.B - B0)
    np.testing.assert_allclose(dots, 0.0, atol=1e-8)


def test_belt_length_is_conserved():
    # Independent model of eq. (4) (whose printed sign order is garbled): the belt is
    # inextensible, so the free length grows by exactly what unwinds from the pulley,
    # b - b0 = r · (turn of the tangent point B on the pulley, in link 2's frame).
    phi = np.radians(np.linspace(-73, 85, 40))
    st = analyze(PAPER, phi)
    AB = st.B - st.A
    ang = np.unwrap(np.arctan2(AB[:, 1], AB[:, 0]) - st.theta)  # 0 in the design position
    np.testing.assert_allclose(st.b - PAPER.b0, PAPER.r * ang, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("phi_deg", [-70.0, -40.0, -10.0, 0.0, 7.0, 33.0, 80.0])
def test_derivatives_against_finite_differences(phi_deg):
    x = math.radians(phi_deg)
    hstep = 1e-4
    st = analyze(PAPER, [x - 2 * hstep, x - hstep, x, x + hstep, x + 2 * hstep])

    def d1(v):  # fourth-order central difference
        return (v[0] - 8 * v[1] + 8 * v[3] - v[4]) / (12 * hstep)

    def d2(v):
        return (-v[0] + 16 * v[1] - 30 * v[2] + 16 * v[3] - v[4]) / (12 * hstep**2)

    assert d1(st.dpsi) == pytest.approx(st.psi1[2], rel=1e-7, abs=1e-8)
    assert d2(st.dpsi) == pytest.approx(st.psi2[2], rel=1e-5, abs=1e-6)
    assert d1(st.beta) == pytest.approx(st.beta1[2], rel=1e-7, abs=1e-8)
    assert d1(st.psi1) == pytest.approx(st.psi2[2], rel=1e-7, abs=1e-7)
    for P, P1, P2 in ((st.C, st.C1, st.C2), (st.H, st.H1, st.H2)):
        np.testing.assert_allclose(d1(P), P1[2], rtol=1e-7, atol=1e-5)
        np.testing.assert_allclose(d2(P), P2[2], rtol=1e-5, atol=1e-3)
        # and the second derivative from differences of the analytic first derivative
        np.testing.assert_allclose(d1(P1), P2[2], rtol=1e-7, atol=1e-5)


def test_printed_13_14_signs_are_wrong():
    # Paper prints y'_C = -a sin Δφ - c(1+ψ') sin θ and x''_C = -a sin Δφ - c[...]; the
    # spec's (and the finite differences') signs differ; show the printed ones fail.
    x, hs = math.radians(30.0), 1e-5
    st = analyze(PAPER, [x - hs, x, x + hs])
    a, c = PAPER.a, PAPER.c
    w, th, p2 = 1 + st.psi1[1], st.theta[1], st.psi2[1]
    fd_y1 = (st.C[2, 1] - st.C[0, 1]) / (2 * hs)
    printed_y1 = -a * math.sin(x) - c * w * math.sin(th)
    assert abs(printed_y1 - fd_y1) > 1.0
    fd_x2 = (st.C1[2, 0] - st.C1[0, 0]) / (2 * hs)
    printed_x2 = -a * math.sin(x) - c * (w**2 * math.cos(th) + p2 * math.sin(th))
    assert abs(printed_x2 - fd_x2) > 1.0
    assert st.C2[1, 0] == pytest.approx(fd_x2, rel=1e-6)


def test_slack_belt_is_flagged_not_raised():
    design = BeltDesign(a=100.0, c=300.0, h=0.0, r=90.0)
    st = analyze(design, np.radians(np.linspace(-180, 180, 361)))
    assert not np.all(st.valid)
    assert np.all(np.isnan(st.dpsi[~st.valid]))
    assert np.all(st.d[~st.valid] <= design.r * (1 + 1e-9))


@pytest.mark.parametrize("kwargs", [dict(a=0, c=1, h=0, r=1), dict(a=1, c=-1, h=0, r=1),
                                    dict(a=1, c=1, h=0, r=0), dict(a=math.nan, c=1, h=0, r=1)])
def test_bad_design_raises(kwargs):
    with pytest.raises(MechsynInputError):
        BeltDesign(**kwargs)


# --------------------------------------------------------------------- paths
def test_path_figures_of_the_spec():
    # Paper 001, fig. 4: horizontal extent ≈1230 mm (C, h = 0) and ≈1270 mm (H, h = 100);
    # the part from the start to the design position ≈800 mm long with positive y
    # deviations ≈45 mm (C) and ≈20 mm (H); link 2 translates over ≈300 mm (spec: 270 mm
    # with |θ| ≤ 3°, 349 mm with |θ| ≤ 5°).
    qc = path_quality(PAPER, RANGE, "C")
    qh = path_quality(PAPER, RANGE, "H")
    assert qc.extent_x == pytest.approx(1228.5, abs=0.1)
    assert qh.extent_x == pytest.approx(1272.8, abs=0.1)
    assert round(qc.extent_x, -1) == 1230 and round(qh.extent_x, -1) == 1270
    assert qc.segment_span == pytest.approx(790, abs=1)
    assert qc.max_positive_deviation == pytest.approx(44.92, abs=0.01)
    assert qh.max_positive_deviation == pytest.approx(20.94, abs=0.01)
    assert qh.translation_length == pytest.approx(270, abs=1)
    q5 = path_quality(PAPER, RANGE, "H", translation_tol=math.radians(5))
    assert q5.translation_length == pytest.approx(349, abs=1)
    lo, hi = q5.translation_dphi_deg
    st = analyze(PAPER, np.radians([lo, hi]))
    np.testing.assert_allclose(np.abs(np.degrees(st.theta)), 5.0, rtol=1e-8)


def test_path_quality_independent_of_step():
    coarse = path_quality(PAPER, RANGE, "C", samples=2001)
    fine = path_quality(PAPER, RANGE, "C", samples=20001)
    assert coarse.max_positive_deviation == pytest.approx(fine.max_positive_deviation,
                                                          abs=1e-3)


def test_best_line_of_known_points():
    x = np.linspace(0, 10, 11)
    P = np.stack([x, 0.5 * x + 2 + np.where(x % 2 == 0, 0.3, -0.3)], axis=-1)
    dev, point, direction = best_line_deviation(P)
    assert dev == pytest.approx(0.3 / math.hypot(1, 0.5), rel=1e-9)
    assert abs(direction[1] / direction[0]) == pytest.approx(0.5, rel=1e-9)
    assert best_line_deviation(np.stack([x, 2 * x], axis=-1))[0] == pytest.approx(0, abs=1e-9)


def test_equivalent_four_bar_agrees_to_second_order():
    small = np.radians([-1e-3, 0.0, 1e-3])
    fb = equivalent_four_bar(PAPER, small)
    st = analyze(PAPER, small)
    np.testing.assert_allclose(fb.C[1], st.C[1], atol=1e-9)
    np.testing.assert_allclose(fb.B[1], [PAPER.r, PAPER.a], atol=1e-9)
    # same positions up to third-order terms: differences ~ Δφ^3 (≈ 1e-6 mm here)
    assert np.max(np.abs(fb.H - st.H)) < 1e-6
    np.testing.assert_allclose(fb.theta, st.theta, atol=1e-8)
    # but not identical further out
    far = np.radians([20.0])
    assert np.max(np.abs(equivalent_four_bar(PAPER, far).C - analyze(PAPER, far).C)) > 1.0


def test_comparison_with_four_bar():
    # Paper 001 claims the belt version is better than the hinged four-bar. Measured over
    # the same lever rotations: on the machine side (Δφ <= 0) both paths are nearly the
    # same (C: 44.9 vs 42.7 mm above the line), but the four-bar cannot be assembled past
    # Δφ ≈ 36°, its path rises 123 mm above the line on the other side where the belt's
    # falls away monotonically, and link 2 translates (|θ| <= 3°) over a longer stroke
    # with the belt.
    cmp = compare_with_four_bar(PAPER, RANGE)
    belt, fb = cmp["belt"], cmp["four_bar"]
    assert belt["assembled_dphi_deg"] == pytest.approx([-73.0, 85.0])
    assert fb["assembled_dphi_deg"][1] == pytest.approx(36.4, abs=0.1)
    assert belt["C"]["machine_side"]["max_positive_deviation"] == pytest.approx(44.92, abs=0.01)
    assert fb["C"]["machine_side"]["max_positive_deviation"] == pytest.approx(42.7, abs=0.1)
    assert belt["C"]["other_side"]["max_positive_deviation"] == 0.0
    assert fb["C"]["other_side"]["max_positive_deviation"] > 100.0
    assert belt["H"]["translation_length"] > fb["H"]["translation_length"] + 5.0


# --------------------------------------------------------------- speeds, accels
def test_constant_speed_motion_matches_chain_rule():
    omega = math.radians(60.0)
    law = ConstantSpeedLaw(RANGE[0], RANGE[1], omega)
    res = motion(PAPER, law, samples=101)
    S1 = np.hypot(*res.state.H1.T)
    np.testing.assert_allclose(res.H.speed, S1 * omega, rtol=1e-12)
    # with φ_ddot = 0 the paper's (19) equals the acceleration's magnitude
    np.testing.assert_allclose(res.H.accel_paper, res.H.accel, rtol=1e-12)
    # finite differences in time of the position
    dt = res.t[1] - res.t[0]
    v_fd = np.gradient(res.state.H, dt, axis=0, edge_order=2)
    np.testing.assert_allclose(v_fd[5:-5], res.H.velocity[5:-5], rtol=2e-3, atol=1.0)


def test_trapezoidal_motion_and_paper_formula_differs():
    law = TrapezoidalLaw(RANGE[0], 0.0, omega_max=math.radians(90), accel=math.radians(360))
    res = motion(PAPER, law, samples=4001)
    assert res.dphi[0] == pytest.approx(RANGE[0]) and res.dphi[-1] == pytest.approx(0.0)
    assert np.max(np.abs(res.phid)) == pytest.approx(math.radians(90), rel=1e-9)
    # time derivatives of position by finite differences agree with the analytic ones
    dt = res.t[1] - res.t[0]
    v_fd = np.gradient(res.state.C, dt, axis=0)
    np.testing.assert_allclose(v_fd[10:-10], res.C.velocity[10:-10], rtol=1e-3, atol=0.5)
    a_fd = np.gradient(res.C.velocity, dt, axis=0)
    smooth = np.abs(np.gradient(res.phidd, dt)) < 1e-9          # away from the jumps
    smooth[:3] = smooth[-3:] = False
    np.testing.assert_allclose(a_fd[smooth], res.C.acceleration[smooth], rtol=2e-3, atol=2.0)
    # during acceleration the paper's form S'' φ'^2 + S' φ'' is not |a|
    acc_phase = np.abs(res.phidd) > 0
    assert np.max(np.abs(res.C.accel_paper - res.C.accel)[acc_phase]) > 1.0
    # tangential acceleration is the time derivative of the speed
    at_fd = np.gradient(res.C.speed, dt)
    np.testing.assert_allclose(at_fd[smooth], res.C.accel_tangential[smooth], rtol=2e-3,
                               atol=2.0)


def test_table_law_and_bad_table():
    t = np.linspace(0, 2, 21)
    law = TableLaw(tuple(t), tuple(RANGE[0] + 0.3 * t**2))
    phi, phid, phidd = law.evaluate(np.array([0.5, 1.0]))
    np.testing.assert_allclose(phid, [0.3, 0.6], rtol=1e-9)
    np.testing.assert_allclose(phidd, [0.6, 0.6], rtol=1e-9)
    with pytest.raises(MechsynInputError):
        TableLaw((0.0, 1.0, 1.0), (0.0, 1.0, 2.0))
    with pytest.raises(MechsynInputError):
        TableLaw((0.0, 1.0), (0.0, 1.0))


def test_inverse_problem_round_trip():
    # forward: a trapezoidal input; inverse: from H's speed and tangential acceleration
    # along its path, recover the servo's φ_dot and φ_ddot
    law = TrapezoidalLaw(RANGE[0], RANGE[1], omega_max=math.radians(80),
                         accel=math.radians(200))
    res = motion(PAPER, law, samples=301)
    inner = slice(1, -1)  # the ends are at rest (speed 0)
    st = res.state
    sub = analyze(PAPER, st.dphi[inner])
    inv = inverse_input(sub, res.H.speed[inner], res.H.accel_tangential[inner], "H")
    np.testing.assert_allclose(inv.phid, res.phid[inner], rtol=1e-9)
    np.testing.assert_allclose(inv.phidd, res.phidd[inner], rtol=1e-7, atol=1e-9)
    # decreasing Δφ: direction -1, signs follow
    back = analyze(PAPER, st.dphi[inner][::-1])
    inv_b = inverse_input(back, 500.0)
    assert np.all(inv_b.phid < 0)
    assert np.all(np.diff(inv_b.t) > 0)
    with pytest.raises(MechsynInputError):
        inverse_input(sub, 0.0)


def test_inverse_constant_speed_duration_is_path_length_over_speed():
    phi = np.linspace(RANGE[0], 0.0, 4001)
    st = analyze(PAPER, phi)
    inv = inverse_input(st, 1000.0, 0.0, "H")
    length = np.sum(np.hypot(*np.diff(st.H, axis=0).T))
    assert inv.t[-1] == pytest.approx(length / 1000.0, rel=1e-5)


def test_four_bar_mechanism_dict_geometry():
    from mechsyn.belt import four_bar_mechanism_dict

    m = four_bar_mechanism_dict(PAPER)
    P = {j["id"]: np.array(j["point"]) for j in m["joints"]}
    assert np.linalg.norm(P["A"] - P["A0"]) == pytest.approx(PAPER.a)
    assert np.linalg.norm(P["B"] - P["A"]) == pytest.approx(PAPER.r)
    assert np.linalg.norm(P["B0"] - P["B"]) == pytest.approx(PAPER.b0)
    assert np.linalg.norm(P["B0"] - P["A0"]) == pytest.approx(PAPER.l0)
    assert (P["A"] - P["B"]) @ (P["B0"] - P["B"]) == pytest.approx(0.0, abs=1e-9)
    assert m["points"]["H"]["at"] == pytest.approx([-350.0, 600.0])


def _narrowest_strip_brute(P):
    """Every hull edge against every hull vertex: O(h^2), the reference."""
    from scipy.spatial import ConvexHull

    V = P[ConvexHull(P).vertices]
    E = np.roll(V, -1, axis=0) - V
    E /= np.hypot(E[:, 0], E[:, 1])[:, None]
    proj = V @ np.stack([-E[:, 1], E[:, 0]], axis=-1).T
    return float((proj.max(axis=0) - proj.min(axis=0)).min() / 2)


@pytest.mark.parametrize("seed", range(6))
def test_best_line_rotating_calipers_match_every_pair(seed):
    rng = np.random.default_rng(seed)
    n = [5, 40, 400, 3000, 50, 8][seed]
    P = rng.normal(size=(n, 2)) * rng.uniform(0.1, 10, size=2) @ np.array([[1, 0.3], [0.2, 1]])
    if seed == 5:                                        # a path like the belt's: many hull points
        t = np.linspace(0, 3, 4000)
        P = np.c_[t * 300, 40 * np.sin(t) + 0.01 * t ** 3]
    dev, point, direction = best_line_deviation(P)
    assert dev == pytest.approx(_narrowest_strip_brute(P), rel=1e-12, abs=1e-12)
    # every point lies within dev of the returned line, and some on both sides reach it
    nrm = np.array([-direction[1], direction[0]])
    dist = (P - point) @ nrm
    assert np.max(np.abs(dist)) == pytest.approx(dev, rel=1e-9)
    assert dist.max() == pytest.approx(dev, rel=1e-9) and dist.min() == pytest.approx(-dev, rel=1e-9)
