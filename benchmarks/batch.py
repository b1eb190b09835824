"""Benchmark: the batch kinematics engine against bare NumPy (issue 14 §3).

Run from the repository root::

    python benchmarks/batch.py [--designs 10000] [--inputs 361] [--repeats 5]

* **Four-bars**: ``K`` random crank-rocker-like four-bars (frame pivots, crank joint,
  coupler joint, coupler point) over ``N`` crank offsets, positions of the coupler
  point only. Timed: :func:`mechsyn.kinematics.batch.simulate_batch` (plan compiled
  once, outside the timing; ``flags=False`` and with the per-design dead-point and
  branch-jump flags) against a bare NumPy closed form written for the four-bar alone
  (the same array work: crank point, circle-circle intersection, coupler point).
  Target: batch ≤ 3x bare NumPy.
* **Six-bars**: Watt and Stephenson six-bars (examples/textbook), ``K`` random
  perturbations; time per design against the four-bar's per-design batch time.
  Target: ≤ 2x.
* Answers: sampled designs are re-simulated through :func:`mechsyn.kinematics.simulate`
  and the largest difference is printed (must be ~1e-12).

Times are the minimum of ``--repeats`` runs (the machine is shared: the minimum is the
least disturbed run).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.io.load import load_mechanism, mechanism_from_dict  # noqa: E402
from mechsyn.kinematics import simulate  # noqa: E402
from mechsyn.kinematics.batch import compile_plan, simulate_batch  # noqa: E402

FOURBAR = {
    "name": "four-bar", "kind": "planar", "ground": "f", "links": ["f", "c", "k", "r"],
    "joints": [
        {"id": "A", "type": "R", "links": ["f", "c"], "point": [0, 0], "actuated": True},
        {"id": "B", "type": "R", "links": ["c", "k"], "point": [0.5, 0.866]},
        {"id": "C", "type": "R", "links": ["k", "r"], "point": [3.33, 2.92]},
        {"id": "D", "type": "R", "links": ["r", "f"], "point": [4, 0]}],
    "points": {"M": {"link": "k", "at": [1.33, 2.70]}},
}


def bare_numpy_fourbar(O, A0, B0, D, M0, u):
    """The four-bar written out in NumPy alone: (K, N) x and y of the coupler point."""
    r2 = np.hypot(A0[:, 0] - O[:, 0], A0[:, 1] - O[:, 1])[:, None]
    th0 = np.arctan2(A0[:, 1] - O[:, 1], A0[:, 0] - O[:, 0])[:, None]
    L1 = np.hypot(B0[:, 0] - A0[:, 0], B0[:, 1] - A0[:, 1])[:, None]
    L2 = np.hypot(B0[:, 0] - D[:, 0], B0[:, 1] - D[:, 1])[:, None]
    sig = np.sign((D[:, 0] - A0[:, 0]) * (B0[:, 1] - A0[:, 1]) - (D[:, 1] - A0[:, 1]) * (B0[:, 0] - A0[:, 0]))[:, None]
    th = th0 + u[None, :]
    ax = O[:, 0, None] + r2 * np.cos(th)
    ay = O[:, 1, None] + r2 * np.sin(th)
    dx, dy = D[:, 0, None] - ax, D[:, 1, None] - ay
    dd = dx * dx + dy * dy
    a = (L1 * L1 - L2 * L2 + dd) / (2 * dd)
    h = np.sqrt(L1 * L1 / dd - a * a)
    bx = ax + a * dx - sig * h * dy
    by = ay + a * dy + sig * h * dx
    # coupler point: fixed in the frame (A, B)
    ex0, ey0 = B0[:, 0] - A0[:, 0], B0[:, 1] - A0[:, 1]
    mx0, my0 = M0[:, 0] - A0[:, 0], M0[:, 1] - A0[:, 1]
    p = ((mx0 * ex0 + my0 * ey0) / (L1[:, 0] ** 2))[:, None]
    q = ((my0 * ex0 - mx0 * ey0) / (L1[:, 0] ** 2))[:, None]
    ex, ey = bx - ax, by - ay
    return ax + p * ex - q * ey, ay + p * ey + q * ex


def best_of(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def perturbed(params, K, rng, scale):
    return params[None, :] + rng.normal(scale=scale, size=(K, len(params)))


def check_against_simulate(mech, plan, designs, offsets, picks):
    from mechsyn.io.load import mechanism_to_dict

    worst = 0.0
    base = mechanism_to_dict(mech)
    res = simulate_batch(plan, designs[picks], offsets)
    for row, k in enumerate(picks):
        d = dict(base)
        xy = designs[k].reshape(-1, 2)
        where = {n: xy[i] for i, n in enumerate(plan.names)}
        d["joints"] = [{**j, "point": where[j["id"]].tolist()} for j in base["joints"]]
        d["points"] = {n: {**p, "at": where[n].tolist()} for n, p in base.get("points", {}).items()}
        m = mechanism_from_dict(d)
        sim = simulate(m, {plan.input_joint: compile_plan(m).reference_input + offsets})
        for n in plan.outputs:
            a, b = res.paths[n][row], sim.points[n].position
            same = np.isfinite(a) == np.isfinite(b)
            if not same.all():
                return np.inf
            if np.isfinite(a).any():
                worst = max(worst, float(np.nanmax(np.abs(a - b))))
    return worst


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=10_000)
    ap.add_argument("--inputs", type=int, default=361)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    K, N = args.designs, args.inputs
    rng = np.random.default_rng(1)
    offsets = np.linspace(0.0, 360.0, N)
    u = np.radians(offsets)
    mech = mechanism_from_dict(FOURBAR)
    plan = compile_plan(mech, points=["M"])
    designs = perturbed(plan.parameters(mech), K, rng, 0.15)
    xy = designs.reshape(K, -1, 2)
    idx = {n: i for i, n in enumerate(plan.names)}
    O, A0, B0, D, M0 = (xy[:, idx[n]] for n in ("A", "B", "C", "D", "M"))

    t_np, (mx, my) = best_of(lambda: bare_numpy_fourbar(O, A0, B0, D, M0, u), args.repeats)
    t_b, res = best_of(lambda: simulate_batch(plan, designs, offsets, flags=False), args.repeats)
    t_bf, resf = best_of(lambda: simulate_batch(plan, designs, offsets), args.repeats)
    P = res.paths["M"]
    fin = np.isfinite(mx)
    diff = float(np.nanmax(np.abs(P[..., 0][fin] - mx[fin]))) if fin.any() else 0.0
    same_mask = bool(np.array_equal(fin, res.assembled))
    print(f"four-bars: {K} designs x {N} inputs (coupler point), best of {args.repeats} runs")
    print(f"  bare NumPy closed form        {t_np * 1e3:9.1f} ms")
    print(f"  simulate_batch, positions     {t_b * 1e3:9.1f} ms   ratio {t_b / t_np:5.2f}  (target <= 3)")
    print(f"  simulate_batch, + flags       {t_bf * 1e3:9.1f} ms   ratio {t_bf / t_np:5.2f}")
    print(f"  largest difference to bare NumPy {diff:.2e}, same assembled masks: {same_mask}; "
          f"{int((~resf.dead_point).sum())} fully rotating, {int(resf.branch_jump.sum())} branch jumps flagged")
    picks = rng.choice(K, size=8, replace=False)
    print(f"  vs simulate on 8 sampled designs: largest difference {check_against_simulate(mech, plan, designs, offsets, picks):.2e}")
    per4 = t_b / K
    for f in ("watt_sixbar", "stephenson_sixbar"):
        m6 = load_mechanism(ROOT / "examples" / "textbook" / f"{f}.yaml")
        last = compile_plan(m6).dyads[-1][1]  # the joint of the last dyad
        plan6 = compile_plan(m6, points=[next(iter(m6.points), last)])
        d6 = perturbed(plan6.parameters(m6), K, rng, 0.1)
        t6, _ = best_of(lambda: simulate_batch(plan6, d6, offsets, flags=False), args.repeats)
        print(f"{f}: {t6 * 1e3:9.1f} ms for {K} designs, per design {t6 / K * 1e6:6.2f} us = "
              f"{t6 / K / per4:4.2f} x the four-bar's (target <= 2); outputs {', '.join(plan6.outputs)}")
        picks6 = rng.choice(K, size=6, replace=False)
        print(f"  vs simulate on 6 sampled designs: largest difference "
              f"{check_against_simulate(m6, plan6, d6, offsets, picks6):.2e}")


if __name__ == "__main__":
    main()
