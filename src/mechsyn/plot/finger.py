"""Drawings of the fingers of paper 000's synthesis: base links grey, attached group
orange, VLL candidates dashed red, frame pairs hatched.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from matplotlib.patches import Polygon

from mechsyn.plot._base import axes, figure
from mechsyn.synthesis.finger.evaluation import apply_design, evaluate_drawn
from mechsyn.synthesis.finger.modes import redraw

__all__ = ["plot_finger_design", "plot_fingers", "sketch_mechanism"]


def sketch_mechanism(data: dict, ax: Any = None, title: str = "", vll: tuple[str, ...] = (),
                     group: tuple[str, ...] = ()) -> Any:
    """Sketch a planar mechanism file dict from its joint points. Returns the Axes."""
    ax = axes(ax, (3.2, 3.4))
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
    unit = data.get("units") or "length"
    ax.set_title(title, fontsize=7)
    ax.set_aspect("equal")
    ax.margins(0.12)
    ax.set_xlabel(f"x ({unit})", fontsize=6, labelpad=1)
    ax.set_ylabel(f"y ({unit})", fontsize=6, labelpad=1)
    ax.tick_params(labelsize=5, length=2, pad=1)
    for spine in ax.spines.values():
        spine.set_color("0.75")
    return ax


def plot_fingers(results: Any, base_data: dict, title: str = "", fig: Any = None) -> Any:
    """The base mechanism and each synthesised finger (paper 000), in a grid. Returns the
    Figure."""
    n = len(results) + 1
    columns = min(4, n)
    rows = math.ceil(n / columns)
    height = rows * 3.4 + 0.9
    fig = figure(fig, (columns * 3.2, height))
    grid = fig.subplots(rows, columns, squeeze=False)
    sketch_mechanism(base_data, grid.flat[0], "base mechanism")
    for ax, r in zip(list(grid.flat)[1:], results):
        attach = ", ".join(f"{t}: {'/'.join(g)}" for t, g in r.attachments.items())
        sketch_mechanism(r.mechanism, ax,
                       f"#{r.number}  n_f={r.n_f}, P_f={r.P_f}\n{attach}\n"
                       f"VLL candidates: {', '.join(r.vll_candidates) or '-'}",
                       vll=r.vll_candidates, group=r.group_links)
    for ax in list(grid.flat)[n:]:
        ax.axis("off")
    fig.suptitle(title + "\n(grey: base, orange: attached group, dashed red: VLL "
                 "candidates, yellow: actuated pair)", fontsize=9, y=1 - 0.08 / height, va="top")
    fig.subplots_adjust(left=0.05, right=0.99, bottom=0.45 / height, top=1 - 1.15 / height,
                        wspace=0.3, hspace=0.55)
    return fig


def _draw_finger(ax: Any, S: Any, q: np.ndarray, color: Any, lw: float = 1.6, ls: str = "-",
                 alpha: float = 0.85) -> None:
    """Every moving link as the polygon of its joint and named points, at pose ``q`` (1, n)."""
    for i, name in enumerate(S.links):
        pts = [S.point(q, i, S.to_local(name, j.point))[0] for j in S.mech.joints if name in j.links]
        pts += [S.point(q, i, S.to_local(name, p.at))[0] for p in S.mech.points.values() if p.link == name]
        if len(pts) >= 2:
            P = np.array(pts + pts[:1]) if len(pts) > 2 else np.array(pts)
            ax.plot(P[:, 0], P[:, 1], ls, marker="o", color=color, lw=lw, ms=2.5, alpha=alpha)


def _legend_below(ax: Any) -> Any:
    """The legend under the axes (outside the drawn mechanism, which fills the panel)."""
    return ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
                     framealpha=0.9)


def plot_finger_design(case: Any, result: Any, fig: Any = None) -> Any:
    """Three panels: the fully actuated mode (finger at the targets, output paths,
    region); the underactuated mode (finger at the ends of the VLL range, at the extreme
    crank angles); a zoom on the output paths for VLL lengths across the range. Returns the
    Figure."""
    from matplotlib import cm

    v = result.best_variant
    combo = v.combination
    d = apply_design(case, np.array(list(v.design.values())), combo)
    ev = evaluate_drawn(case, d)
    fig = figure(fig, (17, 7.2))
    axes = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1, 1.3]})
    S = ev.system
    unit = S.mech.attrs.get("units") or "length"
    idx = np.searchsorted(ev.inputs, case.target_inputs)
    reg = np.vstack([case.region, case.region[:1]])
    for ax in axes:
        ax.fill(reg[:, 0], reg[:, 1], color="#d9f0d3", alpha=0.6, zorder=0, label="working region")
        ax.plot(reg[:, 0], reg[:, 1], color="#1b7837", lw=1.2, zorder=1)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.set_xlabel(f"x ({unit})")
        ax.set_ylabel(f"y ({unit})")
    gp = np.array([j.point for j in S.mech.joints if S.mech.ground in j.links])
    # 1: fully actuated
    ax = axes[0]
    cols = cm.viridis(np.linspace(0, 0.9, len(idx)))
    for c, k in zip(cols, idx):
        _draw_finger(ax, S, ev.q[k:k + 1], c)
        ax.plot([], [], color=c, lw=2, label=f"crank +{ev.inputs[k]:g}° (target)")
    for name, P in ev.paths.items():
        ax.plot(P[:, 0], P[:, 1], "k--", lw=1.2, label=f"{name} path")
    ax.plot(gp[:, 0], gp[:, 1], "ks", ms=7, label="palm pivots")
    ax.set_title(f"1. Fully actuated: VLL {'+'.join(combo)} locked at its minimum\n"
                 f"target error RMS {v.error_rms:.3g}°, max {v.error_max:.3g}°", fontsize=11)
    _legend_below(ax)
    # 2: underactuated, the finger at the ends of the VLL range
    ax = axes[1]
    rng = ", ".join(f"{j} in [{a:.4g}, {b:.4g}]" for j, (a, b) in v.vll_ranges.items())
    ends = [(f"{'+'.join(combo)} = min", d, "0.45")]
    dmax = redraw(case, d, {j: v.vll_ranges[j][1] for j in combo})
    if dmax is not None:
        ends.append((f"{'+'.join(combo)} = max", dmax, "#d95f02"))
    for label, dd, c in ends:
        e2 = evaluate_drawn(case, dd)
        if e2.q is None:
            continue
        for k, ls in ((0, "-"), (len(e2.inputs) - 1, "--")):
            _draw_finger(ax, e2.system, e2.q[k:k + 1], c, ls=ls)
        for P in e2.paths.values():
            ax.plot(P[:, 0], P[:, 1], color=c, lw=2.2)
        ax.plot([], [], color=c, lw=2, label=f"VLL {label}")
    ax.plot([], [], "k-", lw=1, label=f"crank +{ev.inputs[0]:g}° (open)")
    ax.plot([], [], "k--", lw=1, label=f"crank +{ev.inputs[-1]:g}° (closed)")
    ax.plot(gp[:, 0], gp[:, 1], "ks", ms=7)
    ax.set_title(f"2. Underactuated: VLL free, {rng}\npeak reaction {v.forces['peak_reaction']:.3g}, "
                 f"peak input moment {v.forces['peak_input_moment']:.3g} (both modes)", fontsize=11)
    _legend_below(ax)
    xs = axes[0].get_xlim() + axes[1].get_xlim()
    ys = axes[0].get_ylim() + axes[1].get_ylim()
    for ax in axes[:2]:
        ax.set_xlim(min(xs), max(xs))
        ax.set_ylim(min(ys), max(ys))
    # 3: zoom on the output paths across the VLL range
    ax = axes[2]
    for jid, u in v.underactuated.items():
        lens = u["lengths"]
        lc = cm.plasma(np.linspace(0, 0.85, len(lens)))
        for name, P in u["paths"].items():
            for r in range(len(lens)):
                ax.plot(P[r, :, 0], P[r, :, 1], color=lc[r], lw=1.8,
                        label=f"{name}, {jid} = {lens[r]:.4g}" if name == case.points[0] else None)
            for k in idx:  # adaptive motion with the motor still: the VLL sweeps its range
                ax.plot(P[:, k, 0], P[:, k, 1], color="0.3", lw=1.0, ls=":")
        ax.plot([], [], color="0.3", ls=":", label="motor still at a target, VLL moving")
    for name, P in ev.paths.items():
        ax.plot(P[:, 0], P[:, 1], "k--", lw=1.0, label=f"{name}, VLL locked (panel 1)")
    ax.legend(fontsize=8, loc="lower left", framealpha=0.9)
    box = np.vstack([case.region] + [u["paths"][n].reshape(-1, 2) for u in v.underactuated.values()
                                     for n in u["paths"]])
    box = box[np.all(np.isfinite(box), axis=1)]
    blo, bhi = box.min(axis=0), box.max(axis=0)
    pad = 0.06 * (bhi - blo).max()
    ax.set_xlim(blo[0] - pad, bhi[0] + pad)
    ax.set_ylim(blo[1] - 0.5 * (bhi[1] - blo[1]) - pad, bhi[1] + pad)  # room for the legend
    ax.set_title("3. Output paths over the VLL range (zoom on the region)", fontsize=11)
    fig.suptitle(f"Paper 000, steps 8-13: {S.mech.name}", fontsize=12)
    fig.tight_layout()
    return fig
