"""Fixtures of the studio tests: the app in-process, a live server in a thread, Chromium."""

from __future__ import annotations

import pytest

pytest.importorskip("starlette")

from mechsyn.web import create_app  # noqa: E402

from web_helpers import CHROMIUM, CHROMIUM_ARGS, TOKEN, LiveServer  # noqa: E402


@pytest.fixture
def client(tmp_path):
    """The app on ``tmp_path`` (start directory), called in-process; token header set."""
    from starlette.testclient import TestClient

    app = create_app(tmp_path, token=TOKEN)
    with TestClient(app, base_url="http://127.0.0.1", headers={"X-Mechsyn-Token": TOKEN}) as c:
        yield c


@pytest.fixture
def serve(tmp_path):
    """``serve(start_mechanism_dict_or_None, name="")`` → a running :class:`LiveServer` in tmp_path."""
    servers = []

    def start(mechanism=None, name=""):
        srv = LiveServer(create_app(tmp_path, start=mechanism, token=TOKEN, start_name=name))
        servers.append(srv)
        return srv

    yield start
    for s in servers:
        s.stop()


@pytest.fixture(scope="session")
def browser():
    if not CHROMIUM.exists():
        pytest.skip("Debian's Chromium (/usr/bin/chromium) is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture
def page(browser):
    """A page that records every request leaving the server and every console error."""
    ctx = browser.new_context(viewport={"width": 1280, "height": 800}, accept_downloads=True)
    pg = ctx.new_page()
    pg.outside_requests = []
    pg.console_errors = []
    pg.on("request", lambda r: None if r.url.startswith(("http://127.0.0.1", "data:", "blob:"))
          else pg.outside_requests.append(r.url))
    # a 400 answer to a bad edit is shown on the page (the tests check that); Chromium also logs it
    pg.on("console", lambda m: pg.console_errors.append(m.text) if m.type == "error"
          and "status of 400" not in m.text else None)
    pg.on("pageerror", lambda e: pg.console_errors.append(str(e)))
    yield pg
    ctx.close()
