"""Benchmark: hostile inputs of issue 42 from outside (one run, figures printed).

1. A Pyslvs expression with one joint on N links (``J[R, P[0, 0], L[ground, l0, ...]]``):
   the parser with the link limit raised out of the way, so every name is read (the
   names were looked up in a list: quadratic, 47 s for 40,000 on the reporter's machine),
   and ``mechsyn convert`` on 40,000 links with the default limit (refused at the 2,001st).
2. ``mechsyn capability`` at one point on a URDF chain of n revolute joints against a
   planar arm of n joints (the exact limit of a spatial task by linear programming: one
   block-diagonal program per ~20,000 variables instead of one per configuration, and
   the self-motion ascending the measure's gradient: linear in the joints).
3. The outside check of the issue's CLI cases, each a ``mechsyn`` process under a 4 GB
   address-space cap (``ulimit -v 4194304``): ``synth curve`` on /dev/zero and on a FIFO,
   Pyslvs with one joint on 40,000 links, three damaged curve databases (descriptors 3
   wide, all NaN, a header declaring 1e11 rows) and an atlas stream line of 10,000
   nested brackets. Each must answer one line on stderr and exit 2 within 15 s, with no
   traceback; printed as a table.
4. With ``--studio``, a real ``mechsyn serve`` (started as benchmarks/studio_server.py
   does): ``POST /api/spatial/view`` with a joint axis (1e300, 1e300, 1e300) must be a
   400, and a client with its token must be served within 3 s while 250 connections that
   sent a request line only are held open. (The 8 clients hammering the structure check:
   benchmarks/studio_server.py.)

    python benchmarks/hostile_inputs.py [--links 5000 10000 20000 40000] [--joints 20 40 80 100]
                                        [--skip-outside] [--studio]
"""

from __future__ import annotations

import argparse
import io
import os
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.io.pyslvs import parse_expression  # noqa: E402
from mechsyn.limits import set_limit  # noqa: E402


def _expression(n: int) -> str:
    return "M[J[R, P[0, 0], L[ground, " + ", ".join(f"l{i}" for i in range(n)) + "]]]"


def _cli(*args: str) -> float:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "mechsyn.cli.main", *args], env=env, capture_output=True, check=False)
    return time.perf_counter() - t0


def pyslvs(sizes: list[int]) -> None:
    set_limit("links", 10 ** 9)
    try:
        for n in sizes:
            text = _expression(n)
            t0 = time.perf_counter()
            parse_expression(text)
            print(f"pyslvs parse, one joint on {n:>6,} links: {time.perf_counter() - t0:8.3f} s")
    finally:
        set_limit("links", None)
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "big.pyslvs"
        f.write_text(_expression(40_000))
        print(f"mechsyn convert, 40,000 links (refused by the limit): {_cli('convert', str(f), '-o', str(Path(tmp) / 'o.yaml')):.2f} s")


def _urdf(n: int) -> str:
    links = "".join(f'<link name="l{i}"/>' for i in range(n + 1))
    joints = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
        f'<origin xyz="0.1 0 0.05" rpy="0 {0.3 if i % 2 else 0} 0"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
        f'<limit lower="-3" upper="3" velocity="1"/></joint>' for i in range(n))
    return f'<robot name="chain{n}">{links}{joints}</robot>'


def capability(joints: list[int]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        for n in joints:
            urdf, planar = Path(tmp) / f"chain{n}.urdf", Path(tmp) / f"planar{n}.yaml"
            urdf.write_text(_urdf(n))
            planar.write_text(f"kind: planar_serial\nlink_lengths: {[0.1] * n}\n"
                              f"joint_speed_limits_deg_s: {[10] * n}\n")
            tu = _cli("capability", str(urdf), "--direction", "1,0,0", "--point", "0,0,0")
            tp = _cli("capability", str(planar), "--direction", "1,0", "--point", "0.3,0.2")
            print(f"capability, {n:>3} joints: URDF chain {tu:7.1f} s, planar arm {tp:7.1f} s")


def _capped(args: list[str], cwd: Path) -> tuple[int, list[str], float]:
    """``mechsyn ARGS`` under a 4 GB address-space cap (killed after 60 s): exit code,
    stderr lines, wall time."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    cmd = "ulimit -v 4194304; exec " + shlex.join([sys.executable, "-m", "mechsyn.cli.main", *args])
    t0 = time.perf_counter()
    try:
        p = subprocess.run(["bash", "-c", cmd], cwd=cwd, env=env, capture_output=True, text=True, timeout=60)
        rc, err = p.returncode, p.stderr
    except subprocess.TimeoutExpired as e:
        rc, err = -9, (e.stderr or b"").decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
    return rc, [ln for ln in err.splitlines() if ln.strip()], time.perf_counter() - t0


def _damaged_databases(tmp: Path) -> dict[str, Path]:
    """A small curve database and three copies damaged as in the issue."""
    import zipfile

    import numpy as np

    from mechsyn.synthesis.curves.database import build_database

    good = tmp / "db"
    build_database(good, max_links=4, per_topology=30)
    out = {}
    for damage in ("descriptors 3 wide", "descriptors all NaN", "header of 1e11 rows"):
        db = tmp / damage.replace(" ", "_")
        shutil.copytree(good, db)
        f = sorted(db.glob("*.npz"))[0]
        with np.load(f) as z:
            data = {k: z[k] for k in z.files}

        def npy(a):
            b = io.BytesIO()
            np.save(b, a)
            return b.getvalue()

        members = {k: npy(v) for k, v in data.items()}
        desc = data["descriptors"]
        if damage.endswith("wide"):
            members["descriptors"] = npy(desc[:, :3])
        elif damage.endswith("NaN"):
            members["descriptors"] = npy(np.full_like(desc, np.nan))
        else:
            members["descriptors"] = members["descriptors"].replace(str(desc.shape).encode(), b"(100000000000, 20)")
        with zipfile.ZipFile(f, "w", zipfile.ZIP_DEFLATED) as zf:
            for k, v in members.items():
                zf.writestr(f"{k}.npy", v)
        out[damage] = db
    return out


def outside() -> bool:
    """The issue's CLI cases from outside; True when every one holds."""
    ok = True
    with tempfile.TemporaryDirectory() as tmp_name:
        tmp = Path(tmp_name)
        (tmp / "zero.csv").symlink_to("/dev/zero")
        os.mkfifo(tmp / "fifo.csv")
        (tmp / "big.pyslvs").write_text(_expression(40_000))
        (tmp / "t.csv").write_text("0,0\n1,0\n1,1\n0,1\n")
        cases = {"synth curve on /dev/zero": ["synth", "curve", "zero.csv"],
                 "synth curve on a FIFO": ["synth", "curve", "fifo.csv"],
                 "Pyslvs, one joint on 40,000 links": ["convert", "big.pyslvs", "-o", "o.yaml"]}
        for damage, db in _damaged_databases(tmp).items():
            cases[f"curve database, {damage}"] = ["synth", "curve", "t.csv", "--database", str(db),
                                                  "--max-links", "4"]
        stream = tmp / "s.jsonl"
        _capped(["atlas", "-n", "6", "--stream", str(stream)], tmp)
        lines = stream.read_text().splitlines()
        lines[1] = "[" * 10_000 + "]" * 10_000
        stream.write_text("\n".join(lines) + "\n")
        cases["atlas stream line of 10,000 nested brackets"] = ["atlas", "-n", "6", "--stream", str(stream)]
        print(f"{'case (4 GB cap)':<46} {'exit':>4} {'lines':>5} {'time':>7}  verdict")
        for name, args in cases.items():
            rc, err, dt = _capped(args, tmp)
            good = rc == 2 and len(err) == 1 and dt < 15 and not any("Traceback" in ln for ln in err)
            limit = 2.0 if name.startswith("Pyslvs") else 15.0
            good &= dt < limit
            ok &= good
            print(f"{name:<46} {rc:>4} {len(err):>5} {dt:6.2f}s  {'holds' if good else 'FAILS'}")
            print(f"    {err[0][:150] if err else '(nothing on stderr)'}")
    return ok


def studio() -> bool:
    """The issue's server cases against a real ``mechsyn serve``; True when both hold."""
    import socket

    import httpx

    sys.path.insert(0, str(HERE))
    from studio_server import start_server

    from mechsyn.io import load_mechanism, mechanism_to_dict
    from mechsyn.web._service import example_path

    p, base, headers = start_server()
    idle: list[socket.socket] = []
    try:
        m = mechanism_to_dict(load_mechanism(example_path("bennett")))
        m["joints"][2]["axis"] = [1e300, 1e300, 1e300]
        r = httpx.post(f"{base}/api/spatial/view", json={"mechanism": m}, headers=headers, timeout=60)
        axis_ok = r.status_code == 400
        print(f"studio: POST /api/spatial/view, axis (1e300, 1e300, 1e300): {r.status_code} "
              f"{r.text[:120]!r}  {'holds' if axis_ok else 'FAILS'}")
        port = int(base.rsplit(":", 1)[1])
        for _ in range(250):
            s = socket.create_connection(("127.0.0.1", port))
            s.sendall(b"GET /api/start HTTP/1.1\r\n")
            idle.append(s)
        time.sleep(1.0)
        t0 = time.perf_counter()
        r = httpx.get(f"{base}/api/start", headers=headers, timeout=60)
        dt = time.perf_counter() - t0
        idle_ok = r.status_code == 200 and dt < 3
        print(f"studio: GET /api/start with its token, 250 idle connections open: {r.status_code} in "
              f"{dt * 1000:.0f} ms  {'holds' if idle_ok else 'FAILS'}")
        return axis_ok and idle_ok
    finally:
        for s in idle:
            s.close()
        p.send_signal(signal.SIGINT)
        try:
            p.wait(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, nargs="*", default=[5_000, 10_000, 20_000, 40_000])
    ap.add_argument("--joints", type=int, nargs="*", default=[20, 40, 80, 100])
    ap.add_argument("--skip-outside", action="store_true", help="leave out the outside CLI check")
    ap.add_argument("--studio", action="store_true", help="also the server cases (a real mechsyn serve)")
    args = ap.parse_args()
    if not args.skip_outside and not outside():
        print("the outside check FAILS")
    if args.studio and not studio():
        print("the studio check FAILS")
    pyslvs(args.links)
    capability(args.joints)


if __name__ == "__main__":
    main()
