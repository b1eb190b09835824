"""``mechsyn serve`` under signals (issue 27): SIGINT and SIGTERM stop it whatever is open.

A real server process; every wait is for a readiness signal (the printed URL, an accepted
connection, the first event of a stream), never for a time.
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from web_helpers import free_port

SRC = str(Path(__file__).resolve().parents[2] / "src")


def _start_serve(cwd: Path) -> tuple[subprocess.Popen, str, str]:
    port = free_port()
    p = subprocess.Popen([sys.executable, "-m", "mechsyn", "serve", "--no-browser", "--port", str(port)],
                         cwd=cwd, env={**os.environ, "PYTHONPATH": SRC}, text=True, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    line = p.stdout.readline()  # the URL, printed before the server listens
    token = re.search(r"token=([\w-]+)", line)
    assert token, (line, p.poll())
    deadline = time.monotonic() + 120  # only ends a broken run
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=5).close()
            break
        except OSError:
            assert p.poll() is None and time.monotonic() < deadline, p.stderr.read() if p.poll() else "no listen"
            time.sleep(0.05)
    return p, f"http://127.0.0.1:{port}", token.group(1)


@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_serve_stops_on_a_signal_with_an_event_stream_open(tmp_path, sig, code, word):
    import httpx

    p, base, token = _start_serve(tmp_path)
    try:
        headers = {"X-Mechsyn-Token": token}
        job = httpx.post(f"{base}/api/synth/fourbar_path", headers=headers, timeout=60,
                         json={"targets": [[0, 0], [1, 0], [1, 1], [0, 1]], "time_limit": 600, "restarts": 50})
        assert job.status_code == 200, job.text
        with httpx.stream("GET", f"{base}/api/jobs/{job.json()['id']}/events?token={token}", timeout=60) as r:
            first = next(r.iter_text())  # the stream is open: its first event arrived
            assert first.startswith("event: ")
            p.send_signal(sig)
            out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
            p.communicate()
    assert p.returncode == code, err[-2000:]
    assert "Traceback" not in err and err.strip().splitlines()[-1] == word, err[-2000:]
