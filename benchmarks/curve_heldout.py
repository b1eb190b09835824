"""Benchmark: held-out curves (buildable, simplest, any scale).

Run from the repository root::

    python benchmarks/curve_heldout.py [--per-class 5] [--time-limit 60] [--database DIR] [--json out.json]

Targets: closed curves of random fully rotating 4-, 6- and 8-bar linkages drawn by
``benchmarks/curve_synthesis.py``'s generator (link lengths, not joint coordinates;
independent of the database sampler) from a seed family never used while developing
(29 000 + class), each then moved by a random similarity (rotation, mirror image with
probability 1/2, scale 10^-2 .. 10^3, translation), so scale and orientation are part
of the test. Every target goes to :func:`synthesize_curve` with the defaults (up to 8
links, tolerance 0.5 % of the diagonal, size 1.5 diagonals, link ratio 10,
transmission angle 30°) and once more with ``max_links=4`` (time limit a third): when
that four-bar is within the tolerance and the bounds, the default run must return a
four-bar first. Reported: share within 0.5 %, every best inside the bounds, four-bar
first whenever one is within tolerance, median time. Times are wall-clock on a shared
2-core machine.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

from curve_synthesis import random_linkage_curve  # noqa: E402

from mechsyn.synthesis.curves.database import load_database  # noqa: E402
from mechsyn.synthesis.curves.synthesis import synthesize_curve  # noqa: E402
from mechsyn.synthesis.curves.target import target_from_points  # noqa: E402

TOL = 5e-3


def moved(P: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    a = rng.uniform(0, 2 * np.pi)
    Q = P * [1, -1] if rng.random() < 0.5 else P
    R = np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    s = 10.0 ** rng.uniform(-2, 3)
    return (Q - Q.mean(axis=0)) @ R.T * s + rng.uniform(-100, 100, 2) * s


def inside(c) -> bool:
    q = c.quality()
    return q["size_ratio"] <= 1.5 + 1e-9 and q["link_ratio"] <= 10 + 1e-9 and q["min_transmission_angle"] >= 30


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-class", type=int, default=5)
    ap.add_argument("--classes", type=int, nargs="+", default=[4, 6, 8])
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--database", default=None)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    db = load_database(args.database, max_links=8)
    print(f"database: {len(db)} curves; time limit {args.time_limit:g} s; tolerance {100 * TOL:g} %")
    print(f"{'gen':>3} {'#':>2} {'best':>22} {'chamfer %':>9} {'size':>5} {'ratio':>5} {'mu':>3} {'s':>5} "
          f"{'4-bar only %':>12}  four-bar rule")
    rows = []
    for n in args.classes:
        rng = np.random.default_rng(29_000 + n)
        for i in range(args.per_class):
            tgt = target_from_points(moved(random_linkage_curve(n, rng), rng), closed=True)
            t0 = time.perf_counter()
            res = synthesize_curve(tgt, max_links=8, time_limit=args.time_limit, top=3, database=db)
            dt = time.perf_counter() - t0
            four = synthesize_curve(tgt, max_links=4, time_limit=args.time_limit / 3, top=1, database=db)
            c = res.candidates[0] if res.candidates else None
            f = four.candidates[0] if four.candidates else None
            f_ok = f is not None and f.chamfer <= TOL
            rule = (c is not None and c.topology.n_links == 4) if f_ok else None
            rows.append({"generator": n, "chamfer": c.chamfer if c else None, "seconds": dt,
                         "topology": c.topology.label if c else None, "quality": c.quality() if c else None,
                         "inside": bool(c and inside(c)), "fourbar_within": f_ok,
                         "fourbar_chamfer": f.chamfer if f else None, "fourbar_first": rule,
                         "empty_reason": res.reason if not c else ""})
            print(f"{n:3d} {i + 1:2d} {(c.topology.label if c else '-'):>22} "
                  f"{(100 * c.chamfer if c else float('nan')):9.3f} {(c.size_ratio if c else float('nan')):5.2f} "
                  f"{(c.link_length_ratio if c else float('nan')):5.1f} "
                  f"{(c.min_transmission_angle if c else float('nan')):3.0f} {dt:5.1f} "
                  f"{(100 * f.chamfer if f else float('nan')):12.3f}  "
                  f"{'-' if rule is None else ('yes' if rule else 'NO')}", flush=True)
    err = np.array([r["chamfer"] if r["chamfer"] is not None else np.inf for r in rows])
    tt = np.array([r["seconds"] for r in rows])
    rule = [r["fourbar_first"] for r in rows if r["fourbar_first"] is not None]
    print(f"within 0.5 %: {int(np.sum(err <= TOL))} of {len(rows)} ({100 * np.mean(err <= TOL):.0f} %); "
          f"median chamfer {100 * np.median(err):.3f} %; every best inside the bounds: "
          f"{sum(r['inside'] for r in rows)} of {sum(r['chamfer'] is not None for r in rows)}; "
          f"four-bar first when one is within tolerance: {sum(rule)} of {len(rule)}; "
          f"median time {np.median(tt):.1f} s (max {tt.max():.1f} s)")
    if args.json:
        Path(args.json).write_text(json.dumps(rows))


if __name__ == "__main__":
    main()
