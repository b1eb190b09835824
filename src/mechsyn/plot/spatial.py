"""3-D pictures of spatial kinematics (:class:`~mechsyn.kinematics.spatial_result.SpatialSimulation`):
the mechanism at a row of the sweep with the paths of its points (:func:`plot_spatial`),
and its motion (:func:`animate_spatial`), on Matplotlib 3-D axes.

Joints are drawn by type (R: a short stroke along the axis with a round marker; P: a stroke
along the slide with a square; C: a stroke with a diamond; H: a stroke with a star; U: the
two arms of the cross; S: a white ball), links as bars between their joints (a translucent
plate when a link carries three or more joints), point paths in the colour of their link.
The axes are labelled with the file's length unit and have equal scales. Nothing here
writes a file or picks a backend.
"""

from __future__ import annotations

from typing import Any

import matplotlib
import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.plot._base import figure

__all__ = ["plot_spatial", "animate_spatial", "draw_spatial"]

_MARKERS = {"R": ("o", "revolute R"), "P": ("s", "prismatic P"), "C": ("D", "cylindrical C"),
            "H": ("*", "helical H"), "U": ("P", "universal U"), "S": ("o", "spherical S")}


def _pose(sim: Any, link: str, k: int) -> tuple[np.ndarray, np.ndarray]:
    if link not in sim.links:  # the frame
        return np.eye(3), np.zeros(3)
    lp = sim.links[link]
    return lp.rotation[k], lp.translation[k]


def joint_frames(sim: Any, k: int) -> list[tuple[Any, np.ndarray, list[np.ndarray]]]:
    """(joint, position, axes) of every joint with a point at row ``k``: the point carried
    by the joint's second link, the axes by the link each is fixed in."""
    out = []
    for j in sim.model.mech.joints:
        if j.point is None:
            continue
        Ra, _ = _pose(sim, j.links[0], k)
        Rb, tb = _pose(sim, j.links[1], k)
        axes = []
        if j.axis is not None:
            axes.append(Ra @ (np.asarray(j.axis, float) / np.linalg.norm(j.axis)))
        if j.axis2 is not None:
            axes.append(Rb @ (np.asarray(j.axis2, float) / np.linalg.norm(j.axis2)))
        out.append((j, Rb @ np.asarray(j.point, float) + tb, axes))
    return out


def link_colour(sim: Any, link: str) -> Any:
    """Matplotlib's tab10 by the link's place in the file (the planar pictures' rule)."""
    names = list(sim.model.mech.link_names)
    return matplotlib.colormaps["tab10"](names.index(link) % 10 if link in names else 7)


def draw_spatial(ax: Any, sim: Any, k: int, alpha: float = 1.0) -> list:
    """The mechanism at row ``k`` on 3-D axes ``ax``; returns the artists drawn."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mech = sim.model.mech
    L = sim.length_scale
    frames = joint_frames(sim, k)
    arts: list = []
    for link in mech.moving_links:
        pts = [x for j, x, _ in frames if link in j.links]
        if len(pts) < 2:
            continue
        P = np.array(pts)
        colour = link_colour(sim, link)
        if len(P) >= 3:
            poly = Poly3DCollection([P], alpha=0.25 * alpha, facecolor=colour, edgecolor="none")
            ax.add_collection3d(poly)
            arts.append(poly)
            P = np.vstack([P, P[:1]])
        arts += ax.plot(P[:, 0], P[:, 1], P[:, 2], "-", lw=3, color=colour, alpha=alpha, solid_capstyle="round")
    G = np.array([x for j, x, _ in frames if mech.ground in j.links])
    if len(G) >= 2:  # the frame: its joints joined by a dashed line
        G = np.vstack([G, G[:1]]) if len(G) >= 3 else G
        arts += ax.plot(G[:, 0], G[:, 1], G[:, 2], "--", lw=1, color="0.4", alpha=alpha)
    for j, x, axes in frames:
        marker = _MARKERS.get(j.type, ("o", j.type))[0]
        ground = mech.ground in j.links
        for a in axes:
            seg = np.array([x - 0.12 * L * a, x + 0.12 * L * a])
            arts += ax.plot(seg[:, 0], seg[:, 1], seg[:, 2], "-", lw=1.6, color="0.15", alpha=alpha)
        face = "white" if j.type == "S" else ("0.2" if ground else "0.6")
        arts += ax.plot([x[0]], [x[1]], [x[2]], marker, ms=9 if j.type == "S" else 6, mfc=face, mec="0.1",
                        mew=0.8, alpha=alpha, linestyle="none")
    return arts


def _unit(sim: Any) -> str:
    return sim.model.mech.attrs.get("units") or "length"


def _equal_box(ax: Any, P: np.ndarray, unit: str) -> None:
    """Equal scales on the three axes around the points ``P`` (k, 3), labelled."""
    lo, hi = np.nanmin(P, axis=0), np.nanmax(P, axis=0)
    mid, half = (lo + hi) / 2, 0.55 * float(np.max(hi - lo)) + 1e-12
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.tick_params(labelsize=7)
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_zlabel(f"z ({unit})")


def _all_points(sim: Any, rows: np.ndarray) -> np.ndarray:
    P = [x for k in rows[:: max(1, len(rows) // 24)] for _, x, _ in joint_frames(sim, k)]
    P += [pm.position[rows] for pm in sim.points.values()]  # every row: the paths stay inside
    return np.vstack([np.atleast_2d(p) for p in P])


def _legend(ax: Any, sim: Any) -> None:
    from matplotlib.lines import Line2D

    kinds = [t for t in _MARKERS if any(j.type == t for j in sim.model.mech.joints)]
    handles = [Line2D([], [], marker=_MARKERS[t][0], ls="none", mfc="white" if t == "S" else "0.6", mec="0.1",
                      label=_MARKERS[t][1]) for t in kinds]
    handles.append(Line2D([], [], ls="--", color="0.4", label="frame (dark: on the frame)"))
    if handles:
        ax.legend(handles=handles, fontsize=8, loc="upper left")


def _rows(sim: Any) -> np.ndarray:
    idx = np.flatnonzero(sim.assembled)
    if len(idx) == 0:
        raise MechsynInputError("nothing to draw: the mechanism is not assembled at any input",
                                hint="widen the input range")
    return idx


def plot_spatial(sim: Any, ax: Any = None, fig: Any = None, k: int | None = None, title: str | None = None) -> Any:
    """The spatial mechanism at row ``k`` (default: the first assembled row) with the paths
    of its points over the sweep, on 3-D axes ``ax`` (or a new one on ``fig``, or a new
    figure). Returns the axes.

    Examples
    --------
    >>> import matplotlib
    >>> from matplotlib.figure import Figure
    >>> import mechsyn as ms
    >>> s = ms.simulate(ms.examples.load("bennett"), {"R1": ms.input_grid(0, 360, 10)})
    >>> ax = plot_spatial(s, fig=Figure())
    >>> ax.name, ax.get_zlabel()
    ('3d', 'z (length)')
    """
    idx = _rows(sim)
    k = int(idx[0]) if k is None else int(k)
    if ax is None:
        ax = figure(fig, (6.4, 6.0)).add_subplot(projection="3d")
    elif getattr(ax, "name", "") != "3d":
        raise MechsynInputError("a spatial mechanism is drawn on 3-D axes", field="ax",
                                hint="pass ax=fig.add_subplot(projection='3d'), or fig=")
    _scene(ax, sim, idx)
    x = sim.inputs[sim.main_input]
    draw_spatial(ax, sim, k)
    ax.set_title(title or f"{sim.mechanism}\n{sim.main_input} = {x[k]:.4g} {_input_unit(sim)} "
                 "(point paths over the sweep)", fontsize=10)
    return ax


def _input_unit(sim: Any) -> str:
    return _unit(sim) if sim.input_types[sim.main_input] == "P" else "deg"


def _scene(ax: Any, sim: Any, idx: np.ndarray) -> None:
    """The point paths, the equal-scale box around the motion and the joints' legend."""
    for pm in sim.points.values():
        P = pm.position
        ax.plot(P[:, 0], P[:, 1], P[:, 2], "-", lw=1.2, color=link_colour(sim, pm.link), alpha=0.8)
    _equal_box(ax, _all_points(sim, idx), _unit(sim))
    _legend(ax, sim)


def animate_spatial(sim: Any, fig: Any = None, max_frames: int = 90, interval: float = 1000 / 15,
                    title: str | None = None) -> Any:
    """The spatial mechanism moving over its assembled rows on 3-D axes, tracing its points:
    a :class:`matplotlib.animation.FuncAnimation` (``anim.save("m.gif", writer="pillow")``)."""
    from matplotlib.animation import FuncAnimation

    idx = _rows(sim)
    frames = idx[np.unique(np.linspace(0, len(idx) - 1, min(max_frames, len(idx))).astype(int))]
    fig = figure(fig, (6.4, 6.0))
    ax = fig.add_subplot(projection="3d")
    _scene(ax, sim, idx)
    moving: list = []
    x = sim.inputs[sim.main_input]

    def draw(k: int) -> list:
        for a in moving:
            a.remove()
        moving[:] = draw_spatial(ax, sim, k)
        ax.set_title(title or f"{sim.mechanism}\n{sim.main_input} = {x[k]:.4g} {_input_unit(sim)}", fontsize=10)
        return moving

    return FuncAnimation(fig, draw, frames=list(frames), blit=False, interval=interval)
