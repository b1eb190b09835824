"""Animations: blitted frames equal full redraws; GIF, MP4 and HTML written whole."""

from __future__ import annotations

import base64
import re
from pathlib import Path

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from mechsyn.io import load_mechanism
from mechsyn.kinematics.analysis import simulate
from mechsyn.plot.frames import animation_frames
from mechsyn.plot.kinematics import animate_simulation

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def sim():
    mech = load_mechanism(ROOT / "examples/kinematics/inverted_slider_crank.yaml")
    return simulate(mech, {"A": np.arange(0.0, 360.0, 30.0)}, points=["T"])


def test_blitted_frames_equal_full_redraws(sim):
    fast = list(animation_frames(animate_simulation(sim, fig=Figure()), dpi=60))
    anim = animate_simulation(sim, fig=Figure())
    anim.mechsyn_blit = None  # force the whole-figure path
    slow = list(animation_frames(anim, dpi=60))
    assert len(fast) == len(slow) == 12
    for a, b in zip(fast, slow):
        differ = np.any(a != b, axis=2).mean()
        assert differ < 0.002  # anti-aliasing of overlapping edges aside, the same pixels


@pytest.mark.parametrize("suffix", ["gif", "mp4", "html"])
def test_animation_files(suffix, run_cli, tmp_path):
    out = tmp_path / f"m.{suffix}"
    code, _, err = run_cli("simulate", ROOT / "examples/kinematics/crank_rocker.yaml", "--input", "A=0:360:30",
                           "--points", "M", "--animate", out)
    assert code == 0, err
    data = out.read_bytes()
    if suffix == "gif":
        from PIL import Image

        assert Image.open(out).n_frames == 13
    elif suffix == "mp4":
        import imageio_ffmpeg

        reader = imageio_ffmpeg.read_frames(str(out))
        meta = next(reader)
        assert sum(1 for _ in reader) == 13 and meta["fps"] == 15
    else:
        frames = re.findall(r'"([A-Za-z0-9+/=]{100,})"', data.decode())
        assert len(frames) == 13 and base64.b64decode(frames[0])[:8] == b"\x89PNG\r\n\x1a\n"


def test_unknown_animation_suffix(run_cli, tmp_path):
    code, _, err = run_cli("simulate", ROOT / "examples/kinematics/crank_rocker.yaml", "--input", "A=0:360:30",
                           "--animate", tmp_path / "m.avi")
    assert code == 2 and ".gif, .mp4 or .html" in err
