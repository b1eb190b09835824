"""Freudenstein and Burmester synthesis, verified by simulating the produced linkages."""

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.exact import (
    burmester_matrix,
    burmester_points,
    center_point,
    center_point_curve,
    chebyshev_spacing,
    circle_point,
    dyad_fourbar,
    freudenstein_coefficients,
    freudenstein_synthesis,
    motion_synthesis,
    order_defect,
)
from mechsyn.synthesis.fourbar import fourbar_position

REF = (4.0, 1.5, 3.5, 3.0)  # ground, crank, coupler, rocker: a Grashof crank-rocker


def test_freudenstein_recovers_a_known_linkage():
    phi = np.radians([40.0, 75.0, 115.0])
    pose = fourbar_position(*REF, phi, branch=-1)
    res = freudenstein_synthesis(phi, pose.theta4, ground=REF[0])
    assert (res.r1, res.r2, res.r3, res.r4) == pytest.approx(REF, rel=1e-10)
    assert res.branch == -1 and res.max_error < 1e-10
    assert not res.branch_defect and not res.order_defect
    assert res.grashof == "Grashof crank-rocker"
    # K's from their definitions (Norton eq. 5.34)
    a, b, c, d = REF[1], REF[2], REF[3], REF[0]
    assert res.K == pytest.approx([d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)])


def test_freudenstein_function_generator_y_equals_x_squared():
    """y = x^2 on 1 <= x <= 2 with Chebyshev spacing, 60 deg crank and 90 deg rocker ranges
    (the classic textbook setting): the linkage matches at the three precision points."""
    x = chebyshev_spacing(1.0, 2.0, 3)
    y = x**2
    phi = np.radians(45.0 + 60.0 * (x - 1.0))
    psi = np.radians(135.0 + 90.0 * (y - 1.0) / 3.0)
    res = freudenstein_synthesis(phi, psi)
    assert res.max_error < 1e-9
    pose = fourbar_position(res.r1, res.r2, res.r3, res.r4, res.phi, branch=res.branch)
    assert np.allclose(np.angle(np.exp(1j * (pose.theta4 - res.psi))), 0, atol=1e-9)


def test_chebyshev_spacing():
    assert chebyshev_spacing(0, 2, 3) == pytest.approx([1 - np.cos(np.pi / 6), 1, 1 + np.cos(np.pi / 6)])


def test_freudenstein_bad_input():
    with pytest.raises(MechsynInputError):
        freudenstein_coefficients([0.1, 0.2], [0.3, 0.4])
    with pytest.raises(MechsynInputError):
        freudenstein_coefficients([0.1, 0.1, 0.1], [0.3, 0.3, 0.3])


def body_poses(thetas, p=(0.7, 0.4)):
    """Poses of the coupler of REF at crank angles (frame origin at A, x axis along A->B)."""
    pose = fourbar_position(*REF, np.asarray(thetas), branch=-1)
    return np.column_stack([pose.A, pose.theta3])


def test_burmester_matrix_is_zero_for_the_true_dyads():
    P = body_poses(np.radians([30, 60, 95, 130, 170]))
    assert np.allclose(burmester_matrix(P, np.array([0.0, 0.0])) @ np.array([0.0, 0.0, 1.0]), 0, atol=1e-12)
    assert np.allclose(burmester_matrix(P, np.array([4.0, 0.0])) @ np.array([3.5, 0.0, 1.0]), 0, atol=1e-12)


def test_three_positions_from_circle_points_verified():
    P = body_poses(np.radians([30, 70, 110]))
    res = motion_synthesis(P, circle_points=[[0.0, 0.0], [3.5, 0.0]])
    r = res[0]
    assert np.allclose(r.O2, [0, 0], atol=1e-10) and np.allclose(r.O4, [4, 0], atol=1e-10)
    assert r.ok
    # arbitrary circle points: the centres are circumcentres; the simulation either
    # reproduces the poses on one branch or the linkage is flagged (here: branch defect)
    for cps in ([[-1.0, 0.5], [2.0, 1.5]], [[0.5, 1.0], [3.0, -0.5]], [[1.0, 0.0], [2.5, 0.2]]):
        r2 = motion_synthesis(P, circle_points=cps)[0]
        assert r2.branch_defect or (r2.position_error < 1e-9 and r2.angle_error < 1e-9)
        if r2.branch_defect:
            assert r2.position_error > 1e-3 and not r2.ok
    m = center_point(P, [-1.0, 0.5])
    assert np.allclose(circle_point(P, m), [-1.0, 0.5])


def test_four_positions_centre_point_curve_and_verified_linkages():
    P = body_poses(np.radians([30, 65, 100, 140]))
    M, Ps = center_point_curve(P)
    # both true ground pivots lie on the centre-point curve
    for true in ([0.0, 0.0], [4.0, 0.0]):
        assert np.min(np.linalg.norm(M - true, axis=1)) < 0.05
    # every curve point's circle point has its four positions on a circle about it
    R = lambda a: np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])  # noqa: E731
    for m, p in zip(M[::25], Ps[::25]):
        rad = [np.linalg.norm(R(a) @ p + P[j, :2] - m) for j, a in enumerate(P[:, 2])]
        assert np.ptp(rad) < 1e-6 * max(1, np.mean(rad))
    sols = motion_synthesis(P, max_pairs=400)
    good = [s for s in sols if s.ok]
    assert good and all(s.position_error < 1e-6 and s.angle_error < 1e-6 for s in good)
    assert not good[0].branch_defect and not good[0].order_defect


def test_five_positions_burmester_points_recover_the_linkage():
    P = body_poses(np.radians([30, 60, 95, 130, 170]))
    M, Ps = burmester_points(P)
    assert 2 <= len(M) <= 4
    for true_m, true_p in (([0, 0], [0, 0]), ([4, 0], [3.5, 0])):
        k = np.argmin(np.linalg.norm(M - true_m, axis=1))
        assert np.allclose(M[k], true_m, atol=1e-7) and np.allclose(Ps[k], true_p, atol=1e-7)
    sols = motion_synthesis(P)
    assert sols[0].ok
    assert any(np.allclose([s.r1, s.r2, s.r3, s.r4], REF, rtol=1e-7) for s in sols if s.ok)


def test_branch_and_order_defects_are_detected():
    P = body_poses(np.radians([30, 70, 110]))
    # order: poses visited 1, 3, 2 need the crank to go back
    Q = P[[0, 2, 1]]
    r = dyad_fourbar(Q, [0, 0], [0, 0], [4, 0], [3.5, 0])
    assert r.position_error < 1e-9  # it does reach every pose ...
    defect, _ = order_defect(r.r1, r.r2, r.r3, r.r4, r.theta2)
    assert not defect  # ... and a full-rotation crank can go round to visit them in order
    # a double rocker whose positions lie on the two sides of a dead position: order defect
    rock = (3.0, 2.0, 2.0, 2.0)
    assert order_defect(*rock, np.array([1.6, 4.6, 0.0]))[0]
    assert not order_defect(*rock, np.array([1.6, 0.5]))[0]
    # branch defect: the same linkage on the other branch at one pose
    pa = fourbar_position(*REF, np.radians([30, 70, 110]), branch=-1)
    pb = fourbar_position(*REF, np.radians([30, 70, 110]), branch=1)
    mixed = np.column_stack([np.vstack([pa.A[:2], pb.A[2:]]), np.concatenate([pa.theta3[:2], pb.theta3[2:]])])
    r = dyad_fourbar(mixed, [0, 0], [0, 0], [4, 0], [3.5, 0])
    assert r.branch_defect and not r.ok
