"""Figure for docs/kinematics.md, "Spatial kinematics": run from the repository root::

    python docs/figures/spatial_kinematics.py      # writes docs/figures/spatial_kinematics.png

Three spatial sweeps drawn by :func:`mechsyn.plot.spatial.plot_spatial` on 3-D axes: the
Bennett linkage over a full turn of R1 (the paths of its moving joints), the spherical
four-bar (every axis through the sphere's centre; the path of its coupler point P) and the
Delta robot with one arm swept over -30..30 degrees, the other two held (the platform
moves parallel to itself while the six bars' idle spins stay at rest).
"""

from pathlib import Path
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "src"))

import mechsyn as ms  # noqa: E402
from mechsyn.plot.spatial import plot_spatial  # noqa: E402

CASES = [("bennett", "R1", (0, 360, 2), ["R2", "R3"], 20),
         ("spherical_fourbar", "A", (0, 360, 2), ["B", "C", "P"], 30),
         ("delta", "R1", (-30, 30, 1), ["S1a2", "S1a1", "S2a1"], 45)]


def main() -> None:
    fig = plt.figure(figsize=(13, 4.8))
    for i, (name, joint, rng, points, k) in enumerate(CASES):
        s = ms.simulate(ms.examples.load(name), {joint: ms.input_grid(*rng)}, points=points)
        ax = fig.add_subplot(1, 3, i + 1, projection="3d")
        plot_spatial(s, ax=ax, k=k)
        ax.view_init(elev=22, azim=-60 + 25 * i)
    fig.tight_layout()
    fig.savefig(ROOT / "docs/figures/spatial_kinematics.png", dpi=90)


if __name__ == "__main__":
    main()
