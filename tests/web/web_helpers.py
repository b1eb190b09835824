"""Helpers of the studio tests: the token, Debian's Chromium and a live server in a thread."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

TOKEN = "test-token"
CHROMIUM = Path("/usr/bin/chromium")
CHROMIUM_ARGS = ["--no-sandbox", "--headless", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--no-first-run", "--disable-sync"]
IMAGES = Path(__file__).resolve().parents[2] / "docs" / "images"


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
