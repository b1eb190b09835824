"""Figure for docs/rank.md: the shaky octahedron (examples/spatial/octahedron_shaky.yaml).

(a) The octahedral 3-3 platform with its legs locked, at Fichter's pose: the platform's
plane and the planes P1 B1 B2, P2 B2 B3, P3 B3 B1 meet at O (Blaschke-Liebmann); arrows:
the platform vertices' velocities in the framework's one flex (from the bars' rigidity
matrix, not from mechsyn). (b) The relative correction ``ρ(ε) = |θ(ε) - ε d| / ε`` that
Gauss-Newton applies to a tangent step ``ε d`` of the rank method's instantaneous motions:
along the bars' spins it shrinks with ``ε`` (a finite motion), along the flex it stays (the
step is undone: no finite motion follows), and so along a random instantaneous motion,
which has a share of the flex.

Run from the repository root: PYTHONPATH=src python docs/figures/shaky_octahedron.py
(writes docs/figures/shaky_octahedron.png).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # a script that writes a file, not a library function
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import yaml  # noqa: E402

from finite_mobility import rho_curves, system  # noqa: E402  (this folder: the script's own)
from mechsyn.io import load_mechanism  # noqa: E402
from mechsyn.structure import rank as R  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
FILE = ROOT / "examples/spatial/octahedron_shaky.yaml"
OUT = ROOT / "docs/figures/shaky_octahedron.png"


def octahedron():
    """Base and platform vertices, the bars (legs, then platform sides) and the flex."""
    joints = yaml.safe_load(FILE.read_text())["joints"]
    base = sorted({tuple(j["point"]) for j in joints if "frame" in j["links"]})
    top = sorted({tuple(j["point"]) for j in joints if "platform" in j["links"]})
    legs = {}
    for j in joints:
        bar = next(link for link in j["links"] if link.startswith("bar"))
        legs.setdefault(bar, []).append(tuple(j["point"]))
    bars = [tuple(v) for v in legs.values()] + [(top[i], top[(i + 1) % 3]) for i in range(3)]
    Rm = np.zeros((len(bars), 9))
    for k, (a, b) in enumerate(bars):
        d = np.subtract(a, b)
        for p, sign in ((a, 1), (b, -1)):
            if p in top:
                i = top.index(p)
                Rm[k, 3 * i:3 * i + 3] += sign * d
    flex = np.linalg.svd(Rm)[2][-1].reshape(3, 3)
    return np.array(base), np.array(top), bars, flex


def drawing(ax) -> None:
    base, top, bars, flex = octahedron()
    for tri, colour in ((base, "0.8"), (top, "#9ecae1")):
        ax.add_collection3d(plt.matplotlib.collections.PolyCollection([tri[:, :2]], facecolors=colour,
                                                                      alpha=0.5), zs=tri[0, 2], zdir="z")
    for a, b in bars:
        ax.plot(*np.array([a, b]).T, color="C0" if a[2] != b[2] else "C0", lw=1.6)
    ax.scatter(*base.T, color="k", s=18)
    ax.scatter(*top.T, color="C0", s=18)
    o = top.mean(axis=0)
    ax.scatter(*o, color="C3", s=30, marker="x")
    ax.text(*(o + [0.2, 0.2, 0.25]), "O", color="C3")
    for i, p in enumerate(top):
        ax.quiver(*p, *(2.5 * flex[i]), color="C1", lw=1.5, arrow_length_ratio=0.25)
        ax.text(*(p + [-0.5, 0, 0.3]), f"P{i + 1}", fontsize=8)
    for i, p in enumerate(base):
        ax.text(*(p + [0.2, 0, -0.45]), f"B{i + 1}", fontsize=8)
    ax.set_box_aspect((1, 1, 0.45))
    ax.view_init(elev=24, azim=-62)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zticks([0, 1, 2])
    ax.set_title("(a) legs locked, Fichter's pose: the four planes meet at O;\narrows: the one flex, at P1, P2, P3",
                 fontsize=10)


def corrections(ax) -> None:
    mech = load_mechanism(FILE)
    sysm = R._build_system(mech, False)
    proj, N = system("spatial/octahedron_shaky.yaml")
    names, twists = R._link_twists(mech, sysm, N)  # each link's twist per instantaneous motion
    _, _, vt = np.linalg.svd(twists[names.index("platform")])
    flex, spins = N @ vt[0], N @ vt[1:].T  # the platform moves in one motion only; the spins keep it
    rng = np.random.default_rng(1)
    rho_curves(ax, [(proj, spins @ rng.standard_normal(spins.shape[1]), "the bars spinning (idle): finite", "C0", "o"),
                    (proj, N @ rng.standard_normal(N.shape[1]), "a random instantaneous motion", "0.45", "s"),
                    (proj, flex, "the flex: no finite motion", "C1", "D")])
    ax.set_title("(b) instantaneous 7, finite 6: shaky", fontsize=10)
    ax.legend(fontsize=7.5, loc="center left", frameon=False)


def main() -> Path:
    fig = plt.figure(figsize=(11, 4.6))
    drawing(fig.add_subplot(1, 2, 1, projection="3d"))
    corrections(fig.add_subplot(1, 2, 2))
    fig.tight_layout()
    fig.savefig(OUT, dpi=110)
    return OUT


if __name__ == "__main__":
    print(main())
