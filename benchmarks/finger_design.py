"""Speed of paper 000's finger design (``mechsyn synth finger-design``).

Prints, in one process (ratios; medians of repeats):

1. one design in the fully actuated mode (VLL locked) over the crank grid: the compiled
   locked model on a population of designs (``synthesis.finger.population``, what the
   optimiser calls), the one-design closed form (``evaluate_locked``, what it called
   before) and the kinematics engine's Newton continuation of the full file
   (``simulate``, what a user would otherwise call), with their largest differences;
2. one configuration's residual and Jacobian, alone (Newton's call) and per configuration
   of a batch (a sweep's), and the underactuated redraw (Newton continuation to a VLL length);
3. whole runs of the bundled case for three seeds (design, errors, VLL range, forces:
   compare them between versions; ``--time-limit`` large enough that no run stops early).

Run: ``PYTHONPATH=src python benchmarks/finger_design.py [--time-limit 600] [--seeds 0 1 2]``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.system import build_system
from mechsyn.synthesis.finger.cases import load_case
from mechsyn.synthesis.finger.design import design_finger
from mechsyn.synthesis.finger.evaluation import apply_design, evaluate_locked
from mechsyn.synthesis.finger.modes import redraw
from mechsyn.synthesis.finger.population import locked_population

CASE = Path(__file__).resolve().parents[1] / "examples" / "fingers" / "finger_design_case.yaml"


def per_call(fn, n: int, reps: int = 5) -> float:
    """Median over ``reps`` of the mean time of ``n`` calls (seconds)."""
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        t.append((time.perf_counter() - t0) / n)
    return float(np.median(t))


def locked_evaluation(case) -> None:
    x = np.array([14.0, 6.0, 8.0, 48.0, 123.69006753])
    mech = mechanism_from_dict(apply_design(case, x))
    th0 = float(np.degrees(build_system(mech).drivers[0].assembled))
    grid = th0 + case.sweep_inputs
    pop = locked_population(case, ("S",))
    rng = np.random.default_rng(0)
    lo, hi = np.array([v.bounds for v in case.variables]).T
    X = np.vstack([x, lo + rng.random((99, len(lo))) * (hi - lo)])
    batch = per_call(lambda: pop.evaluate(X), 5) / len(X)
    one = per_call(lambda: evaluate_locked(case, x, ("S",)), 30)
    newton = per_call(lambda: simulate(mech, {"E": grid}, points=["tip"], vll={"S": "locked"}, method="newton"), 3)
    ev, pev = evaluate_locked(case, x, ("S",)), pop.evaluate(X[:1])
    sim = simulate(mech, {"E": grid}, points=["tip"], vll={"S": "locked"}, method="newton")
    print(f"1. one design, {len(grid)} crank angles, VLL locked (per design):")
    print(f"   compiled locked model, 100 designs at once {batch * 1e3:8.3f} ms")
    print(f"   one-design closed form (evaluate_locked)   {one * 1e3:8.3f} ms   ratio {one / batch:6.1f}x")
    print(f"   engine Newton (simulate)                   {newton * 1e3:8.3f} ms   ratio {newton / batch:6.1f}x")
    print(f"   largest differences: tip {np.max(np.abs(pev.paths['tip'][0] - sim.points['tip'].position)):.1e} "
          f"(vs Newton), RMS error {abs(pev.error_rms[0] - ev.error_rms):.1e} deg (vs closed form)")


def one_configuration_equations(case) -> None:
    x = np.array([14.0, 6.0, 8.0, 48.0, 123.69006753])
    d = apply_design(case, x, ("S",))
    S = build_system(mechanism_from_dict(d), vll={"S": "free"}, prescribed=("S",))
    q, u = S.q0 + 0.01, np.array([dr.assembled for dr in S.drivers])
    q1, u1 = q[None], u[None]
    qN, uN = np.repeat(q1, 361, axis=0), np.repeat(u1, 361, axis=0)
    one = per_call(lambda: (S.residual(q1, u1), S.jacobian(q1)), 2000)
    batch = per_call(lambda: (S.residual(qN, uN), S.jacobian(qN)), 50) / 361
    print(f"2. one configuration ({S.m} equations, {S.n} unknowns), residual + Jacobian:")
    print(f"   alone                      {one * 1e6:8.1f} us")
    print(f"   in a batch of 361          {batch * 1e6:8.1f} us per configuration")
    lengths = {"S": 30.0}
    print(f"   redraw at S = 30 (Newton continuation): {per_call(lambda: redraw(case, d, lengths), 5) * 1e3:7.2f} ms")


def whole_runs(seeds: list[int], time_limit: float) -> None:
    print(f"3. whole runs (time limit {time_limit:g} s):")
    for seed in seeds:
        t0, c0 = time.perf_counter(), time.process_time()
        r = design_finger(load_case(CASE), seed=seed, time_limit=time_limit)
        v = r.best_variant
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        print(f"   seed {seed}: {wall:6.1f} s wall, {cpu:6.1f} s CPU"
              f"{' (stopped by the limit)' if r.stopped_by_time_limit else ''}, "
              f"{r.nfev} evaluations, stage-1 RMS {v.stage1_error_rms:.3e} deg, final RMS {v.error_rms:.4f} deg, "
              f"S in [{v.vll_ranges['S'][0]:.6g}, {v.vll_ranges['S'][1]:.6g}], peak |R| "
              f"{v.stage1_forces['peak_reaction']:.6g} -> {v.forces['peak_reaction']:.6g}, peak |M_in| "
              f"{v.stage1_forces['peak_input_moment']:.6g} -> {v.forces['peak_input_moment']:.6g}")
        print("      design " + ", ".join(f"{k} {val:.9g}" for k, val in v.design.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--time-limit", type=float, default=600.0)
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2])
    args = ap.parse_args()
    case = load_case(CASE)
    locked_evaluation(case)
    one_configuration_equations(case)
    whole_runs(args.seeds, args.time_limit)


if __name__ == "__main__":
    main()
