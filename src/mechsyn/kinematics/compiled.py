"""One-configuration constraint equations, compiled once per system.

:class:`~mechsyn.kinematics.system.PlanarSystem` evaluates ``Phi(q, u)`` and ``Phi_q``
constraint by constraint on a batch of configurations, which suits sweeps. Newton's
method, continuation steps and assembly work on *one* configuration at a time, where
that loop over constraint blocks of one-row arrays costs far more than the arithmetic.
:func:`one_configuration` gathers the blocks of each kind (R pairs, angles, lines: every
pair of a linkage with R and P pairs, drives and locked or prescribed VLL) into index
arrays once, so that the residual and the Jacobian of one configuration are a few
whole-array operations (Haug, *Computer-Aided Kinematics and Dynamics of Mechanical
Systems*, 1989, eqs. 3.3.9 and the body-coordinate constraints of ch. 3):

* R pair: ``P_a - P_b`` with ``P = r + A(phi) s``; rows ``[I, R90 A s]`` for ``a`` and
  the negatives for ``b``;
* angle: ``phi_b - phi_a - c0 - u``; rows ``+1`` at ``phi_b``, ``-1`` at ``phi_a``;
* line: ``w . (P_b - P_a) - c0 - u`` with ``w = A(phi_a) w_loc``; rows ``-w`` and
  ``R90 w . d - w . R90 A_a s_a`` for ``a``, ``w`` and ``w . R90 A_b s_b`` for ``b``.

Systems with other blocks (gears, cams, belts) are not compiled: :func:`one_configuration`
returns None and the per-block code is used. The answers equal the per-block code's to
round-off (tests compare them on random configurations).

Examples
--------
>>> import numpy as np
>>> import mechsyn as ms
>>> from mechsyn.kinematics.system import build_system
>>> S = build_system(ms.examples.load("crank_rocker"))
>>> one = one_configuration(S)
>>> q = S.q0 + 0.1
>>> u = np.array([d.assembled for d in S.drivers])
>>> bool(np.allclose(one.residual(q, u), S.residual(q[None], u[None])[0]))
True
>>> bool(np.allclose(one.jacobian(q), S.jacobian(q[None])[0]))
True
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["OneConfiguration", "one_configuration"]

_KINDS = ("R", "angle", "line")


def _vectors(values: list, n: int) -> np.ndarray:
    return np.array(values, float).reshape(n, 2)


class OneConfiguration:
    """``Phi(q, u)`` (m,) and ``Phi_q(q)`` (m, n) of one configuration of a system whose
    blocks are R pairs, angles and lines (see the module doc)."""

    def __init__(self, S: Any) -> None:
        nl = len(S.links)
        self.m, self.n, self.nl = S.m, S.n, nl
        blocks: dict[str, list] = {k: [] for k in _KINDS}
        for row, con in S.blocks():
            blocks[con.kind].append((row, con))

        def link(i: int) -> int:  # the frame: an extra all-zero pose row
            return nl if i < 0 else i

        def gather(kind: str) -> tuple:
            items = blocks[kind]
            k = len(items)
            rows = np.array([r for r, _ in items], int)
            a = np.array([link(c.a) for _, c in items], int)
            b = np.array([link(c.b) for _, c in items], int)
            zero = [0.0, 0.0]
            sa = _vectors([list(c.sa) if c.sa is not None else zero for _, c in items], k)
            sb = _vectors([list(c.sb) if c.sb is not None else zero for _, c in items], k)
            w = _vectors([list(c.w) if c.w is not None else zero for _, c in items], k)
            c0 = np.array([c.c0 for _, c in items], float)
            drv = np.array([-1 if c.driver is None else c.driver for _, c in items], int)
            return rows, a, b, sa, sb, w, c0, drv

        self.R = gather("R")
        self.angle = gather("angle")
        self.line = gather("line")
        self._angle_jac = self._angle_entries()

    def _angle_entries(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        rows, a, b = self.angle[:3]
        r = np.concatenate([rows, rows])
        c = np.concatenate([3 * b + 2, 3 * a + 2])
        v = np.concatenate([np.ones(len(rows)), -np.ones(len(rows))])
        return r, c, v

    def _poses(self, q: np.ndarray) -> np.ndarray:
        P = np.zeros((self.nl + 1, 3))
        P[:self.nl] = np.asarray(q, float)[:3 * self.nl].reshape(self.nl, 3)
        return P

    @staticmethod
    def _turned(c: np.ndarray, sn: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``A(phi) s`` row by row, as its x and y."""
        return c * s[:, 0] - sn * s[:, 1], sn * s[:, 0] + c * s[:, 1]

    def _line_terms(self, P: np.ndarray, C: np.ndarray, Sn: np.ndarray) -> tuple:
        """``w = A_a w_loc``, ``A_a s_a``, ``A_b s_b`` and ``d = P_b - P_a`` of the lines (x, y each)."""
        _rows, a, b, sa, sb, w = self.line[:6]
        wx, wy = self._turned(C[a], Sn[a], w)
        ax, ay = self._turned(C[a], Sn[a], sa)
        bx, by = self._turned(C[b], Sn[b], sb)
        return wx, wy, ax, ay, bx, by, P[b, 0] + bx - P[a, 0] - ax, P[b, 1] + by - P[a, 1] - ay

    def residual(self, q: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``Phi(q, u)`` of one configuration ``q`` (n,) at inputs ``u`` (n_inputs,)."""
        P = self._poses(q)
        C, Sn = np.cos(P[:, 2]), np.sin(P[:, 2])
        ue = np.append(np.asarray(u, float), 0.0)  # driver -1: no input
        out = np.empty(self.m)
        rows, a, b, sa, sb, _w, _c0, _d = self.R
        if len(rows):
            ax, ay = self._turned(C[a], Sn[a], sa)
            bx, by = self._turned(C[b], Sn[b], sb)
            out[rows] = P[a, 0] + ax - P[b, 0] - bx
            out[rows + 1] = P[a, 1] + ay - P[b, 1] - by
        rows, a, b, _sa, _sb, _w, c0, drv = self.angle
        if len(rows):
            out[rows] = P[b, 2] - P[a, 2] - (c0 + ue[drv])
        rows, a, b, sa, sb, w, c0, drv = self.line
        if len(rows):
            wx, wy, _ax, _ay, _bx, _by, dx, dy = self._line_terms(P, C, Sn)
            out[rows] = wx * dx + wy * dy - (c0 + ue[drv])
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """``Phi_q`` (m, n) of one configuration ``q`` (n,)."""
        P = self._poses(q)
        C, Sn = np.cos(P[:, 2]), np.sin(P[:, 2])
        J = np.zeros((self.m, 3 * self.nl + 3))  # the last three columns: the frame, dropped
        rows, a, b, sa, sb, _w, _c0, _d = self.R
        if len(rows):
            for i, s, sign in ((a, sa, 1.0), (b, sb, -1.0)):
                x, y = self._turned(C[i], Sn[i], s)
                J[rows, 3 * i] = sign
                J[rows + 1, 3 * i + 1] = sign
                J[rows, 3 * i + 2] = -sign * y
                J[rows + 1, 3 * i + 2] = sign * x
        r, c, v = self._angle_jac
        J[r, c] = v
        rows, a, b = self.line[:3]
        if len(rows):
            wx, wy, ax, ay, bx, by, dx, dy = self._line_terms(P, C, Sn)
            J[rows, 3 * a] = -wx
            J[rows, 3 * a + 1] = -wy
            # d/dphi_a of w.(P_b - P_a) = (R90 w).d - w.(R90 A_a s_a)
            J[rows, 3 * a + 2] = (-wy * dx + wx * dy) - (-wx * ay + wy * ax)
            J[rows, 3 * b] = wx
            J[rows, 3 * b + 1] = wy
            J[rows, 3 * b + 2] = -wx * by + wy * bx
        return J[:, :self.n]


def one_configuration(S: Any) -> OneConfiguration | None:
    """The compiled one-configuration equations of ``S`` (cached on it), or None when it
    has blocks other than R pairs, angles and lines, or unknowns other than link poses."""
    memo = S.cache.get("one_configuration", False)
    if memo is not False:
        return memo
    ok = S.n == 3 * len(S.links) and all(c.kind in _KINDS for c in S.cons)
    one = S.cache["one_configuration"] = OneConfiguration(S) if ok else None
    return one
