"""The studio fills joints and points with the file's colours (e.g. a Pyslvs expression's)."""

from __future__ import annotations

from pathlib import Path

from test_browser import open_studio

from mechsyn.io import mechanism_to_dict
from mechsyn.io.convert import load_any

ROOT = Path(__file__).resolve().parents[2]


def test_pyslvs_colours_fill_the_studio_joints(serve, page):
    mech = mechanism_to_dict(load_any(ROOT / "examples" / "pyslvs" / "crank_rocker.pyslvs"))
    mech["colors"].update({"P1": "(255, 0, 0)", "P2": "dark-blue"})
    srv = serve(mech, "crank_rocker.yaml")
    open_studio(page, srv)
    fill = "s => getComputedStyle(document.querySelector(s)).fill"
    assert page.evaluate(fill, '[data-joint="P0"]') == "rgb(0, 128, 0)"  # Green, on the frame
    assert page.evaluate(fill, '[data-joint="P1"]') == "rgb(255, 0, 0)"
    assert page.evaluate(fill, '[data-joint="P2"]') == "rgb(0, 0, 139)"
    assert page.evaluate(fill, '[data-point="P4"]') == "rgb(0, 0, 255)"  # Blue
    assert page.console_errors == []
