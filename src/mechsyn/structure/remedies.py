"""Remedies: pair-class changes that remove redundant constraints and idle mobilities.

Paper 003: a redundant contour constraint is removed by LOWERING the class of a pair of
that contour, an idle mobility by RAISING one. Each contour's count changes only through
its own new pairs (sequential reading), so per contour we need class changes ``Δi`` of its
new pairs with ``Σ Δi = -S_j`` (lowering is negative ``Δi``); lower pairs stay lower
(classes 3..5) and higher pairs stay higher (classes 1..2). Since
``W = 6n - Σ i·p_i + S_Σ + G_Σ`` and every unit of class removed from contour ``j`` also
removes one from ``S_j``, the mobility ``W`` is unchanged; each variant is re-analysed to
confirm it.

Variants are listed fewest changed pairs first, then smallest total class change.

References
----------
.. [1] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

import heapq
import itertools
from dataclasses import dataclass
from typing import Any

from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.model.pairs import PAIR_KINDS, suggest_type
from mechsyn.structure.analysis import StructuralAnalysis, analyze_structure
from mechsyn.structure.contours import independent_contours


@dataclass(frozen=True)
class PairChange:
    """One pair's change: ``joint`` from (type, class) to (type, class)."""

    joint: str
    contour: int
    old_type: str
    old_class: int
    new_type: str
    new_class: int

    def describe(self) -> str:
        verb = "lower" if self.new_class < self.old_class else "raise"
        return (f"{self.joint}: {verb} {self.old_type}{self.old_class} -> "
                f"{self.new_type}{self.new_class} ({PAIR_KINDS[self.new_type].title})")


@dataclass(frozen=True)
class Remedy:
    """A variant of the mechanism with its changed pairs and its new per-contour numbers."""

    changes: list[PairChange]
    analysis: StructuralAnalysis
    mechanism: Mechanism

    @property
    def n_changes(self) -> int:
        return len(self.changes)

    def to_dict(self) -> dict[str, Any]:
        a = self.analysis
        return {
            "changes": [
                {"joint": c.joint, "contour": c.contour, "from": {"type": c.old_type, "class": c.old_class},
                 "to": {"type": c.new_type, "class": c.new_class}, "text": c.describe()}
                for c in self.changes
            ],
            "pairs_by_class": {str(k): v for k, v in a.pairs_by_class.items()},
            "contours": [{"index": r.index, "S": r.S, "T": r.T, "Z": r.Z, "S_expression": r.S_expression}
                         for r in a.contours],
            "structural_redundancy": a.structural_redundancy,
            "mobility": a.mobility,
            "mobility_expression": a.formulas["somov_malyshev"].expression,
            "degrees_of_mobility": a.degrees_of_mobility,
            "metric_constraints_left": a.metric_constraints,
        }


def _class_range(j: Joint, kind: str) -> range:
    if kind == "planar":
        return range(j.pair_class, j.pair_class + 1)  # planar classes are fixed (5 lower, 4 higher)
    return range(1, 3) if j.is_higher else range(3, 6)


def contour_options(joints: list[Joint], need: int, kind: str, max_changes: int) -> list[dict[str, int]]:
    """Class assignments ``{joint id: new class}`` of ``joints`` with ``Σ (new - old) = need``.

    Only assignments that change at most ``max_changes`` pairs; sorted by the number of
    changed pairs, the total change, then leaving driven pairs and lower pairs alone.
    """
    if need == 0:
        return [{}]
    options: list[tuple[tuple[int, int, int, int], dict[str, int]]] = []
    for k in range(1, min(max_changes, len(joints)) + 1):
        for subset in itertools.combinations(joints, k):
            ranges = [[c for c in _class_range(j, kind) if c != j.pair_class] for j in subset]
            for classes in itertools.product(*ranges):
                delta = sum(c - j.pair_class for c, j in zip(classes, subset))
                if delta == need:
                    total = sum(abs(c - j.pair_class) for c, j in zip(classes, subset))
                    drives = sum(j.actuated for j in subset)
                    lower = sum(not j.is_higher for j in subset)
                    options.append(((k, total, drives, lower), {j.id: c for j, c in zip(subset, classes)}))
        if options and k >= 1 and len(options) > 64:
            break
    # fewest changed pairs, smallest change, drives left alone, higher pairs changed first
    options.sort(key=lambda o: o[0])
    return [o[1] for o in options]


def find_remedies(mech: Mechanism, max_variants: int = 10, max_changes_per_contour: int = 3) -> list[Remedy]:
    """Variants that bring every contour's ``S_j`` to zero by changing pair classes (paper 003).

    Spatial mechanisms only (a planar mechanism's pairs have fixed planar classes; see the
    rank analysis for treating it as spatial). Returns at most ``max_variants`` variants,
    fewest changed pairs first; each is re-analysed and kept only if its mobility equals
    the original's and all its ``S_j`` are zero.

    Examples
    --------
    >>> import mechsyn as ms
    >>> rem = ms.find_remedies(ms.examples.load("gripper_003"), max_variants=3)
    >>> len(rem) > 0 and all(x.analysis.structural_redundancy == 0 for x in rem)
    True
    """
    base = analyze_structure(mech, _with_states=False)
    if mech.kind == "planar":
        return []
    contours, _ = independent_contours(mech)
    joints = {j.id: j for j in mech.joints}
    per_contour: list[list[dict[str, int]]] = []
    for row in base.contours:
        new = [joints[p.id] for p in row.new_pairs]
        # S_j = 3 - Σ(m - i): lowering i by 1 lowers S_j by 1, so Σ Δi must equal -S_j.
        opts = contour_options(new, -row.S, mech.kind, max_changes_per_contour)
        if not opts:
            return []
        per_contour.append(opts)
    # best combinations first: a heap over index vectors (lazy product)
    def cost(idx: tuple[int, ...]) -> tuple[int, int]:
        chosen = [per_contour[c][i] for c, i in enumerate(idx)]
        n = sum(len(o) for o in chosen)
        tot = sum(abs(v - joints[j].pair_class) for o in chosen for j, v in o.items())
        return n, tot, sum(idx)

    start = tuple(0 for _ in per_contour)
    heap = [(cost(start), start)]
    seen = {start}
    results: list[Remedy] = []
    while heap and len(results) < max_variants:
        _, idx = heapq.heappop(heap)
        changes: dict[str, tuple[int, int]] = {}
        for c, i in enumerate(idx):
            for jid, cls in per_contour[c][i].items():
                changes[jid] = (cls, c + 1)
        if changes:
            new_joints = tuple(
                j.with_class(changes[j.id][0], suggest_type(j.type, changes[j.id][0], j.is_higher))
                if j.id in changes else j for j in mech.joints
            )
            variant = mech.with_joints(new_joints, name=f"{mech.name} (remedy {len(results) + 1})")
            va = analyze_structure(variant, _with_states=False)
            if va.mobility == base.mobility and all(r.S == 0 for r in va.contours):
                pcs = [PairChange(jid, contour, joints[jid].type, joints[jid].pair_class,
                                  suggest_type(joints[jid].type, cls, joints[jid].is_higher), cls)
                       for jid, (cls, contour) in changes.items()]
                pcs.sort(key=lambda p: (p.contour, [j.id for j in mech.joints].index(p.joint)))
                results.append(Remedy(changes=pcs, analysis=va, mechanism=variant))
        for c in range(len(idx)):
            if idx[c] + 1 < len(per_contour[c]):
                nxt = idx[:c] + (idx[c] + 1,) + idx[c + 1:]
                if nxt not in seen:
                    seen.add(nxt)
                    heapq.heappush(heap, (cost(nxt), nxt))
    return results
