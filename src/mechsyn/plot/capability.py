"""Figures of a velocity-capability map (paper 004): V_max and the optimal joint values.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University; journal and year are not in the project's copy
   ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mechsyn.plot._base import figure

__all__ = ["plot_capability_map"]


def _labelled_contours(ax: Any, xs: np.ndarray, ys: np.ndarray, data: np.ndarray) -> Any:
    """Labelled contour lines of ``data`` (xs by ys) on ``ax``, interpolated: a coarse grid
    is refined by a cubic spline (linear where some nodes are unreachable), so the lines are
    smooth curves between the nodes rather than polygons through the cells."""
    from scipy.interpolate import RectBivariateSpline, RegularGridInterpolator

    finite = np.isfinite(data)
    if xs.size < 2 or ys.size < 2 or finite.sum() < 4 or np.nanstd(data) == 0:
        return None
    fx = np.linspace(xs[0], xs[-1], max(200, xs.size))
    fy = np.linspace(ys[0], ys[-1], max(200, ys.size))
    if finite.all() and xs.size >= 3 and ys.size >= 3:
        k = min(3, xs.size - 1, ys.size - 1)
        fine = RectBivariateSpline(xs, ys, data, kx=k, ky=k)(fx, fy)
    else:
        gx, gy = np.meshgrid(fx, fy, indexing="ij")
        fine = RegularGridInterpolator((xs, ys), data, bounds_error=False)(np.stack([gx, gy], -1))
    try:
        cs = ax.contour(fx, fy, fine.T, levels=8, colors="k", linewidths=0.7)
        ax.clabel(cs, fontsize=8, fmt="%.4g", inline=True)
    except (ValueError, TypeError):  # no level inside the range
        return None
    return cs


def plot_capability_map(cmap: Any, units: str = "mm/s", fig: Any = None) -> Any:
    """Heat map with contour lines of V_max and panels of the optimal joint values.
    Returns the Figure."""
    n = cmap.q.shape[-1]
    panels = 1 + n
    cols = 2 if panels <= 4 else 3
    rows_ = math.ceil(panels / cols)
    fig = figure(fig, (5.2 * cols, 4.4 * rows_))
    axs = fig.subplots(rows_, cols, squeeze=False)
    small = cmap.xs.size * cmap.ys.size <= 144
    qu = cmap.q_user()
    fields = [(np.where(np.isfinite(cmap.value), cmap.value, np.nan),
               f"V_max along ({', '.join(f'{c:g}' for c in np.round(cmap.direction, 3))}) "
               f"({units})" + ("" if cmap.z is None else f" in z = {cmap.z:g}")
               + f"\n{cmap.measure}, {cmap.search} self-motion", "viridis")]
    for k in range(n):
        data, unit = qu[..., k], "deg" if cmap.joint_is_revolute[k] else units.split("/")[0]
        if cmap.joint_is_revolute[k] and np.nanmax(np.abs(data), initial=0.0) > 180:
            data, unit = (data + 180) % 360 - 180, "deg, shown mod 360"  # same pose
        fields.append((data, f"optimal {cmap.joint_names[k]} ({unit})", "coolwarm"))
    for idx, (data, title, cm) in enumerate(fields):
        ax = axs[idx // cols][idx % cols]
        mesh = ax.pcolormesh(cmap.xs, cmap.ys, data.T, shading="nearest", cmap=cm)
        fig.colorbar(mesh, ax=ax, shrink=0.85)
        if idx == 0:
            _labelled_contours(ax, cmap.xs, cmap.ys, data)
        if small:
            for i, x in enumerate(cmap.xs):
                for j, y in enumerate(cmap.ys):
                    if np.isfinite(data[i, j]):
                        ax.text(x, y, f"{data[i, j]:.1f}", ha="center", va="center", fontsize=8,
                                color="white", bbox=dict(fc="black", alpha=0.35, lw=0, pad=1))
        ax.set_title(title, fontsize=9)
        length = units.split("/")[0]
        ax.set_xlabel(f"x ({length})")
        ax.set_ylabel(f"y ({length})")
        ax.set_aspect("equal")
    for idx in range(panels, rows_ * cols):
        axs[idx // cols][idx % cols].axis("off")
    fig.tight_layout()
    return fig
