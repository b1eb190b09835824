"""The compiled one-configuration equations (issue 17 §2) equal the per-block code."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechsyn.io import load_mechanism
from mechsyn.kinematics.compiled import one_configuration
from mechsyn.kinematics.system import build_system

EX = Path(__file__).resolve().parents[2] / "examples"

SYSTEMS = [
    ("kinematics/crank_rocker.yaml", {}),
    ("kinematics/inverted_slider_crank.yaml", {}),
    ("kinematics/jansen_leg.yaml", {}),
    ("kinematics/peaucellier.yaml", {}),
    ("fingers/two_phalanx_vll_000.yaml", {"vll": {"S": "locked"}}),
    ("fingers/two_phalanx_vll_000.yaml", {"vll": {"S": "free"}, "prescribed": ("S",)}),
    ("fingers/three_phalanx_vll_000.yaml", {"vll": {"S1": "active", "S2": "locked"}}),
]


@pytest.mark.parametrize("name, options", SYSTEMS)
def test_residual_and_jacobian_equal_the_per_block_code(name, options):
    S = build_system(load_mechanism(EX / name), **options)
    one = one_configuration(S)
    assert one is not None
    assert {c.kind for c in S.cons} <= {"R", "angle", "line"}
    rng = np.random.default_rng(0)
    u0 = np.array([d.assembled for d in S.drivers])
    for _ in range(5):
        q = S.q0 + rng.normal(scale=0.3, size=S.n) * np.where(np.arange(S.n) % 3 == 2, 1.0, S.scale)
        u = u0 + rng.normal(scale=0.2, size=len(u0))
        # the batch path (two configurations) is the per-block code
        R2 = S.residual(np.stack([q, q]), np.stack([u, u]))[0]
        J2 = S.jacobian(np.stack([q, q]))[0]
        np.testing.assert_allclose(one.residual(q, u), R2, rtol=0, atol=1e-12 * S.scale)
        np.testing.assert_allclose(one.jacobian(q), J2, rtol=0, atol=1e-12 * S.scale)
        # and the system's one-configuration calls go through it
        np.testing.assert_array_equal(S.residual(q[None], u[None])[0], one.residual(q, u))


def test_systems_with_other_blocks_are_not_compiled():
    S = build_system(load_mechanism(EX / "kinematics" / "cam_roller.yaml"))
    assert one_configuration(S) is None
    q = S.q0[None]
    u = np.array([[d.assembled for d in S.drivers]])
    assert S.residual(q, u).shape == (1, S.m)          # the per-block code still answers


def test_newton_sweep_equal_with_and_without_compiled_equations(monkeypatch):
    """A Newton continuation sweep (assembly, prediction, correction) gives the same poses
    with the compiled equations as with the per-block code."""
    import mechsyn.kinematics.system as system
    from mechsyn.kinematics.analysis import simulate

    mech = load_mechanism(EX / "fingers" / "two_phalanx_vll_000.yaml")
    inputs = {"E": np.linspace(95.0, 150.0, 12), "S": np.linspace(24.0, 30.0, 12)}
    fast = simulate(mech, inputs, points=["tip"], vll={"S": "free"}, method="newton")
    monkeypatch.setattr(system, "_one", lambda S: None)
    slow = simulate(mech, inputs, points=["tip"], vll={"S": "free"}, method="newton")
    assert fast.assembled.all() and slow.assembled.all()
    np.testing.assert_allclose(fast.points["tip"].position, slow.points["tip"].position, atol=1e-10)
