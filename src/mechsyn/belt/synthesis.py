"""Synthesis of paper 001's belt-and-pulley manipulator (primary chain, then the belt).

Given the design and final positions H0, Hf of the gripper point H, the rotation φ_of of
lever 1 between them, a base point A0 (chosen by the designer in the allowed region Ω)
and the pulley radius r, paper 001 (section 2, fig. 2; corrected per the spec
``flexible-manipulator.md``) gives:

1. origin at A0, y parallel to the machine's axis;
2. Hf(1) = Hf rotated by -φ_of about A0 (Hf seen from lever 1):
   x = x_Hf cos φ_of + y_Hf sin φ_of,  y = -x_Hf sin φ_of + y_Hf cos φ_of;
3. midpoint M of H0 Hf(1), slope of its perpendicular bisector
   k_m = -(x_H0 - x_Hf(1)) / (y_H0 - y_Hf(1))   (the printed fraction is OCR-garbled);
4. A = (0, y_M - k_m x_M) where the bisector meets the y axis; a = y_A;
5. c = -x_H0, h = y_H0 - y_A  (legs of the right triangle with hypotenuse A H0);
6. b0, l0, α0 from (1)-(3) (:func:`mechsyn.belt.design.design_constants`).

Why it works: H lies at the fixed distance sqrt(c^2 + h^2) from A on link 2, whatever
link 2's rotation, so A (fixed on lever 1) is equidistant from H0 and Hf(1).

References
----------
.. [1] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from mechsyn.belt.design import BeltDesign
from mechsyn.belt.kinematics import BeltState, analyze
from mechsyn.belt.tables import Table, fmt
from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.problem import SynthesisResult

__all__ = ["BeltSynthesis", "synthesize_belt"]


@dataclass(repr=False)
class BeltSynthesis(SynthesisResult):
    """Result of :func:`synthesize_belt`: the design (in A0's frame), intermediate points of
    the construction (all in A0's frame) and the checks made on the motion H0 -> Hf.

    A :class:`~mechsyn.synthesis.problem.SynthesisResult`: ``design`` is the
    :class:`BeltDesign` (its named values in ``to_dict()["design"]``), ``x`` = (a, c, h),
    ``error`` the distance from Hf at which the belt mechanism puts H at Δφ = φ_of,
    ``feasible`` whether every check passed (``reason`` names those that did not),
    ``nfev`` 0 (a closed-form construction) and ``seed`` None.
    """

    design: BeltDesign
    A0: tuple[float, float]
    H0: tuple[float, float]
    Hf: tuple[float, float]
    phi_of_deg: float
    Hf1: tuple[float, float]
    M: tuple[float, float]
    k_m: float | None
    min_d_minus_r: float
    H_at_phi_of: tuple[float, float]
    checks: dict[str, bool] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, object]:
        """The ``mechsyn belt synthesize --json`` contract: the dimensions flat, the
        construction's points, the checks, and the common synthesis keys."""
        d = self.design
        return {
            "a": d.a, "c": d.c, "h": d.h, "r": d.r,
            "b0": d.b0, "l0": d.l0, "alpha0_deg": math.degrees(d.alpha0),
            "A0": list(self.A0), "A": [0.0, d.a], "B0": d.B0.tolist(),
            "H0": list(self.H0), "Hf": list(self.Hf), "phi_of_deg": self.phi_of_deg,
            "Hf1": list(self.Hf1), "M": list(self.M), "k_m": self.k_m,
            "min_d_minus_r": self.min_d_minus_r, "H_at_phi_of": list(self.H_at_phi_of),
            "Hf_miss": math.dist(self.H_at_phi_of, self.Hf), "checks": self.checks,
            "notes": self.notes, **self.common(),
        }

    def _summary(self) -> list[tuple[str, str]]:
        d = self.design
        rows = [("design", f"a={d.a:.6g} c={d.c:.6g} h={d.h:.6g} r={d.r:g}, b0={d.b0:.6g} l0={d.l0:.6g}"),
                ("Hf miss", f"{self.error:.6g}"), ("feasible", str(self.feasible))]
        rows += [("reason", self.reason)] if self.reason else []
        return rows + [("note", n) for n in self.notes]

    def table(self) -> Table:
        """The dimensions and the construction's points as text cells."""
        d = self.to_dict()
        rows = [(k, fmt(d[k], 6) if d[k] is not None else "∞") for k in (
            "a", "c", "h", "r", "b0", "l0", "alpha0_deg", "k_m", "min_d_minus_r", "Hf_miss")]
        rows += [(k, ", ".join(f"{v:.4f}" for v in d[k]))  # type: ignore[union-attr]
                 for k in ("A", "B0", "H0", "Hf", "Hf1", "M", "H_at_phi_of")]
        return Table("belt manipulator synthesis (paper 001), A0's frame", ("quantity", "value"), rows, labels=True)


def _check_inputs(H0: tuple[float, float], Hf: tuple[float, float], A0: tuple[float, float],
                  phi_of: float, r: float) -> None:
    """Raise :class:`MechsynInputError` on inputs no construction can use."""
    if len(H0) != 2 or len(Hf) != 2 or len(A0) != 2:
        raise MechsynInputError("H0, Hf and A0 are points: two numbers each")
    if not all(math.isfinite(float(v)) for v in [*H0, *Hf, *A0, phi_of, r]):
        raise MechsynInputError("every input of the synthesis must be a finite number")
    if r <= 0:
        raise MechsynInputError(f"pulley radius r must be positive, got {r:g}", field="r")
    if abs(phi_of) < 1e-12:
        raise MechsynInputError("φ_of must not be zero: lever 1 has to turn between H0 and Hf",
                                field="phi")
    if abs(phi_of) >= math.pi:
        raise MechsynInputError("|φ_of| must be below 180°", field="phi")


def _checks(design: BeltDesign, st: BeltState, scale: float) -> dict[str, bool]:
    """What the construction must give over the motion ``st`` from H0 to Hf."""
    return {
        "belt_taut_and_straight (d > r)": bool(np.all(st.valid)),
        "lever_and_belt_parallel_at_design": bool(
            abs(design.B0[0] - design.r) < 1e-9 * scale and abs(math.degrees(st.beta[0]) - 90) < 1e-9
        ),
        "b0_below_a": bool(design.b0 < design.a),
    }


def synthesize_belt(
    H0: tuple[float, float],
    Hf: tuple[float, float],
    phi_of: float,
    r: float,
    A0: tuple[float, float] = (0.0, 0.0),
    samples: int = 721,
    hf_tol: float = 1e-3,
) -> BeltSynthesis:
    """Primary chain (a, c, h) and belt (b0, l0, α0) from H0, Hf, φ_of (rad), r and A0.

    H0, Hf and A0 are in the machine's frame (y along the machine's axis); the result is
    in A0's frame (origin at A0). Raises :class:`MechsynInputError` when the data admit no
    mechanism of this kind: coincident positions, a bisector parallel to (or on) the
    lever's axis, a lever pointing down (a <= 0), H0 not to the left of A (c <= 0), or a
    belt that would go slack or cross the pulley's centre (d <= r) between H0 and Hf.
    Checked by construction: lever 1 and the belt are parallel (both along y) in the
    design position, with the belt at distance r from the lever's axis.

    The construction fixes a, c, h so that *some* rotation of link 2 brings H to Hf; the
    belt then sets that rotation, so H reaches Hf at Δφ = φ_of only when the scene suits
    the belt. ``error`` is H's miss of Hf there; the result is ``feasible`` only when the
    miss is at most ``hf_tol`` times the scene's size (``reason`` says otherwise).

    Examples
    --------
    >>> import math, mechsyn as ms
    >>> s = ms.synthesize_belt(H0=(-350, 600), Hf=(324.62, 597.49), phi_of=math.radians(-60), r=75)
    >>> round(s.design.a, 2), round(s.design.c, 2), round(s.design.h, 2)   # paper 001's 500, 350, 100
    (500.04, 350.0, 99.96)
    >>> s.feasible, round(s.error, 3)                    # Hf given to 0.01: H misses it by 0.019
    (True, 0.019)
    >>> far = ms.synthesize_belt(H0=(-350, 600), Hf=(300, 560), phi_of=math.radians(-55), r=75)
    >>> far.feasible, round(far.error)                   # a scene the belt cannot serve
    (False, 509)
    """
    t0 = time.perf_counter()
    _check_inputs(H0, Hf, A0, phi_of, r)
    x0, y0 = float(H0[0]) - A0[0], float(H0[1]) - A0[1]
    xf, yf = float(Hf[0]) - A0[0], float(Hf[1]) - A0[1]
    cf, sf = math.cos(phi_of), math.sin(phi_of)
    xf1 = xf * cf + yf * sf
    yf1 = -xf * sf + yf * cf
    xm, ym = 0.5 * (x0 + xf1), 0.5 * (y0 + yf1)
    scale = max(1.0, math.hypot(x0, y0), math.hypot(xf, yf))
    dx, dy = x0 - xf1, y0 - yf1
    if math.hypot(dx, dy) <= 1e-12 * scale:
        raise MechsynInputError(
            "H0 and Hf rotated back by φ_of coincide: A is undetermined",
            field="hf", hint="any point of the y axis would do; choose a with the machine")
    if abs(dy) <= 1e-12 * scale:
        raise MechsynInputError(
            "the perpendicular bisector of H0 Hf(1) is parallel to the y axis: it does not "
            "meet the lever's axis", field="hf",
            hint="change Hf, φ_of or A0")
    k_m = -dx / dy
    yA = ym - k_m * xm
    a = yA
    c = -x0
    h = y0 - yA
    if a <= 0:
        raise MechsynInputError(
            f"the construction puts A below A0 (a = {a:.6g}): lever 1 must point up (+y) in "
            "the design position", field="a0", hint="move A0 down or change Hf/φ_of")
    if c <= 0:
        raise MechsynInputError(
            f"H0 must lie to the left of the lever's axis (c = -x_H0 = {c:.6g} <= 0)",
            field="h0", hint="choose A0 to the right of H0")
    design = BeltDesign(a=a, c=c, h=h, r=float(r))
    # check the belt stays taut and straight (d > r) over the motion H0 -> Hf
    st = analyze(design, np.linspace(0.0, phi_of, samples))
    margin = float(np.nanmin(st.d) - r) if np.any(np.isfinite(st.d)) else -math.inf
    checks = _checks(design, st, scale)
    notes: list[str] = []
    if not checks["belt_taut_and_straight (d > r)"]:
        raise MechsynInputError(
            f"the belt would go slack or cross the pulley's centre (d <= r) between H0 and "
            f"Hf (min d - r = {margin:.6g})", field="r", hint="use a smaller pulley radius r")
    if not np.allclose(st.H[-1], [xf, yf], atol=1e-6 * scale):
        miss = math.dist((float(st.H[-1, 0]), float(st.H[-1, 1])), (xf, yf))
        notes.append(
            f"at Δφ = φ_of the belt mechanism puts H {miss:.6g} from Hf: the primary-chain "
            "synthesis fixes a, c, h (A is equidistant from H0 and Hf(1)); link 2's "
            "rotation Δψ relative to lever 1 is then set by the belt")
    H_end = (float(st.H[-1, 0]), float(st.H[-1, 1]))
    miss = math.dist(H_end, (xf, yf))
    failed = [f"check failed: {k}" for k, ok in checks.items() if not ok]
    if miss > hf_tol * scale:
        failed.append(f"H misses Hf by {miss:.6g} at Δφ = φ_of (more than {hf_tol:g} of the scene's size "
                      f"{scale:.6g}): the belt, not this construction, sets link 2's rotation; "
                      "change Hf, φ_of or A0")
    return BeltSynthesis(
        design=design, A0=(float(A0[0]), float(A0[1])), H0=(x0, y0), Hf=(xf, yf),
        phi_of_deg=math.degrees(phi_of), Hf1=(xf1, yf1), M=(xm, ym), k_m=k_m,
        min_d_minus_r=margin, H_at_phi_of=H_end, checks=checks, notes=notes,
        x=np.array([a, c, h]), error=miss, feasible=not failed, reason="; ".join(failed),
        seconds=time.perf_counter() - t0,
    )
