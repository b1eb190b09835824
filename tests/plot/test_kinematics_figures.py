"""Figures of a simulation: one colour per link in every panel, labelled axes, the file's
own (Pyslvs) colours on the pins."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np
import pytest
from matplotlib.colors import to_rgb

import mechsyn as ms
from mechsyn.io.convert import load_any
from mechsyn.plot.kinematics import link_colour, plot_simulation

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def jansen():
    mech = load_any(ROOT / "examples" / "pyslvs" / "jansen.pyslvs")
    return ms.simulate(mech, {"P0": np.arange(0.0, 361.0, 30.0)}, points=["P7"])


def test_a_link_has_one_colour_in_every_panel(jansen):
    fig = plot_simulation(jansen)
    mech_ax, omega_ax = fig.axes[0], fig.axes[3]
    omega = {ln.get_label(): to_rgb(ln.get_color()) for ln in omega_ax.get_lines()}
    bars = {to_rgb(ln.get_color()) for ln in mech_ax.get_lines() if ln.get_linestyle() == "-"
            and ln.get_linewidth() >= 2.5}
    moving = [n for n in jansen.system.mech.link_names if n != jansen.system.mech.ground]
    assert {n: to_rgb(link_colour(jansen, n)) for n in moving} == {n: omega[n] for n in moving}
    assert bars == {omega[n] for n in moving}
    assert "(" in mech_ax.get_xlabel() and "(" in mech_ax.get_ylabel()  # with units


def test_pyslvs_colours_fill_the_pins(jansen):
    colours = jansen.system.mech.attrs["colors"]
    assert colours["P0"] == "Green"
    ax = plot_simulation(jansen).axes[0]
    filled = [ln for ln in ax.get_lines() if ln.get_marker() == "o" and ln.get_markerfacecolor() != "white"]
    green = [ln for ln in filled if np.allclose(to_rgb(ln.get_markerfacecolor()), (0, 128 / 255, 0))]
    assert len(filled) == len(colours) and len(green) == sum(c == "Green" for c in colours.values())
    x0, y0 = green[0].get_xydata()[0]
    assert any(np.allclose(j.point, (x0, y0)) for j in jansen.system.mech.joints if j.id == "P0") or \
        any(np.allclose(ln.get_xydata()[0], [0, 0]) for ln in green)


@pytest.mark.filterwarnings("ignore:Animation was deleted")
def test_animation_frames_use_the_file_colours(jansen):
    """Each frame fills the pins with the file's ``colors:`` at the pins' moved places, as the static figure."""
    from mechsyn.plot.kinematics import _file_colours, animate_simulation

    anim = animate_simulation(jansen, max_frames=5)
    draw, frames = anim.mechsyn_blit
    colours = jansen.system.mech.attrs["colors"]
    for k in (frames[0], frames[len(frames) // 2]):
        moving = draw(k)
        pins = [a for a in moving if getattr(a, "get_marker", lambda: None)() == "o"
                and a.get_markerfacecolor() != "white" and a.get_markerfacecolor() != "k"]
        assert len(pins) == len(colours)
        want = _file_colours(jansen, k)
        for pin, (xy, rgb) in zip(pins, want):
            assert np.allclose(to_rgb(pin.get_markerfacecolor()), rgb)
            assert np.allclose(pin.get_xydata()[0], xy)
    first, middle = _file_colours(jansen, frames[0]), _file_colours(jansen, frames[len(frames) // 2])
    assert any(not np.allclose(a[0], b[0]) for a, b in zip(first, middle))  # the pins move with the links


@pytest.mark.filterwarnings("ignore:Animation was deleted")
def test_redrawn_animation_uses_the_file_colours_and_link_colours():
    """Cams are redrawn whole at each frame: the file's colours fill the pins there too, and
    each point's trail has its link's colour (as in the static figure)."""
    from matplotlib.figure import Figure

    from mechsyn.plot.kinematics import animate_simulation

    mech = ms.load_mechanism(ROOT / "examples" / "kinematics" / "cam_roller.yaml")
    mech.attrs["colors"] = {"O": "Red"}
    sim = ms.simulate(mech, {"O": np.arange(0.0, 361.0, 30.0)}, points=["F"])
    anim = animate_simulation(sim, fig=Figure(), max_frames=4)
    anim._draw_frame(0)  # the first frame, as a writer draws it
    ax = anim._fig.axes[0]
    red = [ln for ln in ax.get_lines() if ln.get_marker() == "o"
           and np.allclose(to_rgb(ln.get_markerfacecolor()), (1, 0, 0))]
    assert len(red) == 1 and np.allclose(red[0].get_xydata()[0], (0, 0))
    trail = [ln for ln in ax.get_lines() if ln.get_label() == "F"]
    assert trail and np.allclose(to_rgb(trail[0].get_color()), to_rgb(link_colour(sim, "follower")))
