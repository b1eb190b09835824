"""Benchmark: spatial kinematics (``ms.simulate`` on a spatial file: positions, orientations,
velocities, accelerations, closure residual, rank test and events), as time and as a ratio to
bare NumPy references in the same process, with every answer checked against them.

Run from the repository root::

    python benchmarks/spatial_kinematics.py [--repeats 5]

Cases (issue 25 item 4):

* ``Bennett``: examples/textbook/bennett.yaml, R1 over 0..360 deg, 361 inputs (target < 50 ms);
* ``spherical four-bar``: examples/textbook/spherical_fourbar.yaml, A over 0..360 deg,
  361 inputs (target < 50 ms);
* ``Delta, one drive``: examples/textbook/delta.yaml, R1 over -30..30 deg in 0.1 deg
  (601 inputs), the other two arms held (target < 200 ms).

References, each a bare NumPy program written for the case, positions only:

* Bennett: a per-input Newton loop on the loop closure in joint coordinates
  (``exp(ξ1 θ1) exp(ξ2 θ2) exp(ξ3 θ3) exp(ξ4 θ4) = I``, product of exponentials, warm
  start from the previous input), the "bare NumPy loop" a user would write;
* spherical four-bar: the spherical Freudenstein equation solved in closed form for all
  inputs at once (array expressions);
* Delta: the closed-form forward kinematics (intersection of the three spheres about the
  elbows), for all inputs at once.

mechsyn's positions are checked against each (1e-9 of the length scale). Times are minima
over ``--repeats`` runs (the least noisy statistic on a shared machine), as wall time and
as CPU time of the process (steadier when other processes compete for the cores);
``ratio`` is mechsyn's CPU time over the reference's, both measured in this process.

Where the time goes (cProfile, Bennett): about half in the SVDs (the Jacobian's
pseudo-inverse at every anchor and, in batches, at every row: the rank test and the
minimum-norm rates need them), the rest in the NumPy calls of the equations (each a few
microseconds on small arrays); the rows between anchors cost one batch, not a Python loop.
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

TARGETS_MS = {"Bennett": 50.0, "spherical four-bar": 50.0, "Delta, one drive": 200.0}


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


def bennett_bare(mech, theta1: np.ndarray) -> np.ndarray:
    """Bare Newton loop: joint angles θ2..θ4 for each θ1, then the point of R3."""
    J = [mech.joint(j) for j in ("R1", "R2", "R3", "R4")]
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


def delta_bare(mech, q1: np.ndarray) -> np.ndarray:
    """Closed-form forward kinematics: the platform's shift from the drawn assembly."""
    E, P0, ell = [], [], []
    for i in (1, 2, 3):
        R = mech.joint(f"R{i}")
        A, u = np.asarray(R.point, float), np.asarray(R.axis, float) / np.linalg.norm(R.axis)
        e0 = (np.asarray(mech.joint(f"S{i}a1").point) + np.asarray(mech.joint(f"S{i}b1").point)) / 2
        p0 = (np.asarray(mech.joint(f"S{i}a2").point) + np.asarray(mech.joint(f"S{i}b2").point)) / 2
        ell.append(np.linalg.norm(e0 - p0))
        th = q1 if i == 1 else np.zeros_like(q1)
        r = e0 - A
        K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
        Rk = (np.eye(3) + np.sin(th)[:, None, None] * K + (1 - np.cos(th))[:, None, None] * (K @ K))
        E.append(A + Rk @ r - p0)  # the sphere centre for the platform's shift
        P0.append(p0)
    c1, c2, c3 = E
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
    ben = ms.examples.load("bennett")
    sph = ms.examples.load("spherical_fourbar")
    dlt = ms.examples.load("delta")
    g360 = ms.input_grid(0, 360, 1)
    gd = ms.input_grid(-30, 30, 0.1)

    def check_bennett(s):
        ref = bennett_bare(ben, np.radians(g360))
        return np.abs(s.point("R3") - ref).max() / s.length_scale

    def check_spherical(s):
        uB, uC = spherical_bare(np.radians(40 + g360))
        return max(np.abs(s.point("B") - uB).max(), np.abs(s.point("C") - uC).max()) / s.length_scale

    def check_delta(s):
        return np.abs(s.link("platform").translation - delta_bare(dlt, np.radians(gd))).max() / s.length_scale

    return [
        ("Bennett", lambda: ms.simulate(ben, {"R1": g360}, points=["R3"]), check_bennett,
         lambda: bennett_bare(ben, np.radians(g360)), "bare NumPy Newton loop"),
        ("spherical four-bar", lambda: ms.simulate(sph, {"A": g360}, points=["B", "C", "P"]), check_spherical,
         lambda: spherical_bare(np.radians(40 + g360)), "closed form, arrays"),
        ("Delta, one drive", lambda: ms.simulate(dlt, {"R1": gd}, points=["S1a2"]), check_delta,
         lambda: delta_bare(dlt, np.radians(gd)), "closed form, arrays"),
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"{'case':<20} {'rows':>5} {'wall ms':>8} {'cpu ms':>7} {'target':>6} {'reference':<24} "
          f"{'ref ms':>7} {'ratio':>7} {'error':>8}")
    ok = True
    for name, run, check, ref, ref_name in cases():
        s = run()  # warm: imports, caches
        err = check(s)
        wall, cpu = _minimum(run, args.repeats)
        wall_ref, cpu_ref = _minimum(ref, args.repeats)
        good = err < 1e-9 and s.assembled.all() and np.nanmax(s.residual) < 1e-9
        ok &= good
        print(f"{name:<20} {len(s.assembled):>5} {1e3 * wall:>8.1f} {1e3 * cpu:>7.1f} {TARGETS_MS[name]:>6.0f} "
              f"{ref_name:<24} {1e3 * cpu_ref:>7.2f} {cpu / cpu_ref:>7.1f} {err:>8.1e}" + ("" if good else "  WRONG"))
    return 0 if ok else 1


if __name__ == "__main__":
    raise SystemExit(main())
