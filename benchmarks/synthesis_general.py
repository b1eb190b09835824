"""Speed of `mechsyn synth mechanism` (mechsyn.synthesis.general): what generality costs.

Prints the time to evaluate one design (build the mechanism from the file, sweep it with
the kinematics engine, compute the error) for the four-bar and the Watt six-bar, against
the closed-form four-bar path module (mechsyn.synthesis.path, vectorised over a DE
population: the tool a user with a plain four-bar would pick), one engine sweep per design
against the batch engine over the whole population (mechsyn.synthesis.general_batch, with
the fitness checked equal), and the synthesis runs of the bundled example cases over 5
seeds, engine and batch.

    python benchmarks/synthesis_general.py
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.general import (MechanismProblem, mechanism_case_from_dict, load_mechanism_case,  # noqa: E402
                                       start_vector, synthesize_mechanism)
from mechsyn.synthesis.path import PathCase, PathProblem  # noqa: E402


def per_design(f, X, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        f(X)
        best = min(best, time.perf_counter() - t)
    return best / len(X)


def main() -> None:
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
