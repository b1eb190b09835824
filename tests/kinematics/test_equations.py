"""The constraint equations of every kind (R pairs, angles, lines, gears, cams, belts):
the analytic Jacobian and ``gamma`` against finite differences of the residual, and one
configuration's call equal to its row of a batch (one implementation serves Newton's
single configurations and the sweeps' batches)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.kinematics.system import build_system

EX = Path(__file__).resolve().parents[2] / "examples"

GEARS = {"name": "gears", "ground": "frame", "links": ["frame", "g1", "g2", "arm"],
         "joints": [{"id": "O1", "type": "R", "links": ["arm", "g1"], "point": [0, 0], "actuated": True},
                    {"id": "O2", "type": "R", "links": ["arm", "g2"], "point": [3, 0]},
                    {"id": "O3", "type": "R", "links": ["frame", "arm"], "point": [0, 0], "actuated": True},
                    {"id": "G", "type": "gear", "links": ["g1", "g2"], "point": [1, 0]}]}
BELT = {"name": "belt between moving links", "ground": "frame", "links": ["frame", "carrier", "wheel"],
        "joints": [{"id": "O", "type": "R", "links": ["frame", "carrier"], "point": [0.0, 0.0], "actuated": True},
                   {"id": "Q", "type": "R", "links": ["frame", "wheel"], "point": [3.0, 1.0], "actuated": True},
                   {"id": "W", "type": "belt", "links": ["carrier", "wheel"], "point": [3.0, 1.0],
                    "anchor": [0.5, 0.8], "radius": 0.7, "wrap": "cw"}]}

SYSTEMS = {
    "R pairs": lambda: build_system(load_mechanism(EX / "kinematics" / "jansen_leg.yaml")),
    "lines": lambda: build_system(load_mechanism(EX / "kinematics" / "inverted_slider_crank.yaml")),
    "locked VLL": lambda: build_system(load_mechanism(EX / "fingers" / "two_phalanx_vll_000.yaml"),
                                       vll={"S": "locked"}),
    "prescribed VLL": lambda: build_system(load_mechanism(EX / "fingers" / "two_phalanx_vll_000.yaml"),
                                           vll={"S": "free"}, prescribed=("S",)),
    "cam": lambda: build_system(load_mechanism(EX / "kinematics" / "cam_roller.yaml")),
    "polar cam": lambda: build_system(load_mechanism(EX / "kinematics" / "cam_polar.yaml")),
    "belt": lambda: build_system(load_mechanism(EX / "belt" / "paper001_mechanism.yaml")),
    "belt between moving links": lambda: build_system(mechanism_from_dict(BELT)),
    "planetary gears": lambda: build_system(mechanism_from_dict(GEARS)),
}


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_jacobian_and_gamma_are_the_residuals_derivatives(name):
    S = SYSTEMS[name]()
    rng = np.random.default_rng(3)
    unit = np.where(np.arange(S.n) % 3 == 2, 1.0, S.scale)  # lengths in the size, angles in radians
    unit[3 * len(S.links):] = 1.0  # cam parameters
    u = np.array([[d.assembled for d in S.drivers]]) + 0.05
    for _ in range(4):
        q = S.q0 + 0.05 * rng.standard_normal(S.n) * unit
        qd = rng.standard_normal(S.n) * unit

        def phi(x):
            return S.residual(x[None], u)[0] / S.row_scale

        h = 1e-6
        fd = np.array([(phi(q + h * e) - phi(q - h * e)) / (2 * h) for e in np.eye(S.n) * unit]).T
        np.testing.assert_allclose(S.unit_jacobian(S.jacobian(q[None])[0]), fd, rtol=1e-6, atol=1e-7)
        # gamma = -(d/dt Phi_q) q' = minus the second derivative of Phi along q + t q'
        h = 1e-4
        d2 = (phi(q + h * qd) - 2 * phi(q) + phi(q - h * qd)) / h ** 2
        np.testing.assert_allclose(S.gamma(q[None], qd[None])[0] / S.row_scale, -d2, rtol=1e-5, atol=1e-5)


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_a_configuration_alone_equals_its_row_of_a_batch(name):
    S = SYSTEMS[name]()
    rng = np.random.default_rng(4)
    N = 5
    q = S.q0 + 0.05 * rng.standard_normal((N, S.n))
    qd = rng.standard_normal((N, S.n))
    u = np.array([d.assembled for d in S.drivers]) + 0.1 * rng.standard_normal((N, len(S.drivers)))
    R, J, G = S.residual(q, u), S.jacobian(q), S.gamma(q, qd)
    assert R.shape == (N, S.m) and J.shape == (N, S.m, S.n) and G.shape == (N, S.m)
    tol = 1e-13 * S.scale
    for k in range(N):
        np.testing.assert_allclose(S.residual(q[k:k + 1], u[k:k + 1])[0], R[k], rtol=0, atol=tol)
        np.testing.assert_allclose(S.jacobian(q[k:k + 1])[0], J[k], rtol=0, atol=tol)
        np.testing.assert_allclose(S.gamma(q[k:k + 1], qd[k:k + 1])[0], G[k], rtol=0, atol=tol * np.abs(G).max())


def test_every_kind_of_block_is_covered():
    kinds = {c.kind for make in SYSTEMS.values() for c in make().cons}
    assert kinds == {"R", "angle", "line", "gear", "curve", "belt"}
