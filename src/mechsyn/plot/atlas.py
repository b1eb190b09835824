"""Drawing of an atlas of kinematic chains: for each chain its graph (links as numbered
nodes, joints as edges) and its kinematic sketch (binary links as bars, ternary links as
triangles, quaternary as quadrilaterals..., revolute joints as circles)."""

from __future__ import annotations

import math
from collections.abc import Sequence

from typing import Any

import numpy as np
from matplotlib.patches import Circle, Polygon

from mechsyn.plot._base import axes, figure
from mechsyn.synthesis.chains import KinematicChain
from mechsyn.synthesis.mechanisms import chain_layout

__all__ = ["draw_chain", "plot_atlas"]

DEGREE_COLOURS = {2: "#ffffff", 3: "#9ecae1", 4: "#fdae6b", 5: "#a1d99b", 6: "#dadaeb"}


def _colour(d: int) -> str:
    return DEGREE_COLOURS.get(d, "#d9d9d9")


def draw_chain(chain: KinematicChain, ax: Any = None, number: int | None = None,
               frame: int | None = None) -> Any:
    """Draw one chain: graph on the left, kinematic sketch on the right. Returns the Axes."""
    ax = axes(ax, (3.6, 1.95))
    link_xy, joints = chain_layout(chain, scale=1.0)
    deg = chain.degrees()
    small = chain.n_links <= 8
    node_size = 0.16 if small else 0.13
    font = 7 if small else 6
    # graph (left, centred at x = 0)
    for a, b in chain.edges:
        ax.plot(*zip(link_xy[a], link_xy[b]), color="#555555", lw=0.8, zorder=1)
    for v, (x, y) in enumerate(link_xy):
        ax.add_patch(Circle((x, y), node_size, facecolor=_colour(deg[v]),
                                edgecolor="black", lw=0.7, zorder=2))
        ax.text(x, y, str(v), ha="center", va="center", fontsize=font, zorder=3)
    # kinematic sketch (right, shifted)
    shift = np.array([2.7, 0.0])
    pts = joints + shift
    for v in range(chain.n_links):
        ks = [k for k, e in enumerate(chain.edges) if v in e]
        p = pts[ks]
        if len(ks) == 2:
            ax.plot(p[:, 0], p[:, 1], color="#333333", lw=2.2, solid_capstyle="round",
                    zorder=1)
        else:
            c = p.mean(axis=0)
            order = np.argsort(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]))
            ax.add_patch(Polygon(p[order], closed=True, facecolor=_colour(deg[v]),
                                 edgecolor="#333333", lw=1.2, alpha=0.9, zorder=1))
        c = p.mean(axis=0)
        ax.text(c[0], c[1] + (0.09 if len(ks) == 2 else 0.0), str(v), ha="center",
                va="center", fontsize=font - 1, color="#08306b", zorder=4)
        if frame is not None and v == frame:
            for q in p:
                ax.plot([q[0] - 0.1, q[0] + 0.1], [q[1] - 0.12, q[1] - 0.12],
                        color="black", lw=1.0)
    ax.scatter(pts[:, 0], pts[:, 1], s=14, facecolor="white", edgecolor="black",
               linewidths=0.8, zorder=5)
    flags = []
    if not chain.planar_graph:
        flags.append("non-planar")
    if chain.fractionated:
        flags.append("fractionated")
    if chain.degenerate:
        flags.append("DEGENERATE")
    title = f"#{number}  " if number is not None else ""
    title += chain.assortment_label() + (f"  ({', '.join(flags)})" if flags else "")
    ax.set_title(title, fontsize=8, pad=2)
    ax.set_xlim(-1.25, 3.95)
    ax.set_ylim(-1.25, 1.25)
    ax.set_aspect("equal")
    ax.axis("off")
    return ax


def plot_atlas(chains: Sequence[KinematicChain], title: str = "", columns: int | None = None,
               fig: Any = None) -> Any:
    """Every chain, numbered from 1, in a grid. Returns the Figure."""
    n = len(chains)
    columns = columns or (2 if n <= 4 else 4)
    rows = max(1, math.ceil(n / columns))
    height = rows * 1.95 + 0.5 + (0.16 if columns <= 2 else 0.0)
    fig = figure(fig, (columns * 3.6, height))
    grid = fig.subplots(rows, columns, squeeze=False)
    for i, ax in enumerate(grid.flat):
        if i < n:
            draw_chain(chains[i], ax, number=i + 1)
        else:
            ax.axis("off")
    key = ("(left: graph, node = link, edge = joint; right: kinematic sketch; "
           "B/T/Q/P = binary/ternary/quaternary/pentagonal links)")
    if columns <= 2:  # a narrow figure: the key on two lines, so that it is not cut
        key = key.replace("; right", ";\nright")
    fig.suptitle(f"{title}\n{key}", fontsize=9, y=1 - 0.08 / height, va="top")
    top = (0.5 + 0.16 * key.count("\n")) / height
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.1 / height, top=1 - top, wspace=0.05, hspace=0.25)
    return fig
