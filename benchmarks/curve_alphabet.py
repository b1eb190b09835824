"""Benchmark: the alphabet as target curves through the CLI (after LInK's LINK-ABC).

Run from the repository root::

    python benchmarks/curve_alphabet.py [--letters ABC...] [--time-limit 60] [--font "DejaVu Sans"]
                                        [--weight normal] [--figure docs/figures/curve_alphabet.png]
                                        [--json out.json]
    python benchmarks/curve_alphabet.py --table out60.json out120.json [--figure F.png]   # the docs' table
    python benchmarks/curve_alphabet.py --font "Liberation Sans" --weight bold --pick 10 --time-limit 100
                                        # ten held-out capitals of a font not used in development

``--pick N`` draws N capitals at random (``numpy.random.default_rng(--seed)``, default
seed 41), sorted, instead of ``--letters``: a held-out set chosen before any was run.
With ``--json`` the rows are written after every letter (a run cut short keeps the letters
done; run again with the same ``--json`` and the letters done are skipped).

Each capital letter of a font Matplotlib ships (default DejaVu Sans; ``--weight bold``
for the bold face) is turned into its outline by ``matplotlib.textpath.TextPath``; the
outer contour (the closed polygon of the largest area; the counters of A, B, D, O, P, Q,
R are dropped) is resampled to 200 points equally spaced in arc length, written as a
JSON target and given to ``mechsyn synth curve TARGET --time-limit T --json`` with
every other option at its default (the default database, up to 8 links, size 1.5
diagonals, link ratio 10, transmission angle 30°, tolerance 0.5 %): one process per
letter, so the time is the command's wall-clock time, loading the database included.
Reported per letter: the error (the symmetric chamfer of
:func:`mechsyn.synthesis.curves.fitting.chamfer_error`, % of the diagonal) of the first
candidate listed and of the most accurate one, its links, and the time; then how many
letters are within 1, 2 and 5 %. The figure shows each letter (grey) and the most
accurate linkage's path (colour) with its error. Times are wall-clock on a shared machine;
the load average (1 min) is sampled every 2 s while each letter runs (mean and largest kept).

Reference: A. Nobari, A. Srivastava, D. Gutfreund, K. Xu and F. Ahmed, "LInK: Learning
joint representations of design and performance spaces through contrastive learning
for mechanism synthesis", *Transactions on Machine Learning Research*, 2024.
"""

from __future__ import annotations

import argparse
import json
import os
import string
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.curves.descriptors import resample  # noqa: E402


def letter_outline(letter: str, n: int = 200, font: str = "DejaVu Sans", weight: str = "normal") -> np.ndarray:
    """The outer contour of a capital letter of a font, ``n`` points equally spaced
    in arc length, counter-clockwise, in font units."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    path = TextPath((0, 0), letter, size=100, prop=FontProperties(family=font, weight=weight))
    polys = path.to_polygons(closed_only=True)

    def area(p):
        return 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))

    outer = max(polys, key=lambda p: abs(area(p)))
    if area(outer) < 0:
        outer = outer[::-1]
    z = resample(outer[:-1], n, closed=True)
    return np.c_[z.real, z.imag]


def run(letters: str, time_limit: float, font: str = "DejaVu Sans", weight: str = "normal",
        out: Path | None = None) -> list[dict]:
    """Each letter through ``mechsyn synth curve`` (one process each, CLI defaults); with
    ``out`` the rows so far are written there after each letter, and the letters it holds
    already are not run again."""
    rows = json.loads(out.read_text()) if out is not None and out.exists() else []
    done = {r["letter"] for r in rows}
    print(f"{'letter':>6} {'first listed':>24} {'error %':>8} {'most accurate':>24} {'error %':>8} "
          f"{'links':>5} {'time s':>7} {'load':>5}")
    with tempfile.TemporaryDirectory() as tmp:
        for ch in letters:
            if ch in done:
                continue
            P = letter_outline(ch, font=font, weight=weight)
            f = Path(tmp) / f"{ch}.json"
            f.write_text(json.dumps({"points": P.tolist(), "closed": True}))
            rows.append(_one(ch, P, f, time_limit))
            r = rows[-1]
            if out is not None:
                tmp_out = out.with_name(out.name + ".tmp")
                tmp_out.write_text(json.dumps(rows))
                tmp_out.replace(out)
            if r["chamfer"] is not None:
                print(f"{ch:>6} {r['first_topology']:>24} {100 * r['first_chamfer']:8.2f} {r['topology']:>24} "
                      f"{100 * r['chamfer']:8.2f} {r['links']:5d} {r['seconds']:7.1f} {r['load_mean']:5.1f}",
                      flush=True)
            else:
                print(f"{ch:>6} {'-':>24} {'-':>8} {'-':>24} {'-':>8} {'':5} {r['seconds']:7.1f}  exit {r['exit']}: "
                      f"{r['reason']}", flush=True)
    print(summary(rows, time_limit))
    return rows


def _one(ch: str, P: np.ndarray, f: Path, time_limit: float) -> dict:
    """One letter's run: the command's result, wall-clock time and the load average meanwhile."""
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", "")}
    loads = [os.getloadavg()[0]]
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "mechsyn", "synth", "curve", str(f), "--time-limit",
                             str(time_limit), "--json"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    while True:
        try:
            stdout, stderr = proc.communicate(timeout=2.0)
            break
        except subprocess.TimeoutExpired:
            loads.append(os.getloadavg()[0])
    dt = time.perf_counter() - t0
    res = json.loads(stdout) if stdout.strip().startswith("{") else {"candidates": []}
    cands = res["candidates"]
    first = cands[0] if cands else None
    best = min(cands, key=lambda c: c["error"]["chamfer"]) if cands else None
    return {"letter": ch, "limit": time_limit, "seconds": dt, "exit": proc.returncode, "notes": res.get("notes", []),
            "search_seconds": res.get("seconds"), "refinements": res.get("refined"),
            "load_mean": float(np.mean(loads)), "load_max": float(np.max(loads)),
            "chamfer": best["error"]["chamfer"] if best else None,
            "nearest": best["error"].get("nearest") if best else None,
            "first_chamfer": first["error"]["chamfer"] if first else None,
            "topology": best["topology"] if best else None, "links": best["links"] if best else None,
            "first_topology": first["topology"] if first else None,
            "refined": best["refined"] if best else None, "reason": res.get("reason", stderr[-300:]),
            "target": P.tolist(), "path": _path(best) if best else None,
            "full_turn": best["quality"]["full_turn"] if best else None}


def summary(rows: list[dict], time_limit: float) -> str:
    """How many letters are within 1, 2 and 5 %, the median error and the times."""
    err = np.array([r["chamfer"] if r["chamfer"] is not None else np.inf for r in rows])
    tt = np.array([r["seconds"] for r in rows])
    return (f"within 1 %: {int(np.sum(err <= 0.01))} of {len(rows)}; within 2 %: {int(np.sum(err <= 0.02))}; "
            f"within 5 %: {int(np.sum(err <= 0.05))}; median error {100 * np.median(err):.2f} %; "
            f"time median {np.median(tt):.1f} s, shortest {tt.min():.1f} s, longest {tt.max():.1f} s "
            f"(limit {time_limit:g} s)")


def table(files: list[Path]) -> str:
    """The docs' Markdown table of one or more result files (a row group per file)."""
    lines = []
    for f in files:
        rows = sorted(json.loads(f.read_text()), key=lambda r: r["letter"])   # a letter run again: in its place
        limit = float(rows[0]["limit"])
        head = "| " + f"{limit:g} s" + " | " + " | ".join(r["letter"] for r in rows) + " |"
        lines += [head, "|---" * (len(rows) + 1) + "|"]
        for r in rows:
            r["in_order"], r["order_free"] = _rescored(r)
        cell = {
            "error % (most accurate, in order)": lambda r: "-" if r["in_order"] is None else
            (f"**{100 * r['in_order']:.2f}**" if r["in_order"] <= 0.02 else f"{100 * r['in_order']:.2f}"),
            "order-free % (same design)": lambda r: "-" if r["order_free"] is None else f"{100 * r['order_free']:.2f}",
            "as reported % (first listed)": lambda r: "-" if r["first_chamfer"] is None else
            f"{100 * r['first_chamfer']:.2f}",
            "links": lambda r: str(r["links"] or "-"),
            "refinements": lambda r: str(r.get("refinements", "-")),
            "wall s": lambda r: f"{r['seconds']:.1f}",
            "load (mean)": lambda r: f"{r['load_mean']:.1f}",
        }
        for name, fn in cell.items():
            lines.append(f"| {name} | " + " | ".join(fn(r) for r in rows) + " |")
        lines += ["", summary([{**r, "chamfer": r["in_order"]} for r in rows], limit) + " (in order)",
                  summary([{**r, "chamfer": r["order_free"]} for r in rows], limit) + " (order-free)", ""]
    return "\n".join(lines)


def _rescored(r: dict) -> tuple[float | None, float | None]:
    """The most accurate design's path (through ``simulate``) scored again against the
    letter by the error in order and by the order-free chamfer, whichever the run ranked by."""
    if r["path"] is None:
        return None, None
    from mechsyn.synthesis.curves.fitting import chamfer_error, nearest_chamfer
    from mechsyn.synthesis.curves.target import TargetCurve

    tgt, P = TargetCurve(np.array(r["target"]), closed=True), np.array(r["path"])
    closed = bool(r["full_turn"])
    P = P[:-1] if closed else P          # 361 samples over a full turn: the last is the first
    return chamfer_error(P, tgt, closed), nearest_chamfer(P, tgt, closed)


def _path(cand: dict) -> list:
    """The candidate's traced path through simulate (its mechanism file and input range)."""
    from mechsyn.io.load import mechanism_from_dict
    from mechsyn.kinematics import simulate

    inp = cand["input"]
    sim = simulate(mechanism_from_dict(cand["mechanism"]), {inp["joint"]: np.linspace(inp["start"], inp["stop"], 361)},
                   points=[cand["tracer"]])
    return sim.points[cand["tracer"]].position.tolist()


def gallery(rows: list[dict], path: Path) -> None:
    """Each letter (grey) and its best path (blue within 2 %, red beyond), error in the title."""
    rows = sorted(rows, key=lambda r: r["letter"])
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mechsyn.results import save_figure_atomic

    cols = 7
    nrow = -(-len(rows) // cols)
    fig, axes = plt.subplots(nrow, cols, figsize=(1.9 * cols, 2.1 * nrow), dpi=100)
    for ax in np.ravel(axes):
        ax.set_axis_off()
    for ax, r in zip(np.ravel(axes), rows):
        err = _rescored(r)[0]          # the error in order, whichever measure the run ranked by
        T = np.array(r["target"])
        T = np.vstack([T, T[:1]])
        ax.fill(T[:, 0], T[:, 1], color="0.85", lw=0)
        ax.plot(T[:, 0], T[:, 1], "-", color="0.45", lw=1.0)
        if r["path"] is not None:
            P = np.array(r["path"])
            P = np.vstack([P, P[:1]]) if r["full_turn"] else P
            ok = err <= 0.02
            ax.plot(P[:, 0], P[:, 1], "-", color="tab:blue" if ok else "tab:red", lw=1.3)
            ax.set_title(f"{r['letter']}: {100 * err:.2f} % ({r['links']} links)", fontsize=8)
        else:
            ax.set_title(f"{r['letter']}: none within bounds", fontsize=8)
        ax.set_aspect("equal", adjustable="datalim")
    fig.suptitle("mechsyn synth curve on font capitals: outer contour (grey), most accurate path, its error "
                 "in order (blue: within 2 % of the diagonal, red: beyond)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure_atomic(fig, path)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--letters", default=string.ascii_uppercase)
    ap.add_argument("--pick", type=int, default=None, help="draw this many capitals at random instead")
    ap.add_argument("--seed", type=int, default=41, help="the seed of --pick")
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--font", default="DejaVu Sans")
    ap.add_argument("--weight", default="normal")
    ap.add_argument("--figure", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--table", nargs="+", default=None, help="print the Markdown table of result files and stop")
    args = ap.parse_args()
    if args.table:   # with --figure: the gallery of the last file
        print(table([Path(f) for f in args.table]))
        if args.figure:
            gallery(json.loads(Path(args.table[-1]).read_text()), Path(args.figure))
        return
    letters = args.letters if args.pick is None else "".join(
        sorted(string.ascii_uppercase[i] for i in np.random.default_rng(args.seed).choice(26, args.pick, replace=False)))
    print(f"{args.font} {args.weight}, time limit {args.time_limit:g} s per letter, CLI defaults, letters {letters}")
    rows = run(letters, args.time_limit, args.font, args.weight, Path(args.json) if args.json else None)
    if args.figure:
        gallery(rows, Path(args.figure))


if __name__ == "__main__":
    main()
