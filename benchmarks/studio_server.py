"""The studio's server under load (issue 42); run by hand, not in the suite.

Run from the repository root:  python benchmarks/studio_server.py [SECONDS_PER_PHASE]

A real ``mechsyn serve`` process, two phases of SECONDS_PER_PHASE (default 60) each:

1. 24 clients hammer the heaviest routes (a 360-frame GIF of the Watt six-bar, analyze,
   a 2,000-step simulation, the 3-D view of the Bennett linkage, the 10-link atlas, the
   structure check of a 199-joint mechanism), each on its own connection;
2. 8 clients hammer the structure check (``POST /api/studio/check``) of a 199-joint
   mechanism (a four-bar and 65 dyads, mobility 1).

Meanwhile a probe asks ``GET /api/start`` every 0.1 s (nothing heavy: answered by the
server's own process) and a second probe the structure check of a four-bar every 0.5 s
(a cheap request that needs a worker: the fair queue). Prints, per phase, the probes'
median, 95th percentile and largest time, the hammering clients' answers by status, and
the server process's resident memory (RSS) before and after. Target (issue 42): the
``/api/start`` probe under 200 ms at the 95th percentile. See docs/reliability.md.
"""

from __future__ import annotations

import os
import random
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import httpx

SECONDS = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
SRC = str(Path(__file__).resolve().parent.parent / "src")


def dyad_chain(dyads: int) -> dict:
    """A four-bar with ``dyads`` RRR dyads chained on it: 4 + 3 dyads joints, mobility 1."""
    links = ["frame", "crank", "coupler", "rocker"]
    joints = [{"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
              {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": [1, 2]},
              {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4, 3]},
              {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [5, 0]}]
    prev, px, py = "coupler", 2.5, 2.5
    for i in range(dyads):
        a, b, x0 = f"a{i}", f"b{i}", 5 + 3 * i
        links += [a, b]
        joints += [{"id": f"P{i}", "type": "R", "links": [prev, a], "point": [px + 0.3, py + 0.7]},
                   {"id": f"Q{i}", "type": "R", "links": [a, b], "point": [x0 + 2, 3.1 + 0.1 * (i % 3)]},
                   {"id": f"G{i}", "type": "R", "links": [b, "frame"], "point": [x0 + 3, 0]}]
        prev, px, py = a, x0 + 1, 3.0
    return {"name": f"a four-bar and {dyads} dyads", "kind": "planar", "ground": "frame", "links": links,
            "joints": joints}


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return float("nan")


def start_server() -> tuple[subprocess.Popen, str, dict]:
    port = 19000 + random.randrange(1000)
    p = subprocess.Popen([sys.executable, "-m", "mechsyn", "serve", "--no-browser", "--port", str(port)],
                         cwd=tempfile.mkdtemp(prefix="mechsyn-bench-"), env={**os.environ, "PYTHONPATH": SRC},
                         text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    token = re.search(r"token=([\w-]+)", p.stdout.readline()).group(1)
    while True:
        try:
            socket.create_connection(("127.0.0.1", port)).close()
            break
        except OSError:
            time.sleep(0.05)
    return p, f"http://127.0.0.1:{port}", {"X-Mechsyn-Token": token}


def phase(base: str, headers: dict, clients: int, requests: list, seconds: float, four: dict) -> dict:
    """``clients`` threads sending ``requests`` (method, path, body) at random for
    ``seconds``, with the two probes; the answers and the probes' times."""
    stop = time.monotonic() + seconds
    codes: dict[int, int] = {}
    start_times: list[float] = []
    check_times: list[float] = []
    lock = threading.Lock()

    def hammer() -> None:
        with httpx.Client(base_url=base, headers=headers, timeout=600) as c:
            while time.monotonic() < stop:
                method, path, body = random.choice(requests)
                try:
                    code = c.request(method, path, json=body).status_code
                except httpx.HTTPError:
                    code = 0
                with lock:
                    codes[code] = codes.get(code, 0) + 1

    def probe(path: str, body, every: float, out: list) -> None:
        with httpx.Client(base_url=base, headers=headers, timeout=600) as c:
            while time.monotonic() < stop:
                t0 = time.perf_counter()
                r = c.request("GET" if body is None else "POST", path, json=body)
                out.append(time.perf_counter() - t0)
                assert r.status_code == 200, (path, r.status_code, r.text[:200])
                time.sleep(max(0.0, every - (time.perf_counter() - t0)))

    threads = [threading.Thread(target=hammer) for _ in range(clients)]
    threads += [threading.Thread(target=probe, args=("/api/start", None, 0.1, start_times)),
                threading.Thread(target=probe, args=("/api/studio/check", {"mechanism": four}, 0.5, check_times))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return {"codes": dict(sorted(codes.items())), "start": start_times, "check": check_times}


def summary(times: list[float]) -> str:
    ms = sorted(1000 * t for t in times)
    p95 = ms[min(len(ms) - 1, int(0.95 * len(ms)))]
    return f"n {len(ms)}, median {statistics.median(ms):.0f} ms, p95 {p95:.0f} ms, max {ms[-1]:.0f} ms"


def main() -> None:
    p, base, headers = start_server()
    try:
        with httpx.Client(base_url=base, headers=headers, timeout=120) as c:
            four = c.get("/api/examples/fourbar").json()["mechanism"]
            six = c.get("/api/examples/watt_sixbar").json()["mechanism"]
            bennett = c.get("/api/examples/bennett").json()["mechanism"]
            big = dyad_chain(65)
            assert c.post("/api/studio/check", json={"mechanism": big}).json()["mobility"] == 1
        heaviest = [("POST", "/api/export", {"mechanism": six, "format": "gif", "frames": 360}),
                    ("POST", "/api/analyze", {"mechanism": six}),
                    ("POST", "/api/simulate", {"mechanism": six, "steps": 2000}),
                    ("POST", "/api/spatial/simulate", {"mechanism": bennett, "steps": 2000}),
                    ("GET", "/api/atlas?links=10", None),
                    ("POST", "/api/studio/check", {"mechanism": big})]
        checks = [("POST", "/api/studio/check", {"mechanism": big})]
        print(f"server pid {p.pid}, RSS at start {rss_mb(p.pid):.0f} MB; {SECONDS:.0f} s a phase, "
              f"{os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}")
        for name, clients, requests in (("24 clients, heaviest routes", 24, heaviest),
                                        ("8 clients, check of 199 joints", 8, checks)):
            before = rss_mb(p.pid)
            out = phase(base, headers, clients, requests, SECONDS, four)
            print(f"\n{name}: answers by status {out['codes']}")
            print(f"  GET /api/start        {summary(out['start'])}")
            print(f"  check of a four-bar   {summary(out['check'])}")
            print(f"  server RSS {before:.0f} -> {rss_mb(p.pid):.0f} MB, load average {os.getloadavg()[0]:.1f}")
    finally:
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=120)
        print(f"\nstopped: exit {p.returncode}, stderr {err.strip().splitlines()[-1:] if err.strip() else []}")


if __name__ == "__main__":
    main()
