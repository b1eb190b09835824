"""Benchmark: paper 001's belt manipulator, closed form (vectorised) against the way a
user would otherwise get the same numbers: a per-position numerical solve of the belt's
length-closure equation with SciPy (brentq) plus finite-difference derivatives.

Run: PYTHONPATH=src python benchmarks/belt.py
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.optimize import brentq

from mechsyn.belt import BeltDesign, analyze, best_line_deviation, path_quality

D = BeltDesign(500.0, 350.0, 100.0, 75.0)


def numeric_dpsi(dphi: float) -> float:
    """Δψ from the belt closure: free length + r·(angle of the tangent point on the
    pulley, in link 2's frame) = b0, solved for Δψ with brentq (no closed form used)."""
    a, r, b0 = D.a, D.r, D.b0
    B0 = D.B0
    A = np.array([-a * math.sin(dphi), a * math.cos(dphi)])
    dx, dy = B0 - A
    d = math.hypot(dx, dy)
    b = math.sqrt(d * d - r * r)
    # tangent point for a ccw wrap, absolute angle of AB
    # direction A->B: belt direction B0->A less its tangent offset, turned by -90°
    ang_AB = math.atan2(-dy, -dx) - math.pi / 2 - math.atan2(r, b)
    ang_AB = math.atan2(math.sin(ang_AB), math.cos(ang_AB))

    def f(dpsi: float) -> float:
        theta = dphi + dpsi
        wrap = math.atan2(math.sin(ang_AB - theta), math.cos(ang_AB - theta))
        return b - b0 - r * wrap

    centre = ang_AB - dphi          # Δψ with the tangent point back at its design place
    return brentq(f, centre - math.pi + 1e-9, centre + math.pi - 1e-9, xtol=1e-13)


def loop_closed_form(phis: np.ndarray) -> list[tuple[float, ...]]:
    """The same formulas, one position at a time in plain Python (a script from the paper)."""
    a, c, h, r = D.a, D.c, D.h, D.r
    b0, l0, al0 = D.b0, D.l0, D.alpha0
    out = []
    for x in phis:
        d = math.sqrt(l0 * l0 + a * a - 2 * a * l0 * math.sin(al0 - x))
        b = math.sqrt(d * d - r * r)
        beta = math.atan(b / r) + math.asin(l0 * math.cos(al0 - x) / d)
        dpsi = (beta - math.pi / 2) - (b - b0) / r
        yg = l0 * math.sin(al0 - x) + l0 * math.cos(al0 - x) / math.tan(beta)
        p1 = a / r * math.cos(beta) - 1
        p2 = a / r * (yg / (yg - a)) * math.sin(beta)
        th = x + dpsi
        w = 1 + p1
        xc = -a * math.sin(x) - c * math.cos(th)
        yc = a * math.cos(x) - c * math.sin(th)
        xc1 = -a * math.cos(x) + c * w * math.sin(th)
        yc1 = -a * math.sin(x) - c * w * math.cos(th)
        xc2 = a * math.sin(x) + c * (w * w * math.cos(th) + p2 * math.sin(th))
        yc2 = -a * math.cos(x) + c * (w * w * math.sin(th) - p2 * math.cos(th))
        out.append((dpsi, p1, p2, xc, yc, xc1, yc1, xc2, yc2,
                    xc - h * math.sin(th), yc + h * math.cos(th)))
    return out


def main() -> None:
    n = 100_000
    phi = np.linspace(math.radians(-73), math.radians(85), n)
    analyze(D, phi[:10])
    t0 = time.perf_counter()
    st = analyze(D, phi)
    t_closed = time.perf_counter() - t0

    m = 2000
    sub = phi[:: n // m][:m]
    t0 = time.perf_counter()
    num = np.array([numeric_dpsi(x) for x in sub])
    t_num = (time.perf_counter() - t0) * n / m
    err = np.max(np.abs(num - st.dpsi[:: n // m][:m]))
    # finite-difference derivatives would need 2-4 more solves per position
    t_num_deriv = t_num * 5

    t0 = time.perf_counter()
    loop = loop_closed_form(phi)
    t_loop = time.perf_counter() - t0
    loop_err = np.max(np.abs(np.array([v[0] for v in loop]) - st.dpsi))

    t0 = time.perf_counter()
    q = path_quality(D, (phi[0], phi[-1]), "C")
    t_q = time.perf_counter() - t0

    print(f"positions: {n}")
    print(f"closed form, Δψ..H'' (all 19 columns), vectorised: {t_closed * 1e3:8.1f} ms  "
          f"({n / t_closed / 1e6:.2f} M positions/s)")
    print(f"same formulas, plain-Python loop (C, H only):      {t_loop * 1e3:8.1f} ms  "
          f"ratio {t_loop / t_closed:6.0f}x  (max Δψ difference {loop_err:.1e})")
    print(f"brentq per position, Δψ only (extrapolated from {m}): {t_num * 1e3:8.1f} ms  "
          f"ratio {t_num / t_closed:6.0f}x")
    print(f"  + finite-difference ψ', ψ'' (5 solves/position):  {t_num_deriv * 1e3:8.1f} ms  "
          f"ratio {t_num_deriv / t_closed:6.0f}x")
    print(f"max |Δψ_closed - Δψ_brentq| = {err:.2e} rad")
    print(f"path quality of C (8001 + 8001 + 8001 samples, brentq ends): {t_q * 1e3:.1f} ms; "
          f"extent {q.extent_x:.1f}, deviation {q.max_positive_deviation:.2f}")


def best_line_ratio(repeats: int = 7) -> None:
    """Minimax best line of C's path (8001 samples): rotating calipers against trying every
    hull edge with every hull vertex (O(h^2), what the straightforward code does)."""
    from scipy.spatial import ConvexHull

    P = analyze(D, np.linspace(math.radians(-73), 0.0, 8001)).C
    V = P[ConvexHull(P).vertices]
    E = (np.roll(V, -1, axis=0) - V) / np.hypot(*(np.roll(V, -1, axis=0) - V).T)[:, None]
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fast = best_line_deviation(P)[0]
        t1 = time.perf_counter()
        proj = V @ np.stack([-E[:, 1], E[:, 0]], axis=-1).T
        every = float((proj.max(axis=0) - proj.min(axis=0)).min() / 2)
        runs.append((time.perf_counter() - t1) / (t1 - t0))
    print(f"best line of C ({V.shape[0]} hull vertices): calipers vs every pair, median ratio "
          f"{sorted(runs)[repeats // 2]:.1f}x of {repeats} (deviations {fast:.9f} and {every:.9f})")


if __name__ == "__main__":
    main()
    best_line_ratio()
