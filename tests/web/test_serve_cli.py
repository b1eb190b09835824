"""``mechsyn serve``: argument checks, and the app it builds (the server itself is mocked)."""

from __future__ import annotations

import pytest


@pytest.fixture
def served(monkeypatch):
    """Replace uvicorn and the browser: record what serve would start."""
    calls = {}

    def fake_run(app, host, port):
        calls.update(app=app, host=host, port=port)
        if "opened" in calls:  # the page opened while the server runs
            from pathlib import Path
            from urllib.parse import urlparse

            page = Path(urlparse(calls["opened"]).path)
            calls.update(page_mode=page.stat().st_mode & 0o777, page_text=page.read_text(), page=page)

    monkeypatch.setattr("mechsyn.web.run_server", fake_run)
    monkeypatch.setattr("webbrowser.open", lambda url: calls.setdefault("opened", url))
    return calls


def test_serve_example_binds_loopback(run_cli, served):
    code, out, err = run_cli("serve", "fourbar", "--no-browser", "--port", "8799")
    assert code == 0, err
    assert served["host"] == "127.0.0.1" and served["port"] == 8799 and "opened" not in served
    token = served["app"].state.token
    assert f"http://127.0.0.1:8799/?token={token}" in out.replace("\n", "")
    from starlette.testclient import TestClient

    c = TestClient(served["app"], base_url="http://127.0.0.1:8799", headers={"X-Mechsyn-Token": token})
    start = c.get("/api/start").json()
    assert start["name"] == "fourbar.yaml" and [j["id"] for j in start["mechanism"]["joints"]] == list("ABCD")


def test_serve_opens_the_browser(run_cli, served, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli("serve", "--port", "0")
    assert code == 0, err
    assert served["port"] > 0 and served["app"].state.root == tmp_path.resolve()
    # the token is not on the browser's command line (ps shows it): a page only this user reads
    token = served["app"].state.token
    assert served["opened"].startswith("file://") and token not in served["opened"]
    assert served["page_mode"] == 0o600
    assert f"http://127.0.0.1:{served['port']}/?token={token}" in served["page_text"]
    assert not served["page"].exists()  # removed when the server stopped


def test_serve_other_host_warns(run_cli, served):
    code, out, err = run_cli("serve", "--host", "0.0.0.0", "--no-browser", "--port", "8799")
    assert code == 0 and served["host"] == "0.0.0.0"
    assert len(err.strip().splitlines()) == 1 and "warning" in err and "TLS" in err


def test_all_addresses_accept_the_machines_own_address(run_cli, served):
    """--host 0.0.0.0 opened the port but refused its own address (remote browsers got 403)."""
    import socket

    run_cli("serve", "--host", "0.0.0.0", "--no-browser", "--port", "8799")
    app, token = served["app"], served["app"].state.token
    for addr in ("192.168.1.5", "10.0.0.7"):  # the address the connection came in on
        scope_server = (addr, 8799)
        r = _get_with_server(app, f"{addr}:8799", scope_server, token)
        assert r == 200
        assert _get_with_server(app, "evil.example:8799", scope_server, token) == 403  # rebinding: a name
        assert _get_with_server(app, "10.9.9.9:8799", scope_server, token) == 403  # another address
    assert _get_with_server(app, f"{socket.gethostname()}:8799", ("10.0.0.7", 8799), token) == 200


def _get_with_server(app, host: str, server: tuple, token: str) -> int:
    """Status of GET /api/examples with Host ``host`` on a connection to ``server``."""
    import asyncio

    sent = []

    async def receive():
        return {"type": "http.request", "body": b"", "more_body": False}

    async def send(message):
        sent.append(message)

    scope = {"type": "http", "method": "GET", "path": "/api/examples", "raw_path": b"/api/examples",
             "query_string": b"", "headers": [(b"host", host.encode()), (b"x-mechsyn-token", token.encode())],
             "server": server, "client": ("10.0.0.99", 5555), "scheme": "http", "http_version": "1.1",
             "root_path": "", "asgi": {"version": "3.0"}}
    _run_coroutine(app(scope, receive, send))
    return next(m["status"] for m in sent if m["type"] == "http.response.start")


def test_serve_unknown_target_is_one_line_exit_2(run_cli, served):
    code, out, err = run_cli("serve", "no_such_mechanism", "--no-browser")
    assert code == 2 and "no example named 'no_such_mechanism'" in err and "fourbar" in err
    code, out, err = run_cli("serve", "missing/file.yaml", "--no-browser")
    assert code == 2 and "no such file or example" in err
    assert "app" not in served


def _run_coroutine(coro):
    """``asyncio.run(coro)`` in a thread of its own: a browser test run earlier in the same
    worker (Playwright's sync API) leaves an event loop running in the main thread, where
    ``asyncio.run`` refuses to start."""
    import asyncio
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1) as pool:
        return pool.submit(asyncio.run, coro).result()
