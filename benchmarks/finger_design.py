"""Speed of paper 000's finger design (``mechsyn synth finger-design``).

Prints the cost of one design evaluation in the fully actuated mode by the closed-form
locked model (what the optimiser calls) against the kinematics engine's Newton
continuation of the full file with the VLL locked (what a user would otherwise call,
``simulate``), their largest difference, and whole runs of the bundled case for three
seeds. Run: ``PYTHONPATH=src python benchmarks/finger_design.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.system import build_system
from mechsyn.synthesis.finger.cases import load_case
from mechsyn.synthesis.finger.design import apply_design, design_finger, evaluate_locked

CASE = Path(__file__).resolve().parents[1] / "examples" / "fingers" / "finger_design_case.yaml"


def best_of(fn, n: int, reps: int = 5) -> float:
    t = []
    for _ in range(reps):
        t0 = time.perf_counter()
        for _ in range(n):
            fn()
        t.append((time.perf_counter() - t0) / n)
    return min(t)


def main() -> None:
    case = load_case(CASE)
    x = np.array([14.0, 6.0, 8.0, 48.0, 123.69006753])
    mech = mechanism_from_dict(apply_design(case, x))
    th0 = float(np.degrees(build_system(mech).drivers[0].assembled))
    grid = th0 + case.sweep_inputs
    fast = best_of(lambda: evaluate_locked(case, x), 50)
    newton = best_of(lambda: simulate(mech, {"E": grid}, points=["tip"], vll={"S": "locked"}, method="newton"), 3)
    ev = evaluate_locked(case, x)
    sim = simulate(mech, {"E": grid}, points=["tip"], vll={"S": "locked"}, method="newton")
    diff = float(np.max(np.abs(ev.paths["tip"] - sim.points["tip"].position)))
    print(f"one design, {len(grid)} crank angles, VLL locked:")
    print(f"  closed-form locked model   {fast * 1e3:8.2f} ms")
    print(f"  engine Newton (simulate)   {newton * 1e3:8.2f} ms   ratio {newton / fast:.1f}x")
    print(f"  largest tip difference     {diff:.2e}")
    for seed in (0, 1, 2):
        t0 = time.perf_counter()
        r = design_finger(load_case(CASE), seed=seed)
        v = r.best_variant
        print(f"seed {seed}: {time.perf_counter() - t0:5.1f} s, stage-1 RMS {v.stage1_error_rms:.2e} deg, "
              f"final RMS {v.error_rms:.3f} deg, VLL S in [{v.vll_ranges['S'][0]:.4g}, {v.vll_ranges['S'][1]:.4g}], "
              f"peak |R| {v.stage1_forces['peak_reaction']:.4g} -> {v.forces['peak_reaction']:.4g}, "
              f"peak |M_in| {v.stage1_forces['peak_input_moment']:.4g} -> {v.forces['peak_input_moment']:.4g}")


if __name__ == "__main__":
    main()
