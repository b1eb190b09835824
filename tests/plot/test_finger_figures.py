"""Finger figures (paper 000): sketches with labelled axes in the file's units; the
finger-design panels' legends clear of the drawn finger."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest
import yaml
from matplotlib.figure import Figure
from matplotlib.transforms import Bbox

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[2]
EX = ROOT / "examples" / "fingers"


def test_sketch_axes_say_x_and_y_with_units():
    from mechsyn.plot.finger import sketch_mechanism

    data = yaml.safe_load((EX / "two_phalanx_base_000.yaml").read_text())
    ax = sketch_mechanism(data, Figure().add_subplot())
    unit = data.get("units") or "length"
    assert ax.axison and ax.get_xlabel() == f"x ({unit})" and ax.get_ylabel() == f"y ({unit})"
    data["units"] = "mm"
    ax = sketch_mechanism(data, Figure().add_subplot())
    assert ax.get_xlabel() == "x (mm)"


@pytest.fixture(scope="module")
def design_figure():
    from mechsyn.plot.finger import plot_finger_design
    from mechsyn.synthesis.finger.cases import load_case
    from mechsyn.synthesis.finger.design import design_finger

    case = load_case(EX / "finger_design_case.yaml")
    case.maxiter, case.popsize, case.force_maxiter, case.vll_steps, case.candidates = 4, 5, 1, 3, 1
    fig = plot_finger_design(case, design_finger(case, seed=7), fig=Figure())
    fig.canvas.draw()
    return fig


def _drawn_bbox(ax) -> Bbox:
    """Display-space box of the finger drawn on ``ax`` (every line with data)."""
    xy = np.vstack([ln.get_xydata() for ln in ax.get_lines() if len(ln.get_xydata())])
    xy = xy[np.all(np.isfinite(xy), axis=1)]
    return Bbox(ax.transData.transform(np.array([xy.min(axis=0), xy.max(axis=0)])))


@pytest.mark.parametrize("panel", [0, 1])
def test_design_legends_leave_the_finger_visible(design_figure, panel):
    ax = design_figure.axes[panel]
    legend = ax.get_legend()
    assert legend is not None
    box = legend.get_window_extent()
    assert not box.overlaps(_drawn_bbox(ax)), "the legend covers the drawn finger"
    assert not box.overlaps(ax.get_window_extent())
    fig_box = design_figure.bbox
    assert fig_box.x0 <= box.x0 and box.x1 <= fig_box.x1 and fig_box.y0 <= box.y0  # not cut off
    assert all("(" in s for s in (ax.get_xlabel(), ax.get_ylabel()))
