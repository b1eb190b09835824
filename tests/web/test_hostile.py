"""The studio under hostile and careless use (issue 27): nothing kills it, nothing runs away.

Each test reproduces a finding of issue 27 and fails on the code before it.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.web._service import example_path

from web_helpers import TOKEN, LiveServer
from web_helpers import wait_for as _wait_for

SRC = str(Path(__file__).resolve().parents[2] / "src")


@pytest.fixture
def fourbar():
    return mechanism_to_dict(load_mechanism(example_path("fourbar")))


@pytest.fixture(scope="module")
def six_link_chain():
    from mechsyn.web import _service

    return _service.atlas(6, 1)[0]["chain"]


def _run_python(code: str, timeout: float = 300) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": SRC}
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          env=env, timeout=timeout)


# ------------------------------------------------------------------ chains: the SIGABRT of bliss
@pytest.mark.slow
def test_bad_chain_during_an_atlas_list_does_not_abort_the_process():
    """Issue 27's high finding: a chain naming link 99 sent while another igraph call ran
    aborted the studio (SIGABRT, exit 134). Everything in one process here (threads), the
    harder case: the check and the lock must hold without the worker processes."""
    proc = _run_python("""
        import threading, warnings
        warnings.simplefilter("ignore")
        from starlette.testclient import TestClient
        from mechsyn.web import create_app
        app = create_app(".", token="t")
        if hasattr(app.state, "heavy"):
            app.state.heavy.isolate = False
        c = TestClient(app, base_url="http://127.0.0.1", headers={"X-Mechsyn-Token": "t"})
        chain = c.get("/api/atlas?links=6").json()["chains"][0]["chain"]
        chain["edges"][0] = [0, 99]
        stop, codes = threading.Event(), set()
        def lister():
            while not stop.is_set():
                codes.add(c.get("/api/atlas?links=8").status_code)
        threads = [threading.Thread(target=lister) for _ in range(2)]
        for t in threads:
            t.start()
        bad = [c.post("/api/atlas/mechanism", json={"chain": chain}) for _ in range(40)]
        stop.set()
        for t in threads:
            t.join()
        assert {r.status_code for r in bad} == {400}, {r.status_code for r in bad}
        assert bad[0].json()["field"] == "chain.edges[0]", bad[0].json()
        assert codes == {200}, codes
        print("survived")
    """)
    assert proc.returncode == 0, (proc.returncode, proc.stderr[-2000:])
    assert "survived" in proc.stdout


def test_canonical_refuses_out_of_range_graphs_concurrently():
    """The library itself: bad graphs raise ValueError in many threads at once, the process lives."""
    proc = _run_python("""
        import threading
        from mechsyn.synthesis import canonical
        errors = []
        def hammer():
            for _ in range(200):
                for bad in ((5, [(0, 99)], [0] * 5), (5, [(0, 1)], [0] * 4)):
                    try:
                        canonical.certificate(*bad)
                    except ValueError as exc:
                        errors.append(str(exc))
                canonical.certificate(6, [(i, (i + 1) % 6) for i in range(6)], [0, 1, 0, 1, 0, 1])
        ts = [threading.Thread(target=hammer) for _ in range(4)]
        [t.start() for t in ts]
        [t.join() for t in ts]
        assert len(errors) == 4 * 200 * 2, len(errors)
        print("survived")
    """)
    assert proc.returncode == 0, (proc.returncode, proc.stderr[-2000:])


@pytest.mark.parametrize("change, field", [
    ({"frame": 99}, "frame"),
    ({"input": 99}, "input"),
    ({"chain.edges": [[0, 0]]}, "chain.edges[0]"),
    ({"chain.edges": [[0, "1"]]}, "chain.edges[0]"),
    ({"chain.mobility": 5}, "chain.mobility"),
    ({"chain.n_links": 3000}, "chain.n_links"),
    ({"chain.assortment": {"2": 99}}, "chain.assortment"),
    ({"chain.degenerate": "no"}, "chain.degenerate"),
    ({"chain": [1, 2]}, "chain"),
])
def test_bad_chains_are_400_naming_the_field(client, six_link_chain, change, field):
    chain = json.loads(json.dumps(six_link_chain))
    body = {"chain": chain, "frame": 0}
    for key, value in change.items():
        if key.startswith("chain."):
            sub = key.split(".", 1)[1]
            if sub == "edges":
                chain["edges"] = value + chain["edges"][1:]
            else:
                chain[sub] = value
        else:
            body[key] = value
    r = client.post("/api/atlas/mechanism", json=body)
    assert r.status_code == 400, r.text
    assert r.json()["field"] == field


def test_a_3000_link_ring_is_refused_before_work(client):
    n = 3000
    ring = {"n_links": n, "mobility": 3 * (n - 1) - 2 * n, "edges": [[i, (i + 1) % n] for i in range(n)],
            "assortment": {"2": n}, "degenerate": False, "fractionated": False, "planar_graph": True}
    r = client.post("/api/atlas/mechanism", json={"chain": ring})
    assert r.status_code == 400 and r.json()["field"] == "chain.n_links"
    assert "MECHSYN_LIMIT_ATLAS_LINKS" in r.json()["hint"]


# ------------------------------------------------------------------ malformed requests: 4xx JSON
def _raw(fourbar: dict, **extra: str) -> bytes:
    body = json.dumps({"mechanism": fourbar})[:-1]
    return (body + "".join(f', "{k}": {v}' for k, v in extra.items()) + "}").encode("utf-8", "surrogatepass")


@pytest.mark.parametrize("route", ["/api/simulate", "/api/analyze", "/api/validate", "/api/export"])
@pytest.mark.parametrize("case", ["nan", "infinity", "overflow", "deep", "bigint", "surrogate", "duplicate"])
def test_malformed_bodies_are_4xx_json(client, fourbar, route, case):
    raw = {
        "nan": lambda: _raw(fourbar, steps="NaN"),
        "infinity": lambda: _raw(fourbar, steps="-Infinity"),
        "overflow": lambda: _raw(fourbar, steps="1e400"),
        "deep": lambda: _raw(fourbar, x="[" * 100_000 + "]" * 100_000),
        "bigint": lambda: _raw(fourbar, steps="9" * 5000),
        "surrogate": lambda: json.dumps({"mechanism": {**fourbar, "name": "\ud800"}}).encode(),
        "duplicate": lambda: _raw(fourbar, mechanism="{}"),
    }[case]()
    r = client.post(route, content=raw, headers={"content-type": "application/json"})
    assert 400 <= r.status_code < 500, (r.status_code, r.text[:300])
    assert r.json()["field"] == ("name" if case == "surrogate" else "body") and "Traceback" not in r.text


def test_hidden_characters_in_ids_are_refused_names_are_not(client, fourbar):
    fourbar["joints"][0]["id"] = "A\u200b"
    r = client.post("/api/validate", json={"mechanism": fourbar}).json()
    assert not r["ok"] and "U+200B" in r["errors"][0]["message"]
    bidi = json.loads(json.dumps(fourbar))
    bidi["joints"][0]["id"] = "A"
    bidi["links"][1] = "crank\u202e"
    assert "U+202E" in client.post("/api/validate", json={"mechanism": bidi}).json()["errors"][0]["message"]
    fourbar["joints"][0]["id"] = "A"
    fourbar["name"] = "four\u200dbar"  # a name is free text
    assert client.post("/api/validate", json={"mechanism": fourbar}).json()["ok"]


def test_booleans_are_booleans(client, fourbar, tmp_path):
    assert client.post("/api/file", json={"path": "m.yaml", "mechanism": fourbar}).status_code == 200
    before = (tmp_path / "m.yaml").read_bytes()
    fourbar["name"] = "changed"
    r = client.post("/api/file", json={"path": "m.yaml", "mechanism": fourbar, "overwrite": "false"})
    assert r.status_code == 400 and r.json()["field"] == "overwrite"
    assert (tmp_path / "m.yaml").read_bytes() == before
    r = client.post("/api/simulate", json={"mechanism": fourbar, "rates": "false"})
    assert r.status_code == 400 and r.json()["field"] == "rates"


@pytest.mark.parametrize("name", ["*", "**", "four*", "[fo]ourbar", "a" * 5000])
def test_example_names_are_not_globs(client, name):
    r = client.get(f"/api/examples/{name}")
    assert r.status_code == 400 and r.json()["field"] == "example"


def test_over_long_file_names_are_400(client, fourbar):
    for name in ("a" * 300 + ".yaml", "/".join(["d"] * 600) + ".yaml"):
        assert client.get("/api/file", params={"path": name}).json()["field"] == "path"
        r = client.post("/api/file", json={"path": name, "mechanism": fourbar})
        assert r.status_code == 400 and r.json()["field"] == "path"
    r = client.post("/api/import", json={"text": "x", "filename": "a" * 5000})
    assert r.status_code == 400 and r.json()["field"] == "filename"


# ------------------------------------------------------------------ files
def test_symlink_loop_does_not_break_the_file_list(client, fourbar, tmp_path):
    client.post("/api/file", json={"path": "good.yaml", "mechanism": fourbar})
    os.symlink("loop.yaml", tmp_path / "loop.yaml")
    os.symlink("b.yaml", tmp_path / "a.yaml")
    os.symlink("a.yaml", tmp_path / "b.yaml")
    os.symlink(".", tmp_path / "sub")  # a folder loop
    r = client.get("/api/files")
    assert r.status_code == 200 and r.json()["files"] == ["good.yaml"]
    for name in ("loop.yaml", "a.yaml"):
        r = client.get("/api/file", params={"path": name})
        assert r.status_code == 400 and r.json()["field"] == "path"


def test_hidden_rule_on_the_resolved_path(client, fourbar, tmp_path):
    (tmp_path / ".secret.yaml").write_text("links: []\njoints: []\n")
    os.symlink(".secret.yaml", tmp_path / "visible.yaml")
    (tmp_path / ".hidden").mkdir()
    os.symlink(".hidden", tmp_path / "shown")
    assert client.get("/api/file", params={"path": "visible.yaml"}).status_code == 400
    r = client.post("/api/file", json={"path": "visible.yaml", "mechanism": fourbar, "overwrite": True})
    assert r.status_code == 400 and (tmp_path / ".secret.yaml").read_text() == "links: []\njoints: []\n"
    assert client.post("/api/file", json={"path": "shown/x.yaml", "mechanism": fourbar}).status_code == 400
    assert not (tmp_path / ".hidden" / "x.yaml").exists()
    assert "visible.yaml" not in client.get("/api/files").json()["files"]


@pytest.mark.parametrize("name, text", [("package.json", '{"name": "app", "version": "1.0.0"}\n'),
                                        ("docker-compose.yml", "services:\n  web:\n    image: nginx\n")])
def test_save_replaces_only_mechanism_files(client, fourbar, tmp_path, name, text):
    (tmp_path / name).write_text(text)
    r = client.post("/api/file", json={"path": name, "mechanism": fourbar, "overwrite": True})
    assert r.status_code == 400 and "not a mechanism file" in r.json()["error"]
    assert (tmp_path / name).read_text() == text


def test_save_keeps_the_mode_of_the_file_it_replaces(client, fourbar, tmp_path):
    client.post("/api/file", json={"path": "private.yaml", "mechanism": fourbar})
    os.chmod(tmp_path / "private.yaml", 0o600)
    fourbar["name"] = "second version"
    r = client.post("/api/file", json={"path": "private.yaml", "mechanism": fourbar, "overwrite": True})
    assert r.status_code == 200 and "second version" in (tmp_path / "private.yaml").read_text()
    assert (tmp_path / "private.yaml").stat().st_mode & 0o777 == 0o600


# ------------------------------------------------------------------ jobs
def test_a_finished_jobs_seconds_stay(monkeypatch):
    from mechsyn.web import _jobs

    now = [100.0]

    class Clock:  # every clock the jobs may read, stopped at now[0]
        time = monotonic = staticmethod(lambda: now[0])

    monkeypatch.setattr(_jobs, "time", Clock)
    job = _jobs.Job("1", "k", lambda params, progress: {"ok": True}, {})
    _run_coroutine(job.run(_jobs.HeavyRunner(isolate=False), "c"))  # finished at t = 100
    now[0] = 250.0
    assert job.snapshot()["state"] == "done" and job.snapshot()["seconds"] == 0.0


# ------------------------------------------------------------------ a live server: disconnects, caps
def _post_raw(port: int, path: str, body: bytes, send_all: bool = True) -> socket.socket:
    s = socket.create_connection(("127.0.0.1", port))
    head = (f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Mechsyn-Token: {TOKEN}\r\n"
            f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\n\r\n").encode()
    s.sendall(head + (body if send_all else body[: len(body) // 3]))
    return s


def test_heavy_work_stops_when_its_client_leaves_and_others_are_answered(tmp_path):
    import httpx

    from mechsyn.web import create_app

    app = create_app(tmp_path, token=TOKEN)
    srv = LiveServer(app)
    try:
        runner = app.state.heavy
        six = mechanism_to_dict(load_mechanism(example_path("watt_sixbar")))
        heavy = _post_raw(srv.port, "/api/export", json.dumps({"mechanism": six, "format": "gif",
                                                               "frames": 360}).encode())
        _wait_for(lambda: len(runner.procs) == 1, "the GIF worker started")
        (worker,) = runner.procs
        headers = {"X-Mechsyn-Token": TOKEN}
        base = f"http://127.0.0.1:{srv.port}"
        assert httpx.get(f"{base}/api/examples", headers=headers, timeout=60).status_code == 200
        fb = mechanism_to_dict(load_mechanism(example_path("fourbar")))
        r = httpx.post(f"{base}/api/simulate", json={"mechanism": fb, "steps": 36}, headers=headers, timeout=60)
        assert r.status_code == 200
        assert worker.is_alive() and worker in runner.procs  # answered while the heavy one still ran
        heavy.close()  # the client leaves
        _wait_for(lambda: worker.exitcode is not None, "the worker stopped")
        assert worker.exitcode == -signal.SIGKILL  # killed, not finished
        _wait_for(lambda: not runner.procs and not any(runner.running.values()), "the slot freed")
    finally:
        srv.stop()


def test_one_client_is_capped(tmp_path):
    import asyncio

    from mechsyn.web._jobs import Busy, HeavyRunner

    runner = HeavyRunner(per_client=1, queue=2, isolate=False)

    async def scenario():
        async def never_gone():
            return False

        runner.running["a"] = 1  # one running, one more may wait
        runner.waiting["a"] = 1
        with pytest.raises(Busy):
            await runner.call("a", never_gone, "examples")
        return await runner.call("b", never_gone, "examples")  # another client is not held up

    assert isinstance(_run_coroutine(scenario()), list)


def test_a_dropped_upload_logs_one_line(tmp_path, caplog, fourbar):
    from mechsyn.web import create_app

    app = create_app(tmp_path, token=TOKEN)
    srv = LiveServer(app)
    try:
        caplog.set_level("INFO")
        for _ in range(5):
            s = _post_raw(srv.port, "/api/import", json.dumps({"text": "x" * 200_000}).encode(), send_all=False)
            s.close()
        _wait_for(lambda: len([r for r in caplog.records if "client left" in r.getMessage()]) >= 5,
                  "each dropped upload logged")
    finally:
        srv.stop()
    assert not [r for r in caplog.records if r.exc_info], [r.getMessage() for r in caplog.records if r.exc_info]


def test_a_silent_connection_is_closed_and_others_served(tmp_path, monkeypatch):
    """No header read timeout before: about 1,100 half-open connections locked a studio out."""
    import threading

    import httpx
    import uvicorn

    from mechsyn.web import _app, create_app
    from web_helpers import free_port

    monkeypatch.setattr(_app, "HEADER_TIMEOUT", 0.5)
    port = free_port()
    server = uvicorn.Server(_app.server_config(create_app(tmp_path, token=TOKEN), port=port))
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    try:
        _wait_for(lambda: server.started, "the server listens")
        silent = [socket.create_connection(("127.0.0.1", port)) for _ in range(3)]
        silent[0].sendall(b"GET /api/examples HTTP/1.1\r\nHost: 127.0.0.1\r\n")  # a head never finished
        for s in silent:
            s.settimeout(60)  # only ends a broken run
            assert s.recv(1024) == b""  # closed by the server
            s.close()
        r = httpx.get(f"http://127.0.0.1:{port}/api/examples", headers={"X-Mechsyn-Token": TOKEN}, timeout=60)
        assert r.status_code == 200
    finally:
        server.should_exit = True
        thread.join(timeout=30)


def test_a_worker_that_dies_is_a_500_and_the_server_lives(client):
    """A crash in native code (bliss aborted the whole studio) now ends one worker only."""
    import threading

    runner = client.app.state.heavy
    six = mechanism_to_dict(load_mechanism(example_path("watt_sixbar")))
    answer = {}
    t = threading.Thread(target=lambda: answer.setdefault("r", client.post(
        "/api/export", json={"mechanism": six, "format": "gif", "frames": 360})))
    t.start()
    _wait_for(lambda: len(runner.procs) == 1, "the GIF worker started")
    (worker,) = runner.procs
    os.kill(worker.pid, signal.SIGKILL)  # as an abort in native code would end it
    t.join()
    r = answer["r"]
    assert r.status_code == 500 and r.json()["error"].startswith("internal server error")
    assert client.get("/api/examples").status_code == 200


def _run_coroutine(coro):
    """``asyncio.run(coro)`` in a thread of its own: a browser test run earlier in the same
    worker (Playwright's sync API) leaves an event loop running in the main thread, where
    ``asyncio.run`` refuses to start."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coro).result()
