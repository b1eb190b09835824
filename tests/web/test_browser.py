"""The studio used as a person would, in Debian's Chromium (Playwright).

Each test starts the server on a free loopback port in a thread. Screenshots for
docs/studio.md are written to docs/images/ by these tests when MECHSYN_SCREENSHOTS=1.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.web._service import example_path

from web_helpers import IMAGES

def wait_js(page, js, arg=None, timeout=30.0):
    """Poll ``js`` (a function expression) until truthy; the page's CSP forbids Playwright's
    string-evaluated wait_for_function, page.evaluate is not affected."""
    t0 = time.time()
    while time.time() - t0 < timeout:
        if page.evaluate(js, arg):
            return
        page.wait_for_timeout(25)
    raise AssertionError(f"timed out waiting for {js}")


def example(name):
    return mechanism_to_dict(load_mechanism(example_path(name)))


def screen(page, x, y):
    """Page coordinates of the world point (x, y) in the current view."""
    return page.evaluate("""([x, y]) => { const r = document.getElementById('canvas').getBoundingClientRect();
        const v = window.__studio.view;
        return [r.left + r.width / 2 + (x - v.ox) * v.s, r.top + r.height / 2 - (y - v.oy) * v.s]; }""", [x, y])


def center(page, selector):
    """Page coordinates of the centre of the element drawn now (the drawing is re-made on
    every repaint, so a locator may hold a detached element)."""
    return page.evaluate("""sel => { const r = document.querySelector(sel).getBoundingClientRect();
        return [r.left + r.width / 2, r.top + r.height / 2]; }""", selector)


def click_world(page, x, y):
    page.mouse.click(*screen(page, x, y))


def wait_simulated(page, count=None):
    """Until the drawn simulation is the one of the mechanism being edited."""
    wait_js(page, "() => window.__studio.simFor === window.__studio.mech && window.__studio.sim", timeout=30)


def wait_settled(page):
    """Until the simulation and the analysis shown are those of the mechanism edited."""
    wait_simulated(page)
    wait_js(page, "() => window.__studio.analysis !== null")
    page.wait_for_timeout(400)


def shot(page, name):
    IMAGES.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(IMAGES / name))


def save_gif(pngs, name):
    """The drag as a small looping GIF for the README (frames shown 120 ms, then back)."""
    import io

    from PIL import Image

    imgs = [Image.open(io.BytesIO(b)).convert("RGB") for b in pngs]
    w, h = imgs[0].size
    imgs = [im.resize((520, round(520 * h / w)), Image.Resampling.LANCZOS).quantize(48, method=Image.Quantize.MAXCOVERAGE) for im in imgs]
    seq = imgs + imgs[-2:0:-1]
    IMAGES.mkdir(parents=True, exist_ok=True)
    seq[0].save(IMAGES / name, save_all=True, append_images=seq[1:], duration=120, loop=0, optimize=True)


def new_canvas(page, srv):
    """Open the studio on an empty canvas (New)."""
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    page.click("#new")


def open_studio(page, srv):
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.simulations > 0", timeout=30)


def test_serve_fourbar_drag_joint_path_follows(serve, page):
    srv = serve(example("fourbar"), "fourbar.yaml")
    open_studio(page, srv)
    path = page.locator('[data-path="M"]')
    d0 = path.get_attribute("d")
    assert d0.count("M") >= 1 and d0.count("L") > 50
    wait_settled(page)
    assert page.locator('[data-joint="B"]').count() == 1
    x, y = center(page, '[data-joint="B"]')
    n = page.evaluate("window.__studio.simulations")
    frames, stage = [], page.locator("#stage").bounding_box()
    page.mouse.move(x, y)
    page.mouse.down()
    for k in range(1, 13):
        page.mouse.move(x - 5 * k, y - 3 * k)
        wait_js(page, "() => window.__studio.simFor === window.__studio.mech")
        frames.append(page.screenshot(clip=stage))
    page.mouse.up()
    wait_simulated(page)
    save_gif(frames, "studio_drag.gif")
    d1 = path.get_attribute("d")
    assert d1 != d0  # the path followed the drag
    b = page.evaluate("window.__studio.mech.joints.find(j => j.id === 'B').point")
    assert b[0] < 1 and b[1] > 2  # B moved left and up in the file's pose
    # the drawn path is the simulated one of the dragged mechanism (compare with the library)
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics.analysis import simulate

    mech = page.evaluate("window.__studio.mech")
    sim = page.evaluate("window.__studio.sim")
    lib = simulate(mechanism_from_dict(mech), {"A": np.array(sim["input"]["values"])}, points=["M"])
    got = np.array([p if p is not None else [np.nan, np.nan] for p in sim["points"]["M"]["position"]], float)
    assert np.allclose(got, lib.points["M"].position, equal_nan=True)
    # each joint and each path follows the contract; nothing fetched from outside; no errors
    assert sorted(page.eval_on_selector_all("[data-joint]", "es => es.map(e => e.dataset.joint)")) == list("ABCD")
    assert page.outside_requests == [] and page.console_errors == []
    # dead points are marked; the analysis panel shows the formulas with their numbers
    assert page.locator("[data-deadpoint]").count() >= 2
    assert "W = 3·3 - 2·4 - 0 = 1" in page.locator("#tab-analysis").inner_text()
    shot(page, "studio_fourbar.png")


def test_undo_redo_and_animation(serve, page):
    srv = serve(example("crank_rocker"), "crank_rocker.yaml")
    open_studio(page, srv)
    before = page.evaluate("JSON.stringify(window.__studio.mech)")
    page.click("text=Drive")
    n = page.evaluate("window.__studio.simulations")
    page.mouse.click(*center(page, '[data-joint="A"]'))
    assert page.evaluate("window.__studio.mech.joints[0].actuated") is None
    page.wait_for_selector("#banner .note")  # no drive: said, not a blank page
    page.click("#undo")
    assert page.evaluate("JSON.stringify(window.__studio.mech)") == before
    wait_simulated(page, n)
    page.click("#redo")
    assert page.evaluate("window.__studio.mech.joints[0].actuated") is None
    page.click("#undo")
    wait_js(page, "() => window.__studio.sim !== null")
    page.click("text=Select")
    page.click("#play")
    wait_js(page, "() => window.__studio.frame > 5")
    page.click("#play")
    # the slider sets the input
    page.locator("#input-slider").fill("30")
    assert page.evaluate("window.__studio.frame") == 30
    assert "A = " in page.locator("#input-value").inner_text()
    # velocity plot of the coupler point, with the cursor at the frame shown
    page.click('#tabs [data-tab="plots"]')
    page.select_option("#plot-what", "point:M")
    # (velocity, acceleration and position: each chart's read-out at the slider's row)
    assert page.locator("#plots [data-cursor='30']").count() == page.locator("#plots .chart-canvas").count() == 3
    assert page.console_errors == []


def test_build_a_sixbar_from_nothing(serve, page):
    srv = serve(None)
    open_studio(page, srv) if False else page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    page.click("#new")
    page.click("text=Pivot")
    click_world(page, 0, 0)
    click_world(page, 5, 0)
    page.click("text=Link")
    for chain in ([(0, 0), (1, 2)], [(1, 2), (4, 3), (2.5, 4.5)], [(4, 3), (5, 0), (6.5, 2.5)],
                  [(2.5, 4.5), (5, 6)], [(5, 6), (6.5, 2.5)]):
        for p in chain:
            click_world(page, *p)
        page.keyboard.press("Enter")
    page.click("text=Drive")
    page.mouse.click(*center(page, '[data-joint="A"]'))
    page.click("text=Point")
    n = page.evaluate("window.__studio.simulations")
    click_world(page, 5.8, 4.9)
    wait_simulated(page, n)
    mech = page.evaluate("window.__studio.mech")
    assert len(mech["links"]) == 6 and len(mech["joints"]) == 7
    assert all(len(j["links"]) == 2 for j in mech["joints"])
    assert list(mech["points"]) == ["P"]
    page.wait_for_selector('[data-path="P"]')
    # the Analysis tab of the last edit (an earlier edit's analysis may still be on the page)
    wait_js(page, "() => document.querySelector('#tab-analysis').innerText.includes('W = 3·5 - 2·7 - 0 = 1')")
    text = page.locator("#tab-analysis").inner_text()
    assert "Assur groups" in text and "class II" in text
    # the same answer as the library for the Watt six-bar of the examples
    from mechsyn.structure.assur import assur_decomposition
    from mechsyn.io import mechanism_from_dict

    formula = assur_decomposition(mechanism_from_dict(mech)).structural_formula
    assert formula == "I(frame,L1) -> II(L2,L3) -> II(L4,L5)" and formula in text
    page.check("#assur-colours")
    page.click("text=Select")
    shot(page, "studio_sixbar.png")
    # an error is shown next to its element, never a blank page
    page.click("text=Delete")
    page.mouse.click(*center(page, '[data-link="L4"] .link-hit'))
    page.wait_for_selector("#banner .err, #banner .note")
    assert page.locator("[data-joint]").count() >= 5, page.console_errors
    assert page.console_errors == []


@pytest.mark.slow
def test_synthesise_fourbar_through_five_points(serve, page):
    srv = serve(None)
    new_canvas(page, srv)
    page.click("text=Targets")
    # five points on a smooth arc
    targets = [(1.0, 3.0), (2.0, 3.6), (3.0, 3.8), (4.0, 3.5), (4.8, 2.8)]
    for p in targets:
        click_world(page, *p)
    assert page.locator("[data-target]").count() == 5
    page.fill("#synth-time", "12")
    page.click("#synth-run")
    wait_js(page, "() => document.querySelector('#synth-progress').value > 0", timeout=30)
    shot(page, "studio_synthesis_progress.png")
    page.wait_for_selector("[data-apply]", timeout=90000)
    status = page.locator("#synth-status").inner_text()
    assert status.startswith("done")
    page.locator("[data-apply='0']").click()
    page.wait_for_selector('[data-path="P"]')
    wait_js(page, "() => window.__studio.sim && window.__studio.mech.name.includes('clicked')")
    sim = page.evaluate("window.__studio.sim")
    path = np.array([p for p in sim["points"]["P"]["position"] if p is not None])
    clicked = np.array(page.evaluate("window.__studio.targets"))
    gap = max(np.min(np.linalg.norm(path - t, axis=1)) for t in clicked)
    best = page.locator("[data-result='0']").inner_text()
    error = float(best.split()[1])
    # the applied four-bar's coupler point passes through every clicked point, up to the reported
    # error and half a step of the drawn sweep (180 input values)
    step = np.max(np.linalg.norm(np.diff(path, axis=0), axis=1))
    assert gap <= np.sqrt(error) + step / 2, (gap, step, best)
    assert error < 0.05, best
    shot(page, "studio_synthesis.png")
    assert page.console_errors == []


def test_save_and_reopen(serve, page, tmp_path):
    srv = serve(example("watt_sixbar"), "watt_sixbar.yaml")
    open_studio(page, srv)
    original = page.evaluate("window.__studio.mech")
    page.fill("#save-name", "my_sixbar.yaml")
    page.click("#save")
    wait_js(page, "() => document.querySelector('#banner').innerText.includes('saved my_sixbar.yaml')")
    assert (tmp_path / "my_sixbar.yaml").is_file()
    page.click("#new")
    wait_js(page, "() => window.__studio.mech.joints.length === 0")
    page.locator("#files").focus()
    page.wait_for_selector("#files option[value='my_sixbar.yaml']", state="attached")
    page.select_option("#files", "my_sixbar.yaml")
    wait_js(page, "() => window.__studio.mech.joints.length === 7")
    assert page.evaluate("window.__studio.mech") == original
    # upload a file from this computer, then download it as YAML
    page.set_input_files("#upload", str(example_path("slider_crank")))
    wait_js(page, "() => window.__studio.mech.name.startsWith('Slider-crank')")
    assert page.locator('rect[data-joint="D"]').count() == 1  # the P joint is drawn as a slider
    with page.expect_download() as dl:
        page.select_option("#export", "yaml")
    text = open(dl.value.path()).read()
    assert "Slider-crank" in text and "type: P" in text
    with page.expect_download() as dl:
        page.select_option("#export", "svg")
    assert "data-joint" in open(dl.value.path()).read()
    assert page.outside_requests == [] and page.console_errors == []


def test_atlas_open_a_chain(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    page.click('#tabs [data-tab="atlas"]')
    page.click("#atlas-go")
    page.wait_for_selector("[data-chain]")
    assert page.locator("[data-chain]").count() == 2
    page.locator("[data-open-chain='1']").click()
    wait_js(page, "() => window.__studio.mech.joints.length === 7")
    assert json.dumps(page.evaluate("window.__studio.mech.ground")).startswith('"L')
    assert page.console_errors == []


def test_draw_a_target_curve(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => window.__studio && window.__studio.mech")
    page.click("text=Targets")
    x0, y0 = screen(page, 0, 0)
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 21):
        page.mouse.move(x0 + 10 * k, y0 - 40 * np.sin(k / 6))
    page.mouse.up()
    n = page.evaluate("window.__studio.targets.length")
    assert 10 <= n <= 21 and page.locator("[data-target]").count() == n
    assert page.locator("#synth-kind option").count() == 3  # path, curve, motion
    page.click("#clear-targets")
    assert page.locator("[data-target]").count() == 0


def test_a_name_with_bidi_controls_is_shown_with_them_visible(serve, page):
    """A mechanism name holding a right-to-left override (U+202E) is shown with the control
    written out, never applied: the status line reads what the file holds."""
    m = example("fourbar")
    m["name"] = "four\u202ebar"
    srv = serve(m, "")
    open_studio(page, srv)
    wait_js(page, "() => document.querySelector('#status').textContent.includes('<U+202E>')")
    text = page.locator("#status").text_content()
    assert "four<U+202E>bar" in text and "\u202e" not in text
