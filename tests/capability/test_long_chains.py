"""Long serial chains: the sensitivities behind the self-motion ascent, and a URDF chain
against the same chain written as a planar arm (issue 42: capability linear in the joints)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm_file import arm_from_dict, load_arm
from mechsyn.capability.maps import measure_gradient, measure_values, refine_over_self_motion
from mechsyn.capability.point import capability_at

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "capability" / "ur5_dh.yaml"


def _planar_with_prismatic():
    return arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 0.5, 0.7, 0.3, 0.4],
                          "joint_types": ["R", "P", "R", "P", "R"], "weights": [1, 2, 1, 3, 1],
                          "joint_speed_limits_deg_s": [10, 0.2, 30, 0.15, 12]})


def _dh_with_prismatic():
    return arm_from_dict({"kind": "dh", "dh": [{"a": 100, "alpha_deg": 30}, {"type": "P", "alpha_deg": 90, "d": 50},
                                               {"a": 80, "alpha_deg": -60}, {"a": 60, "d": 20}],
                          "joint_speed_limits_deg_s": [10, 100, 20, 15]})


def _urdf_text(n: int, planar: bool = False) -> str:
    """A chain of n revolute joints; ``planar``: every axis along z, links of 0.1 along x
    from joint 1 at the base to a fixed tool flange (a planar arm of n links of 0.1)."""
    lo, hi = math.radians(-170), math.radians(170)
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        + (f'<origin xyz="{0.1 if i else 0} 0 0"/><axis xyz="0 0 1"/>' if planar else
           f'<origin xyz="0.1 0 0.05" rpy="0 {0.3 if i % 2 else 0} 0"/><axis xyz="0 {i % 2} {1 - i % 2}"/>')
        + f'<limit lower="{lo!r}" upper="{hi!r}" velocity="1"/></joint>' for i in range(n))
    if planar:
        joints += f'<joint name="flange" type="fixed"><parent link="l{n}"/><child link="tool"/><origin xyz="0.1 0 0"/></joint>'
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1)) + ('<link name="tool"/>' if planar else "")
    return f'<robot name="chain{n}">{links}{joints}</robot>'


def _arms(tmp_path):
    (tmp_path / "chain.urdf").write_text(_urdf_text(7))
    return [_planar_with_prismatic(), _dh_with_prismatic(), load_arm(UR5), load_arm(tmp_path / "chain.urdf")]


def test_jacobian_derivative_is_the_derivative_of_the_jacobian(tmp_path):
    for arm in _arms(tmp_path):
        rng = np.random.default_rng(3)
        q, u = rng.uniform(-1.5, 1.5, (4, arm.n)), rng.normal(size=(4, arm.n))
        D = arm.jacobian_derivative(q, u)
        scale = np.abs(D).max()
        for k in range(arm.n):
            e = np.zeros(arm.n)
            e[k] = 1e-6
            fd = np.einsum("nmk,nk->nm", arm.jacobian(q + e) - arm.jacobian(q - e), u) / 2e-6
            np.testing.assert_allclose(D[:, k], fd, atol=1e-6 * scale, err_msg=f"{arm.name}, joint {k}")


@pytest.mark.parametrize("measure", ["exact", "component", "min_norm"])
def test_measure_gradient_is_the_derivative_of_the_measure(tmp_path, measure):
    for arm in _arms(tmp_path):
        rng = np.random.default_rng(5)
        q, d = rng.uniform(-1.5, 1.5, (4, arm.n)), rng.normal(size=arm.task_dim)
        v, g = measure_gradient(arm, q, d, measure)
        np.testing.assert_array_equal(v, measure_values(arm, q, d, measure))
        e = 1e-7 * np.abs(q).max() * np.eye(arm.n)
        fd = np.array([(measure_values(arm, q + e[k], d, measure) - measure_values(arm, q - e[k], d, measure))
                       / (2 * e[k, k]) for k in range(arm.n)]).T
        np.testing.assert_allclose(g, fd, atol=1e-4 * np.abs(fd).max(), err_msg=f"{arm.name}, {measure}")


def test_stepped_measure_ascends_its_continuous_measure():
    arm = load_arm(UR5)
    p = np.array([400.0, 200.0, 300.0])
    q0 = np.radians([[10.0, -60.0, 80.0, -30.0, 90.0, 20.0]])
    from mechsyn.capability.arm import ik_numeric

    q0, ok = ik_numeric(arm, p, q0)
    assert ok.all()
    qs, vs = refine_over_self_motion(arm, p, q0, (1, 0, 0), measure="stepped", iterations=10)
    qe, ve = refine_over_self_motion(arm, p, q0, (1, 0, 0), measure="exact", iterations=10)
    np.testing.assert_array_equal(qs, qe)
    np.testing.assert_array_equal(vs, measure_values(arm, qe, (1, 0, 0), "stepped"))


def test_urdf_chain_and_the_same_chain_written_planar_give_equal_answers(tmp_path):
    n = 14
    (tmp_path / "flat.urdf").write_text(_urdf_text(n, planar=True))
    urdf = load_arm(tmp_path / "flat.urdf")
    planar = arm_from_dict({"kind": "planar_serial", "link_lengths": [100.0] * n,  # URDF metres read as mm
                            "joint_limits_deg": [[-170, 170]] * n,
                            "joint_speed_limits_deg_s": [math.degrees(1.0)] * n})
    assert urdf.kind == "spatial" and urdf.n == n
    ru = capability_at(urdf, [300.0, 200.0, 0.0], [1, 0, 0])
    rp = capability_at(planar, [300.0, 200.0], [1, 0])
    assert len(ru.configurations) == len(rp.configurations) > 4
    for cu, cp in zip(ru.configurations, rp.configurations):
        np.testing.assert_allclose(cu["q_deg"], cp["q_deg"], atol=1e-6)
        for m in ("exact", "component", "min_norm"):
            assert cu[m] == pytest.approx(cp[m], rel=1e-7, abs=1e-12)
    assert ru.best["exact"] == pytest.approx(rp.best["exact"], rel=1e-7)
    assert ru.continuous_best["exact"] > ru.best["exact"]
    assert ru.continuous_best["exact"] == pytest.approx(rp.continuous_best["exact"], rel=1e-6)
    np.testing.assert_allclose(ru.continuous_best["q_deg"], rp.continuous_best["q_deg"], atol=1e-3)


def test_a_start_not_reached_stays_unreached_and_the_others_are_refined():
    from mechsyn.capability.maps import self_motion

    arm = load_arm(UR5)
    p = np.array([400.0, 200.0, 300.0])
    q, valid = self_motion(arm, p, seeds=16)
    q = np.vstack([q[valid][:2], np.full(6, np.nan)])
    qr, vr = refine_over_self_motion(arm, p, q, (1, 0, 0), iterations=5)
    assert np.isneginf(vr[2]) and np.isnan(qr[2]).all()
    assert np.all(vr[:2] >= measure_values(arm, q[:2], (1, 0, 0)))
