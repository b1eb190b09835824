"""Issue 41: the studio's path synthesis says, as ``synth path`` does, when a bound decides
its result and how to lift it: each listed design carries its report's ``reason``
(:class:`mechsyn.synthesis.optimize.PathSynthesisResult`), shown under it as text."""

from __future__ import annotations

import numpy as np
import pytest

from mechsyn.synthesis.fourbar import fourbar_position
from mechsyn.synthesis.optimize import synthesize_path
from mechsyn.synthesis.path import PathProblem
from mechsyn.web._service import _with_branch, fourbar_path_case

from test_browser import click_world, new_canvas, shot, wait_js
from test_routes import _wait

#: A crank-rocker (frame 3, crank 1, coupler 3, rocker 2.5, coupler point (1, 1)) larger than
#: the studio's size bound of 1.5 target diagonals about its coupler curve's eight points.
KNOWN = (3.0, 1.0, 3.0, 2.5)
RC = (1.0, 1.0)
TH = np.linspace(0.0, 2 * np.pi, 9)[:-1]


def _targets(shift=(0.0, 0.0)) -> list:
    C = np.asarray(fourbar_position(*KNOWN, TH, branch=-1, rcx=RC[0], rcy=RC[1]).C)
    return (C + shift).tolist()


def test_the_known_design_is_outside_the_studios_size_bound():
    """The premise: the exact design is not in the studio's design space, so a bound decides."""
    case = fourbar_path_case(_targets(), 10.0)
    assert case.max_size == 1.5
    problem = PathProblem(case)
    d = {**case.fixed, **dict(zip(("r1", "r2", "r3", "r4"), KNOWN)), "rcx": RC[0], "rcy": RC[1],
         "x0": 0.0, "y0": 0.0, "theta0": 0.0}
    z = np.array([[d[n] for n in problem.linkage_vars] + list(TH)])
    assert problem.size(problem.unpack(z)[0])[0] / problem.frame[1] > 1.5


@pytest.mark.slow
def test_path_job_carries_the_reports_reason(client):
    """The job's results carry the library report's ``reason`` for the same case, seed and
    limit (a generous limit: every restart ends by converging, none is cut by the clock)."""
    targets, limit = _targets(), 120.0
    job = client.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": limit, "restarts": 1}).json()
    s = _wait(client, job["id"], timeout=300)
    assert s["state"] == "done", s
    got = {r["branch"]: (r["reason"], r["error"]) for r in s["result"]["results"]}
    case = fourbar_path_case(targets, limit)
    want = {}
    for b, branch in enumerate((-1, 1)):
        res = synthesize_path(_with_branch(case, branch), seed=b, time_limit=limit / 2, restarts=1)
        want[branch] = (res.to_dict()["reason"], float(res.error))
    assert got == want
    decided = [r for r, _ in got.values() if r.startswith("a bound decides this result: ")]
    assert decided and all("lifts it" in r or "widen it" in r for r in decided), got
    assert any("sits on the size bound 1.5" in r for r in decided), got


@pytest.mark.slow
def test_max_size_0_lifts_the_size_bound(client):
    """``max_size: 0`` (as ``synth path --max-size 0``): the known design's case is decided by
    no size bound, and the best design found is larger than the default bound allows."""
    job = client.post("/api/synth/fourbar_path",
                      json={"targets": _targets(), "time_limit": 120.0, "restarts": 1, "max_size": 0}).json()
    s = _wait(client, job["id"], timeout=300)
    assert s["state"] == "done", s
    results = s["result"]["results"]
    assert not any("size bound" in r["reason"] for r in results), [r["reason"] for r in results]
    assert results[0]["feasible"] and results[0]["quality"]["size_ratio"] > 1.5, results[0]["quality"]


@pytest.mark.parametrize("value, message", [(-1, "greater than or equal to 0"), ("abc", "must be a number")])
def test_a_negative_or_untyped_max_size_is_400_naming_it(client, value, message):
    r = client.post("/api/synth/fourbar_path", json={"targets": _targets(), "max_size": value})
    assert r.status_code == 400, (r.status_code, r.text[:300])
    assert r.json()["field"] == "max_size" and message in r.json()["error"], r.json()


def test_the_page_shows_each_results_reason(serve, page):
    srv = serve(None)
    new_canvas(page, srv)
    page.click("text=Targets")
    for p in _targets(shift=(2.5, 1.2)):
        click_world(page, *p)
    assert page.locator("[data-target]").count() == len(TH)
    page.fill("#synth-time", "200")   # converges in seconds; the limit never cuts a restart
    with page.expect_response("**/api/synth/fourbar_path") as posted:
        page.click("#synth-run")
    job = posted.value.json()["id"]
    page.wait_for_selector("[data-apply]", timeout=300000)
    wait_js(page, "() => document.querySelector('#synth-status').innerText.startsWith('done')")
    result = page.evaluate("""id => fetch(`/api/jobs/${id}`, {headers: {'X-Mechsyn-Token':
        new URLSearchParams(location.search).get('token')}}).then(r => r.json())""", job)["result"]
    reasons = [r.get("reason", "") for r in result["results"]]
    assert any(r.startswith("a bound decides this result: ") for r in reasons), reasons
    for i, reason in enumerate(reasons):   # shown as text under its own result, or nothing
        shown = page.locator(f"[data-result='{i}'] [data-reason]")
        assert shown.all_inner_texts() == ([reason] if reason else [])
    page.locator("[data-result='0']").hover()
    shot(page, "studio_synthesis_reason.png")
    assert page.console_errors == []
