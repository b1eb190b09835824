"""Benchmark: exact directional speed limit, mechsyn vs pycapacity (one run).

The same 10,000 configurations of paper 004's planar 3R arm (random inside the joint
limits, random unit directions d). mechsyn: Jacobians and the closed-form exact limit over
the velocity zonotope, vectorised. pycapacity: ``velocity_polytope`` (hyperplane shifting
method, H-representation ``H v <= d``) per configuration, then the limit along d as
``min_k d_k / (H_k . d)`` over the half-spaces facing d (the user's obvious route).

pycapacity runs in its own environment ``benchmarks/.env-capability`` (created here with
``python3 -m venv`` and ``pip install pycapacity numpy scipy`` when missing), in a
subprocess fed with the same Jacobians.

    python benchmarks/capability.py [--n 10000]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.capability.arm_file import load_arm  # noqa: E402
from mechsyn.capability.measures import exact_limit  # noqa: E402

ENV = HERE / ".env-capability"
PY = ENV / ("Scripts/python.exe" if os.name == "nt" else "bin/python")

PYCAPACITY_RUN = textwrap.dedent("""
    import sys, time
    import numpy as np
    from pycapacity.robot import velocity_polytope
    J = np.load(sys.argv[1]); w = np.load(sys.argv[2]); d = np.load(sys.argv[3])
    out = np.empty(len(J))
    t0 = time.perf_counter()
    for k in range(len(J)):
        poly = velocity_polytope(J[k], w, -w)
        Hd = poly.H @ d[k]
        pos = Hd > 1e-12
        out[k] = np.min(poly.d.ravel()[pos] / Hd[pos]) if pos.any() else 0.0
    t = time.perf_counter() - t0
    np.save(sys.argv[4], out)
    print(t)
""")


def ensure_env() -> None:
    if PY.exists():
        return
    print(f"creating {ENV} (python3 -m venv; pip install pycapacity numpy scipy) ...",
          flush=True)
    subprocess.run([sys.executable, "-m", "venv", str(ENV)], check=True)
    subprocess.run([str(PY), "-m", "pip", "install", "-q", "pycapacity", "numpy", "scipy"],
                   check=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=10_000, help="number of configurations")
    ap.add_argument("--seed", type=int, default=4)
    args = ap.parse_args()
    ensure_env()
    version = subprocess.run([str(PY), "-c", "import importlib.metadata as m;"
                              "print(m.version('pycapacity'))"],
                             capture_output=True, text=True, check=True).stdout.strip()

    arm = load_arm(ROOT / "examples" / "capability" / "paper004_3r.yaml")
    rng = np.random.default_rng(args.seed)
    q = rng.uniform(arm.lower, arm.upper, size=(args.n, arm.n))
    ang = rng.uniform(0, 2 * np.pi, args.n)
    d = np.stack([np.cos(ang), np.sin(ang)], 1)

    # mechsyn: Jacobians + closed form, best of 5 runs
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        J = arm.jacobian(q)
        ours = exact_limit(J, arm.qd_max, d)
        times.append(time.perf_counter() - t0)
    t_ours = min(times)

    with tempfile.TemporaryDirectory() as tmp:
        paths = [Path(tmp) / f for f in ("J.npy", "w.npy", "d.npy", "out.npy")]
        for p, a in zip(paths, (J, arm.qd_max, d)):
            np.save(p, a)
        script = Path(tmp) / "run.py"
        script.write_text(PYCAPACITY_RUN)
        res = subprocess.run([str(PY), str(script), *map(str, paths)], capture_output=True,
                             text=True, check=True)
        t_pc = float(res.stdout.strip().splitlines()[-1])
        theirs = np.load(paths[3])

    diff = np.abs(ours - theirs)
    rel = diff / np.maximum(np.abs(theirs), 1e-300)
    print(f"exact directional speed limit, paper 004 3R arm, {args.n} configurations "
          "(random q within limits, random directions)")
    print(f"  mechsyn (Jacobians + closed form, vectorised): {t_ours * 1e3:9.2f} ms  "
          f"{args.n / t_ours:14,.0f} configurations/s")
    print(f"  pycapacity {version} velocity_polytope (given J): {t_pc * 1e3:9.2f} ms  "
          f"{args.n / t_pc:14,.0f} configurations/s")
    print(f"  ratio (mechsyn / pycapacity, configurations per second): {t_pc / t_ours:,.0f}x")
    print(f"  largest difference of answers: {diff.max():.3e} mm/s absolute, "
          f"{rel.max():.3e} relative (speeds {ours.min():.2f}..{ours.max():.2f} mm/s)")
    print(f"  equal to 1e-9 (relative): {bool(np.all(rel <= 1e-9))}")


if __name__ == "__main__":
    main()
