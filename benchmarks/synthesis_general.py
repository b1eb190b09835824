"""Speed of `mechsyn synth mechanism` (mechsyn.synthesis.general): what generality costs.

Prints the time to evaluate one design (build the mechanism from the file, sweep it with
the kinematics engine, compute the error) for the four-bar and the Watt six-bar, against
the closed-form four-bar path module (mechsyn.synthesis.path, vectorised over a DE
population: the tool a user with a plain four-bar would pick), one engine sweep per design
against the batch engine over the whole population (mechsyn.synthesis.general_batch, with
the fitness checked equal), and the synthesis runs of the bundled example cases over 5
seeds, engine and batch.

First, the topology-keyed fast path of the engine evaluation (issue 30): designs evaluated
per second with each design parsed and its constraint system built (``fast=False``, the
general path) and with its numbers filled into the case's parsed mechanism and compiled
plan (``fast=True``), rounds interleaved in this process, every evaluation checked equal;
then one synthesis run per path with the same seed (results checked equal).

    python benchmarks/synthesis_general.py            # everything
    python benchmarks/synthesis_general.py --fast     # the fast-path part only
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.general import (MechanismProblem, evaluate_mechanism_design,  # noqa: E402
                                       load_mechanism_case, mechanism_case_from_dict, start_vector,
                                       synthesize_mechanism)
from mechsyn.synthesis.path import PathCase, PathProblem  # noqa: E402


def per_design(f, X, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f(X)
        best = min(best, time.perf_counter() - t)
    return best / len(X)


def _equal(a, b) -> bool:
    """Two evaluations equal: feasibility, notes, method exactly, numbers to 1e-12."""
    if (a.feasible, a.reason, a.method) != (b.feasible, b.reason, b.method):
        return False
    if not a.feasible:
        return a.violation == b.violation
    return abs(a.error - b.error) <= 1e-12 * max(1.0, abs(b.error)) and np.allclose(
        a.achieved, b.achieved, rtol=0, atol=1e-12) and np.allclose(a.path, b.path, rtol=0, atol=1e-12)


def fast_path(rounds: int = 5, n: int = 200) -> None:
    """Designs per second of the engine evaluation, general path vs fast path."""
    fourbar = mechanism_case_from_dict({
        "mechanism": str(ROOT / "examples/textbook/fourbar.yaml"),
        "input": {"joint": "A", "values_deg": [40, 50, 60, 70, 80, 90]}, "link": "coupler",
        "poses": [[3, 4, 10 * k] for k in range(6)],
        "variables": [{"joint": j, "coord": c, "lower": lo, "upper": hi} for j, c, lo, hi in
                      (("B", "x", 0.8, 1.2), ("C", "x", 3.8, 4.2), ("D", "x", 4.8, 5.2))]}, "<bench>")
    finger = mechanism_case_from_dict({
        "mechanism": str(ROOT / "examples/fingers/two_phalanx_vll_000.yaml"),
        "input": {"joint": "E", "values_deg": [0, 10, 20, 30, 40]}, "point": "tip", "targets": [[0, 60]] * 5,
        "variables": [{"joint": "S", "length": True, "lower": 24, "upper": 34},
                      {"joint": "C", "coord": "x", "lower": 4, "upper": 12}]}, "<bench>")
    cases = (("slider-crank (bundled case, RRP)", load_mechanism_case(ROOT / "examples/synthesis/slider_crank_path_case.yaml")),
             ("Watt six-bar (bundled case)", load_mechanism_case(ROOT / "examples/synthesis/sixbar_path_case.yaml")),
             ("four-bar, motion generation", fourbar),
             ("finger, locked VLL length", finger))
    rng = np.random.default_rng(0)
    print(f"engine evaluation per design, {n} designs x {rounds} interleaved rounds (median), one process")
    print(f"  {'case':36s} {'general /s':>11s} {'fast /s':>9s} {'speed-up':>8s}  equal")
    for name, case in cases:
        X = rng.uniform(case.lower, case.upper, size=(n, len(case.lower)))
        same = all(_equal(evaluate_mechanism_design(case, x), evaluate_mechanism_design(case, x, fast=False))
                   for x in X)
        probs = {fast: MechanismProblem(case, batch=False, fast=fast) for fast in (False, True)}
        times: dict[bool, list[float]] = {False: [], True: []}
        for _ in range(rounds):
            for fast, p in probs.items():
                t = time.perf_counter()
                p.fitness(X)
                times[fast].append(time.perf_counter() - t)
        g, f = (n / float(np.median(times[k])) for k in (False, True))
        print(f"  {name:36s} {g:11.0f} {f:9.0f} {f / g:7.2f}x  {same}")
    case = cases[0][1]
    print("\nsynth mechanism of the slider-crank case, engine per design (seed 0, 1 restart, 40 generations)")
    runs = {}
    for fast in (False, True):
        r = synthesize_mechanism(case, seed=0, time_limit=600, restarts=1, batch=False, options={"maxiter": 40},
                                 fast=fast)
        runs[fast] = r
        print(f"  {'fast' if fast else 'general':8s} {r.seconds:6.2f} s  {r.nfev} designs  "
              f"{r.nfev / r.seconds:6.0f} designs/s  error {r.error:.3g}")
    a, b = runs[False], runs[True]
    same = a.nfev == b.nfev and a.reason == b.reason and np.allclose(a.x, b.x, rtol=0, atol=1e-12) and \
        abs(a.error - b.error) <= 1e-12 * max(1.0, a.error) and a.mechanism == b.mechanism
    print(f"  same design, error, notes and evaluations on both paths: {same}")


def main() -> None:
    fast_path()
    if "--fast" in sys.argv[1:]:
        return
    print()
    rng = np.random.default_rng(0)
    values = [40, 50, 60, 70, 80, 90]
    fb = mechanism_case_from_dict({
        "mechanism": str(ROOT / "examples/textbook/fourbar.yaml"), "input": {"joint": "A", "values_deg": values},
        "point": "M", "targets": [[3, 4]] * 6,
        "variables": [{"joint": "B", "coord": "x", "lower": 0.8, "upper": 1.2},
                      {"joint": "C", "coord": "x", "lower": 3.8, "upper": 4.2},
                      {"joint": "D", "coord": "x", "lower": 4.8, "upper": 5.2},
                      {"point": "M", "coord": "y", "lower": 3.8, "upper": 4.2}]}, "<bench>")
    six = load_mechanism_case(ROOT / "examples/synthesis/sixbar_path_case.yaml")
    rows = []
    for name, case in (("four-bar (general)", fb), ("Watt six-bar (general)", six)):
        p = MechanismProblem(case, batch=False)
        X = rng.uniform(p.lower, p.upper, size=(200, len(p.lower)))
        rows.append((name + ", engine per design", per_design(p.fitness, X)))
        pb = MechanismProblem(case)
        Xb = rng.uniform(p.lower, p.upper, size=(2000, len(p.lower)))
        rows.append((name + ", batch population", per_design(pb.fitness, Xb)))
        same = np.allclose(p.fitness(X[:50]), pb.fitness(X[:50]), rtol=1e-9, atol=1e-12)
        rows.append((f"  (batch fitness equal to the engine's on 50 designs: {same})", None))
    pc = PathCase.from_dict({
        "id": "bench", "targets": [[3, 4]] * 6, "timing": {"type": "prescribed", "theta2": np.radians(values).tolist()},
        "fixed": {"x0": 0, "y0": 0, "theta0": 0},
        "variables": [{"name": n, "lower": lo, "upper": hi} for n, lo, hi in
                      (("r1", 4.8, 5.2), ("r2", 2.1, 2.4), ("r3", 3.0, 3.3), ("r4", 3.0, 3.3),
                       ("rcx", 1.5, 2.5), ("rcy", 1.0, 2.0))],
        "kinematics": {"branch": -1}})
    pp = PathProblem(pc)
    Z = rng.uniform(pp.lower, pp.upper, size=(5000, len(pp.lower)))
    ref = per_design(pp.fitness, Z)
    print("time per design evaluation (best of 3, shared 2-core machine)")
    print(f"  {'closed-form four-bar (path module, population-vectorised)':60s} {ref * 1e6:9.1f} us")
    for name, t in rows:
        if t is None:
            print(f"  {name}")
            continue
        print(f"  {name:60s} {t * 1e6:9.1f} us   ({t / ref:.1f}x the closed-form module)")
    print("\nsynthesis of the bundled cases (1 restart, default options, 5 seeds)")
    for f in ("sixbar_path_case.yaml", "slider_crank_path_case.yaml"):
        case = load_mechanism_case(ROOT / "examples/synthesis" / f)
        start = MechanismProblem(case).fitness(start_vector(case)[None, :])[0]
        for batch in (False, True):
            errs, secs = [], []
            for seed in range(5):
                r = synthesize_mechanism(case, seed=seed, time_limit=30, restarts=1, batch=batch)
                errs.append(r.error)
                secs.append(r.seconds)
            how = "batch " if batch else "engine"
            print(f"  {f:30s} {how} start {start:.3g}  best {min(errs):.3g}  median {np.median(errs):.3g}  "
                  f"median {np.median(secs):.1f} s")


if __name__ == "__main__":
    main()
