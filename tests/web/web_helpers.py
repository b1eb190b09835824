"""Helpers of the studio tests: the token, Debian's Chromium and a live server in a thread."""

from __future__ import annotations

import os
import socket
import tempfile
import threading
import time
from pathlib import Path

TOKEN = "test-token"
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--headless", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--no-first-run", "--disable-sync"]
#: Screenshots and the README's drag GIF go to docs/images/ only when asked
#: (MECHSYN_SCREENSHOTS=1); otherwise to a temporary folder, so a test run leaves the
#: checkout as it was.
if os.environ.get("MECHSYN_SCREENSHOTS") == "1":
    IMAGES = Path(__file__).resolve().parents[2] / "docs" / "images"
else:
    IMAGES = Path(tempfile.mkdtemp(prefix="mechsyn-screens-"))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class LiveServer:
    """uvicorn serving an app on a free loopback port in a daemon thread."""

    def __init__(self, app):
        import uvicorn

        self.port = free_port()
        self.server = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=self.port, log_level="warning"))
        self.thread = threading.Thread(target=self.server.run, daemon=True)
        self.thread.start()
        deadline = time.time() + 10
        while not self.server.started:
            if time.time() > deadline:
                raise RuntimeError("the studio server did not start")
            time.sleep(0.02)
        self.url = f"http://127.0.0.1:{self.port}/?token={app.state.token}"

    def stop(self) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=10)


def wait_for(predicate, what: str, limit: float = 120.0) -> None:
    """Wait for a readiness signal (``predicate()``); the limit only stops a broken run."""
    deadline = time.monotonic() + limit
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError(f"never happened: {what}")
        time.sleep(0.02)
