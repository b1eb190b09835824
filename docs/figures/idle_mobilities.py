"""Figure for docs/rank.md: idle mobilities of link groups (issue 12 §1).

Left: the Gough-Stewart 6-SPS platform (examples/structural/gough_stewart_6sps.yaml);
each leg (cylinder and piston, one rigid group with its P drive at rest) spins about its
S-S line: family (a). Right: a cam with two geared rollers
(examples/structural/cam_two_rollers_geared.yaml); with the cam at rest the rollers turn
in opposite senses about their pins, every joint centre at rest: family (b) only.
The axes drawn are the ones `analyze_rank` reports.

Run from the repository root: PYTHONPATH=src python docs/figures/idle_mobilities.py
(writes docs/figures/idle_mobilities.png).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # a script that writes a file, not a library function
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle, FancyArrowPatch  # noqa: E402

from mechsyn.io import load_mechanism  # noqa: E402
from mechsyn.structure.rank import analyze_rank  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def stewart(ax) -> None:
    mech = load_mechanism(ROOT / "examples/structural/gough_stewart_6sps.yaml")
    r = analyze_rank(mech)
    pts = {j.id: np.asarray(j.point, float) for j in mech.joints}
    base = np.array([pts[f"Sb{k}"] for k in range(1, 7)])
    plat = np.array([pts[f"Sp{k}"] for k in range(1, 7)])
    for poly, c in ((base, "0.55"), (plat, "0.2")):
        loop = np.vstack([poly, poly[:1]])
        ax.plot(*loop.T, color=c, lw=1.5)
    for k, idle in enumerate(r.idle_mobilities, start=1):
        b, p = pts[f"Sb{k}"], pts[f"Sp{k}"]
        mid = 0.55 * b + 0.45 * p
        ax.plot(*np.array([b, mid]).T, color="tab:blue", lw=5, solid_capstyle="butt")  # cylinder
        ax.plot(*np.array([mid - 0.05 * (p - b), p]).T, color="tab:orange", lw=2.5)  # piston
        d = np.asarray(idle.axis["direction"])
        d = d if d @ (p - b) > 0 else -d
        line = np.array([b - 0.35 * d, p + 0.35 * d])
        ax.plot(*line.T, ls="--", color="tab:red", lw=1, zorder=5)
        # a small circle about the axis near the top: the spin
        e1 = np.cross(d, [0, 0, 1.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        t = np.linspace(0.3, 2 * np.pi - 0.3, 40)
        c0 = p + 0.2 * d
        ring = c0 + 0.16 * (np.outer(np.cos(t), e1) + np.outer(np.sin(t), e2))
        ax.plot(*ring.T, color="tab:red", lw=1)
    ax.scatter(*base.T, color="k", s=12)
    ax.scatter(*plat.T, color="k", s=12)
    ax.set_title(f"Gough-Stewart 6-SPS: m = {r.mobility} = {r.useful_mobility} useful + "
                 f"{len(r.idle_mobilities)} idle\n(each leg spins about its S-S line: family (a))", fontsize=9)
    ax.set_box_aspect((1, 1, 0.55), zoom=1.35)
    ax.set_axis_off()
    ax.view_init(elev=18, azim=-60)


def geared_rollers(ax) -> None:
    mech = load_mechanism(ROOT / "examples/structural/cam_two_rollers_geared.yaml")
    r = analyze_rank(mech)
    (idle,) = r.idle_mobilities
    ax.add_patch(Circle((0, 0), 1.2, fc="0.9", ec="0.3"))
    ax.plot([0], [0], "k+")
    for name, rad in (("roller1", 0.3), ("roller2", 0.3)):
        c = np.asarray(idle.axes[name]["point"][:2])
        ax.add_patch(Circle(c, rad, fc="tab:orange", ec="k", alpha=0.8))
        ax.plot(*c, "ko", ms=3)
        sense = 1 if name == "roller1" else -1
        a0, a1 = (0.3, 2.2) if sense > 0 else (2.2, 0.3)
        ax.add_patch(FancyArrowPatch(c + 0.42 * np.array([np.cos(a0), np.sin(a0)]),
                                     c + 0.42 * np.array([np.cos(a1), np.sin(a1)]),
                                     connectionstyle=f"arc3,rad={0.5 * sense}", arrowstyle="-|>",
                                     mutation_scale=10, color="tab:red"))
    ax.plot([0.6, 0, 0], [1.5, 1.5, 3.0], color="tab:blue", lw=3, zorder=1)  # follower: stem and roller arm
    for x in (-0.1, 0.1):
        ax.plot([x, x], [2.3, 2.9], color="0.4", lw=2)  # frame guide of the P pair
    ax.annotate("cam (at rest)", (0, -0.4), ha="center", fontsize=8)
    ax.annotate("follower (P in the frame)", (0.15, 2.6), fontsize=8, color="tab:blue")
    ax.set_title(f"Cam, two geared rollers: m = {r.mobility} = {r.useful_mobility} useful + "
                 f"{len(r.idle_mobilities)} idle\n(rollers turn oppositely, centres at rest: family (b))", fontsize=9)
    ax.set_aspect("equal")
    ax.set_xlim(-1.5, 1.6)
    ax.set_ylim(-1.4, 3.1)
    ax.set_axis_off()


def main() -> Path:
    fig = plt.figure(figsize=(10, 4.6))
    stewart(fig.add_subplot(1, 2, 1, projection="3d"))
    geared_rollers(fig.add_subplot(1, 2, 2))
    fig.tight_layout()
    out = Path(__file__).with_suffix(".png")
    fig.savefig(out, dpi=110)
    return out


if __name__ == "__main__":
    print(main())
