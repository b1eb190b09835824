"""Benchmark: the cost of two hostile inputs of issue 42 (one run, figures printed).

1. A Pyslvs expression with one joint on N links (``J[R, P[0, 0], L[ground, l0, ...]]``):
   the parser with the link limit raised out of the way, so every name is read (the
   names were looked up in a list: quadratic, 47 s for 40,000 on the reporter's machine),
   and ``mechsyn convert`` on 40,000 links with the default limit (refused at the 2,001st).
2. ``mechsyn capability`` at one point on a URDF chain of n revolute joints against a
   planar arm of n joints (the exact limit of a spatial task by linear programming: one
   block-diagonal program per ~20,000 variables instead of one per configuration).

    python benchmarks/hostile_inputs.py [--links 5000 10000 20000 40000] [--joints 10 20 40]
"""

from __future__ import annotations

import argparse
import os
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, nargs="*", default=[5_000, 10_000, 20_000, 40_000])
    ap.add_argument("--joints", type=int, nargs="*", default=[10, 20, 40])
    args = ap.parse_args()
    pyslvs(args.links)
    capability(args.joints)


if __name__ == "__main__":
    main()
