"""Benchmark: mechsyn's planar kinematics against pylinkage's numba solver.

Run from the repository root::

    python benchmarks/kinematics.py [--steps 1000000]

The same crank-rocker (frame 4, crank 1, coupler 3.5, rocker 3) is swept over N crank
angles by

* pylinkage (``step_fast``: positions; ``step_fast_with_kinematics``: positions,
  velocities, accelerations), numba-compiled; compile time excluded (a warm-up run
  of the same size comes first), run in its own virtual environment
  ``benchmarks/.env-kinematics`` (created and filled with ``pip install pylinkage
  numba`` on first use);
* mechsyn: the closed-form core, the kernel's pass (:func:`mechsyn.kinematics.kernel.run`:
  every link's state and rates, compiled) and the joints' states from it (positions;
  then also their velocities and accelerations), and the whole public
  ``simulate`` call (poses, rates, points, events, angles) for reference.

It prints steps per second, the ratios and the largest differences of the joint
positions, velocities and accelerations between the two (at pylinkage's own angles).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
ENV = HERE / ".env-kinematics"
sys.path.insert(0, str(ROOT / "src"))

PYLINKAGE_SCRIPT = r"""
import json, sys, time
import numpy as np
from pylinkage.components import Ground
from pylinkage.actuators import Crank
from pylinkage.dyads import RRRDyad
from pylinkage.simulation import Linkage

N = int(sys.argv[1]); out = sys.argv[2]; repeats = int(sys.argv[3])

def build():
    A = Ground(0.0, 0.0, name="A"); D = Ground(4.0, 0.0, name="D")
    crank = Crank(anchor=A, radius=1.0, angular_velocity=2 * np.pi / N)
    rocker = RRRDyad(crank.output, D, distance1=3.5, distance2=3.0)
    lk = Linkage([A, D, crank, rocker], name="crank-rocker")
    lk.set_input_velocity(crank, omega=1.0)
    return lk

res = {}
lk = build()
t = time.perf_counter(); lk.step_fast(iterations=N); res["compile_and_first_positions"] = time.perf_counter() - t
best = np.inf
for _ in range(repeats):
    lk = build(); lk.compile(); lk.step_fast(iterations=2)
    lk = build(); lk.compile()
    t = time.perf_counter(); pos = lk.step_fast(iterations=N); best = min(best, time.perf_counter() - t)
res["positions"] = best
lk = build()
t = time.perf_counter(); lk.step_fast_with_kinematics(iterations=N); res["compile_and_first_kinematics"] = time.perf_counter() - t
best = np.inf
for _ in range(repeats):
    lk = build(); lk.compile()
    t = time.perf_counter(); p, v, a = lk.step_fast_with_kinematics(iterations=N); best = min(best, time.perf_counter() - t)
res["kinematics"] = best
np.savez(out + ".npz", pos=pos, p=p, v=v, a=a)
import pylinkage, numba
res["versions"] = {"pylinkage": pylinkage.__version__, "numba": numba.__version__}
with open(out, "w") as fh:
    json.dump(res, fh)
"""


def ensure_env() -> Path:
    py = ENV / "bin" / "python"
    if not py.exists():
        print(f"creating {ENV} and installing pylinkage + numba ...", flush=True)
        subprocess.run([sys.executable, "-m", "venv", str(ENV)], check=True)
        subprocess.run([str(py), "-m", "pip", "install", "-q", "pylinkage", "numba"], check=True)
    return py


def run_pylinkage(n: int, repeats: int) -> tuple[dict, dict]:
    py = ensure_env()
    out = HERE / ".env-kinematics" / "bench_result.json"
    env = dict(os.environ, PYTHONPATH="")
    subprocess.run([str(py), "-c", PYLINKAGE_SCRIPT, str(n), str(out), str(repeats)], check=True, env=env)
    res = json.loads(out.read_text())
    arrays = dict(np.load(str(out) + ".npz"))
    return res, arrays


def mechsyn_setup():
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics import dyads
    from mechsyn.kinematics.system import build_system

    th = np.radians(60.0)
    B = np.array([np.cos(th), np.sin(th)])
    D = np.array([4.0, 0.0])
    d = D - B
    L = np.linalg.norm(d)
    a = (3.5 ** 2 - 3.0 ** 2 + L ** 2) / (2 * L)
    h = np.sqrt(3.5 ** 2 - a ** 2)
    e = d / L
    C = B + a * e + h * np.array([-e[1], e[0]])
    data = {"name": "crank-rocker", "ground": "frame", "links": ["frame", "crank", "coupler", "rocker"],
            "joints": [
                {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
                {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": B.tolist()},
                {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": C.tolist()},
                {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": D.tolist()}]}
    mech = mechanism_from_dict(data, "bench")
    S = build_system(mech)
    plan = dyads.decompose(S)
    return mech, S, plan


def mechsyn_positions(S, plan, U):
    """Positions of the joints B and C (pylinkage returns all four joints)."""
    (PB, _, _), (PC, _, _) = mechsyn_kinematics(S, plan, U, np.ones(1))
    return PB, PC


def mechsyn_kinematics(S, plan, U, speeds):
    """Positions, velocities, accelerations of the joints B and C: the kernel's pass (every
    link's state and rates) and the joints' states from it."""
    from mechsyn.kinematics import kernel
    from mechsyn.kinematics.groups import local_point

    C, W, AL, *_ = kernel.run(kernel.program(S, plan), U, speeds, 0.0)
    idx = np.array([S.index("crank"), S.index("rocker")])
    P = kernel.point_states(C, W, AL, idx, np.array([complex(*local_point(S, i, j)) for i, j in zip(idx, "BC")]))
    return [tuple(P[c, k].view(float).reshape(-1, 2) for c in range(3)) for k in range(2)]


def best_of(f, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--steps", type=int, default=1_000_000)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    n = args.steps
    print(f"crank-rocker (frame 4, crank 1, coupler 3.5, rocker 3), {n:,} crank angles, best of {args.repeats}")
    pl, arr = run_pylinkage(n, args.repeats)
    mech, S, plan = mechsyn_setup()
    # pylinkage's angles: step i is at (i + 1) * 2 pi / n (read back from its crank positions)
    Bp = arr["pos"][:, 2]
    theta = np.unwrap(np.arctan2(Bp[:, 1], Bp[:, 0]))
    U = theta[:, None]
    speeds = np.ones(1)
    mechsyn_positions(S, plan, U[:1000])  # import/first-call costs out of the timing
    t_pos = best_of(lambda: mechsyn_positions(S, plan, U), args.repeats)
    t_kin = best_of(lambda: mechsyn_kinematics(S, plan, U, speeds), args.repeats)
    from mechsyn.kinematics.analysis import simulate

    t_sim = best_of(lambda: simulate(mech, {"A": np.degrees(theta)}, points=["B", "C"]), 1)
    B, C = mechsyn_positions(S, plan, U)
    (PB, VB, AB), (PC, VC, AC) = mechsyn_kinematics(S, plan, U, speeds)
    dpos = max(np.abs(B - arr["pos"][:, 2]).max(), np.abs(C - arr["pos"][:, 3]).max())
    dp = max(np.abs(PC - arr["p"][:, 3]).max(), np.abs(PB - arr["p"][:, 2]).max())
    dv = max(np.abs(VC - arr["v"][:, 3]).max(), np.abs(VB - arr["v"][:, 2]).max())
    da = max(np.abs(AC - arr["a"][:, 3]).max(), np.abs(AB - arr["a"][:, 2]).max())
    rate = lambda t: n / t  # noqa: E731
    print(f"pylinkage {pl['versions']['pylinkage']} (numba {pl['versions']['numba']}); "
          f"compile + first run: {pl['compile_and_first_positions']:.2f} s (positions), "
          f"{pl['compile_and_first_kinematics']:.2f} s (kinematics)")
    rows = [
        ("positions", "pylinkage step_fast", pl["positions"], "mechsyn kernel.run", t_pos),
        ("positions + velocities + accelerations", "pylinkage step_fast_with_kinematics", pl["kinematics"],
         "mechsyn kernel.run", t_kin),
    ]
    for what, n1, t1, n2, t2 in rows:
        print(f"\n{what}:")
        print(f"  {n1:<40s} {t1 * 1e3:9.1f} ms  {rate(t1):14,.0f} steps/s")
        print(f"  {n2:<40s} {t2 * 1e3:9.1f} ms  {rate(t2):14,.0f} steps/s")
        print(f"  ratio mechsyn / pylinkage: {t1 / t2:.2f}x")
    print(f"\nmechsyn simulate() end to end (positions, rates, points B and C, events): {t_sim * 1e3:.0f} ms "
          f"({rate(t_sim):,.0f} steps/s)")
    print(f"largest difference to pylinkage: positions {max(dpos, dp):.2e}, velocities {dv:.2e}, "
          f"accelerations {da:.2e}")


if __name__ == "__main__":
    main()
