"""Figure for docs/python.md: run from the repository root::

    python docs/figures/python_crank_rocker.py      # writes docs/figures/python_crank_rocker.png

What ``s.plot()`` draws for the crank-rocker of the bundled examples swept over a turn of
its crank: the mechanism at its first assembled input and the path of its coupler point M.
"""

from pathlib import Path
import sys

from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "src"))

import mechsyn as ms  # noqa: E402

s = ms.load("crank_rocker").simulate(A=(0, 360, 1))
fig = Figure(figsize=(6.4, 5.2))
s.plot(ax=fig.add_subplot())
fig.tight_layout()
fig.savefig(Path(__file__).with_suffix(".png"), dpi=90)
