"""Arm models: forward kinematics, Jacobians (vs finite differences), IK, file errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm import ik_numeric, ik_planar_3r
from mechsyn.capability.arm_file import arm_from_dict, load_arm
from mechsyn.capability.maps import interpolate_configuration, capability_map, self_motion
from mechsyn.errors import MechsynInputError

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "capability" / "ur5_dh.yaml"
PAPER = ROOT / "examples" / "capability" / "paper004_3r.yaml"

URDF_3R = """<?xml version="1.0"?>
<robot name="three_r">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="0" upper="2.0943951" velocity="0.0698131700797732"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.9 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.0943951" upper="2.0943951" velocity="0.0698131700797732"/></joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
    <origin xyz="0.9 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.0943951" upper="2.0943951" velocity="0.0698131700797732"/></joint>
  <joint name="flange" type="fixed"><parent link="l3"/><child link="tool"/>
    <origin xyz="0.9 0 0"/></joint>
</robot>
"""


def _fd_jacobian(arm, q, h=1e-6):
    J = np.zeros((arm.task_dim, arm.n))
    for i in range(arm.n):
        e = np.zeros(arm.n)
        e[i] = h
        J[:, i] = (arm.fk(q + e)[0] - arm.fk(q - e)[0]) / (2 * h)
    return J


def test_planar_fk_and_jacobian_with_prismatic_joint():
    arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [500, 300, 200],
                         "joint_types": ["R", "P", "R"], "base": [10, -5],
                         "joint_speed_limits_deg_s": [10, 50, 10]})
    q = np.array([0.3, 40.0, -0.7])
    th1, th3 = 0.3, 0.3 - 0.7
    expected = np.array([10 + 500 * np.cos(th1) + 340 * np.cos(th1) + 200 * np.cos(th3),
                         -5 + 500 * np.sin(th1) + 340 * np.sin(th1) + 200 * np.sin(th3)])
    np.testing.assert_allclose(arm.fk(q)[0], expected, atol=1e-9)
    np.testing.assert_allclose(arm.jacobian(q)[0], _fd_jacobian(arm, q), atol=1e-5)
    assert arm.qd_max[1] == 50  # P joint speed stays a length per second


def test_dh_ur5_zero_pose_and_jacobian():
    arm = load_arm(UR5)
    assert arm.kind == "spatial" and arm.n == 6
    # the well-known UR5 zero pose: (a2 + a3, -(d4 + d6), d1 - d5)
    np.testing.assert_allclose(arm.fk(np.zeros(6))[0], [-817.25, -191.45, -5.491], atol=1e-9)
    rng = np.random.default_rng(1)
    for q in rng.uniform(-3, 3, size=(5, 6)):
        np.testing.assert_allclose(arm.jacobian(q)[0], _fd_jacobian(arm, q), atol=1e-4)
    # angular rows: joint 1 turns about the base z axis
    Jg = arm.geometric_jacobian(rng.uniform(-3, 3, 6))[0]
    np.testing.assert_allclose(Jg[3:, 0], [0, 0, 1], atol=1e-12)


def test_dh_prismatic_joint():
    arm = arm_from_dict({"kind": "dh", "dh": [{"a": 100}, {"type": "P", "alpha_deg": 90, "d": 50}],
                         "joint_speed_limits_deg_s": [10, 100]})
    q = np.array([0.4, 30.0])
    np.testing.assert_allclose(arm.jacobian(q)[0], _fd_jacobian(arm, q), atol=1e-5)


def test_urdf_chain_equals_planar_arm(tmp_path):
    (tmp_path / "three_r.urdf").write_text(URDF_3R)
    urdf = load_arm(tmp_path / "three_r.urdf")
    planar = load_arm(PAPER)
    assert urdf.n == 3 and urdf.joint_names == ("j1", "j2", "j3")
    np.testing.assert_allclose(urdf.qd_max, planar.qd_max)
    np.testing.assert_allclose(urdf.lower, planar.lower, atol=1e-7)
    q = np.radians([[80, -28.77, -101.09], [10, 20, 30]])
    np.testing.assert_allclose(urdf.fk(q)[:, :2], planar.fk(q), atol=1e-9)
    np.testing.assert_allclose(urdf.jacobian(q)[:, :2], planar.jacobian(q), atol=1e-9)
    # an arm file pointing at the URDF, with its own limits
    (tmp_path / "arm.yaml").write_text(
        "kind: urdf\nurdf: three_r.urdf\njoint_speed_limits_deg_s: [8, 8, 8]\n")
    arm = load_arm(tmp_path / "arm.yaml")
    np.testing.assert_allclose(np.degrees(arm.qd_max), [8, 8, 8])


def test_ik_planar_branches_and_reach():
    arm = load_arm(PAPER)
    for branch in (-1, 1):
        q, ok = ik_planar_3r(arm, (1500, 500), np.radians([0, 50, 100]), branch)
        assert ok.all() and np.all(np.sign(q[:, 2]) == branch)
        np.testing.assert_allclose(arm.fk(q), [[1500, 500]] * 3, atol=1e-9)
    q, ok = ik_planar_3r(arm, (5000, 0), np.radians([0, 40]))
    assert not ok.any() and np.isnan(q).all()


def test_ik_numeric_ur5_and_self_motion():
    arm = load_arm(UR5)
    target = np.array([400.0, 200.0, 300.0])
    q, valid = self_motion(arm, target, seeds=32)
    assert valid.sum() >= 4
    np.testing.assert_allclose(arm.fk(q[valid]), np.tile(target, (valid.sum(), 1)), atol=1e-3)
    # with joint 1 fixed (the paper's redundancy parameter)
    # (the wrist offset makes q1 a free parameter only near the solutions found)
    q1 = np.unique(np.round(q[valid][:, 0], 9))[:2]
    qf, vf = self_motion(arm, target, q1=q1, seeds=16)
    assert vf.sum() >= 2
    assert set(np.round(qf[vf, 0], 9)) == set(np.round(q1, 9))
    np.testing.assert_allclose(arm.fk(qf[vf]), np.tile(target, (vf.sum(), 1)), atol=1e-3)
    # an unreachable point
    q, ok = ik_numeric(arm, [5000, 0, 0], np.zeros((3, 6)))
    assert not ok.any()


def test_interpolation_of_optimal_configuration():
    arm = load_arm(PAPER)
    xs, ys = np.arange(1300, 1701, 100.0), np.arange(300, 701, 100.0)
    cmap = capability_map(arm, xs, ys, (1, 0), continuous=True)
    f = interpolate_configuration(cmap, "cubic")
    np.testing.assert_allclose(f(xs[1], ys[2]), cmap.q[1, 2], atol=1e-9)
    lin = interpolate_configuration(cmap, "linear")
    mid = lin(1350.0, 500.0)
    np.testing.assert_allclose(mid, (cmap.q[0, 2] + cmap.q[1, 2]) / 2, atol=1e-12)
    # between grid points the interpolated configuration ends near the point
    qi = f(1450.0, 450.0)
    assert np.linalg.norm(arm.fk(qi)[0] - [1450, 450]) < 25


@pytest.mark.parametrize("data,field", [
    ({"kind": "wheel"}, "kind"),
    ({"link_lengths": [1, 2]}, "kind"),
    ({"kind": "planar_serial", "link_lengths": [900, -1], "joint_speed_limits_deg_s": [1, 1]}, None),
    ({"kind": "planar_serial", "link_lengths": [900, 900], "joint_speed_limits_deg_s": [1]}, None),
    ({"kind": "planar_serial", "link_lengths": [900], "joint_speed_limits_deg_s": [0]}, None),
    ({"kind": "planar_serial", "link_lengths": [900], "joint_speed_limits_deg_s": [1],
      "joint_limits_deg": [[10, 0]]}, None),
    ({"kind": "planar_serial", "link_lengths": [900]}, "joint_speed_limits_deg_s"),
    ({"kind": "dh", "dh": [{"a": 1, "beta": 2}], "joint_speed_limits_deg_s": [1]}, None),
    ({"kind": "planar_serial", "link_lengths": [900], "joint_speed_limits_deg_s": [1],
      "colour": "red"}, None),
    ([1, 2, 3], None),
])
def test_bad_arm_data(data, field):
    with pytest.raises(MechsynInputError) as err:
        arm_from_dict(data, source="arm.yaml")
    assert err.value.source == "arm.yaml"
    if field:
        assert field in (err.value.field or "") + err.value.message


def test_bad_files(tmp_path):
    with pytest.raises(MechsynInputError):
        load_arm(tmp_path / "missing.yaml")
    bad = tmp_path / "bad.yaml"
    bad.write_text("kind: [planar_serial\n")
    with pytest.raises(MechsynInputError) as err:
        load_arm(bad)
    assert err.value.line is not None
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot><joint name='a' type='revolute'></robot>")
    with pytest.raises(MechsynInputError):
        load_arm(broken)


def test_refine_over_self_motion_planar_matches_continuous_search():
    from mechsyn.capability.maps import continuous_best, refine_over_self_motion

    arm = load_arm(PAPER)
    p = np.array([1300.0, 900.0])
    q0, _ = self_motion(arm, p, np.radians([80.0, 100.0]))
    qr, vr = refine_over_self_motion(arm, p, q0, (1, 0))
    _, vc = continuous_best(arm, p[None], (1, 0))
    assert vr.max() == pytest.approx(vc[0], rel=1e-6)
    np.testing.assert_allclose(arm.fk(qr), [p, p], atol=1e-6)
    assert arm.within_limits(qr).all()


def test_refine_over_self_motion_spatial_improves_and_stays_on_point():
    from mechsyn.capability.maps import measure_values, refine_over_self_motion

    arm = load_arm(UR5)
    p = np.array([400.0, 200.0, 300.0])
    q, valid = self_motion(arm, p, seeds=16)
    q = q[valid][:4]
    v0 = measure_values(arm, q, (1, 0, 0))
    qr, vr = refine_over_self_motion(arm, p, q, (1, 0, 0), iterations=15)
    assert np.all(vr >= v0) and vr.max() > v0.max()
    np.testing.assert_allclose(arm.fk(qr), np.tile(p, (len(q), 1)), atol=1e-5)
    np.testing.assert_allclose(measure_values(arm, qr, (1, 0, 0)), vr, rtol=1e-12)
