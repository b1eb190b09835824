"""Benchmark: one full ``simulate`` (positions, velocities, accelerations, events) per
mechanism, as a ratio to a bare NumPy closed-form four-bar (positions only), in one process.

Run from the repository root::

    python benchmarks/kinematics_simulate.py [--repeats 30] [--pylinkage /work/venv-pylinkage/bin/python]

Cases (361 inputs, 0..360 degrees):

* ``crank-rocker``: examples/kinematics/crank_rocker.yaml, fully rotating (target <= 15x);
* ``four-bar, 2 dead points``: examples/textbook/fourbar.yaml (target <= 50x);
* ``Watt six-bar``, ``Stephenson six-bar``: examples/textbook/*_sixbar.yaml, with dead
  points (target <= 100x);
* ``Jansen leg``: examples/kinematics/jansen_leg.yaml with its knee double joint written
  three ways (target <= 100x);
* ``drag``: :meth:`KinematicPlan.with_joint_points` + ``simulate`` of the Watt six-bar (the
  editor's drag loop; no target in the issue, reported for the web app).

Then the fixed costs of one call for the crank-rocker, the Watt six-bar and the Jansen leg
(issue 30): a new geometry (``with_joints``), its constraint system, the decomposition,
the engine's sweep, and the rest of ``simulate`` (events, points, result), plan cached
and fresh.

The bare NumPy reference computes the crank-rocker's joint positions B, C for the same
361 angles in five array expressions; mechsyn's answers are checked against it (1e-12),
and the dead points of the textbook four-bar against the law of cosines (1e-6 degree).
Optionally pylinkage (numba; in its own virtual environment, never a mechsyn dependency)
runs build + compile + ``step_fast_with_kinematics`` for the same crank-rocker in a
subprocess, alternately with the same bare NumPy four-bar there; its positions are checked
equal and the two are compared by their ratios to that bare four-bar, each timed in its own
process (so the comparison holds when the load changes between the two processes).

Times are minima (``3 x --repeats`` runs; the bare reference ``10 x``): on a shared
machine minima are the least noisy statistic of each. ``x med`` is a second estimate of
the ratio: the case and the reference timed alternately (``--repeats`` rounds, the median
of 10 calls each), the median of the rounds' ratios (both see the same load in a round).
"""

from __future__ import annotations

import argparse
import inspect
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

N = 361
TARGETS = {"crank-rocker": 15, "four-bar, 2 dead points": 50, "Watt six-bar": 100, "Stephenson six-bar": 100,
           "Jansen leg (double joint on the foot)": 100, "Jansen leg (chain)": 100, "Jansen leg (star)": 100}

PYLINKAGE_SCRIPT = r"""
import json, sys, time
import numpy as np
from pylinkage.components import Ground
from pylinkage.actuators import Crank
from pylinkage.dyads import RRRDyad
from pylinkage.simulation import Linkage
A0, D0, a, b, c, n, repeats, out = json.loads(sys.argv[1])

def build():
    A = Ground(A0[0], A0[1], name="A"); D = Ground(D0[0], D0[1], name="D")
    crank = Crank(anchor=A, radius=a, angular_velocity=2 * np.pi / (n - 1))
    rocker = RRRDyad(crank.output, D, distance1=b, distance2=c)
    lk = Linkage([A, D, crank, rocker], name="crank-rocker")
    lk.set_input_velocity(crank, omega=1.0)
    return lk

lk = build(); lk.compile(); lk.step_fast_with_kinematics(iterations=n)   # numba compile once
th = np.linspace(0, 2 * np.pi, n)
exec(BARE)  # the same bare NumPy four-bar as in mechsyn's process: ratios comparable under any load


def run():
    lk = build(); lk.compile(); return lk.step_fast_with_kinematics(iterations=n)


def bare():
    bare_fourbar(th, np.array(A0), np.array(D0), a, b, c, 1.0)


def med(g):  # median of 10 calls, as mechsyn's paired rounds
    ts = []
    for _ in range(10):
        t = time.perf_counter(); g(); ts.append(time.perf_counter() - t)
    return float(np.median(ts)), min(ts)


best, best_bare, ratios = np.inf, np.inf, []
p, v, acc = run()
for _ in range(repeats):
    (t1, m1), (t2, m2) = med(run), med(bare)
    best, best_bare = min(best, m1), min(best_bare, m2)
    ratios.append(t1 / t2)
import pylinkage
np.save(out + ".npy", p)
print(json.dumps({"build_compile_kinematics": best, "bare": best_bare, "median_ratio": float(np.median(ratios)),
                  "version": pylinkage.__version__}))
"""


def bare_fourbar(theta: np.ndarray, A: np.ndarray, D: np.ndarray, a: float, b: float, c: float,
                 sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """The reference: crank pin B and coupler-rocker joint C of a four-bar, closed form."""
    B = np.stack([A[0] + a * np.cos(theta), A[1] + a * np.sin(theta)], axis=1)
    d = D - B
    t = np.einsum("ij,ij->i", d, d)
    f = 0.5 + (b * b - c * c) / (2 * t)
    g = sigma * np.sqrt(b * b / t - f * f)
    C = B + f[:, None] * d + g[:, None] * np.stack([-d[:, 1], d[:, 0]], axis=1)
    return B, C


def best_of(f, repeats: int) -> float:
    f()
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def paired(f, ref, repeats: int, inner: int = 10) -> tuple[float, float, float]:
    """Median time of ``f``, median time of ``ref`` (each a median of ``inner`` calls) and
    the median of their ratios, the two timed alternately ``repeats`` times: on a shared
    machine both see the same load, so the ratio is steadier than either time."""
    f()
    ref()

    def med(g) -> float:
        ts = []
        for _ in range(inner):
            t = time.perf_counter()
            g()
            ts.append(time.perf_counter() - t)
        return float(np.median(ts))

    tf, tr = [], []
    for _ in range(repeats):
        tf.append(med(f))
        tr.append(med(ref))
    tf_, tr_ = np.array(tf), np.array(tr)
    return float(np.median(tf_)), float(np.median(tr_)), float(np.median(tf_ / tr_))


def both(f, ref, repeats: int, t_ref_min: float) -> tuple[float, float, float]:
    """(minimum time of ``f``, its ratio to the reference's minimum ``t_ref_min``, the
    median ratio of :func:`paired`)."""
    t = best_of(f, repeats * 3)
    return t, t / t_ref_min, paired(f, ref, repeats)[2]


def jansen(writing: str):
    import yaml

    from mechsyn.io import mechanism_from_dict

    d = yaml.safe_load((ROOT / "examples/kinematics/jansen_leg.yaml").read_text())
    J = {j["id"]: j for j in d["joints"]}
    if writing == "chain":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["c", "ghi"]
    elif writing == "star":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["k", "ghi"]
    return mechanism_from_dict(d, f"jansen-{writing}")


def fixed_costs(mech, joint: str, x: np.ndarray, repeats: int) -> dict[str, float]:
    """Where one ``simulate`` call of a freshly built geometry spends its time (minima in
    seconds): a new mechanism with one joint moved (``with_joints``), its constraint
    system (``build_system``), the decomposition into Assur groups (``decompose``), the
    input checks and the sweep of the engine that answers (``first_sweep``), and the rest
    of ``simulate`` (events in input units, named points, link motions, the result)."""
    from dataclasses import replace

    from mechsyn.kinematics.analysis import compile_plan
    from mechsyn.kinematics.engines import PLANAR_ENGINES, first_sweep
    from mechsyn.kinematics.groups import decompose
    from mechsyn.kinematics.solve import assemble, singular_configuration
    from mechsyn.kinematics.system import build_system

    j0 = next(j for j in mech.joints if not j.actuated and j.links[0] != mech.ground)
    k = [0]

    def moved():
        k[0] += 1
        p = np.asarray(j0.point, float) + 1e-9 * (k[0] % 7)
        return mech.with_joints(tuple(replace(j, point=p) if j.id == j0.id else j for j in mech.joints))

    m1 = moved()
    S = build_system(m1)
    kp = compile_plan(m1, inputs=(joint,))
    d = next(dd for dd in S.drivers if dd.joint == joint)
    U = (np.radians(x) if d.type == "R" else x)[:, None]
    sp = np.ones(1)
    out = {"with_joints": best_of(moved, repeats),
           "build_system": best_of(lambda: build_system(m1), repeats),
           "decompose": best_of(lambda: decompose(S), repeats),
           "assemble + mobility": best_of(lambda: assemble(build_system(m1)), repeats),
           "singular drawn config?": best_of(lambda: singular_configuration(build_system(m1)), repeats),
           "sweep (engine)": best_of(lambda: first_sweep(PLANAR_ENGINES, kp.system, kp.groups, U, sp), repeats),
           "simulate, plan cached": best_of(lambda: kp.simulate({joint: x}), repeats),
           "simulate, fresh geometry": best_of(lambda: moved().simulate({joint: x}), repeats)}
    out["events, points, result"] = out["simulate, plan cached"] - out["sweep (engine)"]
    out["assemble + mobility"] -= out["build_system"]
    out["singular drawn config?"] -= out["build_system"]
    return out


def print_fixed_costs(cases: list, x: np.ndarray, repeats: int) -> None:
    """The table of :func:`fixed_costs` for each case (milliseconds, 80 columns)."""
    rows = {name: fixed_costs(m, j, x, repeats) for name, m, j in cases}
    keys = list(next(iter(rows.values())))
    print("\n# fixed costs per call, ms (minima; 'events, points, result' = cached simulate - sweep)")
    print(f"{'':26s}" + "".join(f"{n[:12]:>14s}" for n in rows))
    for key in keys:
        print(f"{key:26s}" + "".join(f"{rows[n][key] * 1e3:14.3f}" for n in rows))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=30)
    ap.add_argument("--pylinkage", default=os.environ.get("PYLINKAGE_PYTHON", "/work/venv-pylinkage/bin/python"),
                    help="python of a virtual environment with pylinkage and numba")
    args = ap.parse_args()
    from mechsyn.io import load_mechanism
    from mechsyn.kinematics.analysis import compile_plan, input_grid, simulate

    x = input_grid(0, 360, 1)
    assert len(x) == N
    th = np.radians(x)
    cr = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    P = {j.id: np.asarray(j.point, float) for j in cr.joints}
    a, b, c = (float(np.linalg.norm(P[p] - P[q])) for p, q in (("A", "B"), ("B", "C"), ("C", "D")))
    B0 = P["B"] - P["A"]
    th0 = np.arctan2(B0[1], B0[0])
    dBD, dBC = P["D"] - P["B"], P["C"] - P["B"]
    sigma = 1.0 if dBD[0] * dBC[1] - dBD[1] * dBC[0] >= 0 else -1.0
    t_bare = best_of(lambda: bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma), args.repeats * 10)

    # answers checked: closed form equals the bare reference; dead points to 1e-6 degree
    sim = simulate(cr, {"A": np.degrees(th0 + th)}, points=["B", "C"])
    Bb, Cb = bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma)
    err = max(np.abs(sim.points["B"].position - Bb).max(), np.abs(sim.points["C"].position - Cb).max())
    assert err < 1e-12, err
    fb = simulate(load_mechanism(ROOT / "examples/textbook/fourbar.yaml"), {"A": x})
    dead = sorted(e["input"]["A"] for e in fb.events if e["kind"] == "dead point")
    # crank sqrt(5), coupler = rocker = sqrt(10), frame 5: stretched when |BD| = 2 sqrt(10)
    lim = np.degrees(np.arccos((5 + 25 - (2 * np.sqrt(10)) ** 2) / (2 * np.sqrt(5) * 5)))
    dead_err = max(abs(dead[0] - lim), abs(dead[1] - (360 - lim)))
    assert dead_err < 1e-6, (dead, lim)

    cases = [("crank-rocker", cr, "A"),
             ("four-bar, 2 dead points", load_mechanism(ROOT / "examples/textbook/fourbar.yaml"), "A"),
             ("Watt six-bar", load_mechanism(ROOT / "examples/textbook/watt_sixbar.yaml"), "A"),
             ("Stephenson six-bar", load_mechanism(ROOT / "examples/textbook/stephenson_sixbar.yaml"), "A"),
             ("Jansen leg (double joint on the foot)", jansen("third"), "P0"),
             ("Jansen leg (chain)", jansen("chain"), "P0"),
             ("Jansen leg (star)", jansen("star"), "P0")]
    print(f"# mechsyn simulate, {N} inputs; 'ms' and 'x bare': minimum of {args.repeats * 3} runs over the "
          f"minimum of the bare NumPy four-bar (positions only, {t_bare * 1e6:.0f} us); 'x med': median ratio of "
          f"{args.repeats} rounds of 10 calls each, the case and the bare reference alternately")
    print(f"# checks: crank-rocker = bare NumPy to {err:.1e}; textbook four-bar dead points to "
          f"{dead_err:.1e} deg")
    print(f"{'case':<40s} {'method':>7s} {'events':>6s} {'ms':>8s} {'x bare':>8s} {'x med':>7s} {'target':>7s}")
    def bare() -> None:
        bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma)

    figures = {}
    for name, mech, joint in cases:
        t, ratio, med = figures[name] = both(lambda: simulate(mech, {joint: x}), bare, args.repeats, t_bare)
        s = simulate(mech, {joint: x})
        tgt = TARGETS[name]
        print(f"{name:<40s} {s.method:>7s} {len(s.events):>6d} {t * 1e3:8.2f} {ratio:8.1f} {med:7.1f} "
              f"{'<=' + str(tgt):>5s} {'ok' if ratio <= tgt else 'MISS'}")
    watt = compile_plan(load_mechanism(ROOT / "examples/textbook/watt_sixbar.yaml"), inputs=("A",))
    k = [0]

    def drag():
        k[0] += 1
        watt.with_joint_points({"G": (5.0 + 0.001 * (k[0] % 7), 6.0)}).simulate({"A": x})

    t, ratio, med = both(drag, bare, args.repeats, t_bare)
    print(f"{'drag (with_joint_points + simulate), Watt':<40s} {'assur':>7s} {'':>6s} {t * 1e3:8.2f} "
          f"{ratio:8.1f} {med:7.1f}")
    print_fixed_costs([(n, m, j) for n, m, j in cases if n in ("crank-rocker", "Watt six-bar", "Jansen leg (chain)")],
                      x, args.repeats)
    py = Path(args.pylinkage)
    if py.exists():
        out = str(Path("/tmp") / f"pylinkage_bench_{os.getpid()}")
        cfg = json.dumps([P["A"].tolist(), P["D"].tolist(), a, b, c, N, args.repeats, out])
        # pylinkage starts its crank at the +x axis: compare at its own angles
        script = PYLINKAGE_SCRIPT.replace("exec(BARE)", "exec(" + repr(inspect.getsource(bare_fourbar)) + ")")
        res = subprocess.run([str(py), "-c", script, cfg], capture_output=True, text=True,
                             env=dict(os.environ, PYTHONPATH=""))
        if res.returncode != 0:
            print(f"pylinkage: failed ({res.stderr.strip().splitlines()[-1] if res.stderr else '?'})")
            return
        r = json.loads(res.stdout.strip().splitlines()[-1])
        pos = np.load(out + ".npy")
        ang = np.unwrap(np.arctan2(pos[:, 2, 1] - P["A"][1], pos[:, 2, 0] - P["A"][0]))
        s2 = simulate(cr, {"A": np.degrees(ang)}, points=["C"])
        dpl = np.abs(s2.points["C"].position - pos[:, 3]).max()
        t_cr, ratio_cr, med_cr = figures["crank-rocker"]
        py_ratio = r["build_compile_kinematics"] / r["bare"]
        print(f"pylinkage {r['version']} build + compile + step_fast_with_kinematics ({N} steps): "
              f"{r['build_compile_kinematics'] * 1e3:.2f} ms = {py_ratio:.1f}x its bare NumPy four-bar "
              f"({r['bare'] * 1e6:.0f} us, timed in its process), {r['median_ratio']:.1f}x median ratio; "
              f"positions differ by {dpl:.1e}")
        print(f"crank-rocker: mechsyn simulate / pylinkage = {ratio_cr / py_ratio:.2f} (minima, each over its "
              f"process's bare four-bar), {med_cr / r['median_ratio']:.2f} (median ratios); "
              f"{t_cr / r['build_compile_kinematics']:.2f} in milliseconds")
    else:
        print(f"pylinkage: not run ({py} not found; make a venv with `pip install pylinkage numba`)")


if __name__ == "__main__":
    main()
