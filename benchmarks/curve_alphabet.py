"""Benchmark: the alphabet as target curves (issue 29; after LInK's LINK-ABC benchmark).

Run from the repository root::

    python benchmarks/curve_alphabet.py [--letters ABC...] [--time-limit 120] [--max-links 8] [--refine 32]
                                        [--database DIR] [--figure docs/figures/curve_alphabet.png]
                                        [--json out.json]

Each capital letter A-Z of a sans-serif font (DejaVu Sans, shipped with Matplotlib) is
turned into its outline by ``matplotlib.textpath.TextPath``; the outer contour (the
closed polygon of the largest area; the counters of A, B, D, O, P, Q, R are dropped) is
resampled to 200 points equally spaced in arc length and given to
:func:`mechsyn.synthesis.curves.synthesis.synthesize_curve` as a closed curve with the
default design bounds (size 1.5 diagonals, link ratio 10, transmission angle 30°).
A letter counts as traced when the best candidate's chamfer error is within 2 % of the
target's bounding-box diagonal (issue 29: at least 13 of 26 in <= 120 s each on 2
cores; the moonshot all 26 within 1 %). Times are wall-clock on a shared machine. The
figure shows each letter (grey) and the best linkage's path (colour) with its error.

Reference: A. Nobari, A. Srivastava, D. Gutfreund, K. Xu and F. Ahmed, "LInK: Learning
joint representations of design and performance spaces through contrastive learning
for mechanism synthesis", *Transactions on Machine Learning Research*, 2024.
"""

from __future__ import annotations

import argparse
import json
import string
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.curves.database import load_database  # noqa: E402
from mechsyn.synthesis.curves.descriptors import resample  # noqa: E402
from mechsyn.synthesis.curves.synthesis import synthesize_curve  # noqa: E402
from mechsyn.synthesis.curves.target import target_from_points  # noqa: E402


def letter_outline(letter: str, n: int = 200) -> np.ndarray:
    """The outer contour of a capital letter of DejaVu Sans, ``n`` points equally spaced
    in arc length, counter-clockwise, in font units."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextPath

    path = TextPath((0, 0), letter, size=100, prop=FontProperties(family="DejaVu Sans"))
    polys = path.to_polygons(closed_only=True)

    def area(p):
        return 0.5 * float(np.sum(p[:-1, 0] * p[1:, 1] - p[1:, 0] * p[:-1, 1]))

    outer = max(polys, key=lambda p: abs(area(p)))
    if area(outer) < 0:
        outer = outer[::-1]
    z = resample(outer[:-1], n, closed=True)
    return np.c_[z.real, z.imag]


def run(letters: str, db, time_limit: float, max_links: int, n_refine: int = 32) -> list[dict]:
    rows = []
    print(f"{'letter':>6} {'best':>24} {'chamfer %':>10} {'size':>5} {'ratio':>6} {'mu':>4} {'time s':>7}")
    for ch in letters:
        P = letter_outline(ch)
        t0 = time.perf_counter()
        res = synthesize_curve(target_from_points(P, closed=True), max_links=max_links, time_limit=time_limit,
                               top=1, database=db, n_refine=n_refine)
        dt = time.perf_counter() - t0
        c = res.candidates[0] if res.candidates else None
        row = {"letter": ch, "seconds": dt, "chamfer": c.chamfer if c else None,
               "topology": c.topology.label if c else None, "links": c.topology.n_links if c else None,
               "quality": c.quality() if c else None, "reason": res.reason if not c else "",
               "target": P.tolist(), "path": c.path.tolist() if c else None}
        rows.append(row)
        if c:
            print(f"{ch:>6} {c.topology.label:>24} {100 * c.chamfer:10.2f} {c.size_ratio:5.2f} "
                  f"{c.link_length_ratio:6.1f} {c.min_transmission_angle:4.0f} {dt:7.1f}", flush=True)
        else:
            print(f"{ch:>6} {'-':>24} {'-':>10} {'':5} {'':6} {'':4} {dt:7.1f}  {res.reason}", flush=True)
    err = np.array([r["chamfer"] if r["chamfer"] is not None else np.inf for r in rows])
    tt = np.array([r["seconds"] for r in rows])
    print(f"within 2 %: {int(np.sum(err <= 0.02))} of {len(rows)}; within 1 %: {int(np.sum(err <= 0.01))}; "
          f"median error {100 * np.median(err):.2f} %; median time {np.median(tt):.1f} s, longest {tt.max():.1f} s")
    return rows


def gallery(rows: list[dict], path: Path) -> None:
    """Each letter (grey) and its best path (blue within 2 %, red beyond), error in the title."""
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
        T = np.array(r["target"])
        T = np.vstack([T, T[:1]])
        ax.fill(T[:, 0], T[:, 1], color="0.85", lw=0)
        ax.plot(T[:, 0], T[:, 1], "-", color="0.45", lw=1.0)
        if r["path"] is not None:
            P = np.array(r["path"])
            P = np.vstack([P, P[:1]]) if r["quality"]["full_turn"] else P
            ok = r["chamfer"] <= 0.02
            ax.plot(P[:, 0], P[:, 1], "-", color="tab:blue" if ok else "tab:red", lw=1.3)
            ax.set_title(f"{r['letter']}: {100 * r['chamfer']:.2f} % ({r['links']} links)", fontsize=8)
        else:
            ax.set_title(f"{r['letter']}: none within bounds", fontsize=8)
        ax.set_aspect("equal", adjustable="datalim")
    fig.suptitle("mechsyn synth curve on DejaVu Sans capitals: outer contour (grey), traced path "
                 "(blue: within 2 % of the diagonal, red: beyond)", fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    save_figure_atomic(fig, path)
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--letters", default=string.ascii_uppercase)
    ap.add_argument("--time-limit", type=float, default=120.0)
    ap.add_argument("--max-links", type=int, default=8)
    ap.add_argument("--refine", type=int, default=32, help="designs refined per letter (synthesize_curve's n_refine)")
    ap.add_argument("--database", default=None)
    ap.add_argument("--figure", default=None)
    ap.add_argument("--json", default=None)
    args = ap.parse_args()
    t0 = time.perf_counter()
    db = load_database(args.database, max_links=args.max_links)
    print(f"database: {len(db)} curves of {len(db.topologies)} topologies, loaded in "
          f"{time.perf_counter() - t0:.1f} s; time limit {args.time_limit:g} s per letter")
    rows = run(args.letters, db, args.time_limit, args.max_links, args.refine)
    if args.json:
        Path(args.json).write_text(json.dumps(rows))
    if args.figure:
        gallery(rows, Path(args.figure))


if __name__ == "__main__":
    main()
