"""Benchmark: curve to mechanism.

Run from the repository root::

    python benchmarks/curve_synthesis.py [--per-class 6] [--time-limit 60] [--shapes-only]
                                         [--database DIR] [--figures DIR]

1. **Curves of random linkages** from a generator of this file, independent of the
   database sampler: a Grashof crank-rocker drawn by its link *lengths* (not by joint
   coordinates), then for six- and eight-bars one or two dyads attached between points
   of links already placed, with lengths chosen so the dyad assembles over the whole
   turn (between the least and the greatest distance of its two end points); the
   tracing point is on the last link. Each curve (a closed loop, 200 samples) is given
   to :func:`synthesize_curve` (max links = the generator's); recovered when the best
   candidate's chamfer error is ≤ 1 % of the target's bounding-box diagonal. Targets:
   ≥ 90 % recovered, median time ≤ 60 s.
2. **Designer shapes** (heart, lemniscate, D-shaped foot path, kidney, rounded
   triangle): the best candidate of ``synth curve`` for 4, 6 and 8 links, side by side
   with the best four-bar of ``synth path`` (differential evolution on 16 points of the
   shape, the crank turning in 16 equal steps), the latter's whole coupler curve
   measured with the same chamfer error. With ``--figures DIR`` one PNG per shape (used by docs/synthesis.md).

The database is the local one (``$MECHSYN_CURVE_DB``) or ``--database``; eight-bar
targets need it built with ``mechsyn curves build --links 8``. Times are wall-clock on a
shared machine.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.synthesis.curves.database import load_database  # noqa: E402
from mechsyn.synthesis.curves.synthesis import curve_errors, synthesize_curve  # noqa: E402
from mechsyn.synthesis.curves.target import target_from_points  # noqa: E402

TH = np.linspace(0, 2 * np.pi, 200, endpoint=False)


def _circle_pick(A, C, L1, L2, sigma):
    d = C - A
    t = np.abs(d) ** 2
    al = (L1 * L1 - L2 * L2 + t) / (2 * t)
    b2 = L1 * L1 / t - al * al
    return A + d * (al + 1j * sigma * np.sqrt(b2)), b2


def random_linkage_curve(n_links: int, rng: np.random.Generator) -> np.ndarray:
    """A closed curve traced by a random fully rotating linkage (see the module doc)."""
    while True:
        g = 1.0
        a = rng.uniform(0.15, 0.4)
        b, c = rng.uniform(0.6, 1.5, size=2)
        if a + max(g, b, c) > g + b + c - max(g, b, c) - 1e-3:
            continue
        A = a * np.exp(1j * TH)
        D = np.full_like(A, g)
        B, _ = _circle_pick(A, D, b, c, 1.0)
        # points available to attach dyads: on the crank, the coupler, the rocker, the frame
        pts = {"coupler": lambda p, A=A, B=B: A + (B - A) * p, "rocker": lambda p, B=B, D=D: D + (B - D) * p,
               "frame": lambda p: np.full_like(A, p)}
        last = pts["coupler"](complex(rng.uniform(-0.3, 1.2), rng.uniform(-0.6, 0.6)))
        ok = True
        for _ in range((n_links - 4) // 2):
            keys = list(pts)
            k1, k2 = rng.choice(len(keys), size=2, replace=False)
            P1 = pts[keys[k1]](complex(rng.uniform(-0.5, 1.5), rng.uniform(-0.8, 0.8)) if keys[k1] != "frame"
                               else complex(rng.uniform(-0.5, 1.5), rng.uniform(-1.0, 1.0)))
            P2 = pts[keys[k2]](complex(rng.uniform(-0.5, 1.5), rng.uniform(-0.8, 0.8)) if keys[k2] != "frame"
                               else complex(rng.uniform(-0.5, 1.5), rng.uniform(-1.0, 1.0)))
            dist = np.abs(P2 - P1)
            lo, hi = dist.min(), dist.max()
            if hi - lo < 1e-3 or lo < 0.05:
                ok = False
                break
            s = rng.uniform(1.05, 1.6) * hi                     # L1 + L2 > max distance
            diff = rng.uniform(0, 0.9) * lo                      # |L1 - L2| < min distance
            L1, L2 = (s + diff) / 2, (s - diff) / 2
            E, b2 = _circle_pick(P1, P2, L1, L2, rng.choice([-1.0, 1.0]))
            if np.any(b2 <= 1e-3):
                ok = False
                break
            name = f"dyad{len(pts)}"
            pts[name] = (lambda p, P1=P1, E=E: P1 + (E - P1) * p)
            last = pts[name](complex(rng.uniform(-0.2, 1.2), rng.uniform(-0.6, 0.6)))
        if not ok:
            continue
        span = np.ptp(last.real) + np.ptp(last.imag)
        if span < 0.05:
            continue
        return np.c_[last.real, last.imag] * rng.uniform(10, 100) + rng.uniform(-50, 50, size=2)


def designer_shapes() -> dict[str, tuple[np.ndarray, bool]]:
    t = np.linspace(0, 2 * np.pi, 160, endpoint=False)
    heart = np.c_[16 * np.sin(t) ** 3, 13 * np.cos(t) - 5 * np.cos(2 * t) - 2 * np.cos(3 * t) - np.cos(4 * t)]
    lem = np.c_[np.cos(t) / (1 + np.sin(t) ** 2), np.sin(t) * np.cos(t) / (1 + np.sin(t) ** 2)] * 10
    # D-shaped foot path: a straight stance of 6 units and a half-elliptic swing 2 high
    stance = np.c_[np.linspace(3, -3, 60, endpoint=False), np.zeros(60)]
    u = np.linspace(np.pi, 0, 100, endpoint=False)
    swing = np.c_[3 * np.cos(u), 2 * np.sin(u)]
    foot = np.vstack([stance, swing])
    kidney = np.c_[(1 + 0.35 * np.cos(2 * t)) * np.cos(t) + 0.25 * np.cos(2 * t),
                   (1 + 0.15 * np.cos(2 * t)) * 0.8 * np.sin(t)] * 5
    kidney[:, 1] -= 1.4 * np.exp(-((np.mod(t - np.pi / 2 + np.pi, 2 * np.pi) - np.pi) / 0.6) ** 2)
    tri = np.c_[np.cos(t), np.sin(t)] * (1 + 0.12 * np.cos(3 * t))[:, None] * 8
    return {"heart": (heart, True), "lemniscate": (lem, True), "D foot path": (foot, True),
            "kidney": (kidney, True), "rounded triangle": (tri, True)}


def best_fourbar_by_synth_path(points: np.ndarray, time_limit: float, seed: int = 0):
    """The best four-bar of ``synth path`` through 16 points of the shape (the crank in 16 equal steps);
    returns its chamfer error against the whole shape and its path."""
    from mechsyn.io.load import mechanism_from_dict
    from mechsyn.kinematics import simulate
    from mechsyn.synthesis.export import fourbar_mechanism_dict
    from mechsyn.synthesis.optimize import synthesize_path
    from mechsyn.synthesis.path import PathCase

    idx = np.linspace(0, len(points), 16, endpoint=False).astype(int)
    T = points[idx]
    lo, hi = T.min(axis=0), T.max(axis=0)
    diag = float(np.hypot(*(hi - lo)))
    c = (lo + hi) / 2
    var = [{"name": "x0", "lower": c[0] - 2 * diag, "upper": c[0] + 2 * diag},
           {"name": "y0", "lower": c[1] - 2 * diag, "upper": c[1] + 2 * diag},
           {"name": "theta0", "lower": 0.0, "upper": 2 * np.pi}]
    var += [{"name": r, "lower": 0.02 * diag, "upper": 3 * diag} for r in ("r1", "r2", "r3", "r4")]
    var += [{"name": r, "lower": -3 * diag, "upper": 3 * diag} for r in ("rcx", "rcy")]
    var += [{"name": "theta2_1", "lower": 0.0, "upper": 2 * np.pi}]
    # the crank at constant speed: 16 equal steps over one turn (free timing lets the
    # optimiser collapse all targets onto one crank angle)
    case = PathCase.from_dict({"id": "shape", "targets": T.tolist(),
                               "timing": {"type": "prescribed_increment", "step": 2 * np.pi / len(T)},
                               "variables": var, "kinematics": {"branch": -1}})
    res = synthesize_path(case, seed=seed, time_limit=time_limit, restarts=2)
    if not res.feasible:
        return np.inf, T, False
    d = {**case.fixed, **res.design}
    mech = mechanism_from_dict(fourbar_mechanism_dict(d["r1"], d["r2"], d["r3"], d["r4"], float(res.theta2[0]),
                                                      branch=case.branch, rcx=d["rcx"], rcy=d["rcy"], x0=d["x0"],
                                                      y0=d["y0"], theta0=d["theta0"]))
    ang = np.degrees(res.theta2[0]) + np.arange(0.0, 360.0, 1.0)
    sim = simulate(mech, {"A": ang}, points=["P"])
    P = sim.points["P"].position
    ok = sim.assembled
    closed = bool(ok.all())
    if not closed:  # the longest run of assembled inputs (cyclic): what the linkage traces
        k = int(np.argmin(ok))
        P, ok = np.roll(P, -k, axis=0), np.roll(ok, -k)
        idx = np.flatnonzero(ok)
        runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
        run = max(runs, key=len)
        P = P[run]
    tgt = target_from_points(points, closed=True)
    ch = curve_errors(P, tgt, closed)[0]
    return ch, P, closed


def run_random(args, db) -> None:
    print(f"Curves of random linkages ({args.per_class} per class, time limit {args.time_limit:g} s each)")
    print(f"{'links':>5} {'#':>3} {'best':>16} {'chamfer %':>10} {'ordered %':>10} {'time s':>7}  ok")
    rng = np.random.default_rng(2026)
    rows = []
    for n in args.classes:
        for i in range(args.per_class):
            pts = random_linkage_curve(n, rng)
            t0 = time.perf_counter()
            res = synthesize_curve(target_from_points(pts, closed=True), max_links=n, time_limit=args.time_limit,
                                   top=1, database=db)
            dt = time.perf_counter() - t0
            c = res.candidates[0] if res.candidates else None
            ch = c.chamfer if c else np.inf
            rows.append((n, ch, dt))
            name = (c.topology.name or c.topology.key) if c else "-"
            print(f"{n:5d} {i + 1:3d} {name:>16} {100 * ch:10.3f} {100 * (c.ordered if c else np.inf):10.3f} "
                  f"{dt:7.1f}  {'yes' if ch <= 0.01 else 'NO'}", flush=True)
    ch = np.array([r[1] for r in rows])
    tt = np.array([r[2] for r in rows])
    for n in args.classes:
        m = np.array([r[0] == n for r in rows])
        print(f"{n}-bars: {np.mean(ch[m] <= 0.01) * 100:.0f} % recovered (chamfer <= 1 %), "
              f"median chamfer {100 * np.median(ch[m]):.3f} %, median time {np.median(tt[m]):.1f} s")
    print(f"all: {np.mean(ch <= 0.01) * 100:.0f} % recovered (target >= 90 %), median time {np.median(tt):.1f} s "
          f"(target <= 60 s)")


def run_shapes(args, db) -> None:
    print(f"\nDesigner shapes: chamfer error, % of the bounding-box diagonal (synth curve: "
          f"time limit {args.time_limit:g} s; synth path: {args.path_time:g} s)")
    head = f"{'shape':>17} {'synth path 4-bar':>17}" + "".join(f"{f'curve {n}-bar':>13}" for n in args.classes)
    print(head)
    figures = Path(args.figures) if args.figures else None
    for name, (pts, closed) in designer_shapes().items():
        tgt = target_from_points(pts, closed=closed)
        fb, fb_path, fb_closed = best_fourbar_by_synth_path(pts, args.path_time)
        cells, best = [], {}
        for n in args.classes:
            res = synthesize_curve(tgt, max_links=n, time_limit=args.time_limit, top=1, database=db)
            c = res.candidates[0] if res.candidates else None
            best[n] = (res, c)
            cells.append(f"{100 * c.chamfer:13.2f}" if c else f"{'-':>13}")
        print(f"{name:>17} {100 * fb:17.2f}" + "".join(cells), flush=True)
        if figures is not None:
            _figure(figures, name, tgt, best, fb, fb_path, fb_closed)


def _figure(directory: Path, name: str, tgt, best, fb, fb_path, fb_closed) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from mechsyn.results import save_figure_atomic
    from mechsyn.plot.curves import plot_candidate

    directory.mkdir(parents=True, exist_ok=True)
    ns = [n for n in best if best[n][1] is not None]
    fig, axes = plt.subplots(1, len(ns) + 1, figsize=(4.2 * (len(ns) + 1), 5.0), dpi=100)
    T = np.vstack([tgt.points, tgt.points[:1]])
    ax = axes[0]
    ax.plot(T[:, 0], T[:, 1], "-", color="0.2", lw=2.5, alpha=0.35, label="target")
    P = np.vstack([fb_path, fb_path[:1]]) if fb_closed else fb_path
    ax.plot(P[:, 0], P[:, 1], "-", color="tab:red", lw=1.4, label=f"synth path 4-bar: {100 * fb:.2f} %")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (target's length unit)")
    ax.set_ylabel("y (target's length unit)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16))  # clear of the drawing
    ax.set_title(f"{name}: best four-bar of synth path", fontsize=9)
    for ax, n in zip(axes[1:], ns):
        c = best[n][1]
        plot_candidate(c, tgt, ax=ax)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.16))  # clear of the drawing
        ax.set_title(f"synth curve, up to {n} links: {c.topology.name or c.topology.key}", fontsize=9)
    fig.tight_layout()
    save_figure_atomic(fig, directory / f"curve_{name.replace(' ', '_')}.png")
    plt.close(fig)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-class", type=int, default=10)
    ap.add_argument("--classes", type=int, nargs="+", default=[4, 6, 8])
    ap.add_argument("--time-limit", type=float, default=60.0)
    ap.add_argument("--path-time", type=float, default=30.0)
    ap.add_argument("--database", default=None)
    ap.add_argument("--figures", default=None)
    ap.add_argument("--shapes-only", action="store_true")
    ap.add_argument("--random-only", action="store_true")
    args = ap.parse_args()
    db = load_database(args.database, max_links=max(args.classes))
    print(f"database: {len(db)} curves of {len(db.topologies)} topologies "
          f"(up to {max(t.n_links for t in db.topologies)} links)")
    if not args.shapes_only:
        run_random(args, db)
    if not args.random_only:
        run_shapes(args, db)


if __name__ == "__main__":
    main()
