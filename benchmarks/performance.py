"""Issue 17's targets in one run: each figure beside the earlier one, the target, met or not.

    python benchmarks/performance.py [--runs 5] [--atlas-links 14] [--suite] [--no-nauty]

Whole commands are timed from outside (process start to exit, start-up included), each
paired with ``python -c "import numpy"`` run just before it (A B A B ...): the ratio is
taken pair by pair and the median quoted, so a machine whose speed drifts (shared with
other jobs) still gives a meaningful ratio. Every figure shows the wall time and the CPU
time (user + system, the process and its children); on a loaded machine the wall time of
a run can be several times its CPU time, and the verdict reads the CPU time then (on an
idle machine the two agree). In-process figures (rank, atlas) run in a fresh subprocess.
Answers are checked: rank m and q against the formulas' ladder, the atlas count against
the literature (318,162 for 14 links: OEIS A233288, Tuttle 1996) and its chains' nauty
certificates (pynauty) for pairwise distinctness, both runs of the atlas chain for chain.

Bytecode is compiled first (``compileall``), as a pip install does: a checkout run with
``PYTHONDONTWRITEBYTECODE=1`` would otherwise compile every module at every start.

"Earlier" is the figure at the previous stop (2026-11-24, see docs/performance.md).
"""

from __future__ import annotations

import argparse
import compileall
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SRC = ROOT / "src"
PY = sys.executable
UR5 = ["capability", "examples/capability/ur5_dh.yaml", "--grid", "200:600:100,-200:200:100",
       "--z", "300", "--direction", "1,0,0"]
DENSE = ["capability", "examples/capability/paper004_3r.yaml", "--grid", "0:2600:10,0:2600:10",
         "--direction", "1,0"]
CASES = str(ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json")
LITERATURE = {(8, 1): 16, (10, 1): 230, (12, 1): 6856, (14, 1): 318162}

#: figures at the previous stop (docs/performance.md, 2026-11-24, CPU unless said)
EARLIER = {
    "help": "2.0x", "analyze": "6.4x", "ur5": "0.97 s", "csv": "+18 %", "rank199": "0.22-0.28 s",
    "rank1999": "1.8-2.6 s", "growth": "-", "suite": "2 min 10 s", "atlas": "not faster",
    "synth": "2.8 s",
}

RANK = """
import json, sys, time
from mechsyn.io import mechanism_from_dict
from mechsyn.structure.rank import analyze_rank
mech = mechanism_from_dict(json.load(open(sys.argv[1])))
t, c = time.perf_counter(), time.process_time()
r = analyze_rank(mech)
print(json.dumps({"s": time.perf_counter() - t, "cpu": time.process_time() - c,
                  "m": r.mobility, "q": r.redundant_constraints}))
"""
ATLAS = """
import hashlib, json, os, sys, time
from mechsyn.synthesis.chains import n_units, synthesize_chains
n, w = int(sys.argv[1]), int(sys.argv[2])
ticks = []
t, c0 = time.perf_counter(), os.times()
chains = synthesize_chains(n, 1, workers=w, progress=ticks.append)
s, c1 = time.perf_counter() - t, os.times()
digest = hashlib.sha256("".join(c.certificate for c in chains).encode()).hexdigest()
print(json.dumps({"s": s, "cpu": c1.user - c0.user + c1.system - c0.system,
                  "children": c1.children_user - c0.children_user + c1.children_system - c0.children_system,
                  "count": len(chains), "sha": digest, "ticks": len(ticks), "ticked": sum(ticks),
                  "units": n_units(n, 1)}))
if len(sys.argv) > 3:  # nauty's certificates of the chains found: pairwise distinct?
    import pynauty
    from mechsyn.synthesis import canonical
    canonical.set_backend("pynauty")
    distinct = len({canonical.certificate(c.n_links, list(c.edges)) for c in chains})
    sys.stderr.write(json.dumps({"nauty_distinct": distinct}) + "\\n")
"""


def run(cmd: list[str], env: dict[str, str] | None = None) -> tuple[float, float, str, str]:
    """Wall and CPU seconds (user + system of the process and its children), stdout, stderr."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(SRC), **(env or {})},
                       capture_output=True, text=True)
    wall = time.perf_counter() - t
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{p.stderr[-2000:]}")
    return wall, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime, p.stdout, p.stderr


def mechsyn(args: list[str]) -> list[str]:
    return [PY, "-m", "mechsyn", *args]


def paired(cmd: list[str], base: list[str], runs: int) -> dict[str, float]:
    """Median wall and CPU of ``cmd`` and of ``base``, and the medians of the pairwise ratios."""
    a, b = [], []
    for _ in range(runs):
        b.append(run(base)[:2])
        a.append(run(cmd)[:2])
    return {"wall": statistics.median(x[0] for x in a), "cpu": statistics.median(x[1] for x in a),
            "base_wall": statistics.median(x[0] for x in b), "base_cpu": statistics.median(x[1] for x in b),
            "wall_ratio": statistics.median(x[0] / y[0] for x, y in zip(a, b)),
            "cpu_ratio": statistics.median(x[1] / y[1] for x, y in zip(a, b))}


def best(cmd: list[str], runs: int, env: dict[str, str] | None = None) -> tuple[float, float, str]:
    """Minimum wall and CPU over ``runs`` (the least disturbed run) and the last stdout."""
    out = [run(cmd, env) for _ in range(runs)]
    return min(o[0] for o in out), min(o[1] for o in out), out[-1][2]


def row(name: str, earlier: str, now: str, target: str, met: bool | None, note: str = "") -> None:
    verdict = {True: "met", False: "NOT MET", None: "-"}[met]
    print(f"{name:40} {earlier:>12} {now:>24} {target:>16} {verdict:>8}  {note}".rstrip(), flush=True)


def startup(runs: int) -> None:
    numpy = [PY, "-c", "import numpy"]
    for key, label, cmd, target in (("help", "mechsyn --help", ["--help"], 2.5),
                                    ("analyze", "mechsyn analyze textbook/fourbar.yaml",
                                     ["analyze", "examples/textbook/fourbar.yaml"], 4.0)):
        r = paired(mechsyn(cmd), numpy, runs)
        row(label, EARLIER[key], f"{r['cpu_ratio']:.1f}x cpu {r['wall_ratio']:.1f}x wall",
            f"<= {target}x numpy", r["cpu_ratio"] <= target,
            f"{r['cpu']:.2f} s cpu, {r['wall']:.2f} s wall; numpy {r['base_cpu']:.2f} / {r['base_wall']:.2f} s")


def maps(runs: int, tmp: str) -> None:
    wall, cpu, text = best(mechsyn(UR5 + ["--json"]), runs)
    v = [x for r in json.loads(text)["v_max"] for x in r]
    row("UR5 map, 25 points, whole process", EARLIER["ur5"], f"{cpu:.2f} s cpu {wall:.2f} wall",
        "<= 1.5 s", cpu <= 1.5, f"{sum(x is not None for x in v)} of {len(v)} points reachable")
    plain = best(mechsyn(DENSE), runs)
    csv = best(mechsyn(DENSE + ["--csv", f"{tmp}/dense.csv"]), runs)
    extra = 100 * (csv[1] / plain[1] - 1)
    row("--csv on a dense planar map (68,121)", EARLIER["csv"], f"+{extra:.0f} % cpu", "<= +30 %",
        extra <= 30, f"{plain[1]:.2f} -> {csv[1]:.2f} s cpu")


def rank(runs: int, tmp: str) -> None:
    sys.path[:0] = [str(HERE), str(SRC)]
    from rank import ladder  # the ladder of four-bars of benchmarks/rank.py

    res = {}
    for loops in (66, 666):
        f = Path(tmp) / f"ladder{loops}.json"
        f.write_text(json.dumps(ladder(loops)))
        for threads in ("default", "1", "2"):
            env = {} if threads == "default" else {"OPENBLAS_NUM_THREADS": threads, "OMP_NUM_THREADS": threads}
            outs = [json.loads(run([PY, "-c", RANK, str(f)], env)[2]) for _ in range(runs if loops < 100 else 1)]
            res[loops, threads] = min(outs, key=lambda o: o["cpu"])
    for loops, key, target in ((66, "rank199", 0.4), (666, "rank1999", 2.0)):  # issue 38
        worst = max((res[loops, t] for t in ("default", "1", "2")), key=lambda o: o["cpu"])
        walls = "/".join(f"{res[loops, t]['s']:.2f}" for t in ("default", "1", "2"))
        ok = all((res[loops, t]["m"], res[loops, t]["q"]) == (1, 0) for t in ("default", "1", "2"))
        row(f"rank, ladder of {1 + 3 * loops} joints, in-process", EARLIER[key],
            f"{worst['cpu']:.2f} s cpu (worst)", f"<= {target:g} s", worst["cpu"] <= target and ok,
            f"wall {walls} s with default/1/2 BLAS threads; m = 1, q = 0: {ok}")
    t1 = max(res[66, t]["cpu"] for t in ("default", "1", "2"))
    t2 = max(res[666, t]["cpu"] for t in ("default", "1", "2"))
    growth = math.log(t2 / t1) / math.log(1999 / 199)
    row("rank, growth exponent 199 -> 1,999 joints", EARLIER["growth"], f"{growth:.2f}", "<= 1.3",
        growth <= 1.3, "time ~ joints^exponent, from the two ladders' CPU times")


def synth() -> None:
    wall, cpu, text = best(mechsyn(["synth", "path", CASES, "--case", "P2_kk5_timing", "--json"]), 1)
    out = json.loads(text)
    row("synth path P2 (default options)", EARLIER["synth"], f"{cpu:.2f} s cpu {wall:.1f} wall", "-",
        None, f"error {out['error']:.3g}; stopped at the target: {out['target_reached']}")


def suite() -> None:
    t = time.perf_counter()
    subprocess.run([PY, "-m", "pytest", "-q", "-p", "no:cacheprovider"], cwd=ROOT, capture_output=True)
    s = time.perf_counter() - t
    row("test suite (pytest, -n auto)", EARLIER["suite"], f"{s / 60:.1f} min wall", "< 2 min", s < 120)


def atlas(n: int, nauty: bool) -> None:
    env = {"MECHSYN_LIMIT_ATLAS_LINKS": str(max(n, 12))}
    w1, c1, t1, _ = run([PY, "-c", ATLAS, str(n), "1"], env)
    w2, c2, t2, err = run([PY, "-c", ATLAS, str(n), "2"] + (["nauty"] if nauty else []), env)
    one, two = json.loads(t1), json.loads(t2)
    known = LITERATURE.get((n, 1))
    same = one["sha"] == two["sha"] and one["count"] == two["count"]
    checks = [f"{two['count']:,} chains" + (f" (literature {known:,})" if known else ""),
              f"same chains in the same order: {same}",
              f"progress: {two['ticks']} calls from the workers adding up to {two['ticked']:.0f} of "
              f"{two['units']} assortments"]
    if nauty:
        distinct = json.loads(err.strip().splitlines()[-1])["nauty_distinct"]
        checks.append(f"nauty certificates pairwise distinct: {distinct == two['count']}")
    print(f"  atlas, {n} links: one process {one['s']:.1f} s wall, {one['cpu']:.1f} s cpu; --workers 2 "
          f"{two['s']:.1f} s wall, cpu {two['cpu']:.1f} s here + {two['children']:.1f} s in the workers")
    ok = same and (known is None or two["count"] == known)
    speed = one["s"] / two["s"]
    # Linux shares the CPU between sessions (autogroups), not processes: with other
    # sessions keeping the cores busy, the workers of one session share that session's
    # part and cannot be faster than one process. There the CPU time tells: the work of
    # the split (workers + this process) spread over 2 idle cores, against one process's.
    overhead = (two["cpu"] + two["children"]) / one["cpu"]
    estimate = 2 / overhead
    idle = os.getloadavg()[0] < 1.5
    row(f"atlas {n} links, --workers 2 vs one process", EARLIER["atlas"],
        f"{speed:.2f}x wall" if idle else f"{estimate:.2f}x est.", "> 1x",
        ok and (speed if idle else estimate) > 1,
        (f"measured {speed:.2f}x wall under load {os.getloadavg()[0]:.0f}; " if not idle else "")
        + f"cpu of the split {overhead:.2f}x one process's; " + "; ".join(checks))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--atlas-links", type=int, default=14)
    ap.add_argument("--suite", action="store_true", help="also time the whole test suite (minutes)")
    ap.add_argument("--no-nauty", action="store_true", help="skip the nauty check of the atlas")
    args = ap.parse_args()
    compileall.compile_dir(str(SRC), quiet=1)
    print(f"load average at the start: {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores)")
    print(f"{'figure':40} {'earlier':>12} {'now':>24} {'target':>16} {'verdict':>8}")
    startup(args.runs)
    with tempfile.TemporaryDirectory() as tmp:
        maps(args.runs, tmp)
        rank(args.runs, tmp)
    synth()
    if args.suite:
        suite()
    else:
        row("test suite", EARLIER["suite"], "not run", "< 2 min", None, "give --suite to time it")
    atlas(args.atlas_links, not args.no_nauty)
    print(f"load average at the end: {os.getloadavg()[0]:.1f} ({os.cpu_count()} cores)")


if __name__ == "__main__":
    main()
