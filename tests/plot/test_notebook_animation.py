"""``Simulation.animate()`` plays in Jupyter and saves GIF/MP4 without Matplotlib's
frame-by-frame writers (issue 26 §5)."""

from __future__ import annotations

import importlib.util
import re

import numpy as np
import pytest
from matplotlib.animation import Animation, FuncAnimation

import mechsyn as ms


@pytest.fixture(scope="module")
def sim():
    return ms.examples.load("crank_rocker").simulate(A=(0, 360, 10))


def test_animate_draws_on_no_pyplot_figure_and_shows_a_player(sim):
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    anim = sim.animate(max_frames=6)
    assert isinstance(anim, Animation) and plt.get_fignums() == before  # no still frame in a notebook
    html = anim._repr_html_()
    frames = re.findall(r'"(iVBOR[A-Za-z0-9+/=]+)"', html)
    assert len(frames) == 6 and "<script>" in html
    ids = re.findall(r'id="(mechsyn-anim-[0-9a-f]+)"', html)
    assert len(ids) == 1 and ids[0] not in anim._repr_html_()  # each showing its own player
    assert "FuncAnimation at" not in repr(anim)


def test_save_gif_draws_only_what_moves(sim, tmp_path, monkeypatch):
    """The GIF comes from the blitted frames, not FuncAnimation.save's full redraws."""
    from PIL import Image

    def refuse(*args, **kwargs):
        raise AssertionError("FuncAnimation.save redraws the whole figure at every frame")

    monkeypatch.setattr(FuncAnimation, "save", refuse)
    anim = sim.animate(max_frames=8)
    anim.save(tmp_path / "m.gif")
    with Image.open(tmp_path / "m.gif") as im:
        assert im.n_frames == 8
        first = np.asarray(im.convert("RGB"))
        im.seek(4)
        assert not np.array_equal(first, np.asarray(im.convert("RGB")))  # it moves


@pytest.mark.skipif(importlib.util.find_spec("imageio_ffmpeg") is None, reason="needs mechsyn[video]")
def test_save_mp4(sim, tmp_path):
    sim.animate(max_frames=5).save(tmp_path / "m.mp4")
    assert (tmp_path / "m.mp4").read_bytes()[4:8] == b"ftyp"


def test_a_writer_still_goes_to_matplotlib(sim, tmp_path):
    sim.animate(max_frames=3).save(tmp_path / "m.gif", writer="pillow", fps=5)
    assert (tmp_path / "m.gif").stat().st_size > 0


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("nbclient") is None, reason="needs mechsyn[notebook]")
def test_animation_plays_in_a_real_jupyter_kernel(tmp_path, monkeypatch):
    """Executed by a Jupyter kernel, a cell ending in ``s.animate()`` gives the HTML player
    and neither a still PNG nor ``<FuncAnimation at 0x...>``."""
    import os
    from pathlib import Path

    import nbclient
    import nbformat

    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell("%matplotlib inline\nimport mechsyn as ms\n"
                                          "s = ms.examples.load('crank_rocker').simulate(A=(0, 360, 30))\n"
                                          "s.animate(max_frames=5)")]
    src = str(Path(__file__).resolve().parents[2] / "src")
    monkeypatch.setenv("PYTHONPATH", src + os.pathsep + os.environ.get("PYTHONPATH", ""))
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = nb.cells[0].outputs
    data = [o.get("data", {}) for o in outputs]
    assert any("<script>" in d.get("text/html", "") for d in data), outputs
    assert not any("image/png" in d for d in data)
    assert not any("FuncAnimation" in d.get("text/plain", "") and "text/html" not in d for d in data)
