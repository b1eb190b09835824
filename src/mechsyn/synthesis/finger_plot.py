"""Drawings of the fingers of paper 000's synthesis: base links grey, attached group
orange, VLL candidates dashed red, frame pairs hatched."""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Polygon  # noqa: E402


def draw_mechanism(ax, data: dict, title: str = "", vll: tuple[str, ...] = (),
                   group: tuple[str, ...] = ()) -> None:
    """Sketch a planar mechanism file dict from its joint points."""
    joints = data["joints"]
    names = [x if isinstance(x, str) else x["name"] for x in data["links"]]
    pts = {j["id"]: np.asarray(j["point"], float) for j in joints}
    ground = data["ground"]
    allp = np.array(list(pts.values()))
    span = float(np.ptp(allp, axis=0).max()) or 1.0
    for name in names:
        ids = [j["id"] for j in joints if name in j["links"]]
        p = np.array([pts[i] for i in ids])
        if name == ground:
            for q in p:
                ax.plot([q[0] - 0.04 * span, q[0] + 0.04 * span], [q[1] - 0.04 * span] * 2,
                        color="black", lw=1.2)
                for k in range(4):
                    x0 = q[0] - 0.04 * span + k * 0.027 * span
                    ax.plot([x0, x0 - 0.02 * span], [q[1] - 0.04 * span, q[1] - 0.065 * span],
                            color="black", lw=0.7)
                ax.plot([q[0], q[0]], [q[1], q[1] - 0.04 * span], color="black", lw=1.0)
            continue
        colour = "#e6550d" if name in group else "#404040"
        style = "--" if name in vll else "-"
        if name in vll:
            colour = "#cb181d"
        c = p.mean(axis=0)
        if len(p) == 1:
            tip = [v["at"] for v in data.get("points", {}).values() if v["link"] == name]
            if tip:
                p = np.vstack([p, np.asarray(tip[0], float)])
        if len(p) <= 2:
            ax.plot(p[:, 0], p[:, 1], style, color=colour, lw=2.4, solid_capstyle="round")
        else:
            order = np.argsort(np.arctan2(p[:, 1] - c[1], p[:, 0] - c[0]))
            ax.add_patch(Polygon(p[order], closed=True, facecolor=colour, alpha=0.25,
                                 edgecolor=colour, lw=1.8, linestyle=style))
        c = p.mean(axis=0)
        ax.text(c[0] + 0.02 * span, c[1] + 0.02 * span, name, fontsize=6, color=colour)
    for j in joints:
        q = pts[j["id"]]
        ax.plot(q[0], q[1], "o", ms=5, mfc="#ffd92f" if j.get("actuated") else "white",
                mec="black", mew=0.8, zorder=5)
    ax.set_title(title, fontsize=7)
    ax.set_aspect("equal")
    ax.margins(0.12)
    ax.axis("off")


def fingers_figure(results, base_data: dict, title: str):
    n = len(results) + 1
    columns = min(4, n)
    rows = math.ceil(n / columns)
    height = rows * 3.4 + 0.9
    fig, axes = plt.subplots(rows, columns, figsize=(columns * 3.2, height), squeeze=False)
    draw_mechanism(axes.flat[0], base_data, "base mechanism")
    for ax, r in zip(list(axes.flat)[1:], results):
        attach = ", ".join(f"{t}: {'/'.join(g)}" for t, g in r.attachments.items())
        draw_mechanism(ax, r.mechanism,
                       f"#{r.number}  n_f={r.n_f}, P_f={r.P_f}\n{attach}\n"
                       f"VLL candidates: {', '.join(r.vll_candidates) or '-'}",
                       vll=r.vll_candidates, group=r.group_links)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    fig.suptitle(title + "\n(grey: base, orange: attached group, dashed red: VLL "
                 "candidates, yellow: actuated pair)", fontsize=9, y=1 - 0.08 / height, va="top")
    fig.subplots_adjust(left=0.02, right=0.98, bottom=0.1 / height, top=1 - 1.15 / height,
                        wspace=0.1, hspace=0.45)
    return fig
