"""Benchmark: topological synthesis of planar kinematic chains, mechsyn vs Pyslvs.

Run from the repository root:  python benchmarks/atlas.py [--pyslvs-timeout SECONDS]

Prints, in one run, the number of mobility-1 chains of 8, 10 and 12 links and the
time each tool takes to enumerate them (mechsyn: best of 3 runs, 12 links: one run),
mechsyn's counts for mobility 2 with 9 and 11 links, and the ratio Pyslvs / mechsyn.

Pyslvs (22.7.0, its structural synthesis: link_synthesis -> contracted_link_synthesis
-> contracted_graph -> conventional_graph) lives in its own virtual environment
``benchmarks/.env-atlas`` (gitignored), which this script creates when missing:
Pyslvs builds from source only, with
    pip install Cython==3.0.0 setuptools wheel numpy lark-parser
    pip install --no-build-isolation pyslvs==22.7.0
(about 3 minutes). Pyslvs runs in a subprocess; its time is measured inside that process
(imports excluded), like mechsyn's.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.chains import synthesize_chains  # noqa: E402

ENV = ROOT / "benchmarks" / ".env-atlas"
PY = ENV / "bin" / "python"

LITERATURE = {(8, 1): 16, (10, 1): 230, (12, 1): 6856, (9, 2): 40, (11, 2): 839}

PYSLVS_WORKER = r"""
import json, sys, time
from pyslvs.graph import (link_synthesis, contracted_link_synthesis, contracted_graph,
                          conventional_graph)
nl = int(sys.argv[1]); nj = (3 * (nl - 1) - 1) // 2
t = time.perf_counter(); total = 0
for la in link_synthesis(nl, nj):
    cgs = contracted_graph(la)
    for cj in contracted_link_synthesis(la):
        total += len(conventional_graph(cgs, cj, 1))  # 1: non-degenerate (Pyslvs GUI)
print(json.dumps({"count": total, "seconds": time.perf_counter() - t}))
"""


def ensure_pyslvs() -> str | None:
    """Create the Pyslvs environment when missing; return an error text or None."""
    if PY.exists():
        check = subprocess.run([str(PY), "-c", "import pyslvs.graph"], capture_output=True)
        if check.returncode == 0:
            return None
    steps = [
        [sys.executable, "-m", "venv", str(ENV)],
        [str(PY), "-m", "pip", "install", "-q", "Cython==3.0.0", "setuptools", "wheel",
         "numpy", "lark-parser"],
        [str(PY), "-m", "pip", "install", "-q", "--no-build-isolation", "pyslvs==22.7.0"],
    ]
    for step in steps:
        print("setting up Pyslvs:", " ".join(step[-3:]), flush=True)
        done = subprocess.run(step, capture_output=True, text=True)
        if done.returncode:
            return f"{' '.join(step)} failed: {done.stderr.strip()[-500:]}"
    return None


def time_mechsyn(n: int, f: int, repeat: int) -> tuple[int, float]:
    best = float("inf")
    count = 0
    for _ in range(repeat):
        t = time.perf_counter()
        count = len(synthesize_chains(n, f))
        best = min(best, time.perf_counter() - t)
    return count, best


def time_pyslvs(n: int, timeout: float) -> tuple[int | None, float | None, str]:
    try:
        done = subprocess.run([str(PY), "-c", PYSLVS_WORKER, str(n)], capture_output=True,
                              text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, None, f"> {timeout:.0f} s (stopped)"
    if done.returncode:
        return None, None, "failed: " + done.stderr.strip().splitlines()[-1]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    return out["count"], out["seconds"], ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pyslvs-timeout", type=float, default=600.0)
    parser.add_argument("--no-pyslvs", action="store_true")
    args = parser.parse_args()

    synthesize_chains(6, 1)  # warm imports and caches
    error = None if args.no_pyslvs else ensure_pyslvs()
    if error:
        print("Pyslvs unavailable:", error)
    print(f"{'links':>5} {'F':>2} {'literature':>10} {'mechsyn':>8} {'time':>9} "
          f"{'Pyslvs':>7} {'time':>10} {'Pyslvs/mechsyn':>15}")
    for n, f in [(8, 1), (10, 1), (12, 1), (9, 2), (11, 2)]:
        count, seconds = time_mechsyn(n, f, 1 if n >= 12 else 3)
        ok = "" if count == LITERATURE[(n, f)] else "  MISMATCH"
        ps_count, ps_seconds, note = (None, None, "-")
        if f == 1 and not args.no_pyslvs and not error:
            ps_count, ps_seconds, note = time_pyslvs(n, args.pyslvs_timeout)
        ratio = f"{ps_seconds / seconds:15.1f}" if ps_seconds else f"{'-':>15}"
        ps_c = f"{ps_count:7d}" if ps_count is not None else f"{'-':>7}"
        ps_t = f"{ps_seconds:9.3f}s" if ps_seconds is not None else f"{note:>10}"
        print(f"{n:5d} {f:2d} {LITERATURE[(n, f)]:10d} {count:8d} {seconds:8.3f}s "
              f"{ps_c} {ps_t} {ratio}{ok}", flush=True)
    print("Pyslvs drops chains with non-planar graphs and keeps some with a rigid "
          "five-link sub-chain (10 links: 223 instead of 230).")


if __name__ == "__main__":
    main()
