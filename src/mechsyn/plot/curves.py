"""Figures of curve synthesis results (Matplotlib imported lazily, no backend chosen,
no file written)."""

from __future__ import annotations

from typing import Any

import numpy as np

from mechsyn.plot._base import axes

__all__ = ["plot_curve_result", "plot_candidate"]


def _axes(ax):
    return axes(ax, (6, 5))


def plot_candidate(candidate, target, ax=None, linkage: bool = True, color: str = "tab:blue",
                   label: str | None = None) -> dict[str, Any]:
    """Draw the target, a candidate's traced path and (``linkage``) the linkage in its
    reference configuration. Returns the artists drawn."""
    ax = _axes(ax)
    T = target.points
    Tc = np.vstack([T, T[:1]]) if target.closed else T
    drawn: dict[str, Any] = {}
    drawn["target"] = ax.plot(Tc[:, 0], Tc[:, 1], "-", color="0.2", lw=2.5, alpha=0.35, label="target")[0]
    P = candidate.path
    closed = candidate.stop - candidate.start >= 360.0 - 1e-9
    Pc = np.vstack([P, P[:1]]) if closed else P
    t = candidate.topology
    name = t.name or f"{t.n_links}-bar"
    drawn["path"] = ax.plot(Pc[:, 0], Pc[:, 1], "-", color=color, lw=1.4,
                            label=label or f"{name}: chamfer {100 * candidate.chamfer:.2f} %")[0]
    if linkage:
        mech = candidate.mechanism()
        pts = {j["id"]: np.array(j["point"]) for j in mech["joints"]}
        pts["T"] = np.array(mech["points"]["T"]["at"])
        lines = []
        by_link: dict[str, list[str]] = {}
        for j in mech["joints"]:
            for ln in j["links"]:
                by_link.setdefault(ln, []).append(j["id"])
        by_link.setdefault(mech["points"]["T"]["link"], []).append("T")
        for ln, ids in by_link.items():
            if ln == mech["ground"]:
                continue
            xy = np.array([pts[i] for i in ids])
            if len(xy) > 2:
                xy = np.vstack([xy, xy[:1]])
            lines.append(ax.plot(xy[:, 0], xy[:, 1], "-", color="0.45", lw=1.0)[0])
        G = np.array([pts[j["id"]] for j in mech["joints"] if mech["ground"] in j["links"]])
        drawn["ground"] = ax.plot(G[:, 0], G[:, 1], "^", color="k", ms=8, label="frame pivots")[0]
        drawn["links"] = lines
        drawn["tracer"] = ax.plot(*pts["T"], "o", color=color, ms=5)[0]
    # frame on the target and the path (a long link or a far pivot is drawn cut off)
    pts = np.vstack([T, P])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    if linkage:
        near = np.array([p for p in pts_all(candidate) if np.all(np.abs(p - (lo + hi) / 2) <= 1.5 * (hi - lo).max())])
        if len(near):
            lo, hi = np.minimum(lo, near.min(axis=0)), np.maximum(hi, near.max(axis=0))
    pad = 0.08 * (hi - lo).max()
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (target's length unit)")
    ax.set_ylabel("y (target's length unit)")
    ax.grid(True, alpha=0.3)
    return drawn


def pts_all(candidate) -> np.ndarray:
    """Joint and tracer points of a candidate's drawn configuration."""
    return np.asarray(candidate.params, float).reshape(-1, 2)


def plot_curve_result(result, ax=None, top: int = 3) -> dict[str, Any]:
    """The target and the best ``top`` candidates' paths (the best with its linkage)."""
    ax = _axes(ax)
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple"]
    drawn: dict[str, Any] = {"candidates": []}
    if not result.candidates:
        T = result.target.points
        drawn["target"] = ax.plot(T[:, 0], T[:, 1], "-", color="0.2", lw=2.5, alpha=0.35, label="target")[0]
    for i, c in enumerate(result.candidates[:top]):
        d = plot_candidate(c, result.target, ax=ax, linkage=(i == 0), color=colors[i % len(colors)],
                           label=f"{i + 1}. {c.topology.name or str(c.topology.n_links) + '-bar'}: "
                                 f"chamfer {100 * c.chamfer:.2f} %")
        if i > 0:
            d["target"].remove()
        drawn["candidates"].append(d)
    ax.legend(fontsize=8, loc="best")
    ax.set_title("curve synthesis: target and traced paths")
    return drawn
