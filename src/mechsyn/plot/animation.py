"""Animations that play in a notebook and save fast.

:class:`MechanismAnimation` is the :class:`matplotlib.animation.FuncAnimation` that
:meth:`mechsyn.kinematics.analysis.Simulation.animate` returns. Shown as a cell's value in
Jupyter it plays (``_repr_html_``: a small HTML5/JavaScript player with play/pause, a
slider and the speed, its frames inlined as palette PNGs); ``save("m.gif")``,
``save("m.mp4")`` and ``save("m.html")`` write the file whole through
:mod:`mechsyn.export.movie`, drawing only what moves at each frame
(:func:`mechsyn.plot.frames.animation_frames`) rather than the whole figure. A
``writer=`` argument hands the call to Matplotlib's own ``FuncAnimation.save``.

Examples
--------
>>> import mechsyn as ms
>>> s = ms.examples.load("crank_rocker").simulate(A=(0, 360, 30))
>>> anim = s.animate(max_frames=4)
>>> html = anim._repr_html_()
>>> html.count('"iVBOR'), "<script>" in html  # four PNG frames in a JavaScript array
(4, True)
"""

from __future__ import annotations

import base64
import io
import json
import os
import secrets
from html import escape
from typing import Any

from matplotlib.animation import FuncAnimation

__all__ = ["MechanismAnimation", "notebook_player"]

#: frame resolution of the notebook player (dots per inch of the figure)
NOTEBOOK_DPI = 72


class MechanismAnimation(FuncAnimation):
    """A ``FuncAnimation`` of a mechanism that plays in Jupyter and saves GIF, MP4 or HTML.

    Parameters
    ----------
    fig, func, frames, interval
        As for :class:`matplotlib.animation.FuncAnimation`.
    title : str
        The player's and the HTML file's title.
    **kwargs
        Passed to ``FuncAnimation``.
    """

    def __init__(self, fig: Any, func: Any, frames: Any = None, *, title: str = "mechsyn animation",
                 interval: float = 1000 / 15, **kwargs: Any) -> None:
        super().__init__(fig, func, frames=frames, interval=interval, **kwargs)
        self.title = title
        self.fps = 1000.0 / interval

    def frames_rgb(self, dpi: float = 100) -> Any:
        """The frames as ``(height, width, 3)`` uint8 arrays (only what moves is redrawn)."""
        from mechsyn.plot.frames import animation_frames

        return animation_frames(self, dpi)

    def save(self, filename: str | os.PathLike[str], writer: Any = None, fps: float | None = None,
             dpi: float | None = None, **kwargs: Any) -> None:
        """Write the animation to ``filename`` (.gif, .mp4 or .html by its suffix), whole or
        not at all. With ``writer`` (or another suffix) Matplotlib's ``FuncAnimation.save``
        writes it instead."""
        suffix = os.fspath(filename).lower().rsplit(".", 1)[-1]
        if writer is not None or suffix not in ("gif", "mp4", "html") or kwargs:
            return super().save(filename, writer=writer, fps=fps, dpi=dpi, **kwargs)
        from mechsyn.export.movie import write_animation

        write_animation(self.frames_rgb(dpi or 100), filename, fps=fps or self.fps, title=self.title)
        return None

    def _repr_html_(self) -> str:
        """The notebook player (Jupyter shows it when the animation is a cell's value)."""
        return notebook_player(self.frames_rgb(NOTEBOOK_DPI), self.fps, self.title)

    def __repr__(self) -> str:
        return (f"<MechanismAnimation {self.title!r}: {len(self._save_seq or [])} frames at {self.fps:g} fps; "
                "show it in a notebook, or .save('m.gif' / 'm.mp4' / 'm.html')>")


def notebook_player(frames: Any, fps: float = 15, title: str = "mechsyn animation") -> str:
    """HTML of a player for a notebook cell: the frames as palette PNGs in a JavaScript array,
    play/pause, a slider and the speed; every id unique, so several players share a page.

    Examples
    --------
    >>> import numpy as np
    >>> html = notebook_player([np.zeros((4, 4, 3), np.uint8), np.full((4, 4, 3), 255, np.uint8)])
    >>> html.count('"iVBOR')  # two PNG frames
    2
    """
    from mechsyn.export.movie import palette_images

    data = []
    for im in palette_images(frames):
        buf = io.BytesIO()
        im.save(buf, format="PNG", optimize=False, compress_level=6)
        data.append(base64.b64encode(buf.getvalue()).decode("ascii"))
    uid = "mechsyn-anim-" + secrets.token_hex(6)
    return _PLAYER.format(uid=uid, title=escape(title), last=len(data) - 1, frames=json.dumps(data), fps=fps)


_PLAYER = """<div id="{uid}" class="mechsyn-animation" style="font-family:sans-serif">
<div style="font-size:90%;margin-bottom:.3em">{title}</div>
<img alt="animation frame" style="max-width:100%;border:1px solid #ccc">
<div style="display:flex;gap:.6em;align-items:center;max-width:40em">
<button type="button">pause</button><input type="range" min="0" max="{last}" value="0" style="flex:1">
<span></span><select><option>0.25</option><option>0.5</option><option selected>1</option>
<option>2</option></select></div></div>
<script>(function(){{
const root=document.getElementById("{uid}");if(!root)return;
const F={frames},fps={fps};let k=0,on=true;
const img=root.querySelector("img"),s=root.querySelector("input"),n=root.querySelector("span"),
p=root.querySelector("button"),v=root.querySelector("select");
function show(i){{k=(i+F.length)%F.length;img.src="data:image/png;base64,"+F[k];s.value=k;
n.textContent=(k+1)+"/"+F.length;}}
function tick(){{if(!document.body.contains(root))return;if(on)show(k+1);
setTimeout(tick,1000/(fps*parseFloat(v.value)));}}
p.onclick=()=>{{on=!on;p.textContent=on?"pause":"play";}};
s.oninput=()=>{{on=false;p.textContent="play";show(parseInt(s.value));}};
show(0);setTimeout(tick,1000/fps);
}})();</script>
"""
