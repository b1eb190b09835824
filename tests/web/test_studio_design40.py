"""Issue 40: the studio as a designer's daily tool, through the page contract in Chromium.

Dimensions typed as design variables, the Burmester choice of motion synthesis, every drive's
own slider and the tool point driven by inverse kinematics, units in the files, instant
centres and a cam's profile. Screenshots go to a temporary folder (docs/images/ with
MECHSYN_SCREENSHOTS=1).
"""

from __future__ import annotations

import numpy as np
import pytest

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.dimensions import link_lengths

from test_browser import center, example, open_studio, shot, wait_js, wait_settled

BANNER = "() => document.querySelector('[data-banner]').innerText"


def select_link(page, name):
    page.click("text=Select")
    x, y = center(page, f'[data-link="{name}"] .link-hit')
    page.mouse.click(x, y)
    wait_js(page, "n => (window.__studio.selected || {}).id === n", name)
    page.click('#tabs button[data-tab="element"]')
    page.wait_for_selector("input[name=length]")


def lengths_drawn(page):
    return link_lengths(mechanism_from_dict(page.evaluate("() => window.__studio.mech")))


def test_typed_rocker_length_keeps_the_other_lengths(serve, page):
    srv = serve(example("crank_rocker"), "crank_rocker.yaml")
    open_studio(page, srv)
    wait_settled(page)
    select_link(page, "rocker")
    assert page.evaluate("() => document.querySelector('[data-link=rocker]').dataset.selected") == "true"
    page.fill("input[name=length]", "3.2")
    page.press("input[name=length]", "Enter")
    wait_js(page, "() => { const m = window.__studio.mech, c = m.joints.find(j => j.id === 'C').point;"
                  " const d = m.joints.find(j => j.id === 'D').point; return Math.abs(Math.hypot(c[0]-d[0], c[1]-d[1]) - 3.2) < 1e-9; }")
    wait_settled(page)
    got = lengths_drawn(page)
    assert got == pytest.approx({"frame": 4.0, "crank": 1.0, "coupler": 3.5, "rocker": 3.2}, rel=1e-9)
    assert page.evaluate("() => window.__studio.sim.assembled.every(Boolean)")  # still a crank-rocker: full turn
    shot(page, "design_length.png")
    # one undo step brings the drawn rocker back
    page.click("#undo")
    wait_js(page, "() => Math.abs(window.__studio.mech.joints.find(j => j.id === 'C').point[0] - 3.330743359258974) < 1e-12")


def test_a_length_that_cannot_assemble_says_why_and_changes_nothing(serve, page):
    srv = serve(example("crank_rocker"), "crank_rocker.yaml")
    open_studio(page, srv)
    wait_settled(page)
    before = page.evaluate("() => JSON.stringify(window.__studio.mech)")
    select_link(page, "rocker")
    page.fill("input[name=length]", "0.05")
    page.press("input[name=length]", "Enter")
    wait_js(page, "() => document.querySelector('[data-banner]').innerText.includes('triangle inequality')")
    text = page.evaluate(BANNER)
    assert "rocker = 0.05" in text and "coupler + rocker" in text and "Grashof" in text
    assert page.evaluate("() => JSON.stringify(window.__studio.mech)") == before
    shot(page, "design_length_refused.png")
