"""Benchmark: synth curve keeps short limits and turned drawings (the outside checks).

Run from the repository root::

    python benchmarks/curve_anytime.py [--short 4] [--limit 30] [--turn 37] [--seeds 3] [--no-turn]
                                       [--no-short] [--refinements N]

Through the CLI (one process per run, CLI defaults, the default database):

* **a short limit**: closed coupler curves of random four-bars from
  ``benchmarks/curve_synthesis.py``'s generator (seed family 41 000, never used in
  development) with ``--time-limit 4``: the command's wall-clock time and whether it
  answers with a candidate (exit status 0);
* **a turned drawing**: closed coupler curves of random six-bars (same generator) and
  the same curve turned by ``--turn`` degrees about the origin, each with
  ``--time-limit`` seconds (or ``--refinements N``, the same amount of work whatever the
  load): the most accurate candidate's error of each and their ratio (within 20 % asked).

Each run's wall-clock and CPU (user + system) seconds are printed with the load average:
the CPU time is what the run itself cost, the wall-clock time what the shared machine
made of it.

Errors are :func:`mechsyn.synthesis.curves.fitting.chamfer_error` (% of the diagonal).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from curve_synthesis import random_linkage_curve  # noqa: E402


def cli(P: np.ndarray, limit: float, tmp: Path, *extra: str) -> tuple[dict, float, int]:
    """``synth curve --json`` on points ``P``: the result, wall-clock seconds, exit status
    (the run's CPU seconds in the result's ``"cpu"``)."""
    f = tmp / "target.json"
    f.write_text(json.dumps({"points": P.tolist(), "closed": True}))
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
    t, c = time.perf_counter(), os.times()
    r = subprocess.run([sys.executable, "-m", "mechsyn", "synth", "curve", str(f), "--time-limit", str(limit),
                        "--json", *extra], capture_output=True, text=True, env=env)
    dt, c2 = time.perf_counter() - t, os.times()
    res = json.loads(r.stdout) if r.stdout.strip().startswith("{") else {"candidates": []}
    res["cpu"] = (c2.children_user - c.children_user) + (c2.children_system - c.children_system)
    return res, dt, r.returncode


def best_error(res: dict) -> float:
    return min((c["error"]["chamfer"] for c in res["candidates"]), default=float("nan"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--short", type=float, default=4.0)
    ap.add_argument("--limit", type=float, default=30.0)
    ap.add_argument("--turn", type=float, default=37.0)
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--no-turn", action="store_true", help="the short limits only")
    ap.add_argument("--no-short", action="store_true", help="the turned drawings only")
    ap.add_argument("--refinements", type=int, default=None, help="turned drawings: this many refinements")
    args = ap.parse_args()
    rng4, rng6 = np.random.default_rng(41_004), np.random.default_rng(41_006)
    a = np.radians(args.turn)
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for i in range(0 if args.no_short else args.seeds):
            res, dt, code = cli(random_linkage_curve(4, rng4) * 50.0, args.short, tmp)
            c = res["candidates"][0] if res["candidates"] else None
            print(f"four-bar {i + 1}, --time-limit {args.short:g}: exit {code}, {dt:.2f} s wall, {res['cpu']:.2f} s CPU "
                  f"(load average {os.getloadavg()[0]:.1f}), "
                  + (f"{c['topology']} at {100 * c['error']['chamfer']:.2f} %"
                     + ("" if c["refined"] else " (retrieved, not refined)")
                     + ("" if c["verified"] else f" ({c['verification']})") if c else "no candidate"), flush=True)
        more = () if args.refinements is None else ("--refinements", str(args.refinements))
        for i in range(0 if args.no_turn else args.seeds):
            P = random_linkage_curve(6, rng6) * 50.0
            r0, t0, _ = cli(P, args.limit, tmp, *more)
            r1, t1, _ = cli(P @ R.T, args.limit, tmp, *more)
            e0, e1 = best_error(r0), best_error(r1)
            print(f"six-bar {i + 1}: error {100 * e0:.3f} % as drawn ({t0:.1f} s), {100 * e1:.3f} % turned "
                  f"{args.turn:g}° ({t1:.1f} s): turned / drawn = {e1 / e0:.3f}", flush=True)


if __name__ == "__main__":
    main()
