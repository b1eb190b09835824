"""The answer of curve synthesis: ranked candidates (:class:`CurveCandidate`), the
result (:class:`CurveSynthesisResult`), the ranking that labels the simplest candidate
within the tolerance and the most accurate one, and the nearest miss when no candidate
is within the bounds."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn.synthesis.curves.fitting import Bounds
from mechsyn.synthesis.curves.target import TargetCurve
from mechsyn.synthesis.curves.topologies import TRACER, CurveTopology
from mechsyn.synthesis.problem import SynthesisResult

__all__ = ["CurveCandidate", "CurveSynthesisResult", "SIMPLEST", "MOST_ACCURATE", "ranked", "miss_reason"]

SIMPLEST = "simplest within tolerance"
MOST_ACCURATE = "most accurate"
#: the verification of a candidate answered before the check by ``simulate`` could be
#: loaded within the time limit (listed, labelled, not dropped)
UNCHECKED = "not checked by simulate: the time limit came first"


@dataclass
class CurveCandidate:
    """One ranked linkage (see :meth:`to_dict` for the reported fields)."""

    topology: CurveTopology
    params: np.ndarray              # design in the target's coordinates
    start: float                    # input offsets from the reference, degrees
    stop: float
    chamfer: float                  # the error: symmetric chamfer along the curves in order / the diagonal
    ordered: float                  # timing diagnostic (not ranked by)
    min_transmission_angle: float
    link_length_ratio: float
    path: np.ndarray                # (N, 2) traced path
    verified: bool = False
    verification: str = ""
    nfev: int = 0
    reference_input: float = float("nan")   # input angle (deg) of the design's configuration
    size: float = float("nan")              # radius about the target's centroid holding every point
    size_ratio: float = float("nan")        # size / target diagonal
    refined: bool = True                    # False: a retrieved database design, mapped, not refined
    role: str = ""                          # SIMPLEST, MOST_ACCURATE, both, or ""
    departs_at: int = -1                    # index of the target point farthest from the path
    departure: float = float("nan")         # that distance / the target's diagonal
    nearest: float = float("nan")           # the order-free chamfer / the diagonal (a diagnostic)

    def __post_init__(self) -> None:
        if not np.isfinite(self.reference_input):
            self.reference_input = float(self.topology.plan.reference_inputs(self.params)[0])

    @property
    def full_turn(self) -> bool:
        """The input turns fully (a crank)."""
        return bool(self.stop - self.start >= 360.0 - 1e-9)

    def quality(self) -> dict[str, Any]:
        """The design-quality fields: ``size`` (radius of the disc about the target's
        centroid that holds every joint and the tracer over the whole motion, target
        units), ``size_ratio`` (that over the target's diagonal), ``link_ratio`` (longest
        over shortest link length), ``min_transmission_angle`` (degrees, worst RRR dyad
        over the motion) and ``full_turn``."""
        return {"size": float(self.size), "size_ratio": float(self.size_ratio),
                "link_ratio": float(self.link_length_ratio),
                "min_transmission_angle": float(self.min_transmission_angle), "full_turn": self.full_turn}

    def mechanism(self) -> dict:
        t = self.topology
        name = f"{t.name or f'{t.n_links}-bar'} tracing the target (mechsyn synth curve)"
        return t.mechanism(self.params, name=name)

    def to_dict(self) -> dict[str, Any]:
        t = self.topology
        ref = self.reference_input
        return {
            "mechanism": self.mechanism(),
            "tracer": TRACER,
            "input": {"joint": t.plan.input_joint, "start": ref + self.start, "stop": ref + self.stop},
            "links": t.n_links,
            "topology": t.label,
            "topology_key": t.key,
            "role": self.role,
            "refined": self.refined,
            "error": {"chamfer": self.chamfer, "nearest": self.nearest, "ordered": self.ordered},
            "departs_most": {"point": self.departs_at, "distance": self.departure},
            "quality": self.quality(),
            "min_transmission_angle": self.min_transmission_angle,
            "link_length_ratio": self.link_length_ratio,
            "crank": self.full_turn,
            "verified": self.verified,
            "verification": self.verification,
        }

    def describe(self, target: TargetCurve) -> str:
        """One line: error, role, refinement, where it departs most, quality."""
        tag = f" [{self.role}]" if self.role else ""
        raw = "" if self.refined else " (retrieved design, not refined)"
        where = ""
        if 0 <= self.departs_at < len(target.points):
            x, y = target.points[self.departs_at]
            where = (f"; departs most at points[{self.departs_at}] ({x:.4g}, {y:.4g}) by "
                     f"{100 * self.departure:.2f} %")
        return (f"{self.topology.label} [{self.topology.key}]{tag}{raw}: error {100 * self.chamfer:.2f} %{where}; "
                f"size {self.size_ratio:.2f} diagonals, link ratio {self.link_length_ratio:.1f}, "
                f"min transmission {self.min_transmission_angle:.0f} deg" + (", full turn" if self.full_turn else "")
                + ("" if self.verified else "  NOT CHECKED (time limit)" if self.verification == UNCHECKED
                   else "  NOT VERIFIED"))


@dataclass(repr=False)
class CurveSynthesisResult(SynthesisResult):
    """Ranked candidates, best first (``to_dict()`` is the ``--json`` output).

    A :class:`~mechsyn.synthesis.problem.SynthesisResult` for the first candidate:
    ``error`` its error (symmetric chamfer over the target's diagonal; NaN without a
    candidate), ``design`` and ``x`` its parameters, ``nfev`` the refinements'
    evaluations, ``seed`` None (the search is deterministic for a fixed number of
    refinements).
    """

    target: TargetCurve
    candidates: list[CurveCandidate]
    retrieved: int
    refined: int
    notes: list[str] = field(default_factory=list)
    bounds: dict[str, Any] = field(default_factory=dict)
    nearest_miss: CurveCandidate | None = None
    time_limit: float | None = None

    def to_dict(self) -> dict[str, Any]:
        miss = self.nearest_miss.to_dict() if self.nearest_miss is not None else None
        return {"candidates": [c.to_dict() for c in self.candidates],
                "target": {"points": self.target.points, "closed": self.target.closed,
                           "diagonal": self.target.diagonal},
                "error_measure": "symmetric chamfer along the curves in order (points to polyline, both ways, "
                                 "mean over arc length, a correspondence running along both curves in order) / "
                                 "the diagonal of the target's principal-axes bounding box; nearest: the same "
                                 "without the order",
                "bounds": self.bounds, "nearest_miss": miss, "time_limit": self.time_limit,
                "seconds": self.seconds, "retrieved": self.retrieved, "refined": self.refined,
                "interrupted": self.interrupted, "notes": self.notes, **self.common()}

    def __str__(self) -> str:
        lines = [f"curve synthesis: {len(self.candidates)} candidates, {self.refined} refinements of "
                 f"{self.retrieved} retrieved designs, {self.seconds:.1f} s"
                 + (" (interrupted)" if self.interrupted else "")]
        for i, c in enumerate(self.candidates, 1):
            lines.append(f"{i}. {c.describe(self.target)}")
        if not self.candidates:
            lines.append(self.reason)
        return "\n".join(lines)

    def plot(self, ax=None, top: int = 3):
        """Target and the best candidates' paths (see :func:`mechsyn.plot.curves.plot_curve_result`)."""
        from mechsyn.plot.curves import plot_curve_result

        return plot_curve_result(self, ax=ax, top=top)


def _rank_key(c: CurveCandidate, tolerance: float, prefer: str) -> tuple:
    if prefer == "accuracy" or c.chamfer > tolerance:
        return (1 if prefer != "accuracy" else 0, 0, 0, 0, c.chamfer)
    return (0, c.topology.n_links, not c.full_turn, -np.floor(c.min_transmission_angle / 5.0),
            c.chamfer)


def _same(a: CurveCandidate, b: CurveCandidate) -> bool:
    return (a.topology.key == b.topology.key and abs(a.chamfer - b.chamfer) < 1e-5
            and abs(a.link_length_ratio - b.link_length_ratio) < 1e-3 * b.link_length_ratio)


def ranked(cands: list[CurveCandidate], top: int, tolerance: float, prefer: str, verify,
           notes: list[str]) -> list[CurveCandidate]:
    """Best first, distinct, each checked by ``verify(candidate)`` (dropped, with a
    note, when it fails; kept when the time left no check, :data:`UNCHECKED`); at most
    ``top``. ``prefer="simple"``: among candidates within
    ``tolerance`` fewer links first (the first three of distinct topologies), then a
    full turn, then the larger transmission angle (5° steps), then the error; the rest
    by error; ``"accuracy"``: by error. The simplest candidate within the tolerance and
    the most accurate one are labelled (:attr:`CurveCandidate.role`); the most
    accurate is always listed: after the ``top`` if it is not among them."""
    cands = sorted(cands, key=lambda c: _rank_key(c, tolerance, prefer))
    order = cands
    if prefer == "simple":
        first: list[CurveCandidate] = []
        for c in cands:
            if c.chamfer <= tolerance and len(first) < 3 and all(o.topology.key != c.topology.key for o in first):
                first.append(c)
        order = first + [c for c in cands if all(c is not o for o in first)]
    out: list[CurveCandidate] = []
    for c in order:
        if len(out) >= top:
            break
        if any(_same(o, c) for o in out):
            continue
        verify(c)
        if _answer(c):
            out.append(c)
        else:
            notes.append(f"{c.topology.key}: dropped, {c.verification}")
    for c in sorted(cands, key=lambda c: c.chamfer):   # the most accurate that verifies
        if any(c is o for o in out) or (out and c.chamfer >= min(o.chamfer for o in out)):
            break
        verify(c)
        if _answer(c):
            out.append(c)
            break
        notes.append(f"{c.topology.key}: dropped, {c.verification}")
    for c in out:
        c.role = ""
    if out:
        best = min(out, key=lambda c: c.chamfer)
        simple = [c for c in out if c.chamfer <= tolerance]
        if prefer == "simple" and simple:
            simple[0].role = SIMPLEST
        best.role = f"{best.role} and {MOST_ACCURATE}" if best.role else MOST_ACCURATE
    return out


def _answer(c: CurveCandidate) -> bool:
    """Checked by ``simulate``, or not checked for want of time (labelled)."""
    return c.verified or c.verification == UNCHECKED


def nearest_miss(misses: list[CurveCandidate], bounds: Bounds, verify, notes: list[str]) -> CurveCandidate | None:
    """The design found closest to the bounds (then the most accurate), verified."""
    def key(c):
        e = bounds.excess(np.array([c.size]), np.array([c.link_length_ratio]), np.array([c.min_transmission_angle]))
        return (float(e.sum()), c.chamfer)

    for c in sorted(misses, key=key):
        verify(c)
        if _answer(c):
            return c
    notes.append("no design assembled over its input range was found")
    return None


def miss_reason(c: CurveCandidate, bounds: Bounds) -> str:
    """``no candidate within the bounds; nearest miss: ...`` with the options that lift them."""
    out = []
    if bounds.radius is not None and c.size > bounds.radius * (1 + 1e-9):
        out.append(f"size {c.size_ratio:.2f} diagonals > {bounds.radius / bounds.unit:g} (--max-size)")
    if bounds.link_ratio is not None and c.link_length_ratio > bounds.link_ratio * (1 + 1e-9):
        out.append(f"link ratio {c.link_length_ratio:.1f} > {bounds.link_ratio:g} (--max-link-ratio)")
    if c.min_transmission_angle < bounds.transmission:
        out.append(f"transmission angle {c.min_transmission_angle:.1f}° < {bounds.transmission:g}° "
                   "(--min-transmission-angle)")
    if not out:
        out.append("frame pivots outside the ground region (--ground-region)")
    return (f"no candidate within the bounds; nearest miss: {c.topology.label}, error {100 * c.chamfer:.2f} %, "
            + ", ".join(out) + "; lift the bound named to accept it")
