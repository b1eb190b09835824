"""Issue 25 item 5 (studio), finished: a spatial file's Element, Plots and Forces tabs.

The route tests check the Plots tab's numbers against ``ms.simulate`` (the same
``SpatialSimulation`` as ``mechsyn simulate``) and against finite differences of the
positions (velocities), and the check's reading of a Bennett linkage whose special geometry
an edit broke (rigid: finite mobility 0) or kept (a point moved along its own axis: still
mobile, the paths unchanged). The browser test drives Debian's Chromium: a click on a joint
in the 3-D view selects it and fills the Element tab with its values, the Plots tab draws a
curve per pair angle at the library's values, the Forces tab says in one line that spatial
statics are missing, a typed point moves the drawing, and a typed point that breaks the
Bennett condition is explained in the banner.
"""

from __future__ import annotations

import numpy as np
import pytest

import mechsyn as ms
from test_browser import shot, wait_js
from test_studio_3d import open_example as open_in_3d
from test_studio_3d import set_slider, spatial_dict


def column(rows, i=None):
    """Rows of a plots answer as an array (NaN for None); component ``i`` of [x, y, z] rows."""
    return np.array([np.nan if v is None else (v if i is None else v[i]) for v in rows], float)


def test_spatial_route_is_ms_simulate_and_the_cli_json(client, cli_json, tmp_path):
    """The 3-D view and the Plots tab draw the library's SpatialSimulation: the route answers its
    ``to_dict()``, which ``mechsyn simulate --json`` prints for the same inputs."""
    import json

    mech = spatial_dict("bennett")
    p = client.post("/api/spatial/simulate", json={"mechanism": mech, "steps": 90}).json()
    u = np.asarray(p["input"]["values"])
    sim = ms.simulate(ms.examples.load("bennett"), {"R1": u})
    assert p == json.loads(json.dumps(sim.to_dict()))
    path = tmp_path / "bennett.json"
    path.write_text(json.dumps(mech))
    assert cli_json("simulate", path, "--input", f"R1={float(u[0])!r}:{float(u[-1])!r}:4.0") == p
    assert sorted(p["joints"]) == ["R1", "R2", "R3", "R4"]
    assert np.allclose(column(p["joints"]["R1"]), u, atol=1e-7)  # the drive's own angle is the input
    L = p["length_scale"]
    for name, pt in p["points"].items():
        X = np.array([column(pt["position"], i) for i in range(3)]).T
        V = np.array([column(pt["velocity"], i) for i in range(3)]).T
        h = np.radians(u[1] - u[0])  # independent: fourth-order central differences per radian of R1
        dX = (-X[4:] + 8 * X[3:-1] - 8 * X[1:-3] + X[:-4]) / (12 * h)
        assert np.allclose(V[2:-2], dX, atol=2e-3 * L), name  # R3's largest difference at 4 degree steps: 6e-4
    w = np.array([column(p["links"]["link1"]["angular_velocity"], i) for i in range(3)]).T
    assert np.allclose(w, [0.0, 0.0, 1.0], atol=1e-9)  # the crank turns about R1's axis z at 1 rad/s


def test_spatial_route_marks_the_rssr_dead_point_and_refuses_a_planar_file(client):
    p = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("rssr"), "steps": 180}).json()
    dead = [e for e in p["events"] if e["kind"] == "dead point"]
    assert dead and all(p["assembled"][e.get("last", e["index"] - 1)] for e in dead)  # the row it bounds
    ok = np.asarray(p["assembled"])
    for values in p["joints"].values():  # rows not assembled are None, never numbers
        assert all((x is None) == (not good) for x, good in zip(values, ok))
    planar = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("fourbar")})
    assert planar.status_code == 400 and planar.json()["field"] == "kind"


def _moved(jid, delta):
    out = spatial_dict("bennett")
    j = next(j for j in out["joints"] if j["id"] == jid)
    j["point"] = (np.asarray(j["point"]) + delta).tolist()
    return out


def test_check_calls_a_broken_bennett_rigid_with_the_finite_mobility_reading(client):
    def diagnostics(mech):
        r = client.post("/api/studio/check", json={"mechanism": mech})
        assert r.status_code == 200, r.text
        return r.json()["diagnostics"]

    # R3 moved across its axis: the axes no longer satisfy Bennett's condition, the loop is rigid
    broken = diagnostics(_moved("R3", [0.05, 0.0, 0.0]))
    assert [d["level"] for d in broken] == ["error"] and broken[0]["blocks"]
    msg = broken[0]["message"]
    assert "rigid at the drawn pose" in msg and "finite mobility 0" in msg and "R1" in msg
    assert broken[0]["elements"] == [{"kind": "joint", "id": "R1"}]
    # R2 moved along its own axis: the same lines, the same linkage, still mobile
    axis = np.asarray(next(j for j in spatial_dict("bennett")["joints"] if j["id"] == "R2")["axis"])
    kept = diagnostics(_moved("R2", 0.4 * axis))
    assert kept[0]["level"] == "note" and kept[0]["message"].startswith("spatial mechanism: 3-D view")
    # ... and its paths are those of the drawn file (every joint point but R2's own is unchanged)
    a = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("bennett"), "steps": 36}).json()
    b = client.post("/api/spatial/simulate", json={"mechanism": _moved("R2", 0.4 * axis), "steps": 36}).json()
    assert np.allclose(np.array(a["points"]["R3"]["position"]), np.array(b["points"]["R3"]["position"]),
                       atol=1e-9 * a["length_scale"])
    # the files that cannot move were already refused with the drives named: the tilted Bennett
    tilted = diagnostics(spatial_dict("bennett_tilted"))
    assert tilted[0]["level"] == "error" and "finite mobility 0" in tilted[0]["message"]


# ------------------------------------------------------------------------------ browser
def open_example(serve, page, name):
    """The studio with example ``name`` in its 3-D view, checked and analysed."""
    page.goto(serve(None).url)
    wait_js(page, "() => document.querySelectorAll('#examples option').length > 20")
    open_in_3d(page, name)
    wait_js(page, "() => window.__studio.check && window.__studio.analysis && !window.__studio.analysis.error")


def settled(page):
    """Until the 3-D view, the check and the analysis are those of the mechanism edited."""
    wait_js(page, "() => window.__view3d.mech === window.__studio.mech && window.__view3d.view && !window.__view3d.loading"
                  " && window.__studio.check !== null", timeout=60)


def centre_of(page, jid):
    return page.evaluate("""id => { const r = document.querySelector(`#view3d [data-joint="${id}"]`).getBoundingClientRect();
        return [r.x + r.width / 2, r.y + r.height / 2]; }""", jid)


CHART_DATA = """() => [...document.querySelectorAll('#plots .chart')].filter(c => c.uplot).map(c => ({
    title: c.querySelector('.chart-title').textContent, labels: c.uplot.series.slice(1).map(s => s.label),
    data: c.uplot.data, marks: c.marks }))"""


@pytest.mark.slow
def test_bennett_element_plots_forces_and_edits(serve, page):
    open_example(serve, page, "bennett")
    mech = spatial_dict("bennett")
    r2 = next(j for j in mech["joints"] if j["id"] == "R2")
    # a click on a joint in the 3-D view selects it and fills the Element tab with its values
    page.click("#tabs button[data-tab=element]")
    page.click('#view3d [data-joint="R2"] text', force=True)
    wait_js(page, "() => document.querySelector('#view3d [data-joint=\"R2\"]').dataset.selected === 'true'"
                  " && document.querySelector('#tab-element input[name=z]')")
    assert page.locator("#view3d [data-selected]").count() == 1
    assert "Joint R2: R pair (revolute)" in page.locator("#tab-element h3").inner_text()
    fields = {n: float(page.input_value(f'#tab-element input[name="{n}"]')) for n in ("x", "y", "z", "ax", "ay", "az")}
    assert [fields[n] for n in "xyz"] == pytest.approx(r2["point"], abs=1e-7)
    assert [fields[n] for n in ("ax", "ay", "az")] == pytest.approx(r2["axis"], abs=1e-7)
    shot(page, "studio_3d_element.png")
    # Plots: a curve per pair angle, the axis in degrees, at the library's values
    page.click("#tabs button[data-tab=plots]")
    wait_js(page, "() => window.__spatialPlots.data && window.__spatialPlots.mech === window.__studio.mech"
                  " && document.querySelector('#plots .chart canvas')")
    (c,) = page.evaluate(CHART_DATA)
    assert c["labels"] == ["R1", "R2", "R3", "R4"]
    assert c["title"] == "joint angles from the drawn pose (°) against R1 (°)"
    u = np.asarray(page.evaluate("() => window.__spatialPlots.data.input.values"))
    sim = ms.simulate(ms.examples.load("bennett"), {"R1": u})
    assert np.array(c["data"][0]) == pytest.approx(u)
    for i, key in enumerate(c["labels"]):  # each curve at the library's values, row by row
        assert np.array(c["data"][i + 1], float) == pytest.approx(np.asarray(sim.joints[key], float), abs=1e-6), key  # the route rounds
    set_slider(page, 30)
    wait_js(page, "() => document.querySelector('#plots [data-cursor]').dataset.cursor === '30'")
    shot(page, "studio_3d_plots.png")
    # Forces: one line saying spatial statics are missing, then the rank method's reading
    page.click("#tabs button[data-tab=forces]")
    wait_js(page, "() => document.querySelector('#tab-forces [data-spatial-forces]') && document.querySelector('#tab-forces li')")
    text = page.locator("#tab-forces").inner_text()
    assert "spatial statics are not in mechsyn yet" in text
    assert "finite mobility 1" in text and "3 redundant constraint(s)" in text
    assert page.locator("#tab-forces .err").count() == 0
    # Joints: x, y, z of every joint; bar lengths in 3-D (Bennett's a1 = 1, a2 = sqrt(3), a3 = 1)
    page.click("#tabs button[data-tab=joints]")
    assert page.input_value('[data-table="joints"] [data-row="R3"] input[data-field="z"]') == "0.28725884"
    bars = {b: float(page.input_value(f'[data-table="links"] [data-row="{b}"] input[data-field="length"]'))
            for b in ("link1", "link2", "link3")}
    assert bars == pytest.approx({"link1": 1.0, "link2": 3 ** 0.5, "link3": 1.0}, abs=1e-7)
    # a typed point moves the 3-D drawing: R1 along its own axis (z), the linkage still moves
    set_slider(page, 0)
    page.click("#tabs button[data-tab=element]")
    page.click('#view3d [data-joint="R1"] text', force=True)
    wait_js(page, "() => document.querySelector('#view3d [data-joint=\"R1\"]').dataset.selected === 'true'")
    before = centre_of(page, "R1")
    page.fill('#tab-element input[name="z"]', "0.4")
    page.press('#tab-element input[name="z"]', "Enter")
    settled(page)
    wait_js(page, "() => window.__studio.mech.joints[0].point[2] === 0.4")
    settled(page)
    after = centre_of(page, "R1")
    assert np.hypot(after[0] - before[0], after[1] - before[1]) > 10
    assert page.locator("[data-banner] .err").count() == 0 and "3-D view" in page.locator("[data-banner]").inner_text()
    assert all(page.evaluate("() => window.__view3d.view.assembled"))
    # a typed point that breaks the Bennett condition: rigid, said in the banner with the reading
    page.click('#view3d [data-joint="R3"] text', force=True)
    wait_js(page, "() => document.querySelector('#view3d [data-joint=\"R3\"]').dataset.selected === 'true'")
    x3 = next(j for j in mech["joints"] if j["id"] == "R3")["point"][0]
    page.fill('#tab-element input[name="x"]', f"{x3 + 0.05:.8f}")
    page.press('#tab-element input[name="x"]', "Enter")
    settled(page)
    wait_js(page, "() => document.querySelector('[data-banner] .err')")
    banner = page.locator("[data-banner] .err").first.inner_text()
    assert "rigid at the drawn pose" in banner and "finite mobility 0" in banner
    shot(page, "studio_3d_rigid.png")
    # undo brings the moving linkage back
    page.click("#undo")
    settled(page)
    wait_js(page, "() => !document.querySelector('[data-banner] .err')")
    assert page.outside_requests == [] and page.console_errors == []


@pytest.mark.slow
def test_rssr_plots_mark_the_dead_point_and_leave_gaps(serve, page):
    open_example(serve, page, "rssr")
    page.click("#tabs button[data-tab=plots]")
    wait_js(page, "() => window.__spatialPlots.data && window.__spatialPlots.mech === window.__studio.mech"
                  " && document.querySelector('#plots .chart canvas')")
    d = page.evaluate("() => window.__spatialPlots.data")
    dead = [e for e in d["events"] if e["kind"] == "dead point"]
    assert dead
    charts = page.evaluate(CHART_DATA)
    assert charts
    for c in charts:  # every plot marks every dead point where the engine found it
        assert [m["x"] for m in c["marks"] if m["kind"] == "dead point"] == pytest.approx(
            [d["input"]["values"][e["index"]] for e in dead], abs=1e-12)
    # the working range stops at the dead point: the curve has a gap, never numbers across it
    ok = np.asarray(d["assembled"])
    runs = int(ok[0]) + int(np.count_nonzero(ok[1:] & ~ok[:-1]))
    assert runs >= 2 and not ok.all()
    a = charts[0]["data"][charts[0]["labels"].index("A") + 1]
    assert [v is not None for v in a] == ok.tolist()  # null (a gap in the curve) exactly where not assembled
    text = page.locator("#plots").inner_text()
    assert f"dead point at A = {dead[0]['input']['A']:.2f}" in text
    assert page.outside_requests == [] and page.console_errors == []
