"""Issue 17's targets in one run: today's figures beside those before the work, and ratios.

Every figure is the minimum over ``--runs`` runs (the machine is shared: the minimum is
the least disturbed run). Whole commands are timed from outside (process start to exit,
start-up included); the rank and atlas figures in-process, each in a fresh subprocess.
"Before" runs the same measurement on a ``git worktree`` of ``--baseline`` (default: the
commit before this work, acd6d94); answers are compared where both give one.

    python benchmarks/performance.py [--runs 3] [--baseline REV] [--atlas-links 14]

Targets (issue 17): ``mechsyn --help`` <= 2.5x and ``mechsyn analyze fourbar`` <= 4x
``python -c "import numpy"``; rank: 199-joint ladder <= 0.4 s in-process whatever the
BLAS threads, 2,000 joints <= 10 s; UR5 25-point map <= 1.5 s whole process; ``--csv``
adds <= 30 % to a dense planar map; atlas of 14-link chains faster with ``--workers 2``
than in one process (count 318,162).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
PY = sys.executable
UR5 = ["capability", "examples/capability/ur5_dh.yaml", "--grid", "200:600:100,-200:200:100",
       "--z", "300", "--direction", "1,0,0"]
DENSE = ["capability", "examples/capability/paper004_3r.yaml", "--grid", "0:2600:10,0:2600:10",
         "--direction", "1,0"]
CASES = str(ROOT / "tests" / "synthesis" / "data" / "synthesis_cases_public.json")

RANK = """
import json, sys, time
from mechsyn.io import mechanism_from_dict
from mechsyn.structure.rank import analyze_rank
mech = mechanism_from_dict(json.load(open(sys.argv[1])))
t = time.perf_counter(); r = analyze_rank(mech); t = time.perf_counter() - t
print(json.dumps({"s": t, "m": r.mobility, "q": r.redundant_constraints}))
"""
ATLAS = """
import json, sys, time
from mechsyn.synthesis.chains import synthesize_chains
n, w = int(sys.argv[1]), int(sys.argv[2])
t = time.perf_counter()
c = synthesize_chains(n, 1) if w == 1 else synthesize_chains(n, 1, workers=w)
print(json.dumps({"s": time.perf_counter() - t, "count": len(c)}))
"""


CPU: dict[str, float] = {}  # CPU seconds (user + system) of the last run() call


def run(cmd: list[str], src: Path, runs: int) -> tuple[float, str]:
    """Minimum wall time of a whole command with ``src`` on PYTHONPATH, and its stdout;
    the minimum CPU time (user + system, the process and its children) goes to CPU["last"]
    (on a machine shared with others the CPU time moves less than the wall time)."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    best, cpu, text = float("inf"), float("inf"), ""
    for _ in range(runs):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        p = subprocess.run(cmd, cwd=src.parent, env=env, capture_output=True, text=True)
        best = min(best, time.perf_counter() - t)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = min(cpu, r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed ({src}):\n{p.stderr[-2000:]}")
        text = p.stdout
    CPU["last"] = cpu
    return best, text


def mechsyn(args: list[str]) -> list[str]:
    return [PY, "-m", "mechsyn", *args]


def baseline_tree(rev: str) -> Path:
    path = Path(tempfile.gettempdir()) / f"mechsyn-baseline-{rev[:10]}"
    if not path.exists():
        subprocess.run(["git", "worktree", "add", "--detach", str(path), rev], cwd=ROOT, check=True,
                       capture_output=True)
    return path / "src"


def row(name: str, old: float | None, new: float, note: str = "",
        cpu: tuple[float | None, float | None] = (None, None)) -> None:
    ratio = f"{old / new:7.1f}x" if old else "       "
    olds = f"{old:9.2f}" if old is not None else "        -"
    cpus = " / ".join("-" if c is None else f"{c:.2f}" for c in cpu)
    print(f"{name:44} {olds} {new:9.2f} {ratio}  cpu {cpus}  {note}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--baseline", default="acd6d94")
    ap.add_argument("--atlas-links", type=int, default=14)
    args = ap.parse_args()
    new, old = ROOT / "src", baseline_tree(args.baseline)
    R = args.runs
    print(f"{'figure (seconds, min of %d runs)' % R:44} {'before':>9} {'now':>9} {'speed-up':>8}")

    numpy_s, _ = run([PY, "-c", "import numpy"], new, R)
    numpy_cpu = CPU["last"]
    row('python -c "import numpy" (the yardstick)', None, numpy_s, cpu=(None, numpy_cpu))
    for label, cmd, target in (("mechsyn --help", ["--help"], 2.5),
                               ("mechsyn analyze textbook/fourbar.yaml",
                                ["analyze", "examples/textbook/fourbar.yaml"], 4.0)):
        a, _ = run(mechsyn(cmd), old, R)
        ca = CPU["last"]
        b, _ = run(mechsyn(cmd), new, R)
        row(label, a, b, f"{b / numpy_s:.1f}x numpy by wall, {CPU['last'] / numpy_cpu:.1f}x by cpu "
            f"(target <= {target}x; before {a / numpy_s:.1f}x, {ca / numpy_cpu:.1f}x)", (ca, CPU["last"]))

    for label, extra in (("UR5 map, 25 points", []), ("UR5 map, 25 points, --continuous", ["--continuous"])):
        a, ta = run(mechsyn(UR5 + extra + ["--json"]), old, R)
        ca = CPU["last"]
        b, tb = run(mechsyn(UR5 + extra + ["--json"]), new, R)
        va = np.array(json.loads(ta)["v_max"], float)
        vb = np.array(json.loads(tb)["v_max"], float)
        row(label, a, b, f"target <= 1.5 s; V_max now - before: {np.nanmin(vb - va):+.1e} .. "
                         f"{np.nanmax(vb - va):+.1e} mm/s", (ca, CPU["last"]))

    with tempfile.TemporaryDirectory() as tmp:
        cpu = {}
        for key, src, extra in (("plain_a", old, []), ("plain_b", new, []),
                                ("csv_a", old, ["--csv", f"{tmp}/a.csv"]),
                                ("csv_b", new, ["--csv", f"{tmp}/b.csv"])):
            cpu[key + "_wall"], _ = run(mechsyn(DENSE + extra), src, R)
            cpu[key] = CPU["last"]
        same = Path(f"{tmp}/a.csv").read_bytes() == Path(f"{tmp}/b.csv").read_bytes()
        row("dense planar map, 68,121 points", cpu["plain_a_wall"], cpu["plain_b_wall"],
            cpu=(cpu["plain_a"], cpu["plain_b"]))
        row("  the same with --csv", cpu["csv_a_wall"], cpu["csv_b_wall"],
            f"--csv adds {100 * (cpu['csv_b'] / cpu['plain_b'] - 1):.0f} % cpu (target <= 30 %; "
            f"before {100 * (cpu['csv_a'] / cpu['plain_a'] - 1):.0f} %); files identical: {same}",
            (cpu["csv_a"], cpu["csv_b"]))

        sys.path.insert(0, str(HERE))
        sys.path.insert(0, str(new))
        from rank import ladder  # the ladder of four-bars of benchmarks/rank.py

        env_threads = {k: os.environ.pop(k) for k in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS")
                       if k in os.environ}
        for loops in (66, 666):
            f = Path(tmp) / f"ladder{loops}.json"
            f.write_text(json.dumps(ladder(loops)))
            res = {}
            for tag, src in (("old", old), ("new", new)):
                if tag == "old" and loops > 100:
                    continue  # minutes before the work
                t, out = run([PY, "-c", RANK, str(f)], src, R if loops < 100 else 1)
                res[tag] = json.loads(out)
            target = "0.4" if loops < 100 else "10"
            agree = "old" not in res or (res["old"]["m"], res["old"]["q"]) == (res["new"]["m"], res["new"]["q"])
            row(f"rank, ladder of {1 + 3 * loops} joints (in-process)",
                res["old"]["s"] if "old" in res else None, res["new"]["s"],
                f"target <= {target} s, default BLAS threads; m, q agree: {agree}")
        os.environ.update(env_threads)

    a, ta = run(mechsyn(["synth", "path", CASES, "--case", "P2_kk5_timing", "--json"]), old, 1)
    ca = CPU["last"]
    b, tb = run(mechsyn(["synth", "path", CASES, "--case", "P2_kk5_timing", "--json"]), new, 1)
    ea, eb = json.loads(ta)["error"], json.loads(tb)
    row("synth path P2 (default options)", a, b,
        f"error {eb['error']:.3g} (before {ea:.3g}); stopped at the target: {eb['target_reached']}",
        (ca, CPU["last"]))

    n = args.atlas_links
    os.environ["MECHSYN_LIMIT_ATLAS_LINKS"] = str(max(n, 12))  # beyond the CLI's default limit
    one, t1 = run([PY, "-c", ATLAS, str(n), "1"], new, 1)
    two, t2 = run([PY, "-c", ATLAS, str(n), "2"], new, 1)
    c1, c2 = json.loads(t1), json.loads(t2)
    print(f"atlas of {n}-link 1-DOF chains: one process {c1['s']:.1f} s, --workers 2 "
          f"{c2['s']:.1f} s ({c1['s'] / c2['s']:.2f}x; cpu of the run with 2 workers "
          f"{CPU['last']:.1f} s); chains {c1['count']} and {c2['count']}"
          + (" (literature: 318,162)" if n == 14 else ""))
    print(f"machine load at the end: {os.getloadavg()[0]:.1f} (2 cores)")


if __name__ == "__main__":
    main()
