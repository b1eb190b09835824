"""Path-synthesis benchmark: mechsyn vs the published best errors (and a plain SciPy DE).

Runs every case of ``spec/data/synthesis_cases_public.json`` (plus ``benchmarks/
synthesis_extra_cases.json`` when present) with seeds 0..N-1 and the default settings of
``mechsyn synth path`` (time limit 60 s per run), and prints for each case: best and
median error, median and max time, how many runs reached the published best, and the
ratio median / published best. ``--baseline-seeds K`` also runs what a user would
otherwise pick: SciPy's ``differential_evolution`` with its defaults (best1bin,
popsize 15, L-BFGS-B polish; tol=0 so that it uses the whole time limit instead of stopping
on an all-infeasible population) on the full design vector with the same feasibility-first
fitness and time limit.

    python benchmarks/synthesis.py [--seeds 10] [--time-limit 60] [--baseline-seeds 3] [--workers 1]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from scipy.optimize import differential_evolution  # noqa: E402

from mechsyn.synthesis.optimize import synthesize_path  # noqa: E402
from mechsyn.synthesis.path import PathProblem, evaluate_design, load_cases  # noqa: E402

SPEC_CANDIDATES = [ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json"]


def baseline(case, seed: int, time_limit: float) -> tuple[float, float]:
    prob = PathProblem(case)
    t0 = time.time()
    res = differential_evolution(lambda X: prob.fitness(X.T), list(zip(prob.lower, prob.upper)), seed=seed,
                                 vectorized=True, updating="deferred", maxiter=100000, tol=0.0,
                                 callback=lambda intermediate_result: time.time() - t0 > time_limit)
    f = float(prob.fitness(res.x[None])[0])
    return (f if f < prob.penalty_base else float("inf")), time.time() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--baseline-seeds", type=int, default=3)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--cases", nargs="*", help="only these case ids")
    ap.add_argument("--json", type=Path, help="also write all run records here")
    args = ap.parse_args()
    spec = next((p for p in SPEC_CANDIDATES if p.exists()), None)
    if spec is None:
        sys.exit("synthesis_cases_public.json not found")
    cases = load_cases(spec)
    extra = ROOT / "benchmarks" / "synthesis_extra_cases.json"
    if extra.exists():
        cases += load_cases(extra)
    if args.cases:
        cases = [c for c in cases if c.id in args.cases]
    records = []
    print(f"# mechsyn synth path benchmark: {args.seeds} seeds, {args.time_limit:g} s limit, workers {args.workers}")
    for case in cases:
        runs = []
        for seed in range(args.seeds):
            r = synthesize_path(case, seed=seed, time_limit=args.time_limit, workers=args.workers)
            chk = evaluate_design(case, r.design)
            assert chk["feasible"] == r.feasible and abs(chk["error"] - r.error) <= 1e-12 * max(1, r.error)
            runs.append((r.error if r.feasible else float("inf"), r.seconds))
            records.append({"case": case.id, "seed": seed, "error": r.error, "feasible": r.feasible,
                            "seconds": r.seconds, "restarts": r.restarts, "design": r.design})
            print(f"  {case.id} seed {seed}: error {r.error:.10g} feasible {r.feasible} "
                  f"{r.seconds:.1f} s ({r.restarts} restarts)", flush=True)
        err = np.array([e for e, _ in runs])
        sec = np.array([s for _, s in runs])
        pub = case.best_known
        line = (f"{case.id}: best {err.min():.6g}  median {np.median(err):.6g}  worst {err.max():.6g}  "
                f"time median {np.median(sec):.1f} s max {sec.max():.1f} s")
        if pub:
            line += (f"  published best {pub:.6g}  runs <= published {int(np.sum(err <= pub))}/{len(err)}"
                     f"  median/published {np.median(err) / pub:.4f}")
        print(line, flush=True)
        if args.baseline_seeds:
            b = [baseline(case, s, args.time_limit) for s in range(args.baseline_seeds)]
            be = np.array([x for x, _ in b])
            bs = np.array([x for _, x in b])
            records.append({"case": case.id, "baseline": [{"error": x, "seconds": t} for x, t in b]})
            print(f"  baseline scipy DE defaults, {args.baseline_seeds} seeds: best {be.min():.6g} median "
                  f"{np.median(be):.6g} time median {np.median(bs):.1f} s;  median ratio baseline/mechsyn "
                  f"{np.median(be) / np.median(err):.3g}", flush=True)
    if args.json:
        args.json.write_text(json.dumps(records, indent=1, default=float))


if __name__ == "__main__":
    main()
