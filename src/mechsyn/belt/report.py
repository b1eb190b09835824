"""The whole analysis of one belt manipulator, as ``mechsyn belt analyze`` reports it.

:func:`analyze_case` runs, over one range of lever rotations Δφ, the closed-form position
and transfer functions (:func:`mechsyn.belt.kinematics.analyze`), the straightness of the
paths of C and H (:func:`mechsyn.belt.straightness.path_quality`), the comparison with
the equivalent hinged four-bar (:func:`mechsyn.belt.four_bar.compare_with_four_bar`) and
the speeds and accelerations under an input law (:func:`mechsyn.belt.kinematics.motion`).
The :class:`BeltReport` it returns is what the command prints (``_repr_markdown_`` shows
the same tables in Jupyter) and its ``to_dict()`` is the command's ``--json``.

References
----------
.. [1] Paper 001 (seed 001), the belt manipulator: the reference in :mod:`mechsyn.belt`.
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001";
   see docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from mechsyn._result import Result
from mechsyn.belt.design import BeltDesign
from mechsyn.belt.four_bar import FourBarState, compare_with_four_bar, equivalent_four_bar
from mechsyn.belt.kinematics import BeltState, ConstantSpeedLaw, MotionLaw, MotionResult, analyze, motion
from mechsyn.belt.straightness import PathQuality, path_quality
from mechsyn.belt.synthesis import BeltSynthesis
from mechsyn.belt.tables import Table, fmt
from mechsyn.errors import MechsynInputError

__all__ = ["BeltReport", "analyze_case", "phi_range"]

#: most positions (or time samples) one report evaluates
MAX_POSITIONS = 200_000


def phi_range(start: float, stop: float, step: float) -> NDArray[np.float64]:
    """Lever rotations Δφ in radians from ``start`` to ``stop`` (both included) by ``step``,
    all in degrees.

    Examples
    --------
    >>> from mechsyn.belt.report import phi_range
    >>> phi_range(-73, 85, 1).size
    159
    """
    if not all(math.isfinite(v) for v in (start, stop, step)) or step == 0:
        raise MechsynInputError("the range needs finite START:STOP:STEP with STEP != 0", field="phi")
    if (stop - start) * step < 0:
        raise MechsynInputError(f"step {step:g} does not lead from {start:g} to {stop:g}", field="phi")
    n = int(math.floor((stop - start) / step + 1e-9)) + 1
    if n > MAX_POSITIONS:
        raise MechsynInputError(f"{n} positions is too many (at most {MAX_POSITIONS})", field="phi",
                                hint="use a larger STEP")
    if n < 2:
        raise MechsynInputError("the range must hold at least 2 positions", field="phi")
    return np.radians(start + step * np.arange(n))


@dataclass(repr=False)
class BeltReport(Result):
    """Analysis of one belt manipulator over a range of Δφ (see :func:`analyze_case`).

    ``state`` (positions, transfer functions, paths), ``four_bar`` and ``motion`` keep the
    arrays for plotting; ``paths`` holds the straightness of C's and H's paths,
    ``four_bar_comparison`` the belt mechanism against its equivalent four-bar, and
    ``warnings`` what the numbers alone would not say (slack belt positions).

    Examples
    --------
    >>> import mechsyn as ms
    >>> rep = ms.belt.analyze_case(ms.BeltDesign(a=100, c=300, h=0, r=200),
    ...                            ms.belt.phi_range(-30, 40, 1))
    >>> rep.valid_positions, len(rep.warnings)      # slack positions are said, not hidden
    (46, 1)
    >>> sorted(rep.to_dict())[:4]
    ['B0', 'alpha0_deg', 'b0', 'design']
    """

    name: str
    design: BeltDesign
    synthesis: BeltSynthesis | None
    paths: dict[str, PathQuality]
    four_bar_comparison: dict[str, Any]
    law: MotionLaw = field(metadata={"json": False})
    state: BeltState = field(metadata={"json": False})
    four_bar: FourBarState = field(metadata={"json": False})
    motion: MotionResult = field(metadata={"json": False})
    warnings: list[str] = field(default_factory=list)

    _plot: ClassVar[str | None] = "belt:plot_belt_report"

    @property
    def valid_positions(self) -> int:
        """Positions where the belt is taut and straight (d > r)."""
        return int(np.count_nonzero(self.state.valid))

    def to_dict(self) -> dict[str, Any]:
        """The ``mechsyn belt analyze --json`` contract (one record per position in ``rows``)."""
        d = self.design
        return {
            "name": self.name, "design": d.to_dict(), "b0": d.b0, "l0": d.l0,
            "alpha0_deg": math.degrees(d.alpha0), "B0": d.B0, "synthesis": self.synthesis,
            "valid_positions": self.valid_positions, "rows": self.state.rows(), "paths": self.paths,
            "four_bar_comparison": self.four_bar_comparison,
            "motion": {"law": type(self.law).__name__, "law_text": self.law.describe(), **self.motion.to_dict()},
            "warnings": self.warnings,
        }

    def headline(self) -> str:
        """One line: the dimensions and the belt's design constants."""
        d = self.design
        return (f"{self.name}: a = {d.a:g}, c = {d.c:g}, h = {d.h:g}, r = {d.r:g}  ->  "
                f"b0 = {d.b0:.3f}, l0 = {d.l0:.3f}, α0 = {math.degrees(d.alpha0):.3f}°")

    def motion_line(self) -> str:
        """One line: the input law's duration and the largest speeds and accelerations."""
        mx = self.motion.to_dict()["max"]
        return (f"input law: {self.law.describe()}; duration {self.motion.t[-1]:.4g} s; max speed "
                f"C {mx['C_speed']:.4g}, H {mx['H_speed']:.4g}; max |a| C {mx['C_accel']:.4g}, "
                f"H {mx['H_accel']:.4g} (unit/s, unit/s²)")

    def _summary(self) -> list[tuple[str, str]]:
        d, q = self.design, self.paths
        return [("design", f"a={d.a:g} c={d.c:g} h={d.h:g} r={d.r:g}, b0={d.b0:.3f} l0={d.l0:.3f}"),
                ("positions", f"{self.valid_positions} of {self.state.dphi.size} with a taut belt"),
                ("C deviation", f"{q['C'].max_positive_deviation:.4g} above the design tangent"),
                ("H deviation", f"{q['H'].max_positive_deviation:.4g} above the design tangent"),
                ("H translation", f"{q['H'].translation_length:.4g} with |θ| ≤ "
                                  f"{q['H'].translation_tol_deg:g}°"),
                ("motion", self.motion_line()), *(("warning", w) for w in self.warnings)]

    def tables(self) -> list[Table]:
        """The tables ``mechsyn belt analyze`` prints, as text cells."""
        return [_transfer_table(self.state), _path_table(self.state), _quality_table(self.paths),
                _comparison_table(self.four_bar_comparison)]

    #: rows of a long table a notebook shows (its head and tail; the size is said)
    NOTEBOOK_ROWS: ClassVar[int] = 10

    def _repr_markdown_(self) -> str:
        """The report in a notebook: long tables show their first and last rows and their size."""
        parts = [f"**{self.headline()}**", *(f"> warning: {w}" for w in self.warnings)]
        parts += [t.markdown(self.NOTEBOOK_ROWS, "in .to_dict()['rows'] and .tables()") for t in self.tables()]
        return "\n\n".join(parts + [self.motion_line()])


def _transfer_table(st: BeltState) -> Table:
    deg = np.degrees
    rows = [(fmt(deg(st.dphi[i]), 2), fmt(deg(st.dpsi[i])), fmt(deg(st.beta[i])), fmt(st.b[i]),
             fmt(st.d[i]), fmt(st.psi1[i], 4), fmt(st.psi2[i], 4)) for i in range(st.dphi.size)]
    return Table("transfer functions (derivatives w.r.t. Δφ in rad)",
                 ("Δφ°", "Δψ°", "β°", "b", "d", "ψ'", "ψ''"), rows)


def _path_table(st: BeltState) -> Table:
    sC, sH = np.hypot(st.C1[:, 0], st.C1[:, 1]), np.hypot(st.H1[:, 0], st.H1[:, 1])
    rows = [(fmt(np.degrees(st.dphi[i]), 2), *(fmt(v, 2) for v in (
        st.C[i, 0], st.C[i, 1], st.H[i, 0], st.H[i, 1], sC[i], sH[i]))) for i in range(st.dphi.size)]
    return Table("paths of C and H; |C'|, |H'|: speed per unit input speed (rad/s)",
                 ("Δφ°", "xC", "yC", "xH", "yH", "|C'|", "|H'|"), rows)


_QUALITY = (("extent_x", "horizontal extent"), ("extent_y", "vertical extent"),
            ("segment_span", "segment length along the design tangent"),
            ("max_positive_deviation", "max deviation above the tangent"),
            ("max_negative_deviation", "max deviation below the tangent"),
            ("best_line_deviation", "max deviation from the best (minimax) line"),
            ("translation_length", "travel with |θ| ≤ tol"))


def _quality_table(q: dict[str, PathQuality]) -> Table:
    rows = [(label, fmt(getattr(q["C"], k)), fmt(getattr(q["H"], k))) for k, label in _QUALITY]
    qc = q["C"]
    caption = (f"segment Δφ = {qc.segment_deg[0]:g}…{qc.segment_deg[1]:g}°, tol = "
               f"{qc.translation_tol_deg:g}° (Δφ {qc.translation_dphi_deg[0]:.2f}…"
               f"{qc.translation_dphi_deg[1]:.2f}°)")
    return Table("straight-line quality of the paths", ("", "C", "H"), rows, caption, labels=True)


def _comparison_table(comparison: dict[str, Any]) -> Table:
    rows = []
    for name in ("belt", "four_bar"):
        e = comparison[name]
        rng = e["assembled_dphi_deg"]
        side = [fmt(e["C"][s]["max_positive_deviation"]) if e["C"][s] else "—"
                for s in ("machine_side", "other_side")]
        rows.append((name, f"{rng[0]:.1f} … {rng[1]:.1f}" if rng else "—", *side,
                     fmt(e["H"]["translation_length"])))
    return Table("belt mechanism vs. its equivalent four-bar A0-A-B-B0",
                 ("", "assembles over Δφ°", "C above line (machine side)", "C above line (other side)",
                  "H travel |θ| ≤ tol"), rows, labels=True)


def analyze_case(
    design: BeltDesign | BeltSynthesis,
    dphi: ArrayLike,
    *,
    synthesis: BeltSynthesis | None = None,
    segment: tuple[float, float] | None = None,
    translation_tol: float = math.radians(3.0),
    law: MotionLaw | None = None,
    samples: int = 201,
    name: str = "belt manipulator",
) -> BeltReport:
    """Positions, transfer functions, path straightness, the comparison with the equivalent
    four-bar, and speeds and accelerations of a belt manipulator.

    Parameters
    ----------
    design : BeltDesign or BeltSynthesis
        The dimensions, or a synthesis result (kept in the report).
    dphi : array_like
        Lever rotations Δφ from the design position, radians (e.g. :func:`phi_range`).
    synthesis : BeltSynthesis, optional
        The synthesis the design came from, when ``design`` is a :class:`BeltDesign`
        (e.g. a synthesised design with a dimension changed afterwards).
    segment : (float, float), optional
        Δφ interval (radians) judged for straightness; default from the range's start
        to the design position (the part paper 001 judges).
    translation_tol : float
        Tolerance (radians) on link 2's attitude θ for the translation run.
    law : MotionLaw, optional
        Input law of lever 1; default a constant 60 °/s over the range.
    samples : int
        Time samples of the motion.
    name : str
        Title of the report.

    Returns
    -------
    BeltReport

    Raises
    ------
    MechsynInputError
        The belt is slack (d <= r) over the whole range (``field="phi"``), a segment
        outside the range (``"segment"``), a non-positive tolerance (``"tol"``) or too
        few or too many samples (``"samples"``).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.belt import analyze_case, phi_range
    >>> rep = analyze_case(ms.BeltDesign(a=500, c=350, h=100, r=75), phi_range(-73, 85, 1))
    >>> round(rep.paths["C"].max_positive_deviation, 2)   # paper 001: about 45 mm
    44.92
    >>> rep.valid_positions
    159
    """
    if isinstance(design, BeltSynthesis):
        synthesis, des = design, design.design
    else:
        des = design
    dphi = np.atleast_1d(np.asarray(dphi, dtype=float))
    if not (math.isfinite(translation_tol) and translation_tol > 0):
        raise MechsynInputError(f"must be positive, got {math.degrees(translation_tol):g}°", field="tol")
    if not 2 <= samples <= MAX_POSITIONS:
        raise MechsynInputError(f"must be 2..{MAX_POSITIONS}, got {samples}", field="samples")
    if dphi.size < 2 or not np.all(np.isfinite(dphi)):
        raise MechsynInputError("need at least 2 finite lever rotations", field="phi")
    state = analyze(des, dphi)
    if not np.any(state.valid):
        raise MechsynInputError("the belt is slack or crosses the pulley (d <= r) over the whole range",
                                field="phi", hint="check r and the range")
    rng = (float(dphi.min()), float(dphi.max()))
    paths = {p: path_quality(des, rng, p, segment, translation_tol) for p in ("C", "H")}
    law = law if law is not None else ConstantSpeedLaw(float(dphi[0]), float(dphi[-1]), math.radians(60.0))
    n_slack = int(np.count_nonzero(~state.valid))
    warnings = ([f"at {n_slack} of {dphi.size} positions the belt is slack or crosses the pulley "
                 "(d <= r): their values are nan"] if n_slack else [])
    return BeltReport(
        name=name, design=des, synthesis=synthesis, paths=paths,
        four_bar_comparison=compare_with_four_bar(des, rng, translation_tol), law=law, state=state,
        four_bar=equivalent_four_bar(des, dphi), motion=motion(des, law, samples), warnings=warnings)
