"""Figure for docs/rank.md: how the finite mobility is measured (issue 25 §3).

(a) The relative correction ``ρ(ε) = |θ(ε) - ε d| / ε`` that Gauss-Newton applies to a
tangent step ``ε d`` (``d`` a random unit direction of the instantaneous motions) to put
it back on the loop closure: it shrinks with ``ε`` where the step extends to a finite
motion (Bennett's linkage: regular) and stays where it does not (a change-point four-bar
folded flat: singular; a taut four-bar and a four-bar with a straight dyad on its coupler:
shaky). (b), (c) Tangent steps of length ``ε = 0.02`` in every direction of the
two-dimensional space of instantaneous motions (grey circle) and where they land (dots),
in the coordinates of that space: on two branches that cross (folded four-bar), and on one
branch, the wobble of the dyad undone (shaky dyad).

Run from the repository root: PYTHONPATH=src python docs/figures/finite_mobility.py
(writes docs/figures/finite_mobility.png).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # a script that writes a file, not a library function
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mechsyn.io import load_mechanism  # noqa: E402
from mechsyn.structure import rank as R  # noqa: E402
from mechsyn.structure.finite import _Projector  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
CASES = [("textbook/bennett.yaml", "Bennett linkage: regular", "C0"),
         ("textbook/fourbar_folded.yaml", "four-bar folded flat: singular", "C3"),
         ("textbook/fourbar_taut.yaml", "taut four-bar: shaky", "C2"),
         ("textbook/fourbar_shaky_dyad.yaml", "straight dyad on a coupler: shaky", "C1")]


def system(rel: str):
    mech = load_mechanism(ROOT / "examples" / rel)
    sysm = R._build_system(mech, mech.kind == "planar")
    tol = R._default_tolerance(mech, sysm)
    N = R._reduce(sysm, np.zeros(sysm.twists.shape[0]), tol).null
    return _Projector(lambda th: R._gauss_newton_step(sysm, th, tol), tol), N


def rho_curves(ax, curves) -> None:
    """``ρ(ε)`` along each tangent direction: ``curves`` of (projector, direction, label,
    colour, marker); also used by shaky_octahedron.py."""
    eps = np.logspace(-3.3, -1, 12)
    for proj, d, label, colour, marker in curves:
        d = d / np.linalg.norm(d)
        rho = [np.linalg.norm(proj(e * d, e) - e * d) / e for e in eps]
        ax.loglog(eps, rho, "-", marker=marker, color=colour, ms=4, lw=1.2, mfc="none", label=label)
    ax.loglog(eps, 0.5 * eps, ":", color="0.4", lw=1)
    ax.text(eps[3], 0.5 * eps[3] * 0.45, "slope 1", color="0.35", fontsize=8)
    ax.set_xlabel("tangent step ε (radians, lengths / length scale)")
    ax.set_ylabel("relative correction ρ(ε)")


def corrections(ax) -> None:
    curves = []
    for (rel, label, colour), marker in zip(CASES, "osD^"):
        proj, N = system(rel)
        d = N @ np.array([1.0, 0.7])[: N.shape[1]]  # a direction between the basis motions
        curves.append((proj, d, label, colour, marker))
    rho_curves(ax, curves)
    ax.set_title("(a) does the step extend to a finite motion?", fontsize=10)
    ax.legend(fontsize=7.5, loc="lower right", frameon=False)


def landings(ax, rel: str, title: str, colour: str) -> None:
    proj, N = system(rel)
    e = 0.02
    phi = np.linspace(0, 2 * np.pi, 73)[:-1]
    circle = np.stack([np.cos(phi), np.sin(phi)], axis=1) * e
    ax.plot(*np.vstack([circle, circle[:1]]).T, color="0.75", lw=1)
    for c in circle:
        t = proj(N @ c, e)
        q = N.T @ t
        ax.plot([c[0], q[0]], [c[1], q[1]], color="0.85", lw=0.6)
        ax.plot(*q, "o", color=colour, ms=3)
    ax.plot(0, 0, "k+", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("instantaneous motion 1")
    ax.set_ylabel("instantaneous motion 2")
    ax.set_title(title, fontsize=10)


def main() -> Path:
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.4), gridspec_kw={"width_ratios": [1.35, 1, 1]})
    corrections(axes[0])
    landings(axes[1], "textbook/fourbar_folded.yaml", "(b) folded four-bar: two branches cross", "C3")
    landings(axes[2], "textbook/fourbar_shaky_dyad.yaml", "(c) straight dyad: one branch, smooth", "C1")
    fig.tight_layout()
    out = ROOT / "docs/figures/finite_mobility.png"
    fig.savefig(out, dpi=110)
    return out


if __name__ == "__main__":
    print(main())
