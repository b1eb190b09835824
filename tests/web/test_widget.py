"""The notebook widget: the studio's front end in a cell, answered by the same app."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("anywidget")

from mechsyn.io import load_mechanism  # noqa: E402
from mechsyn.web._service import example_path  # noqa: E402
from mechsyn.web.widget import MechanismWidget, widget_esm  # noqa: E402


@pytest.fixture
def widget(tmp_path):
    return load_mechanism(example_path("fourbar")).widget(root=tmp_path)


def test_widget_answers_like_the_server(widget):
    assert isinstance(widget, MechanismWidget)
    start = widget.answer({"id": 1, "path": "/api/start", "method": "GET"})
    assert start["ok"] and start["id"] == 1 and start["data"]["mechanism"] == widget.value
    sim = widget.answer({"id": 2, "path": "/api/simulate", "method": "POST",
                         "body": {"mechanism": widget.value, "steps": 12}})
    assert sim["ok"] and len(sim["data"]["points"]["B"]["position"]) == 12
    bad = widget.answer({"id": 3, "path": "/api/simulate", "method": "POST", "body": {"mechanism": {}}})
    assert not bad["ok"] and bad["data"]["field"]
    assert not widget.answer({"id": 4, "path": "/etc/passwd", "method": "GET"})["ok"]


def test_edits_flow_back(widget):
    v = dict(widget.value)
    v["joints"] = [dict(j) for j in v["joints"]]
    v["joints"][1]["point"] = [0.9, 2.1]
    widget.value = v
    assert widget.mechanism.joint("B").point[:2].tolist() == [0.9, 2.1]


def test_widget_front_end_in_chromium(widget, page):
    """The widget's module rendered in Chromium with a stand-in for Jupyter's model,
    whose messages go to the widget's Python side: drag B, the path follows, the
    edit arrives in ``widget.value``."""
    esm = widget_esm().replace("export default {", "const __widget = {")
    harness = esm + """
const model = { handlers: [], values: {}, on(ev, f) { this.handlers.push(f); },
  send(msg) { window.kernelSend(msg).then((r) => this.handlers.forEach((h) => h(r))); },
  set(k, v) { this.values[k] = v; }, save_changes() { window.kernelSave(this.values.value); } };
__widget.render({ model, el: document.body });
"""
    page.expose_function("kernelSend", widget.answer)
    page.expose_function("kernelSave", lambda v: setattr(widget, "value", v))
    page.set_content("<!doctype html><html><body></body></html>")
    page.add_style_tag(content=widget.get_state()["_css"])
    page.add_script_tag(content=harness, type="module")
    page.wait_for_selector('[data-path="M"]', timeout=30000)
    d0 = page.get_attribute('[data-path="M"]', "d")
    x, y = page.evaluate("""() => { const r = document.querySelector('[data-joint="B"]').getBoundingClientRect();
        return [r.left + r.width / 2, r.top + r.height / 2]; }""")
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x - 20, y - 15, steps=4)
    page.mouse.up()
    for _ in range(200):
        if page.evaluate("window.__studio.simFor === window.__studio.mech") and \
                page.get_attribute('[data-path="M"]', "d") != d0:
            break
        page.wait_for_timeout(25)
    assert page.get_attribute('[data-path="M"]', "d") != d0
    b = widget.mechanism.joint("B").point[:2]
    assert b[0] < 1 and b[1] > 2 and not np.allclose(b, [1, 2])
    assert page.console_errors == []


def test_widget_keeps_keys_and_styles_to_itself(widget, page):
    """Issue 24, 13: in a notebook, a studio shortcut (X) must not reach JupyterLab (which cuts
    the cell), and the widget's CSS must not restyle the notebook's own buttons."""
    esm = widget_esm().replace("export default {", "const __widget = {")
    harness = esm + """
const model = { handlers: [], values: {}, on(ev, f) { this.handlers.push(f); },
  send(msg) { window.kernelSend(msg).then((r) => this.handlers.forEach((h) => h(r))); },
  set(k, v) { this.values[k] = v; }, save_changes() {} };
window.outerKeys = [];
document.addEventListener("keydown", (e) => window.outerKeys.push(e.key));
const cell = document.getElementById("cell");
__widget.render({ model, el: cell });
"""
    page.expose_function("kernelSend", widget.answer)
    page.set_content('<!doctype html><html><body><button id="notebook-button">Run</button><div id="cell"></div></body></html>')
    outside = page.evaluate("() => getComputedStyle(document.getElementById('notebook-button')).padding")
    page.add_style_tag(content=widget.get_state()["_css"])
    page.add_script_tag(content=harness, type="module")
    page.wait_for_selector('[data-path="M"]', timeout=30000)
    assert page.evaluate("() => getComputedStyle(document.getElementById('notebook-button')).padding") == outside
    page.click(".mechsyn-studio #canvas")
    page.keyboard.press("x")
    assert page.evaluate("window.__studio.mode") == "delete"  # the studio heard it
    assert page.evaluate("window.outerKeys") == []  # the notebook did not
    assert page.get_attribute(".mechsyn-studio", "data-lm-suppress-shortcuts") == "true"


def test_widget_shows_no_deprecation_warning():
    """Every widget cell showed starlette's StarletteDeprecationWarning about its test client."""
    import subprocess
    import sys

    code = ("import warnings; warnings.simplefilter('always')\n"
            "with warnings.catch_warnings(record=True) as w:\n"
            "    warnings.simplefilter('always')\n"
            "    from mechsyn.web.widget import MechanismWidget\n"
            "    import mechsyn as ms\n"
            "    MechanismWidget(ms.load('fourbar'))\n"
            "print([str(x.message) for x in w if 'starlette' in str(x.message).lower() or 'Starlette' in type(x.message).__name__])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout
