"""Figures of dimensional synthesis: path generation by a four-bar, general mechanism
synthesis (targets against achieved points), Burmester motion generation."""

from __future__ import annotations

from typing import Any

import numpy as np

from mechsyn.plot._base import axes
from mechsyn.synthesis.exact import center_point_curve
from mechsyn.synthesis.fourbar import fourbar_position, rotate

__all__ = ["plot_fourbar_path", "plot_mechanism_synthesis", "plot_motion_synthesis"]


def plot_fourbar_path(design: dict[str, float], targets: np.ndarray, theta2: np.ndarray, branch: int,
                      title: str = "", ax: Any = None) -> Any:
    """Draw the targets, the achieved points, the coupler curve and the linkage at target 1.
    Returns the Axes."""
    ax = axes(ax, (7, 6))
    g = {k: design.get(k, 0.0) for k in ("x0", "y0", "theta0", "rcx", "rcy")}
    r = [design[k] for k in ("r1", "r2", "r3", "r4")]
    sweep = np.linspace(0, 2 * np.pi, 721)
    curve = fourbar_position(*r, sweep, branch=branch, **g)
    C = np.where(curve.assembled[:, None], curve.C, np.nan)
    ax.plot(C[:, 0], C[:, 1], "-", color="0.6", lw=1, label="coupler curve (branch)")
    at = fourbar_position(*r, np.asarray(theta2), branch=branch, **g)
    ax.plot(targets[:, 0], targets[:, 1], "o", mfc="none", mec="tab:red", ms=9, label="targets")
    ax.plot(at.C[:, 0], at.C[:, 1], "x", color="tab:blue", ms=7, label="achieved")
    p0 = fourbar_position(*r, float(theta2[0]), branch=branch, **g)
    ox, oy = rotate(np.float64(r[0]), np.float64(0.0), g["theta0"])
    O2 = np.array([g["x0"], g["y0"]])
    O4 = np.array([ox + g["x0"], oy + g["y0"]])
    chain = np.array([O2, p0.A, p0.B, O4])
    ax.plot(chain[:, 0], chain[:, 1], "-o", color="k", lw=2, ms=4, label="linkage at target 1")
    tri = np.array([p0.A, p0.C, p0.B])
    ax.fill(tri[:, 0], tri[:, 1], color="tab:orange", alpha=0.3)
    ax.plot([O2[0], O4[0]], [O2[1], O4[1]], "k--", lw=1)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (length)")
    ax.set_ylabel("y (length)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    return ax


def plot_mechanism_synthesis(case: Any, res: Any, ax: Any = None) -> Any:
    """Targets against the achieved points and the swept path, with the design drawn at
    its file configuration. Returns the Axes."""
    ax = axes(ax, (7, 6))
    if len(res.path):
        ax.plot(res.path[:, 0], res.path[:, 1], "-", color="0.6", lw=1, label="swept path")
    ax.plot(res.targets[:, 0], res.targets[:, 1], "o", mfc="none", mec="C3", ms=9, label="targets")
    ax.plot(res.achieved[:, 0], res.achieved[:, 1], "x", color="C0", ms=8, label="achieved")
    for t, a in zip(res.targets, res.achieved):
        ax.plot([t[0], a[0]], [t[1], a[1]], "-", color="C3", lw=0.8)
    pts = {j["id"]: j["point"] for j in res.mechanism["joints"] if j.get("point") is not None}
    by_link: dict[str, list] = {}
    for j in res.mechanism["joints"]:
        if j.get("point") is None:
            continue
        for lk in j["links"]:
            by_link.setdefault(lk, []).append(pts[j["id"]])
    for lk, ps in by_link.items():
        if lk == res.mechanism["ground"] or len(ps) < 2:
            continue
        P = np.array(ps + [ps[0]] if len(ps) > 2 else ps)
        ax.plot(P[:, 0], P[:, 1], "-", color="k", lw=1.4, alpha=0.7)
    J = np.array(list(pts.values()))
    ax.plot(J[:, 0], J[:, 1], "o", color="k", ms=4, label="design (file configuration)")
    ax.set_aspect("equal")
    unit = res.mechanism.get("units") or "length"
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    ax.set_title(f"{case.name} ({case.problem} generation): error {res.error:.4g}", fontsize=10)
    return ax


def plot_motion_synthesis(P: np.ndarray, sols: list, ax: Any = None) -> Any:
    """Burmester motion generation: the required poses (red arrows), the centre-point curve
    (4 poses) and the best linkage at pose 1. ``P`` is (n, 3) x, y, angle (rad); ``sols``
    from :func:`mechsyn.synthesis.exact.motion_synthesis`, best first. Returns the Axes."""

    ax = axes(ax, (7, 6))
    best = sols[0]
    # the view is scaled to the poses; the linkage widens it only up to four pose spans
    # (a linkage 30 times larger would shrink the poses to a dot): pivots beyond are marked
    plo, phi = P[:, :2].min(axis=0), P[:, :2].max(axis=0)
    span = max(float((phi - plo).max()), 1e-9)
    best_pts = np.array([best.O2, best.O4, *P[:, :2]])
    lo, hi = best_pts.min(axis=0), best_pts.max(axis=0)
    if (hi - lo).max() > 4 * span:
        centre = (plo + phi) / 2
        lo, hi = centre - 1.0 * span, centre + 1.0 * span
        off = [f"{name} ({q[0]:.4g}, {q[1]:.4g})" for name, q in (("O2", best.O2), ("O4", best.O4))
               if np.any(q < lo) or np.any(q > hi)]
        if off:
            ax.text(0.02, 0.02, "ground pivots off view: " + ", ".join(off), transform=ax.transAxes,
                    fontsize=8, color="0.25", bbox={"fc": "white", "ec": "0.7", "alpha": 0.9})
    pad = 0.3 * (hi - lo).max() + 1e-9
    if len(P) == 4:
        M, _ = center_point_curve(P, n_dir=1440)
        inside = np.all((M > lo - pad) & (M < hi + pad), axis=1)
        ax.plot(M[inside, 0], M[inside, 1], ".", ms=1.5, color="0.6", label="centre-point curve")
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    L = 0.15 * (np.ptp(P[:, :2], axis=0).max() + 1)
    for j, (x, y, a) in enumerate(P):
        ax.annotate("", (x + L * np.cos(a), y + L * np.sin(a)), (x, y),
                    arrowprops={"arrowstyle": "->", "color": "tab:red", "lw": 2})
        # the number behind the arrow's tail, clear of the arrow
        ax.text(x - 0.3 * L * np.cos(a), y - 0.3 * L * np.sin(a), str(j + 1), color="tab:red",
                ha="center", va="center", fontsize=10, fontweight="bold")
    for s in sols[:1]:
        pose = fourbar_position(s.r1, s.r2, s.r3, s.r4, s.theta2[0], branch=s.branch,
                                x0=s.O2[0], y0=s.O2[1], theta0=s.theta0)
        ch = np.array([s.O2, pose.A, pose.B, s.O4])
        ax.plot(ch[:, 0], ch[:, 1], "-o", color="k", label="best linkage at pose 1")
        tri = np.array([pose.A, pose.B, P[0, :2]])
        ax.fill(tri[:, 0], tri[:, 1], color="tab:orange", alpha=0.3, label="coupler (guided body)")
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (length)")
    ax.set_ylabel("y (length)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"Burmester synthesis, {len(P)} poses (red: required poses)")
    return ax
