"""Vectors of the plane: the few operations every planar formulation of the package uses
(the constraint equations, the group steps, the kinetostatics), written once.

Every function works on the last axis of its arrays (a vector is ``v[..., 0], v[..., 1]``),
so one call treats a batch of configurations. ``A(phi)`` is the rotation by the angle
``phi``; ``R90`` the quarter turn ``A(pi / 2)``.

Examples
--------
>>> import numpy as np
>>> c, s = cos_sin(np.array([0.0, np.pi / 2]))
>>> rotate(c, s, np.array([1.0, 0.0])).round(12).tolist()
[[1.0, 0.0], [0.0, 1.0]]
>>> a, b = np.array([1.0, 2.0]), np.array([3.0, 4.0])
>>> float(dot(a, b)), float(cross(a, b)), perp(a).tolist()
(11.0, -2.0, [-2.0, 1.0])
"""

from __future__ import annotations

import numpy as np

__all__ = ["cos_sin", "rotate", "perp", "dot", "cross", "to_frame"]


def cos_sin(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``cos(phi), sin(phi)``: the numbers of ``A(phi)``."""
    return np.cos(phi), np.sin(phi)


def rotate(c: np.ndarray, s: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``A(phi) v`` for a batch of angles (``c, s`` shape (N,)) and a vector ``v`` (2,) or (N, 2)."""
    vx, vy = v[..., 0], v[..., 1]
    x = c * vx - s * vy
    out = np.empty(x.shape + (2,))
    out[..., 0] = x
    out[..., 1] = s * vx + c * vy
    return out


def perp(v: np.ndarray) -> np.ndarray:
    """``R90 v``: the vector turned by +90 degrees."""
    out = np.empty(v.shape)
    out[..., 0] = -v[..., 1]
    out[..., 1] = v[..., 0]
    return out


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a . b`` (a scalar per row)."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The plane cross product ``a x b = a_x b_y - a_y b_x`` (a scalar per row)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def to_frame(c: float, s: float, dx: float, dy: float) -> np.ndarray:
    """The one vector ``(dx, dy)`` turned by the angle whose cosine and sine are ``c``, ``s``
    (floats: a point carried into a link's frame costs a few products)."""
    return np.array([c * dx - s * dy, s * dx + c * dy], float)
