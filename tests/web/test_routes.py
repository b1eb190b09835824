"""Studio routes called in-process: answers equal the library's, safety rules hold."""

from __future__ import annotations

import os
import time

import numpy as np
import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict, mechanism_to_dict
from mechsyn.web._service import example_path

from web_helpers import TOKEN


@pytest.fixture
def fourbar():
    return mechanism_to_dict(load_mechanism(example_path("fourbar")))


def test_examples_list_and_open(client):
    names = {e["name"] for e in client.get("/api/examples").json()["examples"]}
    assert {"fourbar", "watt_sixbar", "slider_crank"} <= names
    r = client.get("/api/examples/fourbar").json()
    assert [j["id"] for j in r["mechanism"]["joints"]] == ["A", "B", "C", "D"]
    bad = client.get("/api/examples/no_such")
    assert bad.status_code == 400 and bad.json()["field"] == "example" and "fourbar" in bad.json()["hint"]


def test_simulate_is_the_motions_to_dict(client, fourbar):
    """The studio draws the library's Motion: the route's answer is
    ``simulation_report(...).to_dict()``, i.e. the Simulation's ``to_dict()`` with its derived
    quantities, nothing of its own."""
    import json

    from mechsyn.kinematics.analysis import simulate
    from mechsyn.kinematics.report import simulation_report

    r = client.post("/api/simulate", json={"mechanism": fourbar, "steps": 90})
    assert r.status_code == 200
    d = r.json()
    u = np.array(d["input"]["values"])
    assert u[0] == pytest.approx(np.degrees(np.arctan2(2, 1)))  # the sweep starts at the drawn pose
    assert d["points"]["B"]["position"][0] == pytest.approx([1, 2])  # index 0 is the file's configuration
    mech = load_mechanism(example_path("fourbar"))
    names = ["A", "B", "C", "D", "M"]
    lib = simulate(mech, {"A": u}, points=names)
    assert {k: v for k, v in d.items() if k != "derived"} == json.loads(json.dumps(lib.to_dict()))
    assert d == json.loads(json.dumps(simulation_report(mech, {"A": u}, points=names).to_dict()))
    for k, p in enumerate(d["points"]["M"]["position"]):
        assert (p is None) == (not lib.assembled[k])
    # a triple rocker: two dead points and two working ranges, reported (not printed as numbers)
    assert len([e for e in d["events"] if e["kind"] == "dead point"]) == 2
    dead = sorted(e["input"]["A"] for e in d["events"] if e["kind"] == "dead point")
    # one working range through 360 deg (the sweep is a whole turn), ending at the dead points
    assert d["working_ranges"] == [pytest.approx([dead[1], dead[0] + 360], abs=1e-9)]
    assert d["derived"]["grashof"]["classification"].startswith("triple rocker")
    mu = d["derived"]["transmission_angle"]["B-C-D"]
    assert 0 < mu["min"] < mu["max"] <= 180


def test_simulate_route_is_the_cli_json(client, fourbar, tmp_path, cli_json):
    """``mechsyn simulate --json`` over the studio's sweep prints the route's answer (one
    regular pass for both)."""
    import json

    from mechsyn.io import mechanism_to_dict

    six = mechanism_to_dict(load_mechanism(example_path("watt_sixbar")))
    for mech in (fourbar, six):
        d = client.post("/api/simulate", json={"mechanism": mech, "steps": 36}).json()
        u = d["input"]["values"]
        path = tmp_path / "m.json"
        path.write_text(json.dumps(mech))
        got = cli_json("simulate", path, "--input", f"{d['input']['joint']}={u[0]!r}:{u[-1]!r}:{10.0!r}",
                       "--points", ",".join(d["points"]))
        assert got == d


def test_analyze(client):
    six = mechanism_to_dict(load_mechanism(example_path("watt_sixbar")))
    d = client.post("/api/analyze", json={"mechanism": six}).json()
    import json

    from mechsyn.results import dumps
    from mechsyn.structure.report import analyze

    assert d["structure"] == json.loads(dumps(analyze(load_mechanism(example_path("watt_sixbar"))).to_dict()))
    assert d["structure"]["formulas"]["chebyshev"]["expression"] == "W = 3·5 - 2·7 - 0 = 1"
    assert d["rank"]["useful_mobility"] == 1
    assert [g["label"] for g in d["assur"]["groups"]] == ["II(coupler,rocker)", "II(link5,link6)"]
    assert d["grashof"] is None


def test_validation_error_names_the_element(client, fourbar):
    fourbar["joints"][1]["links"] = ["crank", "nope"]
    d = client.post("/api/validate", json={"mechanism": fourbar}).json()
    assert not d["ok"]
    (e,) = d["errors"]
    assert e["element"] == {"kind": "joint", "id": "B"} and "nope" in e["message"]
    r = client.post("/api/simulate", json={"mechanism": fourbar})
    assert r.status_code == 400 and r.json()["element"] == {"kind": "joint", "id": "B"}


def test_no_drive_is_reported(client, fourbar):
    del fourbar["joints"][0]["actuated"]
    r = client.post("/api/simulate", json={"mechanism": fourbar})
    assert r.status_code == 400 and "no drive" in r.json()["error"]


@pytest.mark.parametrize("body", [b"{not json", b"[1, 2]", b"\xff\xfe"])
def test_malformed_body_is_400_json(client, body):
    r = client.post("/api/simulate", content=body)
    assert r.status_code == 400
    assert r.json()["field"] == "body" and "Traceback" not in r.text


def test_wrong_types_are_400(client, fourbar):
    assert client.post("/api/simulate", json={"mechanism": fourbar, "steps": "many"}).status_code == 400
    assert client.post("/api/simulate", json={"mechanism": fourbar, "steps": 10**7}).status_code == 400
    assert client.post("/api/simulate", json={"mechanism": "x"}).status_code == 400
    assert client.post("/api/simulate", json={}).json()["field"] == "mechanism"


def test_token_guards_the_api(tmp_path):
    from starlette.testclient import TestClient

    from mechsyn.web import create_app

    c = TestClient(create_app(tmp_path, token=TOKEN), base_url="http://127.0.0.1")
    assert c.get("/api/examples").status_code == 403
    assert c.get("/api/examples", headers={"X-Mechsyn-Token": "wrong"}).status_code == 403
    assert c.get(f"/api/examples?token={TOKEN}").status_code == 200
    assert c.get("/").status_code == 200  # the page itself carries no data


@pytest.mark.parametrize("host", ["evil.example", "127.0.0.1.evil.example", "attacker:8765"])
def test_host_header_refused(client, host):
    r = client.get("/api/examples", headers={"host": host})
    assert r.status_code == 403 and "Host" in r.json()["error"]


@pytest.mark.parametrize("host", ["127.0.0.1:8765", "localhost:1234", "[::1]:80"])
def test_own_host_accepted(client, host):
    assert client.get("/api/examples", headers={"host": host}).status_code == 200


def test_security_headers(client):
    for path in ("/", "/static/studio.js", "/api/examples", "/api/nothing"):
        r = client.get(path)
        csp = r.headers["content-security-policy"]
        assert "script-src 'self'" in csp and "default-src 'none'" in csp
        assert r.headers["x-content-type-options"] == "nosniff"


def test_request_size_limit(client):
    from mechsyn.web._app import MAX_BODY

    r = client.post("/api/validate", content=b"{" + b" " * (MAX_BODY + 10) + b"}",
                    headers={"content-type": "application/json"})
    assert r.status_code == 413


def test_unknown_route_is_json_404(client):
    r = client.get("/api/nothing")
    assert r.status_code == 404 and r.headers["content-type"].startswith("application/json")


def test_a_bug_answers_500_without_trace(tmp_path, monkeypatch):
    from starlette.testclient import TestClient

    from mechsyn.web import _service, create_app

    def boom(*a, **k):
        raise RuntimeError("secret internals")

    monkeypatch.setattr(_service, "analyze", boom)
    client = TestClient(create_app(tmp_path, token=TOKEN, isolate=False), base_url="http://127.0.0.1",
                        headers={"X-Mechsyn-Token": TOKEN})  # threads: the patch is seen
    r = client.post("/api/analyze", json={"mechanism": {}})
    assert r.status_code == 500 and "secret" not in r.text and "Traceback" not in r.text


# ---------------------------------------------------------------- files inside the start directory
def test_save_list_reopen(client, fourbar, tmp_path):
    r = client.post("/api/file", json={"path": "mine.yaml", "mechanism": fourbar})
    assert r.status_code == 200 and (tmp_path / "mine.yaml").is_file()
    assert "mine.yaml" in client.get("/api/files").json()["files"]
    again = client.get("/api/file", params={"path": "mine.yaml"}).json()["mechanism"]
    assert again == fourbar
    # no silent overwrite
    r = client.post("/api/file", json={"path": "mine.yaml", "mechanism": fourbar})
    assert r.status_code == 400 and "exists" in r.json()["error"]
    assert client.post("/api/file", json={"path": "mine.yaml", "mechanism": fourbar, "overwrite": True}).status_code == 200


def test_invalid_mechanism_is_not_written(client, fourbar, tmp_path):
    fourbar["joints"][0]["links"] = ["frame", "nope"]
    r = client.post("/api/file", json={"path": "bad.yaml", "mechanism": fourbar})
    assert r.status_code == 400 and not (tmp_path / "bad.yaml").exists()


@pytest.mark.parametrize("name", ["../out.yaml", "/etc/passwd.yaml", "a/../../out.yaml", "C:/x.yaml",
                                  ".hidden.yaml", "a\\b.yaml", ""])
def test_paths_outside_refused(client, fourbar, name):
    for r in (client.get("/api/file", params={"path": name}),
              client.post("/api/file", json={"path": name, "mechanism": fourbar})):
        assert r.status_code == 400 and r.json()["field"] == "path"


def test_symlink_out_refused(client, tmp_path, fourbar):
    outside = tmp_path.parent / f"outside-{os.getpid()}"
    outside.mkdir(exist_ok=True)
    (tmp_path / "link").symlink_to(outside, target_is_directory=True)
    r = client.post("/api/file", json={"path": "link/x.yaml", "mechanism": fourbar})
    assert r.status_code == 400 and "outside" in r.json()["error"]
    assert not (outside / "x.yaml").exists()
    assert not any(f.startswith("link/") for f in client.get("/api/files").json()["files"])


def test_wrong_suffix_refused(client, fourbar):
    r = client.post("/api/file", json={"path": "x.txt", "mechanism": fourbar})
    assert r.status_code == 400 and ".yaml" in r.json()["hint"]


def test_import_pyslvs(client, tmp_path):
    from mechsyn.io.pyslvs import read_pyslvs

    src = example_path("crank_rocker").parents[1] / "pyslvs" / "crank_rocker.pyslvs"
    text = src.read_text()
    d = client.post("/api/import", json={"text": text, "filename": "crank_rocker.pyslvs"}).json()["mechanism"]
    assert d == mechanism_to_dict(mechanism_from_dict(read_pyslvs(text, "crank_rocker.pyslvs")[0]))
    (tmp_path / "crank_rocker.pyslvs").write_text(text)
    assert "crank_rocker.pyslvs" in client.get("/api/files").json()["files"]
    assert client.get("/api/file", params={"path": "crank_rocker.pyslvs"}).json()["mechanism"] == d
    assert client.post("/api/simulate", json={"mechanism": d, "steps": 10}).status_code == 200
    # opened, not written
    assert client.post("/api/file", json={"path": "out.pyslvs", "mechanism": d}).status_code == 400


def test_import_and_export(client, fourbar):
    text = example_path("fourbar").read_text()
    r = client.post("/api/import", json={"text": text, "filename": "fourbar.yaml"}).json()
    assert r["mechanism"] == fourbar
    bad = client.post("/api/import", json={"text": "joints: [", "filename": "x.yaml"})
    assert bad.status_code == 400
    csv = client.post("/api/export", json={"mechanism": fourbar, "format": "csv", "steps": 10}).text
    lines = csv.splitlines()
    assert lines[0].startswith("input_A,assembled,A_x,A_y") and len(lines) == 11
    y = client.post("/api/export", json={"mechanism": fourbar, "format": "yaml"}).text
    assert "joints:" in y
    assert client.post("/api/export", json={"mechanism": fourbar, "format": "pdf"}).status_code == 400


@pytest.mark.slow
def test_export_animation(client):
    import io

    from PIL import Image

    crank = mechanism_to_dict(load_mechanism(example_path("crank_rocker")))
    r = client.post("/api/export", json={"mechanism": crank, "format": "gif", "frames": 12})
    assert r.status_code == 200 and r.headers["content-type"] == "image/gif"
    im = Image.open(io.BytesIO(r.content))
    assert im.format == "GIF" and im.n_frames == 12


# ---------------------------------------------------------------- atlas and synthesis
def test_atlas_six_links(client):
    chains = client.get("/api/atlas", params={"links": 6, "mobility": 1}).json()["chains"]
    assert len(chains) == 2  # Watt and Stephenson
    m = client.post("/api/atlas/mechanism", json={"chain": chains[0]["chain"]}).json()["mechanism"]
    assert len(m["links"]) == 6 and len(m["joints"]) == 7
    assert client.post("/api/validate", json={"mechanism": m}).json()["ok"]
    assert client.get("/api/atlas", params={"links": "x"}).status_code == 400


def _wait(client, job, timeout=120):
    t0 = time.time()
    while time.time() - t0 < timeout:
        s = client.get(f"/api/jobs/{job}").json()
        if s["state"] != "running":
            return s
        time.sleep(0.1)
    raise AssertionError("job did not finish")


@pytest.mark.slow
def test_fourbar_path_synthesis_job(client):
    from mechsyn.synthesis.fourbar import coupler_point  # noqa: F401  (library present)

    # five points on the coupler curve of a known crank-rocker: an exact fit exists
    from mechsyn.kinematics.analysis import simulate

    mech = load_mechanism(example_path("crank_rocker"))
    sim = simulate(mech, {"A": 60 + np.array([0, 40, 80, 120, 160])}, points=["M"])
    targets = sim.points["M"].position.tolist()
    job = client.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": 10, "restarts": 2}).json()
    s = _wait(client, job["id"])
    assert s["state"] == "done", s
    res = s["result"]["results"]
    assert [r["error"] for r in res] == sorted(r["error"] for r in res if r["feasible"]) + [
        r["error"] for r in res if not r["feasible"]]
    best = res[0]
    assert best["feasible"] and best["error"] < 1e-3 * np.ptp(targets, axis=0).max() ** 2
    # the applied mechanism simulates and its point passes through the targets
    d = client.post("/api/simulate", json={"mechanism": best["mechanism"], "steps": 720}).json()
    path = np.array([p for p in d["points"]["P"]["position"] if p is not None])
    gap = max(np.min(np.linalg.norm(path - t, axis=1)) for t in targets)
    assert gap < 0.05 * np.ptp(targets, axis=0).max()
    # buildable: inside the default size bound, its quality listed; the transmission angle
    # is the simulated one's worst (the crank-rocker's extremes in closed form)
    q = best["quality"]
    assert q["size_ratio"] <= 1.5 + 1e-9 and q["link_ratio"] >= 1 and q["full_turn"]
    mu = d["derived"]["transmission_angle"]
    sim_mu = min(min(v["min"], 180 - v["max"]) for v in mu.values())
    assert abs(q["min_transmission_angle"] - sim_mu) < 1.0, (q, mu)


def test_synthesis_cancel_and_bad_input(client):
    targets = [[0, 0], [1, 0.2], [2, 0.1], [3, -0.4], [3.5, -1.2]]
    job = client.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": 60}).json()
    time.sleep(0.5)
    client.post(f"/api/jobs/{job['id']}/cancel", json={})
    assert _wait(client, job["id"], timeout=30)["state"] == "cancelled"
    r = client.post("/api/synth/fourbar_path", json={"targets": [[0, 0]]})
    s = _wait(client, r.json()["id"])
    assert s["state"] == "failed" and s["error"]["field"] == "targets"
    assert client.post("/api/synth/nope", json={}).status_code == 400


def test_events_stream(client):
    targets = [[0, 0], [1, 0.2], [2, 0.1], [3, -0.4], [3.5, -1.2]]
    job = client.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": 2, "restarts": 1}).json()
    with client.stream("GET", f"/api/jobs/{job['id']}/events") as r:
        assert r.headers["content-type"].startswith("text/event-stream")
        text = "".join(r.iter_text())
    assert "event: end" in text and '"state": "done"' in text


def test_simulate_without_rates(client, fourbar):
    full = client.post("/api/simulate", json={"mechanism": fourbar, "steps": 60}).json()
    lean = client.post("/api/simulate", json={"mechanism": fourbar, "steps": 60, "rates": False}).json()
    assert not lean["rates"] and full["rates"]
    assert {k: sorted(p) for k, p in lean["points"].items()} == {k: ["position"] for k in full["points"]}
    assert all(sorted(v) == ["angle"] for v in lean["links"].values())
    for key in ("events", "working_ranges", "assembled"):
        assert lean[key] == full[key]
    assert {k: p["position"] for k, p in lean["points"].items()} == {k: p["position"] for k, p in full["points"].items()}
    assert lean["derived"]["transmission_angle"] == full["derived"]["transmission_angle"]
    assert "motion" not in lean["derived"] and "motion" in full["derived"]
    assert client.post("/api/simulate", json={"mechanism": fourbar, "rates": "no"}).status_code == 400


def test_curve_synthesis_kind_is_offered_and_checks_its_input(client):
    kinds = client.get("/api/start").json()["synthesis_kinds"]
    assert {"fourbar_path", "curve"} <= set(kinds)  # and "motion" (mechsyn.web._studio)
    r = client.post("/api/synth/curve", json={"targets": [[0, 0], [1, 1], [2, 0]]})
    s = _wait(client, r.json()["id"])
    assert s["state"] == "failed" and s["error"]["field"] == "targets" and "6 points" in s["error"]["message"]
