"""Velocities and accelerations of many configurations at once by linear solves.

``Phi_q q' = B u'`` and ``Phi_q q'' = gamma + B u''`` (Haug 1989, eqs. 3.3.9-3.3.11),
batched over the configurations of a sweep: the rates of the engines whose groups have no
closed-form rates (:mod:`mechsyn.kinematics.dyads`). The one-configuration rates and the
factored forms used by Newton's continuation are in :mod:`mechsyn.kinematics.solve`.

References
----------
.. [1] E. J. Haug, *Computer Aided Kinematics and Dynamics of Mechanical Systems*, vol. 1,
   Allyn and Bacon, 1989, ch. 3.
"""

from __future__ import annotations

import numpy as np

from mechsyn.kinematics.system import PlanarSystem

__all__ = ["batch_rates"]


def batch_rates(S: PlanarSystem, q: np.ndarray, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations for a batch of configurations (N, n), vectorised."""
    N = q.shape[0]
    J = S.jacobian(q)
    B = S.input_matrix()
    rhs = np.broadcast_to(B @ np.asarray(speeds, float), (N, S.m))
    if S.m == S.n:
        qd = np.linalg.solve(J, rhs[..., None])[..., 0]
        qdd = np.linalg.solve(J, S.gamma(q, qd)[..., None])[..., 0]
    else:
        pinv = np.linalg.pinv(J)
        qd = np.einsum("nij,nj->ni", pinv, rhs)
        qdd = np.einsum("nij,nj->ni", pinv, S.gamma(q, qd))
    return qd, qdd
