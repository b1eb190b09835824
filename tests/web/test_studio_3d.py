"""Issue 25 item 5 (studio): spatial files open in a 3-D view drawn from the spatial engine.

The route test checks the view's numbers against the mechanism's geometry (rigid links keep
their lengths, a Bennett linkage's neighbouring axes keep their twist, the drawn pose is
row ``home``); the browser tests drive Debian's Chromium: the Examples menu opens the
Bennett linkage and the Delta robot in the 3-D view with one ``data-joint`` element per
joint, orbiting and the input slider move the joints on the screen, nothing is requested
outside the server.
"""

from __future__ import annotations

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.web._service import example_path

from test_browser import shot, wait_js


def spatial_dict(name):
    return mechanism_to_dict(load_mechanism(example_path(name)))


def rows(view, jid):
    """(N, 3) positions of joint ``jid`` in a scene (NaN where not assembled)."""
    j = next(j for j in view["joints"] if j["id"] == jid)
    return np.array([p if p is not None else [np.nan] * 3 for p in j["position"]], float)


def scene_of(page, motion, mech):
    """The page's scene (``sceneOf`` of static/view3d.js: joints and axes placed by the links'
    poses) of the simulation ``motion`` of ``mech``."""
    return page.evaluate("async ([m, mech]) => (await import('/static/view3d.js')).sceneOf(m, mech)", [motion, mech])


def test_scene_of_bennett_rigid_and_from_the_drawn_pose(client, serve, page):
    """The route answers the SpatialSimulation's to_dict; the page places the joints and their
    axes from the links' poses: rigid links keep their lengths, neighbouring axes their twist,
    the drawn pose is row ``home``."""
    mech = spatial_dict("bennett")
    r = client.post("/api/spatial/simulate", json={"mechanism": mech, "steps": 90})
    assert r.status_code == 200, r.text
    page.goto(serve(None).url)
    v = scene_of(page, r.json(), mech)
    assert v["engine"] == "spatial" and len(v["assembled"]) == 90 and all(v["assembled"])
    L = v["length_scale"]
    k0 = v["home"]
    assert v["input"]["joint"] == "R1" and v["input"]["values"][k0] == 0.0
    for j in mech["joints"]:  # the drawn pose is the file's
        assert np.allclose(rows(v, j["id"])[k0], j["point"], atol=1e-9 * L)
    loop = ["R1", "R2", "R3", "R4"]
    for a, b in zip(loop, loop[1:] + loop[:1]):  # each link keeps its length over the sweep
        d = np.linalg.norm(rows(v, a) - rows(v, b), axis=1)
        assert np.ptp(d) < 1e-8 * L, (a, b, np.ptp(d))
    axes = {j["id"]: np.array([row[0] for row in j["axes"]]) for j in v["joints"]}
    for a, b in zip(loop, loop[1:] + loop[:1]):  # and the twist between its two axes
        c = np.einsum("ij,ij->i", axes[a], axes[b])
        assert np.ptp(c) < 1e-5, (a, b)
    assert np.ptp(rows(v, "R3")[:, 2]) > 0.1 * L  # R3 leaves the plane z = const of R2's circle
    assert v["residual"] < 1e-9 and set(v["paths"]) == {"R2", "R3"}
    # rows not assembled are None in the scene too (the RSSR crank does not turn fully)
    rssr = spatial_dict("rssr")
    w = scene_of(page, client.post("/api/spatial/simulate", json={"mechanism": rssr, "steps": 60}).json(), rssr)
    ok = np.array(w["assembled"])
    assert ok.any() and not ok.all()
    for j in w["joints"]:
        assert all((p is None) == (not good) for p, good in zip(j["position"], ok)), j["id"]


@pytest.mark.slow
def test_spatial_route_rows_not_assembled_are_null_and_refusals_name_the_fix(client):
    v = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("rssr"), "steps": 180}).json()
    ok = np.array(v["assembled"])
    assert ok.any() and not ok.all()  # the RSSR crank does not turn fully
    for name, pm in v["points"].items():
        assert all((p is None) == (not good) for p, good in zip(pm["position"], ok)), name
    assert any(e["kind"] == "dead point" for e in v["events"])
    planar = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("fourbar")})
    assert planar.status_code == 400 and planar.json()["field"] == "kind"
    contact = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("gripper_003")})
    assert contact.status_code == 400 and "line_contact" in contact.json()["error"] and contact.json()["hint"]
    # a P drive: the drawn pose is the middle row (the page's home), input 0 exactly
    p = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("stewart_6ups"), "steps": 180}).json()
    assert len(p["assembled"]) == 181 and p["input"]["values"][90] == 0.0
    assert p["assembled"][90] and p["input"]["type"] == "P"
    bad = client.post("/api/spatial/simulate", json={"mechanism": spatial_dict("bennett"), "steps": 1})
    assert bad.status_code == 400 and bad.json()["field"] == "steps"


def test_check_note_says_3d_where_the_engine_moves_the_file(client):
    def note(name):
        d = client.post("/api/studio/check", json={"mechanism": spatial_dict(name)}).json()
        return [x for x in d["diagnostics"] if x["message"].startswith("spatial mechanism")]

    moved, refused = note("delta"), note("gripper_003")
    assert moved[0]["message"].startswith("spatial mechanism: 3-D view") and moved[0]["blocks"]
    assert refused[0]["message"].startswith("spatial mechanism: structure and rank analysis only")
    assert "line_contact" in refused[0]["message"]


def test_spatial_route_loads_no_matplotlib(tmp_path):
    """The 3-D view is drawn by the page: the route and the check load no Matplotlib."""
    import os
    import subprocess
    import sys
    import textwrap
    from pathlib import Path

    code = textwrap.dedent(f"""
        import sys
        from starlette.testclient import TestClient
        from mechsyn.io import load_mechanism, mechanism_to_dict
        from mechsyn.web._app import create_app
        from mechsyn.web._service import example_path

        app = create_app({str(tmp_path)!r}, token="t")
        with TestClient(app, base_url="http://127.0.0.1", headers={{"X-Mechsyn-Token": "t"}}) as c:
            for name in ("bennett", "delta"):
                m = mechanism_to_dict(load_mechanism(example_path(name)))
                for path in ("/api/spatial/simulate", "/api/studio/check"):
                    r = c.post(path, json={{"mechanism": m, "steps": 12}})
                    assert r.status_code == 200, (path, r.text)
        assert "matplotlib" not in sys.modules, "a 3-D view route imported matplotlib"
        print("ok")
    """)
    src = str(Path(__file__).resolve().parents[2] / "src")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}
    run = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, timeout=300,
                         env=env)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr[-2000:]


# ------------------------------------------------------------------------------ browser
def open_example(page, name):
    page.select_option("#examples", name)
    wait_js(page, "n => window.__studio.fileName.startsWith(n + '.') && window.__view3d.view && !window.__view3d.loading"
                  " && window.__view3d.mech === window.__studio.mech && window.__view3d.draws > 0", name, timeout=60)


def joint_centres(page):
    """Screen centres of the joints' marks (their elements without the labels, which move
    aside to keep clear of each other), relative to the view's box."""
    return page.evaluate("""() => { const v = document.querySelector('#view3d').getBoundingClientRect();
        return Object.fromEntries([...document.querySelectorAll('[data-joint]')].map(e => {
        const marks = [...e.children].filter(c => c.tagName !== 'text' && !c.classList.contains('selection-ring')
            && !c.classList.contains('axis-line')).map(c => c.getBoundingClientRect());
        const x0 = Math.min(...marks.map(b => b.left)), x1 = Math.max(...marks.map(b => b.right));
        const y0 = Math.min(...marks.map(b => b.top)), y1 = Math.max(...marks.map(b => b.bottom));
        const r = marks.length ? {x: x0, y: y0, width: x1 - x0, height: y1 - y0} : e.getBoundingClientRect(); return [e.dataset.joint, [r.x + r.width / 2 - v.x, r.y + r.height / 2 - v.y]]; })); }""")


def moved(a, b, px=2.0):
    return max(np.hypot(a[k][0] - b[k][0], a[k][1] - b[k][1]) for k in a)


def set_slider(page, k):
    page.evaluate("k => { const s = document.querySelector('#input-slider'); s.value = k;"
                  " s.dispatchEvent(new Event('input', { bubbles: true })); }", k)


@pytest.mark.slow
def test_bennett_and_delta_open_in_3d(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => document.querySelectorAll('#examples option').length > 20")
    for name, n_joints in (("bennett", 4), ("delta", 15)):
        open_example(page, name)
        ids = page.eval_on_selector_all("[data-joint]", "es => es.map(e => e.dataset.joint)")
        mech = spatial_dict(name)
        assert sorted(ids) == sorted(j["id"] for j in mech["joints"]) and len(ids) == n_joints
        assert page.locator("#view3d").is_visible() and not page.locator("#canvas").is_visible()
        links = set(page.eval_on_selector_all("#view3d [data-link]", "es => es.map(e => e.dataset.link)"))
        assert links == set(mech["links"])  # every link drawn, the frame included
        assert page.locator("[data-banner] .err").count() == 0
        assert "3-D view" in page.locator("[data-banner]").inner_text()
        # orbit: a drag on the empty view turns the picture
        before = joint_centres(page)
        box = page.locator("#view3d").bounding_box()
        page.mouse.move(box["x"] + 30, box["y"] + box["height"] - 80)
        page.mouse.down()
        page.mouse.move(box["x"] + 130, box["y"] + box["height"] - 50, steps=5)
        page.mouse.up()
        turned = joint_centres(page)
        assert moved(before, turned) > 20
        # the slider moves the mechanism (the drive's row 45: 90 degrees from the drawn pose)
        set_slider(page, 45)
        wait_js(page, "() => window.__studio.frame === 45")
        after = joint_centres(page)
        drive = next(j["id"] for j in mech["joints"] if j.get("actuated"))
        assert moved(turned, after) > 10 and after[drive] == pytest.approx(turned[drive], abs=1.0)
        assert "R1 = 90.0°" in page.locator("#input-value").inner_text()
        # reset brings the first view back
        set_slider(page, 0)
        page.click("#view3d-reset")
        assert moved(before, joint_centres(page)) < 1.0
        set_slider(page, 20)  # the picture for docs/studio.md: 40 degrees on, seen from higher up
        page.mouse.move(box["x"] + 30, box["y"] + box["height"] - 80)
        page.mouse.down()
        page.mouse.move(box["x"] + 10, box["y"] + box["height"] - 50, steps=3)
        page.mouse.up()
        shot(page, f"studio_3d_{name}.png")
    # a planar example brings the editor's canvas back
    page.select_option("#examples", "fourbar")
    wait_js(page, "() => window.__studio.fileName.startsWith('fourbar.') && window.__studio.sim")
    assert page.locator("#canvas").is_visible() and not page.locator("#view3d").is_visible()
    assert page.locator("#canvas [data-joint]").count() == 4
    assert page.outside_requests == [] and page.console_errors == []


@pytest.mark.slow
def test_spherical_fourbar_rssr_dead_point_and_refused_file_keeps_top_view(serve, page):
    srv = serve(None)
    page.goto(srv.url)
    wait_js(page, "() => document.querySelectorAll('#examples option').length > 20")
    open_example(page, "spherical_fourbar")
    box = page.locator("#view3d").bounding_box()
    page.mouse.move(box["x"] + 40, box["y"] + box["height"] - 60)
    page.mouse.down()
    page.mouse.move(box["x"] + 10, box["y"] + box["height"] - 40, steps=3)
    page.mouse.up()
    set_slider(page, 30)
    wait_js(page, "() => window.__studio.frame === 30")
    shot(page, "studio_3d_spherical_fourbar.png")
    # the studio's ▶ (and Space) play the 3-D view through the sweep
    page.click("#play")
    wait_js(page, "() => window.__view3d.playing && window.__studio.frame !== 30")
    assert page.locator("#play").inner_text() == "❚❚"
    page.click("#play")
    assert not page.evaluate("() => window.__view3d.playing") and page.locator("#play").inner_text() == "▶"
    page.keyboard.press(" ")
    wait_js(page, "() => window.__view3d.playing")
    page.keyboard.press(" ")
    assert not page.evaluate("() => window.__view3d.playing")
    # the RSSR crank does not turn fully: beyond its dead point the banner says so, and the
    # view stays at the last assembled input (the engine's rows, never extrapolated)
    open_example(page, "rssr")
    v = page.evaluate("() => window.__view3d.view")
    dead = next(e for e in v["events"] if e["kind"] == "dead point")
    k = max(i for i in range(dead["index"] + 1) if v["assembled"][i])  # the last row the crank reaches
    assert 0 < k and not v["assembled"][k + 5]
    set_slider(page, k + 5)
    wait_js(page, "k => window.__studio.frame === k", k + 5)
    text = page.locator("[data-banner]").inner_text()
    u = v["input"]["values"]
    assert f"not assembled at A = {u[k + 5]:.1f}°" in text and f"shown at A = {u[k]:.1f}°" in text
    assert f"dead point at A = {dead['input']['A']:.2f}" in text
    at_dead = joint_centres(page)
    set_slider(page, k)
    wait_js(page, "k => window.__studio.frame === k", k)
    assert moved(at_dead, joint_centres(page)) < 0.5
    assert "not assembled" not in page.locator("[data-banner]").inner_text()
    # a cam gripper (line contact): the engine cannot move it, the top view and the note stay
    page.select_option("#examples", "gripper_003")
    wait_js(page, "() => window.__studio.fileName.startsWith('gripper_003.') && window.__view3d.error"
                  " && window.__studio.check")
    assert page.locator("#canvas").is_visible() and not page.locator("#view3d").is_visible()
    text = page.locator("[data-banner]").inner_text()
    assert "structure and rank analysis only" in text and text.count("line_contact") == 1
    assert page.outside_requests == [] and page.console_errors == []
