"""Many grid points at once: batched IK and maps equal the point-by-point answers."""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np
import pytest

from mechsyn.capability.arm import ik_numeric
from mechsyn.capability.arm_file import load_arm
from mechsyn.capability.maps import (
    capability_map, halton, measure_values, refine_over_self_motion, self_motion, self_motions,
)

ROOT = Path(__file__).resolve().parents[2]
UR5 = ROOT / "examples" / "capability" / "ur5_dh.yaml"
PAPER = ROOT / "examples" / "capability" / "paper004_3r.yaml"


def test_halton_is_scipys_unscrambled_sequence():
    qmc = pytest.importorskip("scipy.stats").qmc
    for d in (1, 3, 6, 7):
        np.testing.assert_array_equal(halton(300, d),
                                      qmc.Halton(d=d, scramble=False).random(301)[1:])


def test_ik_numeric_rows_independent_of_the_batch():
    arm = load_arm(UR5)
    rng = np.random.default_rng(3)
    targets = arm.fk(rng.uniform(-2, 2, (6, arm.n)))
    seeds = rng.uniform(-2, 2, (6, arm.n))
    q, ok = ik_numeric(arm, targets, seeds)
    assert ok.sum() >= 4
    for k in range(6):
        qk, okk = ik_numeric(arm, targets[k], seeds[k:k + 1])
        np.testing.assert_array_equal(qk[0], q[k])
        assert okk[0] == ok[k]
    err = np.linalg.norm(arm.fk(q[ok]) - targets[ok], axis=1)
    assert err.max() < 1e-7 * 2000


def test_self_motions_equal_point_by_point():
    arm = load_arm(UR5)
    pts = np.array([[400.0, 200, 300], [300, -100, 300], [2000, 0, 0]])  # last: out of reach
    batch = self_motions(arm, pts)
    for p, (qb, vb) in zip(pts, batch):
        q1, v1 = self_motion(arm, p)
        np.testing.assert_array_equal(qb, q1)
        np.testing.assert_array_equal(vb, v1)
    assert len(batch[0][0]) > 2 and len(batch[2][0]) == 0


def test_refine_batched_equals_one_point_at_a_time():
    arm = load_arm(UR5)
    d = np.array([1.0, 0, 0])
    pts = np.array([[400.0, 200, 300], [300, -100, 300]])
    starts, owners = [], []
    for k, p in enumerate(pts):
        q, valid = self_motion(arm, p)
        top = np.argsort(-measure_values(arm, q[valid], d), kind="stable")[:3]
        starts.append(q[valid][top])
        owners += [k] * len(top)
    owners = np.array(owners)
    qb, vb = refine_over_self_motion(arm, pts[owners], np.concatenate(starts), d, iterations=8)
    for k, p in enumerate(pts):
        q1, v1 = refine_over_self_motion(arm, p, starts[k], d, iterations=8)
        np.testing.assert_array_equal(qb[owners == k], q1)
        np.testing.assert_array_equal(vb[owners == k], v1)
    assert np.all(vb >= measure_values(arm, np.concatenate(starts), d))


def test_map_chunks_do_not_change_the_map():
    arm = load_arm(UR5)
    xs, ys = np.array([300.0, 500]), np.array([-100.0, 100, 200])
    a = capability_map(arm, xs, ys, [1, 0, 0], z=300, chunk=64)
    b = capability_map(arm, xs, ys, [1, 0, 0], z=300, chunk=1)
    np.testing.assert_array_equal(a.value, b.value)
    np.testing.assert_array_equal(a.q, b.q)


def test_csv_from_arrays_is_the_repr_of_every_value():
    arm = load_arm(PAPER)
    cmap = capability_map(arm, np.arange(0, 2700, 300.0), np.arange(0, 2700, 450.0), [1, 0])
    assert not np.isfinite(cmap.value).all()  # some cells unreachable: empty fields
    rows = list(csv.reader(io.StringIO(cmap.to_csv())))
    assert rows[0] == ["x", "y", "v_max_exact", "q1_opt", "q2_opt", "q3_opt"]
    expected = [["" if not np.isfinite(v) else repr(float(v)) for v in r] for r in cmap.rows()]
    assert rows[1:] == expected
