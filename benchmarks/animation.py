"""Writing a 72-frame GIF of the crank-rocker: Matplotlib's writer (every frame redrawn
whole, Pillow's adaptive palette per frame) against mechsyn's (static background drawn
once, moving artists blitted, one palette). One process; the minimum of several runs.

    python benchmarks/animation.py [--runs 3]

The answers are checked equal: same number of frames, and blitted frames equal to full
redraws but for anti-aliased pixels (< 0.2 %).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from matplotlib.animation import PillowWriter  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

from mechsyn.export.movie import write_gif  # noqa: E402
from mechsyn.io import load_mechanism  # noqa: E402
from mechsyn.kinematics.analysis import simulate  # noqa: E402
from mechsyn.plot.frames import animation_frames  # noqa: E402
from mechsyn.plot.kinematics import animate_simulation  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    mech = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    sim = simulate(mech, {"A": np.arange(0.0, 360.0, 5.0)}, points=["M"])
    tmp = Path(tempfile.mkdtemp())
    old, new = [], []
    for _ in range(args.runs):
        t = time.perf_counter()
        anim = animate_simulation(sim, fig=Figure())
        anim.save(str(tmp / "old.gif"), writer=PillowWriter(fps=15), dpi=100)
        old.append(time.perf_counter() - t)
        t = time.perf_counter()
        write_gif(animation_frames(animate_simulation(sim, fig=Figure()), dpi=100), tmp / "new.gif", fps=15)
        new.append(time.perf_counter() - t)
    n_old, n_new = Image.open(tmp / "old.gif").n_frames, Image.open(tmp / "new.gif").n_frames
    assert n_old == n_new == 72, (n_old, n_new)
    full = animate_simulation(sim, fig=Figure())
    full.mechsyn_blit = None
    for a, b in zip(animation_frames(animate_simulation(sim, fig=Figure()), dpi=100), animation_frames(full, dpi=100)):
        assert np.any(a != b, axis=2).mean() < 0.002
    print(f"72-frame GIF, min of {args.runs} runs (shared machine: noisy, take the minimum)")
    print(f"  matplotlib writer (full redraw): {min(old):6.2f} s")
    print(f"  mechsyn (blitted, one palette):  {min(new):6.2f} s   speed-up x{min(old) / min(new):.1f}")


if __name__ == "__main__":
    main()
