"""Benchmark of the rank (screw-theory) structural analysis.

A ladder of four-bar loops (each loop's crank is the previous loop's rocker) with about
50 joints, planar and seen in 3-D (3 redundant constraints per loop), and a 6-UPS
Stewart platform. Prints the time of ``analyze_rank`` (with and without the singularity
check that follows the motion numerically) against the papers' formulas
(``analyze_structure``) and against a bare ``numpy.linalg.matrix_rank`` of the same
loop-closure matrix, the floor of any rank-based tool (what a user who hand-assembles
the screw matrix would get).

Run: PYTHONPATH=src python benchmarks/rank.py
BLAS runs single-threaded here (the matrices are small: threads only add overhead, and on a
loaded machine multi-threaded OpenBLAS makes each small SVD 10-50x slower); set
OPENBLAS_NUM_THREADS yourself to compare.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from mechsyn.io import load_mechanism, mechanism_from_dict  # noqa: E402
from mechsyn.structure.analysis import analyze_structure  # noqa: E402
from mechsyn.structure.rank import _build_system, analyze_rank, as_spatial  # noqa: E402


def ladder(loops: int) -> dict:
    rng = np.random.default_rng(1)
    links = ["frame", "r0"]
    joints = [{"id": "A", "type": "R", "links": ["frame", "r0"], "point": [0.0, 0.0], "actuated": True}]
    tip = np.array([0.3, 1.0])  # the moving end of the previous rocker
    for i in range(1, loops + 1):
        pivot = np.array([1.2 * i, 0.0])
        c = pivot + np.array([0.2, 1.0]) + 0.1 * rng.standard_normal(2)
        links += [f"c{i}", f"r{i}"]
        joints += [
            {"id": f"B{i}", "type": "R", "links": [f"r{i-1}", f"c{i}"], "point": tip.tolist()},
            {"id": f"C{i}", "type": "R", "links": [f"c{i}", f"r{i}"], "point": c.tolist()},
            {"id": f"D{i}", "type": "R", "links": [f"r{i}", "frame"], "point": pivot.tolist()},
        ]
        tip = c
    return {"name": f"ladder of {loops} four-bars", "kind": "planar", "ground": "frame", "links": links,
            "joints": joints}


def timeit(fn, repeat: int = 5) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    root = Path(__file__).resolve().parents[1]
    cases = [
        ("ladder, planar", mechanism_from_dict(ladder(16))),
        ("ladder, as spatial", as_spatial(mechanism_from_dict(ladder(16)))),
        ("6-UPS Stewart", load_mechanism(root / "examples/textbook/stewart_6ups.yaml")),
        ("Delta (S-S bars)", load_mechanism(root / "examples/textbook/delta.yaml")),
    ]
    print(f"{'mechanism':22} {'joints':>6} {'m':>3} {'q':>4} {'rank+sing. ms':>14} {'rank ms':>8} "
          f"{'formulas ms':>12} {'bare SVD ms':>12} {'ratio':>6}")
    for name, mech in cases:
        r = analyze_rank(mech)
        t_full = timeit(lambda: analyze_rank(mech))
        t_rank = timeit(lambda: analyze_rank(mech, check_singular=False))
        t_form = timeit(lambda: analyze_structure(mech))
        sysm = _build_system(mech, mech.kind == "planar")
        M, _ = sysm.closure(np.zeros(sysm.twists.shape[0]))
        t_bare = timeit(lambda: np.linalg.matrix_rank(M), repeat=20)
        print(f"{name:22} {len(mech.joints):6d} {r.mobility:3d} {r.redundant_constraints:4d} "
              f"{1e3 * t_full:14.1f} {1e3 * t_rank:8.1f} {1e3 * t_form:12.1f} {1e3 * t_bare:12.3f} "
              f"{t_full / t_form:6.1f}")
    print("ratio: full rank analysis (with the singularity check) / formulas analysis")


if __name__ == "__main__":
    main()
