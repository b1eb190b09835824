"""Directional measures: closed form vs linear programming vs polytope, singular cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mechsyn.capability.arm_file import arm_from_dict
from mechsyn.capability.measures import (
    all_measures, component_limit, exact_limit, exact_limit_lp, min_norm_limit,
    min_norm_rates, stepped_limit, velocity_ellipse, velocity_polytope,
)


def _random_jacobians(rng, N, m, n, singular_every=3):
    J = rng.normal(size=(N, m, n)) * rng.uniform(0.1, 10, size=(N, 1, 1))
    for k in range(0, N, singular_every):  # rank-one Jacobians
        J[k] = np.outer(rng.normal(size=m), rng.normal(size=n))
    J[1] = 0.0  # no motion at all
    return J


@pytest.mark.parametrize("n", [2, 3, 4, 7])
def test_closed_form_equals_linprog_random(n):
    rng = np.random.default_rng(n)
    N = 60
    J = _random_jacobians(rng, N, 2, n)
    w = rng.uniform(0.2, 3.0, size=(N, n))
    d = rng.normal(size=(N, 2))
    d[2] = J[2, :, 0]  # along a rank-one zonotope (a segment): positive speed
    exact = exact_limit(J, w, d)
    lp = exact_limit_lp(J, w, d)
    assert np.all(np.isfinite(exact))
    np.testing.assert_allclose(exact, lp, rtol=1e-7, atol=1e-9)
    assert exact[1] == 0.0 and exact[2] > 0
    # the other measures bracket the exact one
    assert np.all(component_limit(J, w, d) >= exact - 1e-9)
    assert np.all(min_norm_limit(J, w, d) <= exact + 1e-9)


def test_closed_form_on_arm_singularities():
    """Stretched and folded 3R arm: radial speed 0, tangential speed finite."""
    arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [900, 900, 900],
                         "joint_speed_limits_deg_s": [4, 4, 4]})
    q = np.radians([[0, 0, 0], [30, 0, 0], [0, 180, 0], [10, 180, -180], [45, 0, 180]])
    J = arm.jacobian(q)
    w = arm.qd_max
    for d in ([1, 0], [0, 1], [1, 1], [np.cos(np.radians(30)), np.sin(np.radians(30))]):
        m = all_measures(J, w, d)
        for v in m.values():
            assert np.all(np.isfinite(v)) and np.all(v >= 0)
        np.testing.assert_allclose(m["exact"], exact_limit_lp(J, w, d), rtol=1e-7, atol=1e-9)
    # stretched along x: no speed along x; along y all joints add up: w * (2700+1800+900)
    assert exact_limit(J[0], w, (1, 0))[0] == 0.0
    assert min_norm_limit(J[0], w, (1, 0))[0] == 0.0
    assert exact_limit(J[0], w, (0, 1))[0] == pytest.approx(w[0] * 5400, rel=1e-12)
    assert min_norm_limit(J[0], w, (0, 1))[0] > 0


def test_polytope_of_an_almost_stretched_arm_keeps_its_digits():
    # a thin sliver of a zonogon: the facet normals from the generators, not from Qhull's
    # fit to nearly collinear vertices (which gave 0.0101635013, 2.3e-7 too large)
    arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [900, 700, 500],
                         "joint_speed_limits_deg_s": [4, 6, 10]})
    J = arm.jacobian(np.array([0.5, 1.1444091796875e-05, 0.0]))[0]
    for angle in (2.0, 0.3, 1.6, 4.0):
        d = np.array([np.cos(angle), np.sin(angle)])
        exact = exact_limit(J, arm.qd_max, d)[0]
        assert velocity_polytope(J, arm.qd_max).directional_limit(d) == pytest.approx(exact, rel=1e-9)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3),
       st.floats(0.0, 2 * np.pi))
def test_polytope_and_ellipse_agree_with_exact(q, angle):
    arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [900, 700, 500],
                         "joint_speed_limits_deg_s": [4, 6, 10]})
    J = arm.jacobian(np.array(q))[0]
    d = np.array([np.cos(angle), np.sin(angle)])
    exact = exact_limit(J, arm.qd_max, d)[0]
    poly = velocity_polytope(J, arm.qd_max)
    assert poly.directional_limit(d) == pytest.approx(exact, rel=1e-7, abs=1e-9)
    # every vertex is the image of a box corner; all satisfy every facet
    assert np.all(poly.vertices @ poly.normals.T <= poly.offsets + 1e-9)
    ell = velocity_ellipse(J, arm.qd_max)
    # the ellipse is the image of the inscribed ball: never beyond the zonotope
    assert ell.radius(d) <= exact + 1e-9
    np.testing.assert_allclose(np.sort(ell.semi_axes),
                               np.sort(np.linalg.svd(J * arm.qd_max, compute_uv=False)),
                               rtol=1e-9, atol=1e-12)


def test_polytope_2d_vertices_ccw_count():
    J = np.array([[1.0, 0.0, 1.0], [0.0, 1.0, 1.0]])
    poly = velocity_polytope(J, [1, 1, 1])
    assert len(poly.vertices) == 6 and len(poly.normals) == 6  # 3 generators: hexagon
    c = poly.vertices - poly.vertices.mean(0)
    ang = np.unwrap(np.arctan2(c[:, 1], c[:, 0]))
    assert np.all(np.diff(ang) > 0)


def test_polytope_flat_when_singular():
    J = np.array([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0]])  # rank one
    poly = velocity_polytope(J, [1, 1, 1])
    assert poly.equalities.shape == (1, 2)
    assert poly.directional_limit((0, 1)) == 0.0
    assert poly.directional_limit((1, 2)) == pytest.approx(
        exact_limit(J, [1, 1, 1], (1, 2))[0], rel=1e-12)


def test_three_dimensions_lp_facets_and_polytope_agree():
    rng = np.random.default_rng(7)
    for _ in range(10):
        J = rng.normal(size=(3, 6))
        w = rng.uniform(0.5, 2, 6)
        d = rng.normal(size=3)
        lp = exact_limit_lp(J, w, d)[0]
        assert exact_limit(J, w, d)[0] == pytest.approx(lp, rel=1e-9)  # facet closed form
        poly = velocity_polytope(J, w)
        assert poly.directional_limit(d) == pytest.approx(lp, rel=1e-7)


@pytest.mark.parametrize("m,n", [(3, 3), (3, 6), (3, 7), (4, 5), (6, 6), (6, 7)])
def test_facet_closed_form_equals_linprog_with_singular(m, n):
    rng = np.random.default_rng(10 * m + n)
    N = 40
    J = _random_jacobians(rng, N, m, n)
    for k in range(2, N, 7):
        J[k][:, 0] = 2 * J[k][:, 1]  # parallel generators (full rank may remain)
    for k in range(3, N, 11):
        J[k][m - 1] = J[k][0] + J[k][1]  # rank m - 1
    w = rng.uniform(0.5, 2, size=(N, n))
    d = rng.normal(size=(N, m))
    d[3] = J[3] @ rng.normal(size=n)  # inside the range of a rank-deficient J
    exact = exact_limit(J, w, d)
    np.testing.assert_allclose(exact, exact_limit_lp(J, w, d), rtol=1e-8, atol=1e-9)
    assert exact[3] > 0 and exact[1] == 0


def test_min_norm_rates_and_weights():
    J = np.array([[1.0, 1.0, 0.5]])
    qd, ok = min_norm_rates(J, [1.0])
    np.testing.assert_allclose(qd[0], np.linalg.pinv(J) @ [1.0])
    assert ok[0]
    # a heavy weight on joint 1 moves the motion to the others
    qdw, _ = min_norm_rates(J, [1.0], weights=[100.0, 1.0, 1.0])
    assert abs(qdw[0, 0]) < abs(qd[0, 0]) and J @ qdw[0] == pytest.approx(1.0)


def test_stepped_limit_is_the_papers_loop():
    def loop(limit, step=5.0):  # the paper's procedure, literally
        v = 0.0
        while v + step <= limit:
            v += step
        return v

    for limit in [0.0, 4.99, 5.0, 5.0000001, 68.36, 95.0, 99.99999, 110.27]:
        assert stepped_limit(np.array([limit]))[0] == loop(limit)
    assert stepped_limit(np.array([7.0]), step=2.5)[0] == 5.0


def test_direction_must_be_nonzero():
    with pytest.raises(ValueError):
        exact_limit(np.eye(2), [1, 1], (0, 0))
