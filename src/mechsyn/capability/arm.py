"""Serial arm models: forward kinematics, Jacobians, inverse kinematics.

The arm files (planar_serial, dh, urdf) are read by :mod:`mechsyn.capability.arm_file`,
which validates them with pydantic; this module computes on arrays and imports none of it.
Joint i of a ``dh`` arm contributes ``Rz(theta_i + q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``
(``d_i + q_i`` for P).

Angles are degrees in files (R joints; P joint values and limits are lengths), lengths in
any unit (mm in the paper); speeds are then length/s. Inside, every function works on
arrays of many configurations at once: ``q`` has shape ``(N, n)`` in radians.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import Literal

import numpy as np


JointType = Literal["R", "P"]


# --------------------------------------------------------------------------- runtime model
def _rot(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) about unit ``axis`` by ``angle`` (N,) (Rodrigues)."""
    k = np.asarray(axis, float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def _homog(R: np.ndarray | None = None, p=(0.0, 0.0, 0.0)) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


@dataclass(frozen=True)
class SerialArm:
    """A serial arm, vectorised over configurations.

    ``kind`` is ``"planar"`` (task: end point (x, y)) or ``"spatial"`` (task: tool point
    (x, y, z)). Internal units: radians, rad/s; lengths and length/s as in the file.
    A spatial chain is ``T = F_0 M_1(q_1) F_1 ... M_n(q_n) F_n``: fixed transforms ``F``
    and joint motions ``M`` about / along unit ``axes`` (in the joint's own frame).

    Examples
    --------
    >>> import mechsyn as ms
    >>> arm = ms.examples.load("paper004_3r")     # planar 3R of paper 004
    >>> arm.n, arm.task_dim, arm.joint_names
    (3, 2, ('q1', 'q2', 'q3'))
    """

    name: str
    kind: Literal["planar", "spatial"]
    joint_types: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    qd_max: np.ndarray
    weights: np.ndarray
    link_lengths: np.ndarray | None = None  # planar
    base: np.ndarray | None = None  # planar
    fixed: tuple[np.ndarray, ...] = ()  # spatial: n + 1 homogeneous transforms
    axes: tuple[np.ndarray, ...] = ()  # spatial: n unit axes
    joint_names: tuple[str, ...] = field(default=())

    # ----------------------------------------------------------------- basic facts
    @property
    def n(self) -> int:
        return len(self.joint_types)

    @property
    def task_dim(self) -> int:
        return 2 if self.kind == "planar" else 3

    @property
    def is_revolute(self) -> np.ndarray:
        return np.array([t == "R" for t in self.joint_types])

    def to_user(self, q: np.ndarray) -> np.ndarray:
        """Joint values in file units: degrees for R, lengths for P."""
        q = np.asarray(q, float)
        return np.where(self.is_revolute, np.degrees(q), q)

    def from_user(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, float)
        return np.where(self.is_revolute, np.radians(q), q)

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """Mask (N,) of configurations inside the joint position limits."""
        q = np.atleast_2d(q)
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=-1)

    # ----------------------------------------------------------------- kinematics
    def fk(self, q: np.ndarray) -> np.ndarray:
        """Tool point, shape (N, task_dim), of configurations ``q`` (N, n)."""
        q = np.atleast_2d(np.asarray(q, float))
        if self.kind == "planar":
            theta, reach = self._planar_angles(q)
            return self.base + np.stack(
                [(reach * np.cos(theta)).sum(-1), (reach * np.sin(theta)).sum(-1)], -1)
        return self._frames(q)[1][:, -1]

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Jacobian of the tool point's velocity, shape (N, task_dim, n).

        Planar: column i of an R joint is ``sum_{k>=i} l_k (-sin th_k, cos th_k)`` with
        absolute link angles ``th_k = q_1 + ... + q_k``; of a P joint, the unit vector of
        its link. Spatial: ``z_i x (p - o_i)`` for R joints, ``z_i`` for P joints.
        """
        return self.fk_and_jacobian(q)[1]

    def fk_and_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`fk` and :meth:`jacobian` together, the joint frames computed once.

        Returns the tool points (N, task_dim) and the Jacobians (N, task_dim, n); the
        inner loop of :func:`ik_numeric`.

        Examples
        --------
        >>> from mechsyn.capability.arm_file import arm_from_dict
        >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 1.0],
        ...                      "joint_speed_limits_deg_s": [10, 10]})
        >>> p, J = arm.fk_and_jacobian(np.array([[0.0, np.pi / 2]]))
        >>> np.round(p, 12).tolist(), np.round(J[0], 12).tolist()
        ([[1.0, 1.0]], [[-1.0, -1.0], [1.0, 0.0]])
        """
        q = np.atleast_2d(np.asarray(q, float))
        if self.kind == "planar":
            theta, reach = self._planar_angles(q)
            vx, vy = -reach * np.sin(theta), reach * np.cos(theta)
            p = self.base + np.stack(
                [(reach * np.cos(theta)).sum(-1), (reach * np.sin(theta)).sum(-1)], -1)
            # suffix sums: column i gets links i..n-1 (all links move with an R joint i)
            cx = np.cumsum(vx[:, ::-1], axis=1)[:, ::-1]
            cy = np.cumsum(vy[:, ::-1], axis=1)[:, ::-1]
            J = np.stack([cx, cy], 1)
            prism = ~self.is_revolute
            if prism.any():
                J[:, 0, prism] = np.cos(theta[:, prism])
                J[:, 1, prism] = np.sin(theta[:, prism])
            return p, J
        J, p = self._geometric_jacobian(self._frames(q))
        return p, J[:, :3, :]

    def joint_axes(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The tool-point Jacobian and the joint axes ``z_i`` in the base frame, both
        (N, 3, n) (a planar arm in the plane z = 0: R axes along z, P axes along their link).

        >>> from mechsyn.capability.arm_file import arm_from_dict
        >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0],
        ...                      "joint_speed_limits_deg_s": [10]})
        >>> J, Z = arm.joint_axes(np.zeros((1, 1)))
        >>> (J[0, :, 0] + 0.0).tolist(), Z[0, :, 0].tolist()
        ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0])
        """
        q = np.atleast_2d(np.asarray(q, float))
        rev = self.is_revolute
        if self.kind == "planar":
            J = np.concatenate([self.fk_and_jacobian(q)[1], np.zeros((q.shape[0], 1, self.n))], axis=1)
            return J, np.where(rev, np.array([0.0, 0.0, 1.0])[:, None], J)
        Jg = self._geometric_jacobian(self._frames(q))[0]
        return Jg[:, :3], np.where(rev, Jg[:, 3:], Jg[:, :3])

    def jacobian_derivative(self, q: np.ndarray, u: np.ndarray,
                            axes: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Derivatives ``d(J(q) u) / dq_k`` of the tool velocity of fixed joint rates ``u``,
        shape (N, n, task_dim), for configurations ``q`` (N, n) and rates ``u`` (N, n).

        For a serial chain, column i of J (R: ``z_i x (p - o_i)``, P: ``z_i``) turns with
        every R joint k <= i (``z_k x J_i``) and, for an R joint i, follows the tool when
        a joint k > i moves (``z_i x J_k``); so row k is
        ``[k is R] z_k x sum_{i>=k} u_i J_i + (sum_{i<k, R} u_i z_i) x J_k``: one suffix and
        one prefix sum, linear in the number of joints (the chain-rule sensitivity of the
        capability measures, :func:`mechsyn.capability.maps.measure_gradient`). ``axes``:
        :meth:`joint_axes` of ``q`` when already known.

        Examples
        --------
        >>> from mechsyn.capability.arm_file import arm_from_dict
        >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 1.0],
        ...                      "joint_speed_limits_deg_s": [10, 10]})
        >>> q, u = np.array([[0.3, 0.5]]), np.array([[1.0, -2.0]])
        >>> D, e = arm.jacobian_derivative(q, u), 1e-6 * np.eye(2)
        >>> fd = [(arm.jacobian(q + e[k]) - arm.jacobian(q - e[k]))[0] @ u[0] / 2e-6 for k in range(2)]
        >>> bool(np.allclose(D[0], fd, atol=1e-8))
        True
        """
        q = np.atleast_2d(np.asarray(q, float))
        u = np.broadcast_to(np.asarray(u, float), q.shape)
        rev = self.is_revolute
        J, Z = self.joint_axes(q) if axes is None else axes
        uJ = J * u[:, None, :]
        suffix = np.cumsum(uJ[:, :, ::-1], axis=2)[:, :, ::-1]  # sum_{i>=k} u_i J_i
        uZ = np.where(rev, Z * u[:, None, :], 0.0)
        prefix = np.cumsum(uZ, axis=2) - uZ  # sum_{i<k, R} u_i z_i
        D = np.where(rev, np.cross(Z, suffix, axis=1), 0.0) + np.cross(prefix, J, axis=1)
        return np.swapaxes(D, 1, 2)[:, :, :self.task_dim]

    def geometric_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Spatial arms: (N, 6, n) Jacobian, rows (v_x, v_y, v_z, w_x, w_y, w_z)."""
        if self.kind == "planar":
            raise ValueError("geometric_jacobian is for spatial arms")
        q = np.atleast_2d(np.asarray(q, float))
        return self._geometric_jacobian(self._frames(q))[0]

    def _geometric_jacobian(self, frames: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(N, 6, n) Jacobian from the joint frames (:meth:`_frames`), and the tool point;
        all joints at once."""
        Rs, ps = frames
        p = ps[:, -1]
        z = np.einsum("nkij,kj->nik", Rs[:, :-1], self._axes)  # joint axes in the base frame (N, 3, n)
        rev = self.is_revolute
        lin = np.where(rev, np.cross(z, p[:, :, None] - np.swapaxes(ps[:, :-1], 1, 2), axis=1), z)
        return np.concatenate([lin, np.where(rev, z, 0.0)], axis=1), p

    def _planar_angles(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rev = self.is_revolute
        theta = np.cumsum(np.where(rev, q, 0.0), axis=1)
        reach = self.link_lengths + np.where(rev, 0.0, q)
        return theta, reach

    @cached_property
    def _axes(self) -> np.ndarray:
        return np.array(self.axes, float).reshape(self.n, 3)

    @cached_property
    def _motion_terms(self) -> tuple[np.ndarray, ...]:
        """``M_i(q) F_i`` of every joint as ``A0 + sin(q) A1 + (1 - cos q) A2`` (rotation
        and translation parts, stacked over the joints (n, 3, 3) and (n, 3); Rodrigues with
        ``K`` the axis' cross-product matrix)."""
        k = self._axes
        K = np.zeros((self.n, 3, 3))
        K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
        K = K - np.swapaxes(K, 1, 2)
        F = np.array(self.fixed[1:], float).reshape(self.n, 4, 4)
        R, t = F[:, :3, :3], F[:, :3, 3]
        K2 = K @ K
        return R, K @ R, K2 @ R, t, np.einsum("kij,kj->ki", K, t), np.einsum("kij,kj->ki", K2, t)

    def _frames(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rotations (N, n + 1, 3, 3) and origins (N, n + 1, 3) of the frames of joints
        1..n (before their motion) and of the tool: ``T = F_0 M_1(q_1) F_1 ... M_n(q_n) F_n``.

        Every joint's ``M_i F_i`` at once, then their running products (a parallel prefix
        scan was slower: log2(n) rounds over every joint cost 3x more at 320
        configurations of 100 joints).
        """
        N = q.shape[0]
        A0, A1, A2, b0, b1, b2 = self._motion_terms
        rev = self.is_revolute[:, None]
        qt = q.T  # joint-major (n, N): each joint's slice is contiguous
        s = np.where(rev, np.sin(qt), 0.0)[:, :, None]
        c = np.where(rev, 1.0 - np.cos(qt), 0.0)[:, :, None]
        R = A0[:, None] + s[..., None] * A1[:, None] + c[..., None] * A2[:, None]  # (n, N, 3, 3)
        t = b0[:, None] + s * b1[:, None] + c * b2[:, None] + np.where(rev, 0.0, qt)[:, :, None] * self._axes[:, None]
        Rs, ps = np.empty((self.n + 1, N, 3, 3)), np.empty((self.n + 1, N, 3))
        Rs[0], ps[0] = self.fixed[0][:3, :3], self.fixed[0][:3, 3]
        for i in range(self.n):  # running products, joint by joint (cheaper than a scan)
            ps[i + 1] = ps[i] + (Rs[i] @ t[i, :, :, None])[:, :, 0]
            Rs[i + 1] = Rs[i] @ R[i]
        Rs, ps = np.moveaxis(Rs, 0, 1), np.moveaxis(ps, 0, 1)
        return Rs, ps


# --------------------------------------------------------------------------- inverse kinematics
def ik_planar_3r(arm: SerialArm, point, q1: np.ndarray, branch: int = -1) -> tuple[np.ndarray, np.ndarray]:
    """Exact IK of a planar 3R arm for given q1 (radians, shape (K,)) and elbow ``branch``.

    With q1 fixed, joint 2 sits at ``B = base + l1 (cos q1, sin q1)``; the 2R sub-chain
    reaches ``r = point - B`` with ``cos q3 = (|r|^2 - l2^2 - l3^2) / (2 l2 l3)``,
    ``q3 = branch * acos(.)`` (paper 004's table: branch -1, q3 < 0) and
    ``q2 = atan2(r) - q1 - atan2(l3 sin q3, l2 + l3 cos q3)``.

    ``point`` is (2,) or (K, 2). Returns ``q`` (K, 3) and ``reachable`` (K,); unreachable
    rows hold NaN.
    """
    if arm.kind != "planar" or arm.n != 3 or not arm.is_revolute.all():
        raise ValueError("ik_planar_3r needs a planar 3R arm")
    l1, l2, l3 = arm.link_lengths
    q1 = np.atleast_1d(np.asarray(q1, float))
    P = np.broadcast_to(np.asarray(point, float) - arm.base, (q1.size, 2))
    rx = P[:, 0] - l1 * np.cos(q1)
    ry = P[:, 1] - l1 * np.sin(q1)
    c3 = (rx**2 + ry**2 - l2**2 - l3**2) / (2 * l2 * l3) if l2 * l3 > 0 else np.full(q1.size, np.nan)
    ok = np.abs(c3) <= 1 + 1e-12
    q3 = branch * np.arccos(np.clip(c3, -1, 1))
    q2 = np.arctan2(ry, rx) - q1 - np.arctan2(l3 * np.sin(q3), l2 + l3 * np.cos(q3))
    q2 = (q2 + np.pi) % (2 * np.pi) - np.pi
    q = np.stack([q1, q2, q3], -1)
    q[~ok] = np.nan
    return q, ok


def ik_numeric(arm: SerialArm, point, seeds: np.ndarray, *, fixed_first: bool = False,
               respect_limits: bool = True, iterations: int = 200, tol: float = 1e-7
               ) -> tuple[np.ndarray, np.ndarray]:
    """Damped least squares IK of the tool point from many seeds at once (vectorised).

    ``q <- q + J^T (J J^T + lambda^2 I)^-1 (p* - p(q))``, clipped to the limits when
    ``respect_limits``; with ``fixed_first`` joint 1 keeps its seed value (the redundancy
    parameter of paper 004). ``point`` is one target (task_dim,) or one per seed
    (K, task_dim), so the seeds of many grid points run together.

    Every seed iterates on its own: it stops as soon as its end point error is below
    ``tol`` times the arm's size (or when an iteration no longer changes it, e.g. held
    by a joint limit), so its answer does not depend on the other seeds of the batch.

    Returns ``q`` (K, n) and ``converged`` (K,).

    Examples
    --------
    >>> from mechsyn.capability.arm_file import arm_from_dict
    >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 1.0],
    ...                      "joint_speed_limits_deg_s": [10, 10]})
    >>> q, ok = ik_numeric(arm, [[1.0, 1.0], [0.0, 1.5]], [[0.1, 1.0], [1.0, 0.5]])
    >>> bool(ok.all()), bool(np.abs(arm.fk(q) - [[1.0, 1.0], [0.0, 1.5]]).max() < 1e-6)
    (True, True)
    """
    q = np.array(np.atleast_2d(seeds), float)
    K = q.shape[0]
    target = np.broadcast_to(np.asarray(point, float), (K, arm.task_dim))
    scale = max(_arm_size(arm), 1e-12)
    lam = 1e-3 * scale
    lo = np.where(np.isfinite(arm.lower), arm.lower, -np.inf)
    hi = np.where(np.isfinite(arm.upper), arm.upper, np.inf)
    damping = lam**2 * np.eye(arm.task_dim)
    active = np.arange(K)
    for _ in range(iterations):
        p, J = arm.fk_and_jacobian(q[active])
        e = target[active] - p
        pending = np.linalg.norm(e, axis=1) >= tol * scale
        active, e, J = active[pending], e[pending], J[pending]
        if not active.size:
            break
        if fixed_first:
            J[:, :, 0] = 0.0
        JJt = J @ np.swapaxes(J, 1, 2) + damping
        dq = np.einsum("kmn,km->kn", J, np.linalg.solve(JJt, e[:, :, None])[:, :, 0])
        old = q[active]
        new = np.clip(old + dq, lo, hi) if respect_limits else old + dq
        q[active] = new
        active = active[np.any(new != old, axis=1)]  # a seed that no longer moves is done
        if not active.size:
            break
    err = np.linalg.norm(target - arm.fk(q), axis=1)
    return q, err < tol * scale


def _arm_size(arm: SerialArm) -> float:
    if arm.kind == "planar":
        return float(np.sum(np.abs(arm.link_lengths)))
    return float(sum(np.linalg.norm(F[:3, 3]) for F in arm.fixed))
