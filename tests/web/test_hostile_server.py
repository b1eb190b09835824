"""The studio's server under hostile use, third pass (issue 42): idle sockets, heavy work
kept out of the server's process, typed bodies, numeric overflow, file names and CSV cells.

Each test reproduces a finding of issue 42 and fails on the code before it. Every wait is
for a readiness signal; the time limits only end a broken run.
"""

from __future__ import annotations

import json
import socket
import threading
import time

import pytest

from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.web._service import example_path

from web_helpers import TOKEN, free_port
from web_helpers import wait_for as _wait_for


@pytest.fixture
def example():
    return lambda name: mechanism_to_dict(load_mechanism(example_path(name)))


@pytest.fixture
def real_server(tmp_path):
    """``start(app=None)`` → (uvicorn.Server, base URL) of the studio's own server settings
    (:func:`mechsyn.web._app.server_config`) on a free loopback port, listening."""
    import uvicorn

    from mechsyn.web import _app, create_app

    running = []

    def start(app=None):
        app = app or create_app(tmp_path, token=TOKEN)
        port = free_port()
        server = uvicorn.Server(_app.server_config(app, port=port))
        thread = threading.Thread(target=server.run, daemon=True)
        thread.start()
        running.append((server, thread))
        _wait_for(lambda: server.started, "the server listens")
        return server, f"http://127.0.0.1:{port}"

    yield start
    for server, thread in running:
        server.should_exit = True
        thread.join(timeout=30)


# ------------------------------------------------------------------ idle connections (finding 6)
def test_250_idle_connections_do_not_lock_out_the_user(real_server):
    """250 sockets that send a request line only made every request of the real user fail
    with 503 (``limit_concurrency`` counted open connections)."""
    import httpx

    server, base = real_server()
    port = int(base.rsplit(":", 1)[1])
    idle = []
    try:
        for _ in range(250):
            s = socket.create_connection(("127.0.0.1", port))
            s.sendall(b"GET /api/start HTTP/1.1\r\n")
            idle.append(s)
        _wait_for(lambda: len(server.server_state.connections) >= 250, "the server holds the 250 sockets")
        r = httpx.get(f"{base}/api/start", headers={"X-Mechsyn-Token": TOKEN}, timeout=60)
        assert r.status_code == 200, r.text
        # a request without the token is refused at once and its connection closed
        with socket.create_connection(("127.0.0.1", port)) as s:
            s.settimeout(60)
            s.sendall(f"GET /api/start HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
            answer = b""
            while chunk := s.recv(65536):
                answer += chunk
        assert answer.startswith(b"HTTP/1.1 403") and b"connection: close" in answer.lower()
    finally:
        for s in idle:
            s.close()


def test_silent_sockets_beyond_the_bound_close_the_oldest(real_server, monkeypatch):
    """Descriptors stay bounded: past ``MAX_PENDING_HEADS`` silent sockets, the oldest is closed."""
    import httpx

    from mechsyn.web import _app

    monkeypatch.setattr(_app, "MAX_PENDING_HEADS", 20)
    server, base = real_server()
    port = int(base.rsplit(":", 1)[1])
    idle = [socket.create_connection(("127.0.0.1", port)) for _ in range(30)]
    try:
        for s in idle[:10]:
            s.settimeout(60)
            assert s.recv(1024) == b""  # the first ten: closed by the server
        _wait_for(lambda: len(server.server_state.connections) == 20, "twenty silent sockets left")
        r = httpx.get(f"{base}/api/start", headers={"X-Mechsyn-Token": TOKEN}, timeout=60)
        assert r.status_code == 200
    finally:
        for s in idle:
            s.close()


# ------------------------------------------------------------------ typed bodies (finding 8)
@pytest.mark.parametrize("change, field", [
    ({"links": 5}, "links"), ({"ground": []}, "ground"), ({"joints": 5}, "joints"),
    ({"joints": [5]}, "joints[0]"), ({"links": [[1]]}, "links[0]"), ({"name": 7}, "name"),
])
def test_the_structure_check_answers_400_to_wrong_types(client, example, change, field):
    r = client.post("/api/studio/check", json={"mechanism": {**example("fourbar"), **change}})
    assert r.status_code == 400, r.text
    assert r.json()["field"] == field


def test_the_structure_check_names_the_joint_of_a_wrongly_typed_field(client, example):
    m = example("fourbar")
    m["joints"][1]["links"] = 5
    r = client.post("/api/studio/check", json={"mechanism": m})
    assert r.status_code == 400 and r.json()["field"].startswith("joints[1]")
    assert r.json()["element"] == {"kind": "joint", "id": m["joints"][1]["id"]}


@pytest.mark.parametrize("axis", [[1e200, 1e200, 0], [1e300, 1e300, 1e300], [0, 1e13, 0]])
@pytest.mark.parametrize("route", ["/api/spatial/simulate", "/api/studio/check", "/api/validate",
                                   "/api/analyze", "/api/export", "/api/studio/drawing"])
def test_an_overflowing_axis_is_a_400(client, example, route, axis):
    m = example("bennett")
    m["joints"][2]["axis"] = axis
    r = client.post(route, json={"mechanism": m})
    assert r.status_code == 400, (r.status_code, r.text[:300])
    assert r.json()["field"] == "joints[2].axis[1]" if axis[0] == 0 else "joints[2].axis[0]"
    assert r.json()["element"] == {"kind": "joint", "id": m["joints"][2]["id"]}


@pytest.mark.parametrize("route, body, field", [
    ("/api/simulate", {"steps": "36"}, "steps"), ("/api/simulate", {"steps": 36.5}, "steps"),
    ("/api/simulate", {"rates": 1}, "rates"), ("/api/export", {"format": "xls"}, "format"),
    ("/api/export", {"format": "gif", "frames": 1000}, "frames"), ("/api/studio/forces", {"gravity": [0]}, "gravity"),
    ("/api/studio/forces", {"speed": "fast"}, "speed"), ("/api/studio/forces", {"gravity": [0, 1e300]}, "gravity[1]"),
    ("/api/spatial/simulate", {"steps": True}, "steps"), ("/api/file", {"path": "a.yaml", "overwrite": "false"}, "overwrite"),
])
def test_wrongly_typed_fields_are_400_naming_them(client, example, route, body, field):
    r = client.post(route, json={"mechanism": example("fourbar"), **body})
    assert r.status_code == 400, (r.status_code, r.text[:300])
    assert r.json()["field"] == field


@pytest.mark.parametrize("kind, params, field", [
    ("fourbar_path", {"time_limit": "10"}, "time_limit"), ("fourbar_path", {"restarts": [1]}, "restarts"),
    ("fourbar_path", {"restarts": 2.5}, "restarts"), ("fourbar_path", {"targets": "abc"}, "targets"),
    ("fourbar_path", {"targets": [[0, 0], [1, "0"], [1, 1]]}, "targets[1][1]"),
    ("fourbar_path", {"targets": [[0, 0, 0], [1, 0], [1, 1]]}, "targets[0]"),
    ("fourbar_path", {"time_limit": 1e300}, "time_limit"),
    ("curve", {"closed": "false"}, "closed"), ("curve", {"closed": 0}, "closed"), ("curve", {"max_links": "6"}, "max_links"),
    ("motion", {"angles": ["0", 1, 2]}, "angles[0]"),
])
def test_wrongly_typed_synthesis_parameters_are_400_naming_the_field(client, kind, params, field):
    body = {"targets": [[0, 0], [1, 0.2], [2, 0.1], [3, -0.4], [3.5, -1.2], [4, 0]], **params}
    r = client.post(f"/api/synth/{kind}", json=body)
    assert r.status_code == 400, (r.status_code, r.text[:300])
    assert r.json()["field"] == field and "internal" not in r.json()["error"]


# ------------------------------------------------------------------ Save and CSV (finding 8)
@pytest.mark.parametrize("name", ["a\nb.yaml", "evil\u202eLMY.yaml", "x\u2066.yaml", "<img src=x onerror=alert(1)>.yaml",
                                  "tab\there.yaml", "nul\u0000.yaml", "line\u2028sep.yaml", "zw\u200bj.yaml"])
def test_save_refuses_names_that_are_not_printable_text(client, example, tmp_path, name):
    r = client.post("/api/file", json={"path": name, "mechanism": example("fourbar")})
    assert r.status_code == 400 and r.json()["field"] == "path", r.text
    assert list(tmp_path.iterdir()) == []
    r = client.post("/api/import", json={"text": "x", "filename": name})
    assert r.status_code == 400 and r.json()["field"] == "filename"


def test_save_keeps_ordinary_names(client, example, tmp_path):
    for name in ("four-bar (v2) & co's.yaml", "Четырёхзвенник.yaml", "sub dir name.json"):
        r = client.post("/api/file", json={"path": name, "mechanism": example("fourbar")})
        assert r.status_code == 200, r.text
    assert len(list(tmp_path.iterdir())) == 3


def test_csv_export_escapes_formula_cells(client, example):
    m = example("fourbar")
    old = m["joints"][2]["id"]
    evil = '=HYPERLINK("http://evil.example","x")'
    m["joints"][2]["id"] = evil
    m["points"] = {k: v for k, v in m.get("points", {}).items()}
    for name, p in list(m["points"].items()):  # named points may be formulas too
        m["points"]["@" + name] = m["points"].pop(name)
    text = json.dumps(m).replace(f'"{old}"', json.dumps(evil))
    r = client.post("/api/export", json={"mechanism": json.loads(text), "format": "csv", "steps": 8})
    assert r.status_code == 200, r.text
    import csv
    import io

    rows = list(csv.reader(io.StringIO(r.text)))
    cells = [c for row in rows for c in row]
    assert f"'{evil}_x" in cells and any(c.startswith("'@") for c in cells)
    assert not [c for c in cells if c.startswith(("=", "+", "@")) or (c.startswith("-") and not _number(c))]


def _number(text: str) -> bool:
    try:
        float(text)
        return True
    except ValueError:
        return False


# ------------------------------------------------------------------ heavy work (finding 7)
def _run_coroutine(coro):
    """``asyncio.run(coro)`` in a thread of its own (a browser test may leave a loop running)."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coro).result()


async def _never_gone() -> bool:
    return False


def test_the_queue_serves_the_client_served_least_recently_first():
    """A cheap request of a second client waited behind every queued request of the first
    (61 s behind others, no fairness): now it goes next."""
    import asyncio

    from mechsyn.web._jobs import HeavyRunner

    runner = HeavyRunner(total=1, per_client=1, queue=4, isolate=False)
    order, release = [], threading.Event()

    def work(tag: str) -> str:
        order.append(tag)
        if tag == "a1":
            release.wait(60)  # only ends a broken run
        return tag

    async def scenario():
        first = asyncio.ensure_future(runner.call("a", _never_gone, work, "a1"))
        await asyncio.to_thread(_wait_for, lambda: order == ["a1"], "a1 runs")
        rest = [asyncio.ensure_future(runner.call("a", _never_gone, work, t)) for t in ("a2", "a3")]
        await asyncio.sleep(0)
        late = asyncio.ensure_future(runner.call("b", _never_gone, work, "b1"))
        await asyncio.to_thread(_wait_for, lambda: runner.waiting.get("b") == 1, "b1 waits")
        release.set()
        return await asyncio.gather(first, *rest, late)

    assert sorted(_run_coroutine(scenario())) == ["a1", "a2", "a3", "b1"]
    assert order == ["a1", "b1", "a2", "a3"]


def test_a_worker_past_its_time_limit_is_killed():
    from mechsyn.web._jobs import HeavyRunner, TooLong

    runner = HeavyRunner(total=1)

    async def scenario():
        with pytest.raises(TooLong):
            await runner.call("a", _never_gone, time.sleep, 600, limit=0.5)

    try:
        _run_coroutine(scenario())
        assert not runner.procs and not runner.running and runner.started == 1
    finally:
        runner.stop()


def test_caps_are_keyed_by_the_connection_not_a_header():
    from starlette.requests import Request

    from mechsyn.web._routing import _client

    def request(port: int, header: str) -> Request:
        return Request({"type": "http", "method": "GET", "path": "/", "client": ("127.0.0.1", port),
                        "headers": [(b"x-mechsyn-client", header.encode())]})

    assert _client(request(5000, "x")) == _client(request(5000, "y")) == "127.0.0.1:5000"
    assert _client(request(5001, "x")) != _client(request(5000, "x"))


def test_the_check_and_synthesis_run_in_workers_and_jobs_leave_one_free(client, example):
    """The structure check ran in the server's threads (an 801-link check: 103 s, the
    server's RSS 261 → 1,236 MB), synthesis jobs in its threads too."""
    runner = client.app.state.heavy
    before = runner.started
    r = client.post("/api/studio/check", json={"mechanism": example("fourbar")})
    assert r.status_code == 200 and r.json()["mobility"] == 1
    assert runner.started == before + 1  # a worker answered it
    targets = [[0, 0], [1, 0.2], [2, 0.1], [3, -0.4], [3.5, -1.2]]
    jobs = [client.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": 600, "restarts": 50}).json()
            for _ in range(runner.total)]
    try:
        _wait_for(lambda: runner.lanes["job"] == runner.job_slots and len(runner.procs) == runner.job_slots,
                  "the jobs' workers run")
        _wait_for(lambda: client.get(f"/api/jobs/{jobs[0]['id']}").json()["progress"]["done"] > 0,
                  "the first job reports progress")
        assert runner.job_slots < runner.total  # one worker left for requests
        r = client.post("/api/studio/check", json={"mechanism": example("fourbar")})  # served meanwhile
        assert r.status_code == 200
    finally:
        workers = set(runner.procs)
        for j in jobs:
            client.post(f"/api/jobs/{j['id']}/cancel", json={})
    for j in jobs:
        _wait_for(lambda: client.get(f"/api/jobs/{j['id']}").json()["state"] == "cancelled", "cancelled")
    _wait_for(lambda: all(w.exitcode is not None for w in workers), "the job workers end")
    assert {w.exitcode for w in workers} == {-9}  # killed by the cancel


# ------------------------------------------------------------------ signals during heavy work (finding 7)
def _children(pid: int) -> list[int]:
    out = []
    for stat in __import__("pathlib").Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


@pytest.mark.skipif(not __import__("os").path.isdir("/proc/self"), reason="reads /proc to see the worker start")
@pytest.mark.parametrize("sig, code, word", [(__import__("signal").SIGTERM, 143, "terminated"),
                                             (__import__("signal").SIGINT, 130, "interrupted")])
def test_a_signal_during_a_heavy_request_gives_clean_output(tmp_path, example, sig, code, word):
    """SIGTERM during heavy work left a traceback (CancelledError) and a plain-text 500."""
    import httpx

    from test_hostile_signals import _start_serve

    p, base, token = _start_serve(tmp_path)
    answer = {}

    def heavy():
        try:
            answer["r"] = httpx.post(f"{base}/api/export", headers={"X-Mechsyn-Token": token}, timeout=120,
                                     json={"mechanism": example("watt_sixbar"), "format": "gif", "frames": 360})
        except httpx.HTTPError as exc:  # the connection closed: acceptable, no 500
            answer["r"] = exc

    t = threading.Thread(target=heavy)
    try:
        t.start()
        # the worker runs: a child of the fork server (a child of serve)
        _wait_for(lambda: any(_children(c) for c in _children(p.pid)), "the GIF worker started")
        p.send_signal(sig)
        out, err = p.communicate(timeout=60)
        t.join(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == code, err[-2000:]
    assert "Traceback" not in err and "Error" not in err and err.strip().splitlines()[-1] == word, err[-2000:]
    r = answer["r"]
    if isinstance(r, httpx.Response):
        assert r.status_code == 503 and r.json()["error"] == "the server is stopping", r.text[:300]


def test_a_job_outlives_the_event_loop_of_its_request(tmp_path):
    """The notebook widget calls the app through a TestClient without its context: each
    request has an event loop of its own, closed when it returns. A job (now a worker
    process) must finish all the same."""
    import warnings

    from mechsyn.web import create_app

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from starlette.testclient import TestClient

    app = create_app(tmp_path, token=TOKEN)
    c = TestClient(app, base_url="http://127.0.0.1", headers={"X-Mechsyn-Token": TOKEN})  # no `with`: no lifespan
    targets = [[0, 0], [1, 0.2], [2, 0.1], [3, -0.4], [3.5, -1.2]]
    job = c.post("/api/synth/fourbar_path", json={"targets": targets, "time_limit": 1, "restarts": 1}).json()
    _wait_for(lambda: c.get(f"/api/jobs/{job['id']}").json()["state"] != "running", "the job ends")
    snap = c.get(f"/api/jobs/{job['id']}").json()
    assert snap["state"] == "done" and snap["result"]["results"], snap
    assert app.state.heavy.started == 1
    app.state.heavy.stop()


def test_a_stopped_fork_server_is_started_again():
    """``stop()`` killed the fork server but left it remembered as alive: the next worker of
    the process (another app, a notebook's next widget) failed with "unexpected EOF"."""
    from mechsyn.web._jobs import HeavyRunner

    for _ in range(2):
        runner = HeavyRunner(total=1)
        runner.warm()
        try:
            assert _run_coroutine(runner.call("a", _never_gone, len, [1, 2, 3])) == 3
        finally:
            runner.stop()
