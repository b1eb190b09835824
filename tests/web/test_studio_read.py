"""Issue 40: the studio as a designer's daily tool, the reading side. One browser test per
flow, through the page contract (data-joint, data-path, [data-banner], data-readout, inputs
named x, y), each checked against the library's answer; screenshots for a person to look at.
"""

from __future__ import annotations

import csv
import io
import re

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics.summary import motion_summary

from test_browser import center, click_world, example, new_canvas, open_studio, shot, wait_js, wait_settled, wait_simulated

BANNER = "() => document.querySelector('[data-banner]').innerText"


def banner_has(page, text, timeout=30.0):
    wait_js(page, "t => document.querySelector('[data-banner]').innerText.includes(t)", text, timeout=timeout)


def opened(serve, page, name, mech=None):
    """The studio open on example ``name`` (or ``mech`` under its name), simulated and analysed."""
    srv = serve(mech or example(name), f"{name}.yaml")
    open_studio(page, srv)
    wait_settled(page)
    return srv


def analysis_text(page, until):
    """The Analysis tab's text once the element ``until`` (a selector) or text is in it."""
    page.click('#tabs [data-tab="analysis"]')
    wait_js(page, """u => { const t = document.querySelector('#tab-analysis');
        return u.startsWith('[') ? t.querySelector(u) : t.innerText.includes(u); }""", until)
    return page.locator("#tab-analysis").inner_text()


def numbers(text):
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", text)]


# the cached check ---------------------------------------------------------------------------
def test_a_fourbar_built_along_one_line_then_opened_out_moves(serve, page):
    """The structure check is cached by everything it reads: a four-bar clicked along one row
    (W = 2 at that pose, it cannot be driven) and then given a regular shape by typing a
    joint's y is checked again and simulates; before, the first answer stayed forever."""
    new_canvas(page, serve(None))
    wait_js(page, "() => window.__studio.mech.joints.length === 0")
    page.click("text=Pivot")
    click_world(page, 0, 0)
    click_world(page, 4, 0)
    page.click("text=Link")
    for chain in ([(0, 0), (1, 0)], [(1, 0), (3, 0)], [(3, 0), (4, 0)]):
        for p in chain:
            click_world(page, *p)
        page.keyboard.press("Enter")
    page.click("text=Drive")
    page.mouse.click(*center(page, '[data-joint="A"]'))
    wait_js(page, "() => window.__studio.check && window.__studio.check.result.drives.length === 1")
    first = page.evaluate("window.__studio.check.result")
    assert first["mobility"] == 2 and any(d["blocks"] for d in first["diagnostics"])  # one line: cannot be driven
    assert page.evaluate("window.__studio.sim") is None
    shot(page, "studio_read_straight_fourbar.png")
    # the same topology opened out: pivot B, drawn at (4, 0), typed off the line
    page.click("text=Select")
    page.mouse.click(*center(page, '[data-joint="B"]'))
    page.click('#tabs [data-tab="element"]')
    page.fill('#tab-element input[name="y"]', "1")
    page.press('#tab-element input[name="y"]', "Enter")
    wait_js(page, "() => window.__studio.mech.joints.find(j => j.id === 'B').point[1] === 1")
    wait_js(page, "() => window.__studio.check && window.__studio.sim && window.__studio.simFor === window.__studio.mech && window.__studio.sim.rates")
    result = page.evaluate("window.__studio.check.result")
    assert result["mobility"] == 1 and not any(d["blocks"] for d in result["diagnostics"])
    sim = page.evaluate("window.__studio.sim")
    C = np.array([p for p in sim["points"]["C"]["position"] if p is not None])
    assert sim["assembled"][0] and len(C) > 10 and np.ptp(C, axis=0).max() > 0.1  # it moves
    lib = ms.simulate(ms.load(page.evaluate("window.__studio.mech")), {"A": np.array(sim["input"]["values"])})
    ok = lib.assembled
    assert np.allclose(np.array([p if p else [np.nan] * 2 for p in sim["points"]["C"]["position"]], float)[ok], lib.point("C")[ok])
    assert "W = 2" not in page.evaluate(BANNER) and "cannot move" not in page.evaluate(BANNER)
    shot(page, "studio_read_opened_fourbar.png")
    assert page.console_errors == []


# plots a designer reads -----------------------------------------------------------------------
def hover(page, selector, fx, fy=0.5):
    """Move the mouse over the element (a chart drawn again meanwhile is looked up again)."""
    for _ in range(50):
        el = page.locator(selector).first
        el.scroll_into_view_if_needed()
        box = el.bounding_box()
        if box:
            page.mouse.move(box["x"] + box["width"] * fx, box["y"] + box["height"] * fy)
            return
        page.wait_for_timeout(100)
    raise AssertionError(f"{selector} is not shown")


def test_plots_read_values_at_the_cursor_and_the_slider(serve, page):
    opened(serve, page, "crank_rocker")
    page.locator("#input-slider").fill("40")
    page.click('#tabs [data-tab="plots"]')
    page.select_option("#plot-what", "point:M")
    wait_js(page, "() => document.querySelectorAll('#plots .chart-canvas canvas').length === 3")
    sim = page.evaluate("window.__studio.sim")
    v = np.array(sim["points"]["M"]["velocity"], float)
    # the read-out at the slider: the velocity of M at row 40, as the library's
    readout = page.locator('#plots [data-plot="velocity of M"] [data-readout]')
    assert readout.get_attribute("data-cursor") == "40"
    got = numbers(readout.inner_text().split("\n")[0].split(":", 1)[1])
    assert got[:3] == pytest.approx([v[40, 0], v[40, 1], np.hypot(*v[40])], rel=1e-3, abs=1e-6)
    # hovering reads the value under the cursor, in every chart of the tab (shared cursor)
    hover(page, '#plots [data-plot="velocity of M"] .u-over', 0.25)
    wait_js(page, "() => document.querySelectorAll('#plots [data-readout]')[1].innerText.includes('at the cursor')")
    texts = page.eval_on_selector_all("#plots .chart:has(.chart-canvas) [data-readout]", "es => es.map(e => e.innerText)")
    rows = [re.search(r"at the cursor, A = (-?[\d.]+)°", t) for t in texts]
    assert all(rows) and len({r.group(1) for r in rows}) == 1  # the same input in all three
    x = float(rows[0].group(1))
    k = int(np.argmin(np.abs(np.array(sim["input"]["values"]) - x)))
    assert numbers(texts[0].split("\n")[1].split(":", 1)[1])[:2] == pytest.approx(v[k].tolist(), rel=1e-3, abs=1e-6)
    shot(page, "studio_read_plots.png")
    # max, min, mean and RMS of the plotted series
    cells = page.eval_on_selector_all('#plots [data-plot="velocity of M"] tr[data-series="vx"] td', "ts => ts.map(t => t.textContent)")
    vx = v[:, 0]
    assert [float(c) for c in cells[1:]] == pytest.approx([vx.max(), vx.min(), vx.mean(), np.sqrt(np.mean(vx**2))], rel=2e-3)
    # the legend toggles a series; the read-out leaves it out
    page.locator('#plots [data-plot="velocity of M"] .u-legend .u-series').nth(1).click()
    assert "u-off" in page.locator('#plots [data-plot="velocity of M"] .u-legend .u-series').nth(1).get_attribute("class")
    # zoom: a drag across the chart narrows its x range
    box = page.locator('#plots [data-plot="velocity of M"] .u-over').bounding_box()
    page.mouse.move(box["x"] + box["width"] * 0.3, box["y"] + 40)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] * 0.6, box["y"] + 40, steps=5)
    page.mouse.up()
    span = page.evaluate("""() => { const u = document.querySelector('#plots [data-plot="velocity of M"]').uplot;
        return u.scales.x.max - u.scales.x.min; }""")
    assert span < 0.5 * 360
    # CSV of the plotted data: the input and every series, as plotted
    with page.expect_download() as dl:
        page.click('#plots [data-plot="acceleration of M"] [data-csv]')
    table = list(csv.reader(io.StringIO(open(dl.value.path()).read())))
    assert table[0] == ["A (°)", "ax (units/s²)", "ay (units/s²)", "|a| (units/s²)"]
    a = np.array(sim["points"]["M"]["acceleration"], float)
    assert np.allclose(np.array(table[1:], float)[:, 1:3], a)
    # the coupler path as an x/y plot with its read-out
    assert page.locator('#plots [data-plot="path of M"] svg path').count() == 1
    assert "x = " in page.locator('#plots [data-plot="path of M"] [data-readout]').inner_text()
    assert page.console_errors == [] and page.outside_requests == []


def test_plots_of_joints_sliders_and_transmission(serve, page):
    opened(serve, page, "slider_crank")
    page.click('#tabs [data-tab="plots"]')
    labels = page.eval_on_selector_all("#plot-what optgroup", "gs => gs.map(g => g.label)")
    assert labels == ["joints", "links", "motion"]  # no named point in this file
    page.select_option("#plot-what", "joint:D")
    wait_js(page, "() => document.querySelector('#plots [data-plot=\"slide of D along its guide\"] canvas')")
    sim = page.evaluate("window.__studio.sim")
    s = np.array(sim["derived"]["slides"]["D"]["value"], float)
    assert np.allclose(s, np.array(sim["points"]["D"]["position"], float)[:, 0])  # a guide along x from the origin
    assert np.ptp(s) == pytest.approx(2.0, rel=1e-3)  # the stroke: twice the crank
    page.select_option("#plot-what", "joint:A")
    wait_js(page, "() => document.querySelector('#plots [data-plot=\"angle of joint A\"] canvas')")
    page.select_option("#plot-what", "transmission")
    wait_js(page, "() => document.querySelector('#plots [data-plot=\"transmission angle\"] canvas')")
    hover(page, "#plots .u-over", 0.5)
    wait_js(page, "() => /at the cursor, A = [\\d.]+°: μ B-C-D = [\\d.]+/.test(document.querySelector('#plots [data-readout]').innerText)")
    shot(page, "studio_read_transmission.png")
    assert page.console_errors == []


def test_forces_read_torque_with_its_sign_and_statistics(serve, page):
    mech = example("crank_rocker")
    named = lambda link: link if isinstance(link, str) else link["name"]  # noqa: E731
    mech["links"] = [{"name": "rocker", "mass": 2.0} if named(link) == "rocker" else link for link in mech["links"]]
    opened(serve, page, "crank_rocker", mech)
    page.click('#tabs [data-tab="forces"]')
    page.check("#forces-gravity")
    wait_js(page, """() => { const f = window.__studio.forces; return f && f.mech === window.__studio.mech && f.r && f.r.gravity[1] < 0
        && document.querySelector('#tab-forces [data-plot="drive A"] canvas'); }""")
    text = page.locator("#tab-forces").inner_text()
    assert "counter-clockwise positive" in text and "first link on its second" in text
    tau = np.array(page.evaluate("window.__studio.forces.r.drives.A.value"), float)
    cells = page.eval_on_selector_all('#tab-forces [data-plot="drive A"] tr[data-series] td', "ts => ts.map(t => t.textContent)")
    assert [float(c) for c in cells[1:]] == pytest.approx([tau.max(), tau.min(), tau.mean(), np.sqrt(np.mean(tau**2))], rel=2e-3, abs=1e-9)
    hover(page, '#tab-forces [data-plot="drive A"] .u-over', 0.7)
    wait_js(page, "() => document.querySelector('#tab-forces [data-plot=\"drive A\"] [data-readout]').innerText.includes('at the cursor')")
    got = page.locator('#tab-forces [data-plot="drive A"] [data-readout]').inner_text()
    assert re.search(r"at the cursor, A = [\d.]+°: τ A = -?[\d.]+", got), got
    # the four reactions in four distinct colours
    colours = page.eval_on_selector_all('#tab-forces [data-plot="reactions"] tr[data-series] td:first-child', "ts => ts.map(t => t.style.color)")
    assert len(colours) == 4 and len(set(colours)) == 4
    page.locator("#input-slider").fill("40")
    assert page.locator('#tab-forces [data-plot="reactions"] [data-cursor="40"]').count() == 1
    shot(page, "studio_read_forces.png")
    assert page.console_errors == []


# the Analysis tab --------------------------------------------------------------------------------
def test_analysis_names_the_stroke_the_rocker_range_and_the_time_ratio(serve, page):
    opened(serve, page, "slider_crank")
    text = analysis_text(page, '[data-stroke="D"]')
    m = ms.examples.load("slider_crank")
    lib = motion_summary(m, ms.simulate(m, {"A": np.array(page.evaluate("window.__studio.sim.input.values"))}))
    stroke = re.search(r"slider D: stroke ([\d.]+)", text)
    assert stroke and float(stroke.group(1)) == pytest.approx(lib["sliders"]["D"]["stroke"], rel=1e-3)
    assert "time ratio 1 " in text
    # the result first: the mobility in words at the top, the formulas folded away
    assert text.startswith("Mobility W = 1: moves with 1 drive")
    assert not page.locator("#tab-analysis details.specialist").get_attribute("open")
    shot(page, "studio_read_analysis_slider.png")
    page.select_option("#examples", "crank_rocker")
    wait_js(page, "() => document.querySelector('#tab-analysis [data-rocker=\"rocker\"]') && window.__studio.fileName.startsWith('crank_rocker')")
    text = page.locator('#tab-analysis [data-rocker="rocker"]').inner_text()
    m = ms.examples.load("crank_rocker")
    lib = motion_summary(m, ms.simulate(m, {"A": np.array(page.evaluate("window.__studio.sim.input.values"))}))["rockers"]["rocker"]
    swing, ratio = re.search(r"swings ([\d.]+)°", text), re.search(r"time ratio ([\d.]+)", text)
    assert float(swing.group(1)) == pytest.approx(lib["range"], abs=0.06)
    assert float(ratio.group(1)) == pytest.approx(lib["time_ratio"]["ratio"], abs=6e-4)
    assert page.console_errors == []


def test_one_working_range_through_360_and_a_closed_curve_drawn_closed(serve, page):
    opened(serve, page, "fourbar")
    text = analysis_text(page, "working range")
    dead = sorted(e["input"]["A"] for e in page.evaluate("window.__studio.sim.events") if e["kind"] == "dead point")
    line = next(x for x in text.split("\n") if x.startswith("working range"))
    assert line == f"working range of A: {dead[1]:.1f}° … {dead[0]:.1f}° through 360° ({dead[0] + 360 - dead[1]:.1f}° wide)"
    # a crank-rocker's coupler curve is closed: its drawing ends where it starts
    page.select_option("#examples", "crank_rocker")
    wait_js(page, "() => window.__studio.fileName.startsWith('crank_rocker') && window.__studio.simFor === window.__studio.mech && window.__studio.sim")
    d = page.get_attribute('[data-path="M"]', "d")
    pts = re.findall(r"[ML](-?[\d.]+) (-?[\d.]+)", d)
    assert d.count("M") == 1 and pts[0] == pts[-1] and len(pts) == 181
    shot(page, "studio_read_closed_curve.png")
    assert page.console_errors == []


# the rest of the list -------------------------------------------------------------------------------
def test_a_stale_or_missing_token_says_how_to_open_the_studio(serve, page):
    srv = serve(example("fourbar"), "fourbar.yaml")
    page.goto(srv.url.replace("token=", "token=from-before-a-restart"))
    banner_has(page, "token is stale")
    assert "mechsyn serve" in page.evaluate(BANNER)
    shot(page, "studio_read_stale_token.png")
    page.goto(srv.url.split("?")[0])
    banner_has(page, "opened without its token")
    assert "?token=" in page.evaluate(BANNER)


def test_new_first_pivot_arrow_keys_and_examples(serve, page):
    opened(serve, page, "crank_rocker")
    # the arrow keys step the input, again and again (held down, the key repeats)
    page.locator("#input-slider").click()
    start = page.evaluate("window.__studio.frame")
    for _ in range(5):
        page.keyboard.press("ArrowRight")
    assert page.evaluate("window.__studio.frame") == start + 5
    page.keyboard.press("ArrowLeft")
    assert page.evaluate("window.__studio.frame") == start + 4
    # New: no file name, the default zoom
    page.mouse.move(*center(page, '[data-joint="B"]'))
    page.mouse.wheel(0, -600)
    assert page.evaluate("window.__studio.view.s") > 61
    page.click("#new")
    wait_js(page, "() => window.__studio.mech.joints.length === 0")
    assert page.input_value("#save-name") == "" and page.evaluate("window.__studio.fileName") == ""
    assert page.evaluate("window.__studio.view") == {"s": 60, "ox": 3, "oy": 2}
    # the first pivot: the next step, not a file-syntax error
    page.click("text=Pivot")
    click_world(page, 0, 0)
    banner_has(page, "not joined to a moving link yet")
    assert "links: [" not in page.evaluate(BANNER)
    assert "links: [" not in analysis_text(page, "Nothing to analyse yet")
    shot(page, "studio_read_first_pivot.png")
    # the examples grouped, planar first, and a search box that narrows them
    groups = page.eval_on_selector_all("#examples optgroup", "gs => gs.map(g => g.label)")
    assert groups[0].startswith("planar — ") and any(g.startswith("spatial — ") for g in groups)
    kinds = [g.split(" — ")[0] for g in groups]
    assert kinds == sorted(kinds, key=lambda k: k != "planar")
    page.fill("#examples-search", "jansen")
    shown = page.eval_on_selector_all("#examples option[data-words]", "os => os.filter(o => !o.hidden).map(o => o.value)")
    assert shown and all("jansen" in page.evaluate("n => [...document.querySelectorAll('#examples option')].find(o => o.value === n).dataset.words", n) for n in shown)
    page.press("#examples-search", "Enter")
    wait_js(page, "n => window.__studio.fileName.startsWith(n + '.')", shown[0])
    wait_simulated(page)
    assert page.console_errors == []


def test_taut_and_duplicate_bar_banners(serve, page):
    srv = serve(example("fourbar_taut"), "fourbar_taut.yaml")
    page.goto(srv.url)
    banner_has(page, "cannot move")
    assert "branch" not in page.evaluate(BANNER)
    shot(page, "studio_read_taut.png")
    page.select_option("#examples", "double_parallelogram")
    banner_has(page, "is redundant")
    text = page.evaluate(BANNER)
    assert "crank2" in text and "crank3" in text and "still moves" in text
    wait_js(page, "() => window.__studio.analysis && window.__studio.analysis.structure && window.__studio.sim")
    assur = next(x for x in analysis_text(page, "Assur groups").split("\n") if x.startswith("Assur groups"))
    assert "it moves" in assur and "not a mechanism" not in assur
    shot(page, "studio_read_double_parallelogram.png")
    assert page.console_errors == []
