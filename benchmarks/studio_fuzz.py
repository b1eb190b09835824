"""Concurrency fuzz of a real ``mechsyn serve`` (issue 27); run by hand, not in the suite.

Run from the repository root:  python benchmarks/studio_fuzz.py [SECONDS]

Six clients hammer the studio with hostile and heavy requests (bad chains during atlas
lists, malformed bodies, simulate/analyze of a six-bar, Save over package.json and a
symlink loop, abandoned 360-frame GIF exports, dropped uploads) while a probe client
times a cheap request pair (examples list, validate) every 0.25 s. At the end the server
gets SIGINT. Prints whether it lived, its exit code and stop time, the status codes
(5xx counted), the probe's latency (median, p99, max, how many over 200 ms) and the
tracebacks in its log. See docs/reliability.md for figures.
"""
import json, os, random, re, signal, socket, subprocess, sys, tempfile, threading, time
from pathlib import Path

import httpx

DURATION = float(sys.argv[1]) if len(sys.argv) > 1 else 300
SRC = str(Path(__file__).resolve().parent.parent / "src")
ROOT = Path(tempfile.mkdtemp(prefix="mechsyn-fuzz-"))
(ROOT / "loop.yaml").symlink_to("loop.yaml")
(ROOT / "package.json").write_text('{"name": "app", "version": "1"}\n')
port = 18000 + random.randrange(1000)
env = {**os.environ, "PYTHONPATH": SRC}
p = subprocess.Popen([sys.executable, "-m", "mechsyn", "serve", "--no-browser", "--port", str(port)],
                     cwd=ROOT, env=env, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
line = p.stdout.readline()
token = re.search(r"token=([\w-]+)", line).group(1)
base = f"http://127.0.0.1:{port}"
H = {"X-Mechsyn-Token": token}
while True:
    try:
        socket.create_connection(("127.0.0.1", port)).close(); break
    except OSError:
        time.sleep(0.05)
c0 = httpx.Client(base_url=base, headers=H, timeout=120)
fb = c0.get("/api/examples/fourbar").json()["mechanism"]
six = c0.get("/api/examples/watt_sixbar").json()["mechanism"]
chain = c0.get("/api/atlas?links=6").json()["chains"][0]["chain"]
stats = {"requests": 0, "5xx": 0, "errors": 0, "codes": {}}
lat = []
stop = time.monotonic() + DURATION
lock = threading.Lock()


def note(code):
    with lock:
        stats["requests"] += 1
        stats["codes"][code] = stats["codes"].get(code, 0) + 1
        if code >= 500:
            stats["5xx"] += 1


def bad_chain():
    ch = json.loads(json.dumps(chain))
    k = random.randrange(4)
    if k == 0: ch["edges"][0] = [0, 99]
    elif k == 1: ch["edges"][0] = [1, 1]
    elif k == 2: ch["n_links"] = 3000
    else: ch["edges"] = [[i, (i + 1) % 3000] for i in range(3000)]
    return {"chain": ch, "frame": random.choice([None, 0, 99, -1])}


RAWS = [b'{"mechanism": NaN}', b'{"mechanism": ' + b"[" * 50000 + b"]" * 50000 + b"}",
        b'{"steps": ' + b"9" * 5000 + b"}", b'{"mechanism": {"name": "\\ud800"}}', b"\xff\xfe", b'{"a":1,"a":2}']


def hostile_client(i):
    c = httpx.Client(base_url=base, headers={**H, "X-Mechsyn-Client": f"h{i}"}, timeout=120)
    while time.monotonic() < stop:
        k = random.randrange(8)
        try:
            if k == 0:
                r = c.post("/api/atlas/mechanism", json=bad_chain())
            elif k == 1:
                r = c.get(f"/api/atlas?links={random.choice([6, 8, 10])}")
            elif k == 2:
                r = c.post(random.choice(["/api/simulate", "/api/analyze", "/api/validate", "/api/export"]),
                           content=random.choice(RAWS), headers={"content-type": "application/json"})
            elif k == 3:
                r = c.post("/api/simulate", json={"mechanism": random.choice([fb, six]), "steps": random.choice([36, 720, 2000])})
            elif k == 4:
                r = c.post("/api/analyze", json={"mechanism": six})
            elif k == 5:
                r = c.post("/api/file", json={"path": random.choice(["a.yaml", "package.json", "x/../y.yaml", "loop.yaml"]),
                                               "mechanism": fb, "overwrite": random.choice([True, "false", 1])})
            elif k == 6:  # an abandoned GIF export
                s = socket.create_connection(("127.0.0.1", port))
                body = json.dumps({"mechanism": six, "format": "gif", "frames": 360}).encode()
                s.sendall(f"POST /api/export HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Mechsyn-Token: {token}\r\n"
                          f"Content-Type: application/json\r\nContent-Length: {len(body)}\r\n\r\n".encode() + body)
                time.sleep(random.uniform(0.1, 2)); s.close(); continue
            else:  # a dropped upload
                s = socket.create_connection(("127.0.0.1", port))
                s.sendall(f"POST /api/import HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Mechsyn-Token: {token}\r\n"
                          f"Content-Type: application/json\r\nContent-Length: 200000\r\n\r\n".encode() + b'{"text": "' + b"x" * 5000)
                s.close(); continue
            note(r.status_code)
        except httpx.HTTPError as exc:
            with lock:
                stats["errors"] += 1
            if p.poll() is not None:
                return


def probe():
    c = httpx.Client(base_url=base, headers={**H, "X-Mechsyn-Client": "probe"}, timeout=120)
    while time.monotonic() < stop:
        t = time.perf_counter()
        r = c.get("/api/examples")
        lat.append(time.perf_counter() - t)
        note(r.status_code)
        t = time.perf_counter()
        r = c.post("/api/validate", json={"mechanism": fb})
        lat.append(time.perf_counter() - t)
        note(r.status_code)
        time.sleep(0.25)


threads = [threading.Thread(target=hostile_client, args=(i,)) for i in range(6)] + [threading.Thread(target=probe)]
[t.start() for t in threads]
[t.join() for t in threads]
alive = p.poll() is None
p.send_signal(signal.SIGINT)
t = time.perf_counter()
out, err = p.communicate(timeout=60)
stop_s = time.perf_counter() - t
lat.sort()
q = lambda f: lat[min(len(lat) - 1, int(f * len(lat)))]
print(json.dumps({"duration_s": DURATION, "alive_at_end": alive, "exit_code": p.returncode, "stop_seconds": round(stop_s, 2),
                  **stats, "probe_requests": len(lat), "probe_median_ms": round(1000 * q(0.5), 1),
                  "probe_p99_ms": round(1000 * q(0.99), 1), "probe_max_ms": round(1000 * lat[-1], 1),
                  "probe_over_200ms": sum(x > 0.2 for x in lat),
                  "tracebacks_in_log": err.count("Traceback"), "log_lines": len(err.splitlines())}, indent=1))
