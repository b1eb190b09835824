"""Frames of an animation as RGB arrays, blitted when the animation says what moves.

Saving a :class:`matplotlib.animation.FuncAnimation` through a writer redraws the whole
figure at every frame (axes, ticks, grid, static paths, legend). The animations of
:mod:`mechsyn.plot` that set ``anim.mechsyn_blit = (draw, frames)`` (``draw(frame)``
moves the artists and returns them) are rendered here by drawing the static background
once and only the moving artists at each frame. Nothing is written to a file.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

__all__ = ["animation_frames", "figure_frames"]


def animation_frames(anim: Any, dpi: float = 100) -> Iterator[np.ndarray]:
    """Yield the frames of ``anim`` as ``(height, width, 3)`` uint8 RGB arrays."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = anim._fig
    fig.set_dpi(dpi)
    canvas = FigureCanvasAgg(fig)
    spec = getattr(anim, "mechsyn_blit", None)
    if spec is None:  # every frame drawn whole
        for f in anim.new_saved_frame_seq():
            anim._draw_frame(f)
            canvas.draw()
            yield np.asarray(canvas.buffer_rgba())[..., :3].copy()
        return
    draw, frames = spec
    moving = draw(frames[0])
    for a in moving:
        a.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for f in frames:
        moving = draw(f)
        canvas.restore_region(background)
        for a in sorted(moving, key=lambda a: a.get_zorder()):  # stable: as a full draw orders them
            fig.draw_artist(a)
        yield np.asarray(canvas.buffer_rgba())[..., :3].copy()


def figure_frames(animate: Any, *args: Any, dpi: float = 100, **kwargs: Any) -> Iterator[np.ndarray]:
    """Build an animation with a :mod:`mechsyn.plot` function (``animate(*args, fig=...,
    **kwargs)``) on a bare Figure (no pyplot, no backend) and yield its frames as RGB
    arrays (see :func:`animation_frames`): what a server or a file writer needs, with
    Matplotlib imported here only.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.plot.frames import figure_frames
    >>> from mechsyn.plot.kinematics import animate_simulation
    >>> sim = ms.simulate(ms.examples.load("crank_rocker"), {"A": ms.input_grid(0, 360, 30)})
    >>> frames = list(figure_frames(animate_simulation, sim, dpi=20, max_frames=4))
    >>> len(frames), frames[0].shape[2]
    (4, 3)
    """
    from matplotlib.figure import Figure

    yield from animation_frames(animate(*args, fig=Figure(), **kwargs), dpi)
