"""Figure for docs/kinematics.md, "Branches": run from the repository root::

    python docs/figures/kinematics_branches.py      # writes docs/figures/kinematics_branches.png

Left: a parallelogram four-bar (crank 1, coupler 4, rocker 1, frame 4) drawn at 60 degrees
and swept over -30..390: the sweep stays a parallelogram through the change points at 0,
180 and 360 degrees (reported as singular, with null rates there); a fixed assembly sign
(dashed, what the closed form did before) turns it into an anti-parallelogram between them.
Right: the textbook four-bar (examples/textbook/fourbar.yaml): the dead points found on the
dyad's discriminant, the gap, and the reassembly in the drawn mode.
"""

from pathlib import Path
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "src"))

from mechsyn.io import load_mechanism, mechanism_from_dict  # noqa: E402
from mechsyn.kinematics import dyads  # noqa: E402
from mechsyn.kinematics.analysis import input_grid, simulate  # noqa: E402


def parallelogram(theta=60.0):
    t = np.radians(theta)
    B = [np.cos(t), np.sin(t)]
    return mechanism_from_dict({
        "name": "parallelogram", "ground": "frame", "links": ["frame", "crank", "coupler", "rocker"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": B},
            {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4 + B[0], B[1]]},
            {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [4, 0]}]}, "parallelogram")


def direction(angle_deg):
    """The rocker's direction from its frame pivot D to C (its reference line runs C to D),
    in 0..360, broken (NaN) where it wraps."""
    a = np.mod(np.asarray(angle_deg, float) + 180, 360)
    a[1:][np.abs(np.diff(a)) > 180] = np.nan
    return a


def rocker_angle(sim):
    return direction(sim.links["rocker"].angle)


def fixed_sign(mech, x):
    """Rocker angle with every dyad's sign fixed to the drawn one (no branch tracking)."""
    S = sim0 = simulate(mech, {"A": x[:1]}).system
    plan = dyads.decompose(S)
    u0 = np.array([d.assembled for d in S.drivers])
    _, sig = dyads.solve_positions(S, plan, u0[None])
    with np.errstate(invalid="ignore"):
        q, _ = dyads.solve_positions(S, plan, np.radians(x)[:, None], sigmas=sig)
    i = S.index("rocker")
    return direction(np.degrees(q[:, 3 * i + 2])), sim0


fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
m = parallelogram(60.0)
x = input_grid(-30, 390, 0.5)
sim = simulate(m, {"A": x})
fixed, _ = fixed_sign(m, x)
ax1.plot(x, fixed, "--", color="0.6", lw=1.2, label="sign fixed (old closed form)")
ax1.plot(x, rocker_angle(sim), color="C0", lw=2, label="drawn branch kept (assur = newton)")
for e in sim.events:
    if e["kind"] == "singular" and not e.get("before_sweep"):
        ax1.axvline(e["input"]["A"], color="C3", lw=0.8)
ax1.plot([60], [60], "o", color="k", label="drawn configuration")
ax1.text(185, 20, "change points:\nsingular, rates null", color="C3", fontsize=8)
ax1.set(title="Parallelogram four-bar drawn at 60°", xlabel="crank angle (deg)", ylabel="rocker direction D→C (deg)")
ax1.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.1, 1.0))

m2 = load_mechanism(ROOT / "examples/textbook/fourbar.yaml")
x2 = input_grid(0, 360, 0.5)
s2 = simulate(m2, {"A": x2})
ax2.plot(x2, rocker_angle(s2), color="C0", lw=2, label="sweep (drawn mode)")
for e in s2.events:
    if e["kind"] == "dead point":
        ax2.axvline(e["input"]["A"], color="C3", lw=0.8)
        ax2.text(e["input"]["A"] + 3, 150, f"dead point\n{e['input']['A']:.9f}°", color="C3", fontsize=8)
ax2.axvspan(*[e["input"]["A"] for e in s2.events if e["kind"] == "dead point"][:2], color="0.92",
            label="not assembled (null)")
P0 = m2.joint("B").point
ax2.plot([np.degrees(np.arctan2(P0[1], P0[0]))], [rocker_angle(simulate(m2, {"A": [63.43494882]}))[0]], "o",
         color="k", label="drawn configuration")
ax2.set(title="Textbook four-bar: dead points and gap", xlabel="crank angle (deg)", ylabel="rocker direction D→C (deg)")
ax2.legend(fontsize=8, loc="upper right")
fig.tight_layout()
fig.savefig(Path(__file__).with_suffix(".png"), dpi=110)
