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


def _wait_for(predicate, what: str, limit: float = 120.0) -> None:
    deadline = time.monotonic() + limit
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"never happened: {what}")
        time.sleep(0.02)


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
