"""Points carried into their links' drawn frames, many at once
(:meth:`mechsyn.kinematics.system.PlanarSystem.to_locals`).

A link's frame has its origin ``o`` at its first joint and turns by ``phi0``; a point
``p`` of the plane has the local coordinates ``R(-phi0) (p - o)``, with ``c = cos(-phi0)``,
``s = sin(-phi0)``: ``(c dx - s dy, s dx + c dy)``. Every function here does that
arithmetic in that order (one rounding per product and sum), so the numbers are those of
:meth:`~mechsyn.kinematics.system.PlanarSystem.to_local`, point for point.
"""

from __future__ import annotations

import numpy as np

__all__ = ["points_to_frames"]

#: Up to this many points the arithmetic is done on Python floats: a NumPy call costs
#: about a microsecond whatever its size, a point on floats a fraction of one.
FEW = 24


def points_to_frames(frames: tuple[list, list, list], idx: np.ndarray, pts: np.ndarray) -> np.ndarray:
    """The points ``pts`` (m, 2) in the frames of the links ``idx`` (m,; -1: the frame of
    the mechanism, the point itself), (m, 2). ``frames``: every moving link's
    ``cos(-phi0)``, ``sin(-phi0)`` and origin, as lists
    (:meth:`~mechsyn.kinematics.system.PlanarSystem.frames`).

    Examples
    --------
    >>> import numpy as np
    >>> frames = ([0.0], [-1.0], [[1.0, 1.0]])  # link 0 turned by +90 degrees about (1, 1)
    >>> idx, pts = np.array([0, -1]), np.array([[1.0, 3.0], [0.5, -0.0]])
    >>> points_to_frames(frames, idx, pts).tolist()
    [[2.0, 0.0], [0.5, -0.0]]
    >>> many = points_to_frames(frames, np.tile(idx, 20), np.tile(pts, (20, 1)))  # the array path
    >>> bool(np.array_equal(many[:2], points_to_frames(frames, idx, pts)))
    True
    """
    cos, sin, org = frames
    if len(idx) <= FEW:
        out = []
        for i, (x, y) in zip(idx.tolist(), pts.tolist()):
            if i < 0:
                out.append((x, y))
                continue
            dx, dy = x - org[i][0], y - org[i][1]
            out.append((cos[i] * dx - sin[i] * dy, sin[i] * dx + cos[i] * dy))
        return np.array(out, float).reshape(-1, 2)
    mov, k = idx >= 0, np.where(idx >= 0, idx, 0)
    c, sn = np.array(cos + [1.0])[k], np.array(sin + [0.0])[k]
    o = np.array(org, float).reshape(-1, 2)[k] if len(org) else np.zeros((len(idx), 2))
    dx, dy = pts[:, 0] - o[:, 0], pts[:, 1] - o[:, 1]
    return np.stack([np.where(mov, c * dx - sn * dy, pts[:, 0]), np.where(mov, sn * dx + c * dy, pts[:, 1])], 1)
