"""Benchmark: spatial kinematics (``ms.simulate`` on a spatial file: positions, orientations,
velocities, accelerations, closure residual, rank test and events), as time and as a ratio to
bare NumPy references in the same process, with every answer checked against them.

Run from the repository root::

    python benchmarks/spatial_kinematics.py [--repeats 5]

Cases:

* ``Bennett``: examples/textbook/bennett.yaml, R1 over 0..360 deg, 361 inputs (target < 50 ms);
* ``spherical 4-bar``: examples/textbook/spherical_fourbar.yaml, A over 0..360 deg,
  361 inputs (target < 50 ms);
* ``Delta, 1 drive``: examples/textbook/delta.yaml, R1 over -30..30 deg in 0.1 deg
  (601 inputs), the other two arms held (target < 200 ms).

References, each a bare NumPy program written for the case, positions only:

* for every case, a bare per-input Newton loop, warm-started from the previous input (the
  "bare NumPy loop" a user would write): for the Bennett and spherical four-bar the loop
  closure of the four R pairs in joint coordinates (``exp(ξ1 θ1) exp(ξ2 θ2) exp(ξ3 θ3)
  exp(ξ4 θ4) = I``, product of exponentials, a least-squares step per iteration); for the
  Delta the platform's shift ``x`` with ``|c_i(θ_i) - x| = ℓ`` for its three arms (a 3 x 3
  step per iteration);
* where one exists, the closed form for all inputs at once (array expressions): the
  spherical Freudenstein equation; the Delta's forward kinematics (the intersection of the
  three spheres about the elbows).

mechsyn's positions are checked against each (1e-9 of the length scale). Times are minima
over ``--repeats`` runs (the least noisy statistic on a shared machine), as wall time and
as CPU time of the process (steadier when other processes compete for the cores); the
ratios are mechsyn's CPU time over the reference's, both measured in this process. The
references compute positions only; mechsyn also gives every link's pose, velocities and
accelerations, the closure residual and the rank test of every row, and (Delta) moves
all ten links (24 unknowns, each S-S bar one distance equation between its ends, against
the loop's 3).

Targets: the time targets below, and as ratios to the bare loop (CPU time): the Bennett
and the spherical four-bar within 0.3x, the Delta within 1x (column ``x tgt``).

Where the time goes: the spatial engine's arithmetic is compiled with Numba
(``mechsyn.kinematics._spatial_numba``: the equations from tables built once per model, the
corrector of a whole block of rows in one call, the exponentials, the Gram inverses by
Cholesky factors, the rates, the bars' poses and the pair check), so NumPy's per-call cost
is gone; the first sweep on a machine compiles the kernel (about 30 s of CPU time, kept in
``__pycache__``; later processes load it in under a second). CPU time of the parts of the
Delta's 18.5 ms at load 5: the walk 7.2 ms (10 blocks of 64 rows, about 4.4 chord steps a
row on 24 unknowns, each step about 1.5 us), one compiled pass over the 601 rows for their
residuals, Jacobians, Gram inverses (24 x 24), singular-value bounds and rates with
refinement about 6.5 ms (the Gram inverse about 5 us a row), the result 1.2 ms (the bars'
poses 0.4), compiling the model 1.0 ms, the crossing test 0.6 ms, the check that the drives
determine the motion 0.6 ms, the rows' verification and rank 0.6 ms. The Bennett's 19 ms:
the walk about 12 ms (its blocks are shorter: 0.75 rad of predictor step), the rows' pass 4 ms.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import mechsyn as ms  # noqa: E402

TARGETS_MS = {"Bennett": 50.0, "spherical 4-bar": 50.0, "Delta, 1 drive": 200.0}
#: Targets of the CPU time over the bare per-input Newton loop's.
TARGETS_LOOP = {"Bennett": 0.3, "spherical 4-bar": 0.3, "Delta, 1 drive": 1.0}


def _minimum(f, repeats: int) -> tuple[float, float]:
    """Least wall time and least CPU time of the process (all its threads) over the runs:
    on a shared machine the CPU time is the steadier estimate of a quiet machine's wall time."""
    wall = cpu = np.inf
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        f()
        wall, cpu = min(wall, time.perf_counter() - t), min(cpu, time.process_time() - c)
    return wall, cpu


# --------------------------------------------------------------------------- references
def _exp(w: np.ndarray, q: np.ndarray, th: float) -> np.ndarray:
    """exp of the unit rotation twist about axis ``w`` through ``q`` by ``th`` (4 x 4)."""
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    R = np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, q - R @ q
    return T


def loop4r_bare(mech, theta1: np.ndarray, joints=("R1", "R2", "R3", "R4")) -> np.ndarray:
    """Bare Newton loop on a single loop of four R pairs (Bennett, spherical four-bar):
    joint angles θ2..θ4 for each θ1, then the point of the third pair."""
    J = [mech.joint(j) for j in joints]
    w = [np.asarray(j.axis, float) / np.linalg.norm(j.axis) for j in J]
    q = [np.asarray(j.point, float) for j in J]
    x = np.zeros(3)
    out = np.empty((len(theta1), 3))
    for k, t1 in enumerate(theta1):
        for _ in range(20):
            Ts = [_exp(w[0], q[0], t1), _exp(w[1], q[1], x[0]), _exp(w[2], q[2], x[1]), _exp(w[3], q[3], x[2])]
            T = Ts[0] @ Ts[1] @ Ts[2] @ Ts[3]
            R, p = T[:3, :3], T[:3, 3]
            e = np.concatenate([0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]), p])
            if np.abs(e).max() < 1e-13:
                break
            G = Ts[0]
            cols = []
            for i in (1, 2, 3):
                a = G[:3, :3] @ w[i]
                b = G[:3, :3] @ q[i] + G[:3, 3]
                cols.append(np.concatenate([a, np.cross(b, a)]))
                G = G @ Ts[i]
            x -= np.linalg.lstsq(np.array(cols).T, e, rcond=None)[0]
        T2 = _exp(w[0], q[0], t1) @ _exp(w[1], q[1], x[0])
        out[k] = T2[:3, :3] @ q[2] + T2[:3, 3]
    return out


def spherical_bare(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed form of the spherical four-bar of the example file: axes B and C."""
    a1, a2, a3, a4 = np.radians([60, 25, 55, 45])
    A = np.sin(a2) * np.cos(theta) * np.cos(a1) * np.sin(a4) - np.cos(a2) * np.sin(a1) * np.sin(a4)
    B = np.sin(a2) * np.sin(theta) * np.sin(a4)
    C = np.cos(a3) - np.sin(a2) * np.cos(theta) * np.sin(a1) * np.cos(a4) - np.cos(a2) * np.cos(a1) * np.cos(a4)
    phi = np.arctan2(B, A) + np.arccos(C / np.hypot(A, B))
    uB = np.stack([np.sin(a2) * np.cos(theta), np.sin(a2) * np.sin(theta), np.full_like(theta, np.cos(a2))], 1)
    v = np.stack([np.sin(a4) * np.cos(phi), np.sin(a4) * np.sin(phi), np.full_like(phi, np.cos(a4))], 1)
    Ry = np.array([[np.cos(a1), 0, np.sin(a1)], [0, 1, 0], [-np.sin(a1), 0, np.cos(a1)]])
    return uB, v @ Ry.T


def _delta_spheres(mech, q1: np.ndarray) -> tuple[list, list]:
    """The three sphere centres for the platform's shift (each elbow's centre minus the
    platform's drawn ball centre) over the inputs, and the bar lengths."""
    C, ell = [], []
    for i in (1, 2, 3):
        R = mech.joint(f"R{i}")
        A, u = np.asarray(R.point, float), np.asarray(R.axis, float) / np.linalg.norm(R.axis)
        e0 = (np.asarray(mech.joint(f"S{i}a1").point) + np.asarray(mech.joint(f"S{i}b1").point)) / 2
        p0 = (np.asarray(mech.joint(f"S{i}a2").point) + np.asarray(mech.joint(f"S{i}b2").point)) / 2
        ell.append(np.linalg.norm(e0 - p0))
        th = q1 if i == 1 else np.zeros_like(q1)
        K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
        Rk = np.eye(3) + np.sin(th)[:, None, None] * K + (1 - np.cos(th))[:, None, None] * (K @ K)
        C.append(A + Rk @ (e0 - A) - p0)
    return C, ell


def delta_newton_bare(mech, q1: np.ndarray) -> np.ndarray:
    """Bare Newton loop: for each input, the platform's shift ``x`` with
    ``|c_i - x|² = ℓ_i²`` for the three arms (3 x 3 Newton steps, warm start from the
    previous input; the first from the drawn assembly)."""
    C, ell = _delta_spheres(mech, q1)
    C, ell2 = np.stack(C, axis=1), np.square(ell)
    x = np.zeros(3)
    out = np.empty((len(q1), 3))
    for k in range(len(q1)):
        for _ in range(30):
            d = C[k] - x
            f = (d * d).sum(axis=1) - ell2
            if np.abs(f).max() < 1e-13:
                break
            x += np.linalg.solve(2 * d, f)
        out[k] = x
    return out


def delta_bare(mech, q1: np.ndarray) -> np.ndarray:
    """Closed-form forward kinematics: the platform's shift from the drawn assembly (the
    intersection of the three spheres, for all inputs at once)."""
    (c1, c2, c3), ell = _delta_spheres(mech, q1)
    r = ell[0]  # equal bar lengths: three spheres of radius r about c1, c2, c3
    ex = (c2 - c1) / np.linalg.norm(c2 - c1, axis=1)[:, None]
    i_ = np.einsum("ij,ij->i", ex, c3 - c1)
    ey = c3 - c1 - i_[:, None] * ex
    ey /= np.linalg.norm(ey, axis=1)[:, None]
    ez = np.cross(ex, ey)
    d = np.linalg.norm(c2 - c1, axis=1)
    j = np.einsum("ij,ij->i", ey, c3 - c1)
    x = d / 2
    y = (i_ ** 2 + j ** 2 - 2 * i_ * x) / (2 * j)
    z = np.sqrt(np.maximum(r * r - x * x - y * y, 0.0))
    sols = [c1 + x[:, None] * ex + y[:, None] * ey + s * z[:, None] * ez for s in (1, -1)]
    return np.where((np.abs(sols[0]).sum(1) <= np.abs(sols[1]).sum(1))[:, None], sols[0], sols[1])


# --------------------------------------------------------------------------- cases
def cases():
    """(name, mechsyn's run, its error against the references, the bare per-input Newton
    loop, the closed form or None)."""
    ben = ms.examples.load("bennett")
    sph = ms.examples.load("spherical_fourbar")
    dlt = ms.examples.load("delta")
    g360 = ms.input_grid(0, 360, 1)
    gd = ms.input_grid(-30, 30, 0.1)
    t360, td = np.radians(g360), np.radians(gd)

    def err_bennett(s):
        return np.abs(s.point("R3") - loop4r_bare(ben, t360)).max() / s.length_scale

    def err_spherical(s):
        uB, uC = spherical_bare(np.radians(40 + g360))
        loop = loop4r_bare(sph, t360, ("A", "B", "C", "D"))
        return max(np.abs(s.point("B") - uB).max(), np.abs(s.point("C") - uC).max(),
                   np.abs(s.point("C") - loop).max()) / s.length_scale

    def err_delta(s):
        x = s.link("platform").translation
        return max(np.abs(x - delta_bare(dlt, td)).max(), np.abs(x - delta_newton_bare(dlt, td)).max()) / s.length_scale

    return [
        ("Bennett", lambda: ms.simulate(ben, {"R1": g360}, points=["R3"]), err_bennett,
         lambda: loop4r_bare(ben, t360), None),
        ("spherical 4-bar", lambda: ms.simulate(sph, {"A": g360}, points=["B", "C", "P"]), err_spherical,
         lambda: loop4r_bare(sph, t360, ("A", "B", "C", "D")), lambda: spherical_bare(np.radians(40 + g360))),
        ("Delta, 1 drive", lambda: ms.simulate(dlt, {"R1": gd}, points=["S1a2"]), err_delta,
         lambda: delta_newton_bare(dlt, td), lambda: delta_bare(dlt, td)),
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"{'case':<15} {'rows':>4} {'wall':>6} {'cpu':>6} {'target':>6} {'loop':>7} {'x loop':>6} {'x tgt':>5} "
          f"{'closed':>7} {'x closed':>8} {'error':>7}")
    ok = True
    for name, run, check, loop, closed in cases():
        s = run()  # warm: imports, caches
        err = check(s)
        wall, cpu = _minimum(run, args.repeats)
        cpu_loop = _minimum(loop, args.repeats)[1]
        cpu_closed = _minimum(closed, args.repeats)[1] if closed else None
        good = err < 1e-9 and s.assembled.all() and np.nanmax(s.residual) < 1e-9
        ok &= good
        vs_closed = f"{1e3 * cpu_closed:>7.2f} {cpu / cpu_closed:>8.0f}" if closed else f"{'-':>7} {'-':>8}"
        print(f"{name:<15} {len(s.assembled):>4} {1e3 * wall:>6.1f} {1e3 * cpu:>6.1f} {TARGETS_MS[name]:>6.0f} "
              f"{1e3 * cpu_loop:>7.1f} {cpu / cpu_loop:>6.2f} {TARGETS_LOOP[name]:>5.1f} {vs_closed} {err:>7.1e}"
              + ("" if good else "  WRONG"))
    print("(ms, minima of the runs; cpu: the process's CPU time; x loop, x closed: mechsyn's CPU\n"
          " time over the bare per-input Newton loop's and over the closed form's; x tgt: the target\n"
          " of x loop; error: the"
          " largest distance from them in units of the length scale)")
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
