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


def run_motion(page, poses):
    """Targets clicked at ``poses`` (x, y, angle in degrees), the motion kind run to its end."""
    from test_browser import click_world

    page.click("#new")
    page.click('#tabs button[data-tab="synthesis"]')
    page.select_option("#synth-kind", "motion")
    page.click('#modes button[data-mode="target"]')
    for x, y, _ in poses:
        click_world(page, x, y)
    for i, (_, _, a) in enumerate(poses):
        page.fill(f'input[data-pose="{i}"]:not([data-coord])', str(a))
        page.press(f'input[data-pose="{i}"]:not([data-coord])', "Tab")
    page.click("#synth-run")
    wait_js(page, "() => document.querySelectorAll('#synth-results li').length > 0", timeout=60)


def test_three_poses_offer_linkages_and_a_dragged_pivot(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    poses = [(0.0, 0.0, 0.0), (1.0, 0.5, 20.0), (2.0, 0.6, 45.0)]
    run_motion(page, poses)
    applies = page.locator("#synth-results button[data-apply]")
    assert applies.count() >= 2
    labels = page.locator("#synth-results li").all_inner_texts()
    assert all("× the poses" in t and "min μ" in t and "Grashof" in t for t in labels)
    assert not any("error 1" in t for t in labels)
    # the pivots of the first result drawn
    for kind in ("fixed", "moving", "circle", "linkage"):
        assert page.locator(f'[data-burmester="{kind}"]').count() >= 1, kind
    shot(page, "design_burmester3.png")
    # a moving pivot typed: the linkage it gives is computed and offered
    page.fill("input[name=pivot-ax]", "-0.5")
    page.press("input[name=pivot-ax]", "Enter")
    wait_js(page, "() => window.__studio.previewResult && window.__studio.previewResult.custom")
    r = page.evaluate("() => window.__studio.previewResult")
    assert r["pivots"]["moving"][0][0][0] == pytest.approx(-0.5)
    # the linkage's moving pivot runs on a circle about its fixed pivot through the three poses
    f = np.array(r["pivots"]["fixed"][0])
    d = [np.linalg.norm(np.array(p) - f) for p in r["pivots"]["moving"][0]]
    assert np.ptp(d) < 1e-9 * max(d)
    # drag the other moving pivot
    x, y = center(page, '[data-burmester="moving"][data-which="1"]')
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + 30, y - 20, steps=4)
    page.mouse.up()
    wait_js(page, "p => Math.abs(window.__studio.previewResult.pivots.moving[1][0][0] - p) > 1e-6", r["pivots"]["moving"][1][0][0])
    assert page.locator('button[data-apply="custom"]').count() == 1
    page.click('button[data-apply="custom"]')
    wait_settled(page)
    assert page.evaluate("() => window.__studio.mode") == "select"
    m = page.evaluate("() => window.__studio.mech")
    assert m["name"].startswith("Four-bar motion generator")
    shot(page, "design_burmester3_applied.png")


def test_four_poses_ranked_and_labelled(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    poses = [(0.0, 0.0, 0.0), (1.0, 0.5, 20.0), (2.0, 0.6, 45.0), (3.0, 0.4, 70.0)]
    run_motion(page, poses)
    labels = page.locator("#synth-results li").all_inner_texts()
    assert len(labels) >= 2
    assert all("reaches the poses on one branch, in order" in t for t in labels)
    ratios = [float(t.split("× the poses")[0].split(";")[-1]) for t in labels]
    assert max(ratios) <= 10
    assert page.locator('[data-burmester="centre-curve"]').count() == 1
    shot(page, "design_burmester4.png")
