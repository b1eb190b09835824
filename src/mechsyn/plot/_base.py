"""Where a drawing goes: the Axes or Figure the caller gives, else a new pyplot one.

Nothing here chooses a backend or writes a file: a notebook gets its inline figure, a
script its window, and the command line passes a bare :class:`matplotlib.figure.Figure`
that it saves itself (``mechsyn.io.output.save_figure_atomic``).
"""

from __future__ import annotations

from typing import Any

__all__ = ["axes", "figure"]


def figure(fig: Any = None, figsize: tuple[float, float] = (6.4, 4.8)) -> Any:
    """The Figure to draw on: ``fig`` (sized to ``figsize`` while it is still empty) or a new
    pyplot figure of that size."""
    if fig is None:
        import matplotlib.pyplot as plt

        return plt.figure(figsize=figsize)
    if not fig.axes:
        fig.set_size_inches(figsize)
    return fig


def axes(ax: Any = None, figsize: tuple[float, float] = (6.4, 4.8)) -> Any:
    """The Axes to draw on: ``ax`` or the single Axes of a new figure."""
    if ax is not None:
        return ax
    return figure(None, figsize).add_subplot()
