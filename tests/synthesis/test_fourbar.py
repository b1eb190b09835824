"""Closed-form four-bar kinematics against the cases' published vectors and references."""

import numpy as np
import pytest
from dimsynth_data import public_cases, public_data  # noqa: F401  (fixtures)

from mechsyn.synthesis.fourbar import (
    arc_cos_extremes,
    cabrera_theta3,
    coupler_point,
    crank_cos_range,
    fourbar_position,
    grashof_excess,
    slider_crank_position,
)


def verify_error(case, x, branch):
    """The cases' objective by Cabrera et al. 2002's half-angle formula (the verify.py
    convention of the data file), written independently of the library's geometric form."""
    x = {**case["fixed"], **x}
    th2 = np.array(x["theta2"]) if "theta2" in x else np.array(case["timing"]["theta2"])
    r1, r2, r3, r4 = x["r1"], x["r2"], x["r3"], x["r4"]
    k1, k4, k5 = r1 / r2, r1 / r3, (r4**2 - r1**2 - r2**2 - r3**2) / (2 * r2 * r3)
    D = np.cos(th2) - k1 + k4 * np.cos(th2) + k5
    E = -2 * np.sin(th2)
    F = k1 + (k4 - 1) * np.cos(th2) + k5
    disc = E**2 - 4 * D * F
    assert np.all(disc >= 0)
    t3 = 2 * np.arctan((-E + branch * np.sqrt(disc)) / (2 * D))
    cx = r2 * np.cos(th2) + x["rcx"] * np.cos(t3) - x["rcy"] * np.sin(t3)
    cy = r2 * np.sin(th2) + x["rcx"] * np.sin(t3) + x["rcy"] * np.cos(t3)
    c0, s0 = np.cos(x["theta0"]), np.sin(x["theta0"])
    gx, gy = c0 * cx - s0 * cy + x["x0"], s0 * cx + c0 * cy + x["y0"]
    T = np.array(case["targets"])
    return float(np.sum((gx - T[:, 0]) ** 2 + (gy - T[:, 1]) ** 2))


def all_published(data):
    for case in data["cases"]:
        for sol in case["published_solutions"]:
            yield case, sol


def test_published_vectors_recompute_by_reference_formula(public_data):
    n = 0
    for case, sol in all_published(public_data):
        branch = sol.get("branch", case["kinematics"]["branch"])
        err = verify_error(case, sol["x"], branch)
        assert err == pytest.approx(sol["recomputed_error"], rel=1e-9), sol["label"]
        n += 1
    assert n == 10


def test_published_vectors_recompute_by_library(public_data):
    for case, sol in all_published(public_data):
        x = {**case["fixed"], **sol["x"]}
        th2 = np.array(x["theta2"]) if "theta2" in x else np.array(case["timing"]["theta2"])
        branch = sol.get("branch", case["kinematics"]["branch"])
        pose = fourbar_position(x["r1"], x["r2"], x["r3"], x["r4"], th2, branch=branch, rcx=x["rcx"],
                                rcy=x["rcy"], x0=x["x0"], y0=x["y0"], theta0=x["theta0"])
        assert pose.assembled.all()
        err = float(np.sum((pose.C - np.array(case["targets"])) ** 2))
        assert err == pytest.approx(sol["recomputed_error"], rel=1e-9), sol["label"]
        # the other branch does not reproduce it (the branch matters)
        other = fourbar_position(x["r1"], x["r2"], x["r3"], x["r4"], th2, branch=-branch, rcx=x["rcx"],
                                 rcy=x["rcy"], x0=x["x0"], y0=x["y0"], theta0=x["theta0"])
        assert float(np.sum((other.C - np.array(case["targets"])) ** 2)) > 10 * sol["recomputed_error"]


def test_branch_minus_one_puts_B_left_of_A_to_O4_and_matches_cabrera():
    rng = np.random.default_rng(3)
    r = rng.uniform(0.2, 5, (4, 20000))
    t = rng.uniform(-7, 7, 20000)
    for branch in (-1, 1):
        p = fourbar_position(*r, t, branch=branch)
        ok = p.assembled
        ref = cabrera_theta3(*r, t, branch)
        assert np.all(np.isnan(ref[~ok])) and not np.any(np.isnan(ref[ok]))
        assert np.allclose(np.angle(np.exp(1j * (ref[ok] - p.theta3[ok]))), 0, atol=1e-9)
        O4 = np.stack([r[0], 0 * r[0]], -1)
        ao4, ab = O4 - p.A, p.B - p.A
        cross = ao4[..., 0] * ab[..., 1] - ao4[..., 1] * ab[..., 0]
        assert np.all(np.sign(cross[ok]) == -branch)
        # loop closure: |B - O4| = r4, |B - A| = r3
        assert np.allclose(np.linalg.norm(p.B[ok] - O4[ok], axis=1), r[3][ok])
        assert np.allclose(np.linalg.norm(ab[ok], axis=1), r[2][ok])
        cx, cy, ok2 = coupler_point(*r, t, branch, 0.3, -0.7, 1.0, 2.0, 0.4)
        q = fourbar_position(*r, t, branch=branch, rcx=0.3, rcy=-0.7, x0=1.0, y0=2.0, theta0=0.4)
        assert np.array_equal(ok2, ok) and np.allclose(cx[ok], q.C[ok, 0]) and np.allclose(cy[ok], q.C[ok, 1])


def test_cannot_assemble_is_masked_not_a_real_part():
    # r3 + r4 < |A O4| at every crank angle: never assembles
    p = fourbar_position(10.0, 1.0, 2.0, 2.0, np.linspace(0, 6, 7))
    assert not p.assembled.any()
    assert np.all(np.isnan(p.theta3)) and np.all(np.isnan(p.C))


def test_crank_cos_range_matches_dense_assembly():
    rng = np.random.default_rng(5)
    t = np.linspace(-np.pi, np.pi, 4001)
    for _ in range(50):
        r = rng.uniform(0.3, 4, 4)
        lo, hi = crank_cos_range(*r)
        ok = fourbar_position(*r, t).assembled
        c = np.cos(t)
        inside = (c >= lo) & (c <= hi)
        assert np.array_equal(ok, inside)


def test_arc_cos_extremes_against_dense_sampling():
    rng = np.random.default_rng(0)
    a, s = rng.uniform(-10, 10, 500), rng.uniform(-7, 7, 500)
    cmin, cmax = arc_cos_extremes(a, s)
    grid = a[:, None] + s[:, None] * np.linspace(0, 1, 20001)
    assert np.allclose(np.cos(grid).min(1), cmin, atol=1e-7)
    assert np.allclose(np.cos(grid).max(1), cmax, atol=1e-7)


def test_grashof_excess():
    assert grashof_excess(4, 1.5, 3.5, 3) == pytest.approx(1.5 + 4 - 3.5 - 3)
    assert grashof_excess(1, 1, 1, 1) == 0


def test_slider_crank_loop_closure():
    t = np.linspace(0, 2 * np.pi, 73)
    for branch in (-1, 1):
        p = slider_crank_position(1.0, 3.0, 0.5, t, branch=branch, rcx=1.0, rcy=0.5)
        assert p.assembled.all()
        assert np.allclose(np.linalg.norm(p.B - p.A, axis=1), 3.0)
        assert np.allclose(p.B[:, 1], 0.5)
        assert np.all(np.sign(p.B[:, 0] - p.A[:, 0]) == -branch)
    bad = slider_crank_position(1.0, 0.2, 3.0, t)
    assert not bad.assembled.any() and np.all(np.isnan(bad.C))


@pytest.mark.parametrize("branch", [-1, 1])
def test_folded_coupler_point_is_the_law_of_cosines_pose_with_its_cosine_clipped(branch):
    """``coupler_point(..., folded=True)`` (the RRR kernel's circle intersection) equals the
    law-of-cosines pose ``theta3 = gamma - branch acos(ca)`` where the four-bar assembles
    and, with ``ca`` clipped to [-1, 1], where it does not (the coupler laid along ``d``):
    the least-squares residual of path synthesis is finite everywhere."""
    rng = np.random.default_rng(7)
    r1, r2, r3, r4 = (rng.uniform(0.3, 3.0, (200, 1)) for _ in range(4))
    th = rng.uniform(0, 2 * np.pi, (200, 5))
    rcx, rcy = rng.uniform(-1, 1, (2, 200, 1))
    cx, cy, ok = coupler_point(r1, r2, r3, r4, th, branch, rcx, rcy, folded=True)
    assert 0 < ok.mean() < 1 and np.isfinite(cx).all() and np.isfinite(cy).all()
    ax, ay = r2 * np.cos(th), r2 * np.sin(th)
    dx, dy = r1 - ax, -ay
    d = np.hypot(dx, dy)
    t3 = np.arctan2(dy, dx) - branch * np.arccos(np.clip((r3 * r3 + d * d - r4 * r4) / (2 * r3 * d), -1, 1))
    wx = ax + rcx * np.cos(t3) - rcy * np.sin(t3)
    wy = ay + rcx * np.sin(t3) + rcy * np.cos(t3)
    assert np.abs(cx - wx).max() < 1e-9 and np.abs(cy - wy).max() < 1e-9
    nx, ny, ok2 = coupler_point(r1, r2, r3, r4, th, branch, rcx, rcy)
    assert np.array_equal(ok, ok2) and np.isnan(nx[~ok]).all() and np.array_equal(nx[ok], cx[ok])
