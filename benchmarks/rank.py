"""Benchmark of the rank (screw-theory) structural analysis.

A ladder of four-bar loops (each loop's crank is the previous loop's rocker) with about
50 joints, planar and seen in 3-D (3 redundant constraints per loop), and a 6-UPS
Stewart platform. Prints the time of ``analyze_rank`` (with and without the singularity
check that follows the motion numerically) against the papers' formulas
(``analyze_structure``) and against a bare ``numpy.linalg.matrix_rank`` of the same
loop-closure matrix, the floor of any rank-based tool (what a user who hand-assembles
the screw matrix would get).

Then the growth with size (issue 17 §3): ladders of 49 to 1,999 joints (planar, and seen in
3-D: the finite-mobility check's shortcut by the subgroup the twists generate), the whole
``analyze_rank`` (contours, rank, idle mobilities, singularity check) with the machine's
default BLAS threads (``analyze_rank`` limits BLAS to one thread itself), against the same
analysis forced onto one dense SVD (the method before the contour-by-contour elimination)
up to 601 joints; the answers are checked equal, and the growth exponent is fitted between
199 and 1,999 joints. Targets: 199 joints <= 0.4 s, 1,999 joints <= 2 s (issue 38), exponent <= 1.3.

Run: PYTHONPATH=src python benchmarks/rank.py [--quick]
Times are the minimum of several runs; on a machine shared with other jobs they are noisy.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure import rank as rank_mod
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.rank import _build_system, analyze_rank, as_spatial


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
    scaling("--quick" in sys.argv)


def scaling(quick: bool = False) -> None:
    """Ladders of growing size: elimination against one dense SVD, answers checked equal."""
    sizes = [16, 66, 200] if quick else [16, 66, 200, 666]
    print(f"\n{'ladder joints':>13} {'rank s':>8} {'in 3-D s':>9} {'dense SVD s':>12} {'ratio':>6}  "
          "answer (m, q, useful)")
    times = {}
    for loops in sizes:
        mech = mechanism_from_dict(ladder(loops))
        n = len(mech.joints)
        r = analyze_rank(mech)
        t = timeit(lambda: analyze_rank(mech), repeat=3 if n < 1000 else 2)
        times[n] = t
        mech3 = as_spatial(mech)  # 3 redundant constraints a loop: regular by its subgroup's dimension
        t3 = timeit(lambda: analyze_rank(mech3), repeat=3 if n < 1000 else 2)
        dense = ""
        if n <= 601:
            saved = rank_mod.DENSE_MAX_FREEDOMS
            rank_mod.DENSE_MAX_FREEDOMS = 10 ** 9
            try:
                rd = analyze_rank(mech)
                td = timeit(lambda: analyze_rank(mech), repeat=2)
            finally:
                rank_mod.DENSE_MAX_FREEDOMS = saved
            same = (rd.mobility, rd.redundant_constraints, rd.useful_mobility, rd.redundant_by_contour) == \
                (r.mobility, r.redundant_constraints, r.useful_mobility, r.redundant_by_contour)
            assert same, "elimination and dense SVD disagree"
            dense = f"{td:12.3f} {td / t:6.1f}"
        else:
            dense = f"{'-':>12} {'-':>6}"
        print(f"{n:13d} {t:8.3f} {t3:9.3f} {dense}  ({r.mobility}, {r.redundant_constraints}, {r.useful_mobility})")
    ns = sorted(n for n in times if n >= 199)
    if len(ns) >= 2:
        slope = np.polyfit(np.log(ns), np.log([times[n] for n in ns]), 1)[0]
        print(f"growth exponent (time ~ joints^k, {ns[0]}..{ns[-1]} joints): k = {slope:.2f}")


if __name__ == "__main__":
    main()
