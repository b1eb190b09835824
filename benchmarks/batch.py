"""Benchmark: the batch kinematics engine against bare NumPy (issue 14 §3).

Run from the repository root::

    python benchmarks/batch.py [--designs 10000] [--inputs 361] [--rounds 7] [--check]

* **Four-bars**: ``K`` random crank-rocker-like four-bars (frame pivots, crank joint,
  coupler joint, coupler point) over ``N`` crank offsets, positions of the coupler
  point only. Timed: :func:`mechsyn.kinematics.batch.simulate_batch` (plan compiled
  once, outside the timing; ``flags=False`` and with the per-design dead-point and
  branch-jump flags) against a bare NumPy closed form written for the four-bar alone
  (the same array work: crank point, circle-circle intersection, coupler point).
  Target: batch <= 3x bare NumPy.
* **Six-bars**: Watt and Stephenson six-bars (examples/textbook), ``K`` random
  perturbations, positions of one point; time per design against the four-bar's
  per-design batch time. Target: <= 2x.
* Answers: the four-bar paths against the bare NumPy closed form (every design), and
  sampled designs of each kind re-simulated through :func:`mechsyn.kinematics.simulate`
  (the same assembled samples, largest difference of the positions); an answer is
  "equal" when the assembled masks agree and the positions within 1e-9. ``--check``
  exits 1 when one is not.

Timing: ``--rounds`` rounds, each timing every case in turn (the least of three calls in
a row), so that the cases of a round see the same load; printed are the median time, the
median of the rounds' ratios and the ratio of the minima (the least disturbed runs), with
the load average.
"""

from __future__ import annotations

import argparse
import os
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
    with np.errstate(invalid="ignore"):      # NaN where the four-bar does not assemble
        return _bare_numpy_fourbar(O, A0, B0, D, M0, u)


def _bare_numpy_fourbar(O, A0, B0, D, M0, u):
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


def timed_rounds(cases: dict, rounds: int, calls: int = 3) -> dict[str, np.ndarray]:
    """Seconds per call of each case: ``rounds`` rounds of every case in turn, each case
    called ``calls`` times in a row in a round and its least time kept (the first call
    after another case pays for the memory that case returned to the system)."""
    times = {name: [] for name in cases}
    for _ in range(rounds):
        for name, fn in cases.items():
            best = np.inf
            for _ in range(calls):
                t0 = time.perf_counter()
                fn()
                best = min(best, time.perf_counter() - t0)
            times[name].append(best)
    return {name: np.array(t) for name, t in times.items()}


def ratio(t: dict, a: str, b: str, per: float = 1.0) -> tuple[float, float]:
    """Median of the rounds' ratios ``a / b`` and the ratio of the minima (``per`` divides
    ``a``: designs per design)."""
    return float(np.median(t[a] / t[b])) * per, float(t[a].min() / t[b].min()) * per


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


SIXBARS = ("watt_sixbar", "stephenson_sixbar")
TOL = 1e-9


def six_bar_case(f: str, K: int, rng):
    """Plan (one output: the named point, else the last dyad's joint) and K perturbed designs."""
    m6 = load_mechanism(ROOT / "examples" / "textbook" / f"{f}.yaml")
    last = compile_plan(m6).dyads[-1][1]
    plan6 = compile_plan(m6, points=[next(iter(m6.points), last)])
    return m6, plan6, perturbed(plan6.parameters(m6), K, rng, 0.1)


def verdict(diff: float, same: bool = True) -> str:
    """``equal`` when the assembled samples agree and the positions within TOL."""
    if same and diff <= TOL:
        return f"equal (largest difference {diff:.1e})"
    return f"DIFFER ({diff:.1e})" if same else f"DIFFER (assembled samples; {diff:.1e})"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=10_000)
    ap.add_argument("--inputs", type=int, default=361)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--check", action="store_true", help="exit 1 when an answer differs")
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
    six = {f: six_bar_case(f, K, rng) for f in SIXBARS}
    cases = {"numpy": lambda: bare_numpy_fourbar(O, A0, B0, D, M0, u),
             "four-bar": lambda: simulate_batch(plan, designs, offsets, flags=False),
             "four-bar+flags": lambda: simulate_batch(plan, designs, offsets)}
    for f, (_, p6, d6) in six.items():
        cases[f] = lambda p6=p6, d6=d6: simulate_batch(p6, d6, offsets, flags=False)
    load0 = os.getloadavg()[0]
    t = timed_rounds(cases, args.rounds)
    print(f"simulate_batch: {K} designs x {N} inputs, positions of one point")
    print(f"{args.rounds} rounds, load average {load0:.2f} -> {os.getloadavg()[0]:.2f}; time: median of the rounds;")
    print("ratio: median of the rounds' ratios / ratio of the minima; six-bars per design")
    report(t, six)
    return check_answers(mech, plan, designs, offsets, (O, A0, B0, D, M0, u), six, rng)


NAMES = {"watt_sixbar": "Watt six-bar", "stephenson_sixbar": "Stephenson six-bar"}


def report(t: dict, six: dict) -> None:
    """The timing table (80 columns)."""
    print(f"\n  {'case':24s}{'time':>9s}  {'ratio':11s}  {'to':12s}target")
    print(f"  {'bare NumPy four-bar':24s}{np.median(t['numpy']) * 1e3:6.1f} ms")
    rows = [("four-bar", "four-bars, positions", "numpy", "bare NumPy", 3.0),
            ("four-bar+flags", "four-bars, + flags", "numpy", "bare NumPy", None)]
    rows += [(f, f"{NAMES[f]} ({', '.join(p6.outputs)})", "four-bar", "four-bar", 2.0) for f, (_, p6, _) in six.items()]
    for name, label, ref, to, target in rows:
        med, mn = ratio(t, name, ref)
        goal = "" if target is None else f"<= {target:g}: {'met' if max(med, mn) <= target else 'NOT met'}"
        print(f"  {label:24s}{np.median(t[name]) * 1e3:6.1f} ms  {med:4.2f} / {mn:4.2f}  {to:12s}{goal}".rstrip())


def check_answers(mech, plan, designs, offsets, fourbar_args, six, rng) -> int:
    """Print the answer checks; 1 when one differs."""
    mx, my = bare_numpy_fourbar(*fourbar_args)
    res = simulate_batch(plan, designs, offsets)
    P, fin = res.paths["M"], np.isfinite(mx)
    diff = float(np.nanmax(np.abs(P[fin] - np.stack([mx, my], -1)[fin]))) if fin.any() else 0.0
    same = bool(np.array_equal(fin, res.assembled))
    picks = rng.choice(len(designs), 8, replace=False)
    lines = [("four-bars vs bare NumPy, every design", verdict(diff, same)),
             ("four-bars vs simulate, 8 designs", verdict(check_against_simulate(mech, plan, designs, offsets, picks)))]
    for f, (m6, p6, d6) in six.items():
        lines.append((f"{NAMES[f]} vs simulate, 6 designs",
                      verdict(check_against_simulate(m6, p6, d6, offsets, rng.choice(len(d6), 6, replace=False)))))
    print(f"\n  answers ({int((~res.dead_point).sum())} of {len(designs)} four-bars fully rotating, "
          f"{int(res.branch_jump.sum())} branch jumps flagged)")
    for what, v in lines:
        print(f"  {what:41s} {v}")
    return int(any(v.startswith("DIFFER") for _, v in lines))


if __name__ == "__main__":
    code = main()
    sys.exit(code if "--check" in sys.argv else 0)
