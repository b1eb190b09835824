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
        page.fill(f'input[data-pose="{i}"]', str(a))
        page.press(f'input[data-pose="{i}"]', "Tab")
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


def test_five_bar_every_drive_its_slider_and_the_tool_point_typed_and_dragged(serve, page):
    srv = serve(example("five_bar_5r"), "five_bar_5r.yaml")
    open_studio(page, srv)
    wait_settled(page)
    wait_js(page, "() => document.querySelectorAll('input[data-drive]').length === 2")
    assert sorted(page.eval_on_selector_all("input[data-drive]", "es => es.map(e => e.dataset.drive)")) == ["A", "E"]
    # the second drive moved alone: E turns, A stays
    before = page.evaluate("() => window.__studio.mech.joints.map(j => j.point)")
    page.eval_on_selector('input[data-drive="E"]', "e => { e.value = +e.value + 10; e.dispatchEvent(new Event('input')); e.dispatchEvent(new Event('change')); }")
    wait_js(page, "b => JSON.stringify(window.__studio.mech.joints.map(j => j.point)) !== b", __import__("json").dumps(before))
    wait_settled(page)
    after = page.evaluate("() => window.__studio.mech.joints.map(j => j.point)")
    assert after[1] == pytest.approx(before[1], abs=1e-9)  # B on the left arm: A held
    assert np.linalg.norm(np.subtract(after[3], before[3])) > 0.1  # D on the right arm: E turned
    # the tool point typed: the drives follow (inverse kinematics)
    page.click('#tabs button[data-tab="design"]')
    page.wait_for_selector("input[name=tool-x]")
    page.fill("input[name=tool-x]", "2.3")
    page.press("input[name=tool-x]", "Enter")
    wait_js(page, "() => Math.abs(window.__studio.mech.points.tool.at[0] - 2.3) < 1e-6")
    wait_settled(page)
    shot(page, "design_fivebar_tool.png")
    # out of reach: the workspace boundary in the banner, the mechanism at the nearest reach
    page.fill("input[name=tool-y]", "40")
    page.press("input[name=tool-y]", "Enter")
    wait_js(page, "() => document.querySelector('[data-banner]').innerText.includes('workspace boundary')")
    # dragging the tool's ring moves the mechanism
    wait_settled(page)
    x0 = page.evaluate("() => window.__studio.mech.points.tool.at[0]")
    x, y = center(page, "[data-tool]")
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x - 25, y + 25, steps=5)
    page.mouse.up()
    wait_js(page, "x => Math.abs(window.__studio.mech.points.tool.at[0] - x) > 0.05", x0)
    shot(page, "design_fivebar_drag.png")


@pytest.mark.slow
def test_delta_every_drive_its_slider_and_the_platform_typed(serve, page):
    srv = serve(example("delta"), "delta.yaml")
    page.goto(srv.url)
    wait_js(page, "() => window.__view3d && window.__view3d.view", timeout=60)
    wait_js(page, "() => document.querySelectorAll('input[data-drive]').length === 3", timeout=60)
    assert sorted(page.eval_on_selector_all("input[data-drive]", "es => es.map(e => e.dataset.drive)")) == ["R1", "R2", "R3"]
    # planar editing modes hidden in the 3-D view
    hidden = page.eval_on_selector_all("#modes button", "bs => bs.filter(b => b.hidden).map(b => b.dataset.mode)")
    assert set(hidden) == {"pivot", "link", "point", "drive", "delete", "target"}
    # labels round the platform do not overlap
    boxes = page.eval_on_selector_all("#view3d text.view3d-label:not([visibility=hidden])",
                                      "ts => ts.map(t => { const b = t.getBBox(); return [b.x, b.y, b.width, b.height]; })")
    for i, a in enumerate(boxes):
        for b in boxes[i + 1:]:
            assert not (a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]), (a, b)
    # R2 moved alone
    s1 = page.evaluate("() => window.__studio.mech.joints.find(j => j.id === 'S1a1').point")
    page.eval_on_selector('input[data-drive="R2"]', "e => { e.value = 20; e.dispatchEvent(new Event('input')); e.dispatchEvent(new Event('change')); }")
    wait_js(page, "() => Math.abs(window.__studio.mech.joints.find(j => j.id === 'S2a1').point[2] + 0.6) > 1e-3", timeout=60)
    assert page.evaluate("() => window.__studio.mech.joints.find(j => j.id === 'S1a1').point") == pytest.approx(s1, abs=1e-9)
    # the platform point typed: the three drives follow
    page.click('#tabs button[data-tab="design"]')
    page.wait_for_selector("input[name=tool-z]")
    z0 = float(page.input_value("input[name=tool-z]"))
    page.fill("input[name=tool-z]", str(round(z0 - 0.1, 6)))
    page.press("input[name=tool-z]", "Enter")
    wait_js(page, "z => { const r = window.__robot; const j = window.__studio.mech.joints.find(q => q.id === r.tool); return Math.abs(j.point[2] - z) < 1e-6; }", z0 - 0.1, timeout=60)
    page.wait_for_timeout(1500)
    shot(page, "design_delta.png")


def test_instant_centres_listed_and_drawn_and_kennedy_holds(serve, page):
    srv = serve(example("crank_rocker"), "crank_rocker.yaml")
    open_studio(page, srv)
    wait_settled(page)
    page.click('#tabs button[data-tab="design"]')
    page.check("#show-centres")
    wait_js(page, "() => document.querySelectorAll('table[data-table=centres] tr[data-centre]').length === 6")
    assert page.locator("[data-centre]").count() >= 6 + 4  # rows and canvas marks (P24's may be far)
    cs = {tuple(c["numbers"]): c for c in page.evaluate("() => window.__centres.list")}
    # Kennedy: P12, P23, P13 on one line; P13 on lines AB and DC
    p12, p23, p13 = (np.array(cs[k]["point"]) for k in ((1, 2), (2, 3), (1, 3)))
    u, w = p23 - p12, p13 - p12
    assert abs(u[0] * w[1] - u[1] * w[0]) < 1e-9 * np.linalg.norm(u) * np.linalg.norm(w)
    assert cs[(1, 2)]["kind"] == "primary" and cs[(1, 3)]["kind"] == "Kennedy"
    shot(page, "design_centres.png")
    # another frame: the list follows
    page.eval_on_selector("#input-slider", "e => { e.value = 40; e.dispatchEvent(new Event('input')); }")
    wait_js(page, "p => JSON.stringify(window.__centres.list.find(c => c.numbers.join('') === '13').point) !== p",
            __import__("json").dumps(cs[(1, 3)]["point"]))


def test_cam_profile_drawn_on_the_cam_example(serve, page):
    srv = serve(example("cam_follower"), "cam_follower.yaml")
    open_studio(page, srv)
    wait_settled(page)
    wait_js(page, "() => document.querySelector('[data-cam]')")
    pts = page.evaluate("() => window.__centres.cams[0].points")
    c = np.mean(pts, axis=0)
    assert np.ptp(np.linalg.norm(np.subtract(pts, c), axis=1)) < 1e-9 and c == pytest.approx([0, 0.2])  # the disc cam
    shot(page, "design_cam.png")
    # turned with the cam: at another input the profile's drawn centre moved
    d0 = page.get_attribute("[data-cam]", "points")
    page.eval_on_selector("#input-slider", "e => { e.value = 45; e.dispatchEvent(new Event('input')); }")
    wait_js(page, "p => document.querySelector('[data-cam]').getAttribute('points') !== p", d0)


def test_unit_chosen_goes_to_the_dxf(serve, page):
    srv = serve(example("crank_rocker"), "crank_rocker.yaml")
    open_studio(page, srv)
    wait_settled(page)
    page.click('#tabs button[data-tab="design"]')
    assert page.input_value("#unit") == ""
    page.select_option("#unit", "mm")
    wait_js(page, "() => window.__studio.mech.unit === 'mm'")
    wait_settled(page)
    with page.expect_download() as dl:
        page.select_option("#export", "dxf")
    text = open(dl.value.path()).read().replace("\r", "")
    assert "$INSUNITS\n 70\n4\n" in text


def test_pose_xy_typed_moves_the_target(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    from test_browser import click_world

    page.click('#tabs button[data-tab="synthesis"]')
    page.select_option("#synth-kind", "motion")
    page.click('#modes button[data-mode="target"]')
    for x, y in ((0, 0), (1, 0.5), (2, 0.6)):
        click_world(page, x, y)
    page.fill('input[data-pose-xy="1"][data-coord="y"]', "0.75")
    page.press('input[data-pose-xy="1"][data-coord="y"]', "Enter")
    wait_js(page, "() => window.__studio.targets[1][1] === 0.75")
    cy = float(page.get_attribute('[data-target="1"]', "cy"))
    assert page.evaluate("() => window.__studio.targets[1]") == [1, 0.75]
    assert cy == pytest.approx(page.evaluate("""() => { const r = document.getElementById('canvas').getBoundingClientRect();
        const v = window.__studio.view; return r.height / 2 - (0.75 - v.oy) * v.s; }"""), abs=0.5)


def test_slider_guide_offset_typed_keeps_the_lengths(serve, page):
    from test_studio_designer import select_joint

    srv = serve(example("slider_crank"), "slider_crank.yaml")
    open_studio(page, srv)
    wait_settled(page)
    before = lengths_drawn(page)
    select_joint(page, "D")
    page.click('#tabs button[data-tab="element"]')
    page.wait_for_selector("input[name=offset]")
    page.fill("input[name=offset]", "0.4")
    page.press("input[name=offset]", "Enter")
    wait_js(page, "() => Math.abs(window.__studio.mech.joints.find(j => j.id === 'D').point[1] - 0.4) < 1e-9")
    wait_settled(page)
    assert lengths_drawn(page) == pytest.approx(before, rel=1e-9)
    assert page.evaluate("() => window.__studio.mech.joints.find(j => j.id === 'C').point[1]") == pytest.approx(0.4)
    shot(page, "design_slider_offset.png")
