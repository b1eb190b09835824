"""Figures of paper 001's belt manipulator.

``plot_belt_report`` draws a :class:`mechsyn.belt.BeltReport`'s mechanism and paths on
one Axes (``report.plot()``); ``plot_belt`` draws the mechanism in its design and extreme positions with the
paths of C and H (as the paper's fig. 4), the equivalent four-bar's coupler paths for
comparison, and the speed and acceleration curves of C and H; ``animate_belt`` returns
an animation of the motion. Nothing here writes a file or chooses a backend.

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.plot._base import axes, figure
from mechsyn.belt.design import BeltDesign
from mechsyn.belt.four_bar import FourBarState, equivalent_four_bar
from mechsyn.belt.kinematics import BeltState, MotionResult, analyze

__all__ = ["animate_belt", "draw_belt", "plot_belt", "plot_belt_report"]


def _dense(design: BeltDesign, state: BeltState, n: int = 1500) -> BeltState:
    """The same range as ``state`` on a fine grid, for smooth path curves."""
    return analyze(design, np.linspace(state.dphi.min(), state.dphi.max(), n))

_COLOURS = {"lever": "#1f4e79", "hand": "#b03a2e", "belt": "#2e7d32", "pulley": "#555555",
            "C": "#e67e22", "H": "#8e44ad", "fb": "#7f8c8d"}


def _ground(ax: Any, p: np.ndarray, size: float) -> None:
    """Frame symbol: a small triangle with hatching under point p."""
    x, y = p
    ax.fill([x, x - size, x + size], [y, y - 1.4 * size, y - 1.4 * size], color="white",
            ec="k", lw=0.8, zorder=4)
    ax.plot([x - 1.6 * size, x + 1.6 * size], [y - 1.4 * size] * 2, "k", lw=0.8, zorder=4)
    for k in np.linspace(-1.5, 1.2, 6):
        ax.plot([x + k * size, x + (k + 0.4) * size], [y - 1.4 * size, y - 1.9 * size],
                "k", lw=0.5, zorder=4)


def draw_belt(ax: Any, design: BeltDesign, state: BeltState, i: int, alpha: float = 1.0,
                   labels: bool = False) -> list[Any]:
    """Draw the mechanism at position ``i`` of ``state``; returns the artists."""
    from matplotlib.patches import Circle

    A0 = np.zeros(2)
    B0 = design.B0
    A, B, C, H = state.A[i], state.B[i], state.C[i], state.H[i]
    art: list[Any] = []
    if not state.valid[i]:
        return art
    lw = 2.2
    art += ax.plot([A0[0], A[0]], [A0[1], A[1]], color=_COLOURS["lever"], lw=lw + 1,
                   alpha=alpha, solid_capstyle="round", zorder=3)
    art += ax.plot([A[0], C[0], H[0]], [A[1], C[1], H[1]], color=_COLOURS["hand"], lw=lw,
                   alpha=alpha, solid_capstyle="round", zorder=3)
    circ = Circle(tuple(A), design.r, fill=False, ec=_COLOURS["pulley"], lw=1.2, alpha=alpha,
                  zorder=3)
    ax.add_patch(circ)
    art.append(circ)
    art += ax.plot([B0[0], B[0]], [B0[1], B[1]], color=_COLOURS["belt"], lw=1.6, alpha=alpha,
                   zorder=3)
    pts = np.array([A0, A, B0, C, H])
    art += ax.plot(pts[:, 0], pts[:, 1], "o", ms=4, mfc="white", mec="k", alpha=alpha,
                   zorder=5)
    if labels:
        off = 0.03 * design.a
        for name, p in (("A0", A0), ("A", A), ("B0", B0), ("B", B), ("C", C), ("H", H)):
            art.append(ax.annotate(name, p, xytext=(p[0] + off, p[1] + off), fontsize=9,
                                   zorder=6))
    return art


def _draw_paths(ax: Any, design: BeltDesign, state: BeltState, four_bar: bool, title: str) -> None:
    """Design and extreme positions, the paths of C and H (and the four-bar's) on ``ax``."""
    valid = np.nonzero(state.valid)[0]
    i0 = int(np.argmin(np.abs(state.dphi)))
    for i in ([int(valid[0]), int(valid[-1])] if valid.size else []):
        draw_belt(ax, design, state, i, alpha=0.45)
    draw_belt(ax, design, state, i0, labels=True)
    _ground(ax, np.zeros(2), 0.035 * design.a)
    _ground(ax, design.B0, 0.035 * design.a)
    fine = _dense(design, state)
    ax.plot(fine.C[:, 0], fine.C[:, 1], color=_COLOURS["C"], lw=1.8, label="path of C (h = 0)")
    ax.plot(fine.H[:, 0], fine.H[:, 1], color=_COLOURS["H"], lw=1.8,
            label=f"path of H (h = {design.h:g})")
    fb = equivalent_four_bar(design, fine.dphi) if four_bar else None
    if fb is not None and np.any(fb.valid):
        ax.plot(fb.C[:, 0], fb.C[:, 1], "--", color=_COLOURS["fb"], lw=1.1,
                label="equivalent four-bar A0-A-B-B0: C")
        ax.plot(fb.H[:, 0], fb.H[:, 1], ":", color=_COLOURS["fb"], lw=1.3,
                label="equivalent four-bar: H")
    for P, name in ((state.C, "C"), (state.H, "H")):
        ax.axhline(P[i0, 1], color=_COLOURS[name], lw=0.6, ls=(0, (6, 4)), alpha=0.6)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("x, machine plane (unit)")
    ax.set_ylabel("y, machine axis (unit)")
    rng = f"Δφ = {math.degrees(state.dphi[0]):g}° … {math.degrees(state.dphi[-1]):g}°"
    ax.set_title(f"{title}\na = {design.a:g}, c = {design.c:g}, h = {design.h:g}, "
                 f"r = {design.r:g};  b0 = {design.b0:.3f}, l0 = {design.l0:.3f}, "
                 f"α0 = {math.degrees(design.alpha0):.3f}°\n"
                 f"design (solid) and extreme positions (faded), {rng}", fontsize=10)
    ax.legend(loc="center", bbox_to_anchor=(0.38, 0.45), fontsize=8, framealpha=0.9)


def _draw_motion(axv: Any, axa: Any, motion: MotionResult) -> None:
    """Speeds (with the input speed φ̇ on a second axis) and accelerations over Δφ."""
    x = np.degrees(motion.dphi)
    for name, pm in (("C", motion.C), ("H", motion.H)):
        axv.plot(x, pm.speed, color=_COLOURS[name], label=f"speed of {name}")
        axa.plot(x, pm.accel, color=_COLOURS[name], label=f"|a| of {name}")
        axa.plot(x, pm.accel_tangential, color=_COLOURS[name], ls="--", lw=1,
                 label=f"tangential a of {name}")
        if np.any(motion.phidd != 0):
            axa.plot(x, pm.accel_paper, color=_COLOURS[name], ls=":", lw=1,
                     label=f"paper's (19) for {name}")
    axv2 = axv.twinx()
    axv2.plot(x, np.degrees(motion.phid), color="k", lw=0.8, alpha=0.6)
    axv2.set_ylabel("input φ̇ (°/s)", fontsize=9)
    axv.set_ylabel("speed (unit/s)")
    axa.set_ylabel("acceleration (unit/s²)")
    axv.legend(fontsize=8, loc="upper left")
    axa.legend(fontsize=8, loc="upper left", ncol=2)
    axv.set_title("speeds and accelerations for the input law φ(t) (black: φ̇)", fontsize=10)


def plot_belt(design: BeltDesign, state: BeltState, four_bar: FourBarState | None = None,
              motion: MotionResult | None = None, title: str = "", fig: Any = None) -> Any:
    """Figure like paper 001's fig. 4 (left) with speed/acceleration curves (right).
    Returns the Figure."""
    fig = figure(fig, (15, 8))
    fig.set_layout_engine("constrained")
    gs = fig.add_gridspec(2, 2, width_ratios=[1.35, 1])
    _draw_paths(fig.add_subplot(gs[:, 0]), design, state, four_bar is not None, title)
    axv = fig.add_subplot(gs[0, 1])
    axa = fig.add_subplot(gs[1, 1], sharex=axv)
    if motion is not None:
        _draw_motion(axv, axa, motion)
    axa.set_xlabel("Δφ (°)")
    for a_ in (axv, axa):
        a_.grid(alpha=0.3)
    return fig


def plot_belt_report(report: Any, ax: Any = None, four_bar: bool = True) -> Any:
    """The mechanism of a :class:`mechsyn.belt.BeltReport` in its design and extreme
    positions with the paths of C and H (and, with ``four_bar``, the equivalent four-bar's)
    on ``ax`` (a new Figure's Axes when None). Returns the Axes.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.belt import analyze_case, phi_range
    >>> rep = analyze_case(ms.BeltDesign(a=500, c=350, h=100, r=75), phi_range(-73, 85, 1))
    >>> ax = rep.plot()
    >>> len(ax.lines) > 4
    True
    """
    ax = axes(ax, (9, 8))
    _draw_paths(ax, report.design, report.state, four_bar, report.name)
    return ax


def animate_belt(design: BeltDesign, state: BeltState, max_frames: int = 160, title: str = "",
                 fig: Any = None, interval: float = 50) -> Any:
    """The motion over ``state`` as a :class:`matplotlib.animation.FuncAnimation`."""
    from matplotlib.animation import FuncAnimation

    idx = np.nonzero(state.valid)[0]
    if idx.size == 0:
        raise MechsynInputError("nothing to animate: the belt is slack over the whole range")
    if idx.size > max_frames:
        idx = idx[np.linspace(0, idx.size - 1, max_frames).round().astype(int)]
    fig = figure(fig, (8, 6))
    fig.set_layout_engine("constrained")
    ax = fig.add_subplot()
    pts = np.concatenate([state.C[idx], state.H[idx], state.A[idx], [design.B0, [0, 0]]])
    pad = 0.12 * design.a
    ax.set_xlim(pts[:, 0].min() - pad, pts[:, 0].max() + pad)
    ax.set_ylim(pts[:, 1].min() - pad - 0.1 * design.a, pts[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    fine = _dense(design, state)
    ax.plot(fine.C[:, 0], fine.C[:, 1], color=_COLOURS["C"], lw=1, alpha=0.7)
    ax.plot(fine.H[:, 0], fine.H[:, 1], color=_COLOURS["H"], lw=1, alpha=0.7)
    _ground(ax, np.zeros(2), 0.035 * design.a)
    _ground(ax, design.B0, 0.035 * design.a)
    ax.set_title(title or "belt manipulator (paper 001)", fontsize=10)
    text = ax.text(0.02, 0.96, "", transform=ax.transAxes, fontsize=9, va="top")
    current: list[Any] = []

    def frame(k: int) -> list[Any]:
        for artist in current:
            artist.remove()
        current.clear()
        i = int(idx[k])
        current.extend(draw_belt(ax, design, state, i))
        text.set_text(f"Δφ = {math.degrees(state.dphi[i]):7.2f}°   "
                      f"θ = {math.degrees(state.theta[i]):7.2f}°")
        return [*current, text]

    return FuncAnimation(fig, frame, frames=len(idx), blit=False, interval=interval)
