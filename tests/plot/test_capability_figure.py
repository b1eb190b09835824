"""Velocity-capability map figure (paper 004): on small grids the contour labels and the
cell values are both legible (no overlap); on dense grids the cells are not annotated."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[2]
PAPER = ROOT / "examples" / "capability" / "paper004_3r.yaml"


def _map(xs, ys):
    from mechsyn.capability.arm_file import load_arm
    from mechsyn.capability.maps import capability_map

    return capability_map(load_arm(PAPER), xs, ys, (1, 0))


def _drawn(cmap):
    from mechsyn.plot.capability import plot_capability_map

    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = plot_capability_map(cmap, fig=Figure())
    FigureCanvasAgg(fig).draw()
    ax = fig.axes[0]
    cells = [t for t in ax.texts if t.get_color() == "white"]
    labels = [t for t in ax.texts if t not in cells]
    return fig, ax, cells, labels


@pytest.mark.parametrize("grid", [(np.arange(1300, 2101, 200.0), np.arange(100, 901, 200.0)),
                                  (np.arange(1300, 1701, 100.0), np.arange(300, 701, 100.0))])
def test_contour_labels_clear_of_cell_values(grid):
    cmap = _map(*grid)
    fig, ax, cells, labels = _drawn(cmap)
    assert len(cells) == np.isfinite(cmap.value).sum()  # every reached cell annotated
    assert labels, "the contour lines are labelled"
    r = fig.canvas.get_renderer()
    boxes = [t.get_window_extent(r) for t in cells]
    for lab in labels:
        lb = lab.get_window_extent(r)
        assert not any(lb.overlaps(b) for b in boxes), f"contour label {lab.get_text()} covers a cell value"


def test_dense_grid_draws_no_cell_values():
    xs, ys = np.arange(1300, 2101, 50.0), np.arange(100, 901, 50.0)
    _, ax, cells, labels = _drawn(_map(xs, ys))
    assert not cells and labels


def test_every_panel_annotated_or_none():
    """One decision for the figure: a panel with shorter numbers is not annotated alone."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from mechsyn.plot.capability import plot_capability_map

    for step in (200.0, 100.0):
        cmap = _map(np.arange(1300, 2101, step), np.arange(100, 901, step))
        fig = plot_capability_map(cmap, fig=Figure())
        FigureCanvasAgg(fig).draw()
        counts = {sum(t.get_color() == "white" for t in ax.texts) for ax in fig.axes if ax.get_title()}
        assert len(counts) == 1, counts
