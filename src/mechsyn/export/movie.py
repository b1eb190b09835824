"""Animations written as GIF (Pillow), MP4 (ffmpeg through imageio-ffmpeg) or a
self-contained HTML player, from RGB frames (see :func:`mechsyn.plot.frames.animation_frames`).

Every writer writes the file whole or not at all. MP4 needs the optional extra
``video`` (``pip install 'mechsyn[video]'``: imageio-ffmpeg ships an ffmpeg binary).
"""

from __future__ import annotations

import base64
import io
import os
from collections.abc import Iterable
from html import escape

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.results import atomic_output, write_atomic

__all__ = ["ANIMATION_SUFFIXES", "write_animation", "write_gif", "write_mp4", "write_html", "palette_images"]

ANIMATION_SUFFIXES = (".gif", ".mp4", ".html")


def _pil():
    try:
        from PIL import Image
    except ImportError:
        raise MechsynInputError("GIF and HTML animations need Pillow", hint="pip install pillow") from None
    return Image


def palette_images(frames: Iterable[np.ndarray]) -> list:
    """Pillow images of ``frames`` on one 255-colour palette (taken from the first, middle and
    last frames), no dithering: flat colours stay flat and encoding is fast."""
    Image = _pil()
    images = [Image.fromarray(f) for f in frames]
    if not images:
        raise MechsynInputError("no frame to write")
    sample = [images[0], images[len(images) // 2], images[-1]]
    montage = Image.new("RGB", (sample[0].width, sample[0].height * 3))
    for i, im in enumerate(sample):
        montage.paste(im, (0, i * im.height))
    palette = montage.quantize(colors=255, method=Image.Quantize.MEDIANCUT)
    return [im.quantize(palette=palette, dither=Image.Dither.NONE) for im in images]


def write_gif(frames: Iterable[np.ndarray], path: str | os.PathLike[str], fps: float = 15) -> None:
    """A looping GIF of :func:`palette_images` (one palette for all frames)."""
    q = palette_images(frames)
    with atomic_output(path) as tmp:
        q[0].save(tmp, format="GIF", save_all=True, append_images=q[1:], duration=round(1000 / fps), loop=0)


def write_mp4(frames: Iterable[np.ndarray], path: str | os.PathLike[str], fps: float = 15) -> None:
    """An H.264 MP4 (yuv420p, plays everywhere); frames padded to even sizes."""
    try:
        import imageio_ffmpeg
    except ImportError:
        raise MechsynInputError("MP4 animations need imageio-ffmpeg", hint="pip install 'mechsyn[video]'") from None
    it = iter(frames)
    first = next(it, None)
    if first is None:
        raise MechsynInputError("no frame to write")
    h, w = first.shape[:2]
    H, W = h + h % 2, w + w % 2

    def even(f: np.ndarray) -> bytes:
        if (H, W) != (h, w):
            f = np.pad(f, ((0, H - h), (0, W - w), (0, 0)), mode="edge")
        return np.ascontiguousarray(f).tobytes()

    with atomic_output(path) as tmp:
        writer = imageio_ffmpeg.write_frames(str(tmp), (W, H), fps=fps, codec="libx264", pix_fmt_out="yuv420p",
                                             macro_block_size=1, output_params=["-f", "mp4"])
        writer.send(None)
        writer.send(even(first))
        for f in it:
            writer.send(even(f))
        writer.close()


_PLAYER = """<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{title}</title>
<style>body{{font-family:sans-serif;margin:1em}} img{{max-width:100%;border:1px solid #ccc}}
#bar{{display:flex;gap:.6em;align-items:center;margin:.5em 0}} input[type=range]{{flex:1}}</style></head>
<body><h3>{title}</h3><img id="f" alt="frame">
<div id="bar"><button id="p">pause</button><input id="s" type="range" min="0" max="{last}" value="0">
<span id="n"></span><label>speed <select id="v"><option>0.25</option><option>0.5</option>
<option selected>1</option><option>2</option></select></label></div>
<script>
const F={frames};const fps={fps};let k=0,on=true,t=null;
const img=document.getElementById('f'),s=document.getElementById('s'),n=document.getElementById('n'),
p=document.getElementById('p'),v=document.getElementById('v');
function show(i){{k=(i+F.length)%F.length;img.src='data:image/png;base64,'+F[k];s.value=k;n.textContent=(k+1)+'/'+F.length;}}
function tick(){{if(on)show(k+1);t=setTimeout(tick,1000/(fps*parseFloat(v.value)));}}
p.onclick=()=>{{on=!on;p.textContent=on?'pause':'play';}};
s.oninput=()=>{{on=false;p.textContent='play';show(parseInt(s.value));}};
document.onkeydown=e=>{{if(e.key===' '){{p.click();e.preventDefault();}}
if(e.key==='ArrowRight'){{on=false;show(k+1);}}if(e.key==='ArrowLeft'){{on=false;show(k-1);}}}};
show(0);tick();
</script></body></html>
"""


def write_html(frames: Iterable[np.ndarray], path: str | os.PathLike[str], fps: float = 15,
               title: str = "mechsyn animation") -> None:
    """A self-contained HTML player (frames inlined as PNG; play, pause, step, scrub, speed)."""
    Image = _pil()
    data = []
    for f in frames:
        buf = io.BytesIO()
        Image.fromarray(f).save(buf, format="PNG", optimize=False, compress_level=6)
        data.append(base64.b64encode(buf.getvalue()).decode("ascii"))
    if not data:
        raise MechsynInputError("no frame to write")
    frames_js = "[" + ",".join(f'"{d}"' for d in data) + "]"
    write_atomic(path, _PLAYER.format(title=escape(title), last=len(data) - 1, frames=frames_js, fps=fps))


def write_animation(frames: Iterable[np.ndarray], path: str | os.PathLike[str], fps: float = 15,
                    title: str = "mechsyn animation") -> None:
    """Write ``frames`` in the format of ``path``'s suffix (.gif, .mp4 or .html)."""
    suffix = os.fspath(path).lower().rsplit(".", 1)[-1]
    if suffix == "gif":
        write_gif(frames, path, fps)
    elif suffix == "mp4":
        write_mp4(frames, path, fps)
    elif suffix == "html":
        write_html(frames, path, fps, title)
    else:
        raise MechsynInputError(f"animations are .gif, .mp4 or .html files, not .{suffix}", source=os.fspath(path))
