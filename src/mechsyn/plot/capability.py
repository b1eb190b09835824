"""Figures of a velocity-capability map (paper 004): V_max and the optimal joint values.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
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
        return ax.contour(fx, fy, fine.T, levels=8, colors="k", linewidths=0.7)
    except (ValueError, TypeError):  # no level inside the range
        return None


def _text_size(ax: Any, text: str, fontsize: float) -> tuple[float, float]:
    """Approximate half width and half height of ``text`` in data units of ``ax`` (its
    final, equal-aspect position)."""
    ax.apply_aspect()
    pos, (w_in, h_in) = ax.get_position(), ax.figure.get_size_inches()
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    per_pt_x = abs(x1 - x0) / (pos.width * w_in * 72)
    per_pt_y = abs(y1 - y0) / (pos.height * h_in * 72)
    return 0.5 * (0.62 * fontsize * len(text) + 2) * per_pt_x, 0.5 * (1.2 * fontsize + 2) * per_pt_y


def _values_fit(ax: Any, xs: np.ndarray, ys: np.ndarray, fields: list, fontsize: float = 8) -> bool:
    """Whether the widest cell value of any panel fits its cell on ``ax`` (one answer for
    every panel: all annotated or none)."""
    values = np.concatenate([d[np.isfinite(d)] for d, _, _ in fields])
    if not values.size or xs.size < 2 or ys.size < 2:
        return False
    hw, hh = _text_size(ax, max((f"{v:.1f}" for v in values), key=len), fontsize)
    return 2 * hw <= 0.8 * np.min(np.diff(xs)) and 2 * hh <= 0.6 * np.min(np.diff(ys))


def _cell_values(ax: Any, xs: np.ndarray, ys: np.ndarray, data: np.ndarray,
                 fontsize: float = 8) -> list:
    """Write each finite cell value at its node. Returns the Texts written."""
    finite = np.isfinite(data)
    return [ax.text(x, y, f"{data[i, j]:.1f}", ha="center", va="center", fontsize=fontsize,
                    color="white", bbox=dict(fc="black", alpha=0.35, lw=0, pad=1))
            for i, x in enumerate(xs) for j, y in enumerate(ys) if finite[i, j]]


def _label_contours(ax: Any, cs: Any, texts: list, fontsize: float = 8) -> list:
    """Label each contour level once, inline on a light box, at the point of its line
    farthest from the cell-value texts (a level whose every point is under a text is left
    unlabelled rather than written over one). Returns the label Texts."""
    if not texts:
        labels = ax.clabel(cs, fontsize=fontsize, fmt="%.4g", inline=True)
    else:
        centres = np.array([t.get_position() for t in texts])
        thw, thh = _text_size(ax, max((t.get_text() for t in texts), key=len), fontsize)
        (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
        levels, spots = [], []
        for level, segs in zip(cs.levels, cs.allsegs):
            pts = np.vstack([s for s in segs if len(s)] or [np.empty((0, 2))])
            if not len(pts):
                continue
            lhw, lhh = _text_size(ax, f"{level:.4g}", fontsize)
            dx = np.abs(pts[:, None, 0] - centres[None, :, 0]) / (thw + lhw)
            dy = np.abs(pts[:, None, 1] - centres[None, :, 1]) / (thh + lhh)
            clear = np.maximum(dx, dy).min(axis=1)
            inside = ((pts[:, 0] - lhw > x0) & (pts[:, 0] + lhw < x1)
                      & (pts[:, 1] - lhh > y0) & (pts[:, 1] + lhh < y1))
            clear = np.where(inside, clear, -1.0)
            k = int(np.argmax(clear))
            if clear[k] > 1.05:
                levels.append(level)
                spots.append(tuple(pts[k]))
        if not spots:
            return []
        # written at the chosen points (clabel's manual placement of a subset of levels
        # fails in Matplotlib 3.8): the light box below keeps the line from the digits
        labels = [ax.text(x, y, f"{level:.4g}", fontsize=fontsize, ha="center", va="center", zorder=3)
                  for level, (x, y) in zip(levels, spots)]
    for t in labels:
        t.set_bbox(dict(fc="white", alpha=0.75, lw=0, pad=0.6))
    return labels


def plot_capability_map(cmap: Any, units: str = "mm/s", fig: Any = None) -> Any:
    """Heat map with contour lines of V_max and panels of the optimal joint values.
    Returns the Figure."""
    n = cmap.q.shape[-1]
    panels = 1 + n
    cols = 2 if panels <= 4 else 3
    rows_ = math.ceil(panels / cols)
    fig = figure(fig, (5.2 * cols, 4.4 * rows_))
    axs = fig.subplots(rows_, cols, squeeze=False)
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
        ax.set_title(title, fontsize=9)
        length = units.split("/")[0]
        ax.set_xlabel(f"x ({length})")
        ax.set_ylabel(f"y ({length})")
        ax.set_aspect("equal")
    for idx in range(panels, rows_ * cols):
        axs[idx // cols][idx % cols].axis("off")
    fig.tight_layout()
    # texts last, on the final layout: cell values where they fit, contour labels clear of them
    fit = _values_fit(axs[0][0], cmap.xs, cmap.ys, fields)
    for idx, (data, _, _) in enumerate(fields):
        ax = axs[idx // cols][idx % cols]
        texts = _cell_values(ax, cmap.xs, cmap.ys, data) if fit else []
        cs = _labelled_contours(ax, cmap.xs, cmap.ys, data) if idx == 0 else None
        if cs is not None:
            _label_contours(ax, cs, texts)
    return fig
