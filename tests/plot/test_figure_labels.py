"""Every mechanism panel of the synthesis and belt figures has its axes labelled with units."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[2]
_UNIT = re.compile(r"\((?:length|unit|mm|[^)]*unit[^)]*)\)")


def _labelled(ax) -> bool:
    return bool(_UNIT.search(ax.get_xlabel())) and bool(_UNIT.search(ax.get_ylabel()))


def test_burmester_figure_is_scaled_to_the_poses_and_labelled():
    from mechsyn.plot.synthesis import plot_motion_synthesis
    from mechsyn.synthesis.exact import motion_synthesis

    poses = json.loads((ROOT / "examples" / "synthesis" / "poses_4.json").read_text())["poses"]
    P = np.array([[x, y, math.radians(a)] for x, y, a in poses])
    ax = plot_motion_synthesis(P, motion_synthesis(P))
    assert _labelled(ax)
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    span = np.ptp(P[:, :2], axis=0).max()
    assert max(x1 - x0, y1 - y0) < 10 * span  # the poses are not shrunk to a dot
    assert all(x0 < x < x1 and y0 < y < y1 for x, y, _ in P)
    numbers = [t for t in ax.texts if t.get_text() in {"1", "2", "3", "4"}]
    assert len(numbers) == 4  # each pose numbered, beside (not on) its arrow's tail
    for t, (x, y, _) in zip(numbers, P):
        assert 0 < np.hypot(*(np.array(t.get_position()) - (x, y)))


def test_four_bar_path_figure_is_labelled():
    from mechsyn.plot.synthesis import plot_fourbar_path

    design = {"r1": 4.0, "r2": 1.0, "r3": 3.5, "r4": 3.0, "rcx": 1.0, "rcy": 1.0}
    ax = plot_fourbar_path(design, np.array([[1.0, 2.0], [2.0, 2.5]]), np.radians([30.0, 60.0]), 1)
    assert _labelled(ax)


def test_belt_figure_is_labelled():
    import mechsyn as ms
    from mechsyn.belt import analyze
    from mechsyn.plot.belt import plot_belt

    design = ms.BeltDesign(a=500, c=350, h=100, r=75)
    state = analyze(design, np.radians(np.arange(-60.0, 61.0, 5.0)))
    fig = plot_belt(design, state)
    assert _labelled(fig.axes[0])


def test_forces_figure_names_units_and_gravity():
    import mechsyn as ms
    from mechsyn.plot.kinematics import plot_forces

    mech = ms.load_mechanism(ROOT / "examples" / "kinematics" / "crank_rocker.yaml")
    fa = ms.forces(mech, {"A": np.arange(0.0, 361.0, 30.0)})
    fig = plot_forces(fa)
    assert "/s²)" in fig.axes[0].get_ylabel() and "moment" in fig.axes[1].get_ylabel()
    assert "-0.0" not in fig._suptitle.get_text()
