"""Structural analysis of a mechanism by the papers' formulas (papers 002 and 003).

:func:`analyze_structure` computes Chebyshev's, Grübler's, Malyshev's, Somov-Malyshev's,
Gokhman's and Ozol's formulas, paper 003's per-contour table (redundant contour
constraints ``S_j``, idle mobilities, redundant links ``Z_j``, metric constraints ``T_j``,
``A_j`` and the number of degrees of mobility ``H``) and, for each state of a
variable-structure mechanism, the same analysis plus paper 002's external constraints.

Per-contour rules (paper 003), contours taken in order; a pair or a link counts in the
first contour that contains it (the *sequential reading*):

- ``S_j = 3 - Σ_new pairs (m - i)``, ``m = 5`` lower, ``4`` higher pair; ``S_j < 0``
  means ``|S_j|`` idle mobilities.
- ``Z_j = Σ_new pairs (5 - m)`` for contours of three or more moving links, else 0.
- ``T_j`` (only when every pair of the contour has class 3..5): one contour:
  ``T = 0.5·((2.5 - n_j)/|2.5 - n_j| + 1)``; several:
  ``T_j = 0.25·(1 - (n_j - 3.5)/|n_j - 3.5|)·((1.5 - n_k)/|1.5 - n_k| + 1)``.
- ``S_Σ = Σ S_j``, ``G_Σ = Σ T_j + Σ Z_j``, ``W = 6n - Σ i·p_i + S_Σ + G_Σ``.
- ``H = n - Σ A_j``: several contours ``A_j = 2`` if ``n_k >= 2``, ``1`` if ``n_k = 1``;
  one contour ``A = 2`` if ``n_j >= 3`` else 1.

References
----------
.. [1] "Rational structural synthesis of schemes of crank-slider mechanisms of gripping
   devices" (in Ukrainian, with an English abstract) ("paper 002"; see docs/references.md).
.. [2] O. D. Egorov and M. A. Buynov, "Structural analysis of the mechanisms of the
   mechatronic and robotic devices" (in Russian), *Mekhatronika, Avtomatizatsiya,
   Upravlenie*, 17(4), 239-244, 2016. doi:10.17587/mau.17.239-244 ("paper 003").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from mechsyn.model.contour import contour_links
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.structure import formulas as F
from mechsyn.structure.contours import cycle_rank, independent_contours
from mechsyn.structure.external import ExternalAnalysis, external_analysis


@dataclass(frozen=True)
class PairCount:
    """A pair as it enters a contour's count: id, type, class ``i`` and ``m``."""

    id: str
    type: str
    pair_class: int
    m: int


@dataclass(frozen=True)
class ContourAnalysis:
    """One row of paper 003's per-contour table."""

    index: int
    joints: list[str]
    links: list[str]
    new_pairs: list[PairCount]
    new_links: list[str]
    S: int
    T: float
    Z: int
    A: int
    n_j: int
    n_k: int
    n_exclusive: int
    A_exclusive: int
    idle_mobilities: int
    redundant_constraints: int
    S_expression: str
    T_expression: str
    from_file: bool

    def to_dict(self) -> dict[str, Any]:
        return {
            "index": self.index, "joints": self.joints, "links": self.links,
            "new_pairs": [{"id": p.id, "type": p.type, "class": p.pair_class, "m": p.m} for p in self.new_pairs],
            "new_links": self.new_links, "S": self.S, "T": _num(self.T), "Z": self.Z, "A": self.A,
            "n_j": self.n_j, "n_k": self.n_k, "n_exclusive": self.n_exclusive,
            "A_exclusive": self.A_exclusive, "idle_mobilities": self.idle_mobilities,
            "redundant_constraints": self.redundant_constraints, "S_expression": self.S_expression,
            "T_expression": self.T_expression, "from_file": self.from_file,
        }


def _num(x: float) -> float | int:
    return int(x) if float(x).is_integer() else x


@dataclass(frozen=True)
class StructuralAnalysis:
    """Everything the papers' formulas say about a mechanism (one state)."""

    name: str
    kind: str
    moving_links: int
    moving_link_names: list[str]
    links_with_frame: int
    pairs: int
    pairs_by_class: dict[int, int]
    independent_contours: int
    formulas: dict[str, F.Formula]
    contours: list[ContourAnalysis]
    contours_chosen_by_program: bool
    structural_redundancy: int
    redundant_constraints: int
    idle_mobilities: int
    metric_constraints: float
    redundant_links: int
    constructive_redundancy: float
    degrees_of_mobility: int
    degrees_of_mobility_exclusive: int
    degrees_of_mobility_expression: str
    mobility: int | float
    mobility_source: str
    declared_mobility: int | None
    actuated: list[str]
    notes: list[str] = field(default_factory=list)
    external: ExternalAnalysis | None = None
    states: dict[str, "StructuralAnalysis"] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {
            "name": self.name, "kind": self.kind,
            "moving_links": self.moving_links, "moving_link_names": self.moving_link_names,
            "links_with_frame": self.links_with_frame, "pairs": self.pairs,
            "pairs_by_class": {str(k): v for k, v in self.pairs_by_class.items()},
            "independent_contours": self.independent_contours,
            "formulas": {k: {"value": _num(v.value) if v.value is not None else None,
                             "expression": v.expression} for k, v in self.formulas.items()},
            "contours": [c.to_dict() for c in self.contours],
            "contours_chosen_by_program": self.contours_chosen_by_program,
            "structural_redundancy": self.structural_redundancy,
            "redundant_constraints": self.redundant_constraints,
            "idle_mobilities": self.idle_mobilities,
            "metric_constraints": _num(self.metric_constraints),
            "redundant_links": self.redundant_links,
            "constructive_redundancy": _num(self.constructive_redundancy),
            "degrees_of_mobility": self.degrees_of_mobility,
            "degrees_of_mobility_exclusive": self.degrees_of_mobility_exclusive,
            "degrees_of_mobility_expression": self.degrees_of_mobility_expression,
            "mobility": _num(self.mobility), "mobility_source": self.mobility_source,
            "declared_mobility": self.declared_mobility,
            "actuated": self.actuated, "drives_declared": len(self.actuated),
            "notes": self.notes,
        }
        if self.external is not None:
            e = self.external
            d["external"] = {
                "S_a": e.S_a, "W_f": e.W_f, "W_rob": e.W_rob, "W_a": e.W_a, "S_ai": e.S_ai,
                "S_i": e.S_i, "S": e.S, "N": e.N,
                "external_redundant": {"value": e.external_redundant.value,
                                       "expression": e.external_redundant.expression},
                "system_redundant": {"value": e.system_redundant.value,
                                     "expression": e.system_redundant.expression},
            }
        d["states"] = {k: v.to_dict() for k, v in self.states.items()}
        return d


def _sign(x: float) -> float:
    return 1.0 if x > 0 else -1.0


def metric_constraint(n_j: int, n_k: int, several: bool) -> tuple[float, str]:
    """Paper 003's ``T_j`` and its substituted expression (pairs of classes 3..5 assumed)."""
    if not several:
        t = 0.5 * (_sign(2.5 - n_j) + 1)
        return t, f"T = 0.5·(({2.5:g} - {n_j})/|2.5 - {n_j}| + 1) = {_num(t)}"
    a = 1 - _sign(n_j - 3.5)
    b = _sign(1.5 - n_k) + 1
    t = 0.25 * a * b
    return t, f"T = 0.25·({_num(a)})·({_num(b)}) = {_num(t)}"


def _s_expression(index: int, new_pairs: list[PairCount], s: int) -> str:
    groups: dict[tuple[int, int], int] = {}
    for p in new_pairs:
        groups[(p.m, p.pair_class)] = groups.get((p.m, p.pair_class), 0) + 1
    terms = sorted(groups.items(), key=lambda kv: (-(kv[0][0] - kv[0][1]), -kv[0][0]))
    body = "".join(f" - ({m}-{i})·{c}" for (m, i), c in terms)
    return f"S{index} = 3{body} = {s}"


def contour_table(mech: Mechanism, contours: list[tuple[str, ...]], from_file: list[bool]) -> list[ContourAnalysis]:
    """Paper 003's per-contour rows for ``contours`` in order (sequential reading)."""
    joints = {j.id: j for j in mech.joints}
    several = len(contours) > 1
    counted_pairs: set[str] = set()
    counted_links: set[str] = set()
    link_sets = []
    for c in contours:
        links = contour_links([joints[j] for j in c]) or []
        link_sets.append([lk for lk in links if lk != mech.ground])
    rows = []
    for idx, (c, moving) in enumerate(zip(contours, link_sets), start=1):
        new = [joints[j] for j in c if j not in counted_pairs]
        counted_pairs.update(c)
        new_links = [lk for lk in moving if lk not in counted_links]
        counted_links.update(moving)
        others = set().union(*(set(s) for k, s in enumerate(link_sets) if k != idx - 1)) if several else set()
        exclusive = [lk for lk in moving if lk not in others]
        pcs = [PairCount(j.id, j.type, j.pair_class, j.m) for j in new]
        s = 3 - sum(p.m - p.pair_class for p in pcs)
        n_j, n_k = len(moving), len(new_links)
        z = sum(5 - p.m for p in pcs) if n_j >= 3 else 0
        all_classes = [joints[j].pair_class for j in c]
        if all(3 <= i <= 5 for i in all_classes):
            t, t_expr = metric_constraint(n_j, n_k, several)
        else:
            t, t_expr = 0.0, "T = 0 (the contour has a class-1 or class-2 pair)"
        if several:
            a = min(n_k, 2)
            a_ex = min(len(exclusive), 2)
        else:
            a = a_ex = 2 if n_j >= 3 else (1 if n_j >= 1 else 0)
        rows.append(ContourAnalysis(
            index=idx, joints=list(c), links=contour_links([joints[j] for j in c]) or [],
            new_pairs=pcs, new_links=new_links, S=s, T=t, Z=z, A=a, n_j=n_j, n_k=n_k,
            n_exclusive=len(exclusive), A_exclusive=a_ex, idle_mobilities=max(0, -s),
            redundant_constraints=max(0, s), S_expression=_s_expression(idx, pcs, s),
            T_expression=t_expr, from_file=from_file[idx - 1],
        ))
    return rows


def _freedom(j: Joint, planar: bool) -> int:
    if planar:
        return 2 if j.is_higher else 1
    return j.freedom


def analyze_structure(mech: Mechanism, _with_states: bool = True) -> StructuralAnalysis:
    """Structural analysis of ``mech`` by the formulas of papers 002 and 003.

    Returns a :class:`StructuralAnalysis`; each state of a variable-structure mechanism
    is analysed separately (``states``), with paper 002's external constraints where the
    state declares them.

    Examples
    --------
    >>> import mechsyn as ms
    >>> a = ms.analyze_structure(ms.examples.load("fourbar"))
    >>> a.formulas["chebyshev"].expression
    'W = 3·3 - 2·4 - 0 = 1'
    """
    n = mech.n_moving
    N = len(mech.links)
    planar = mech.kind == "planar"
    pbc = mech.pairs_by_class()
    K = cycle_rank(mech)
    contours, from_file = independent_contours(mech)
    rows = contour_table(mech, contours, from_file)
    s_sum, t_sum, z_sum = (sum(getattr(r, k) for r in rows) for k in ("S", "T", "Z"))
    g_sum = t_sum + z_sum
    forms = _mobility_formulas(mech, pbc, K, s_sum, g_sum)
    if planar:
        mobility, source = forms["chebyshev"].value, "Chebyshev's formula (planar reading)"
    else:
        mobility = forms["somov_malyshev"].value
        source = "Somov-Malyshev's formula with paper 003's contour counts (W = 6n - Σ i·p_i + S_Σ + G_Σ)"
    h, h_ex, h_expr = _degrees_of_mobility(n, K, rows)
    actuated = [j.id for j in mech.actuated_joints]
    notes = _notes(mech, forms, rows, from_file, K, h, h_ex, mobility)
    result = StructuralAnalysis(
        name=mech.name, kind=mech.kind, moving_links=n, moving_link_names=list(mech.moving_links),
        links_with_frame=N, pairs=len(mech.joints), pairs_by_class=pbc, independent_contours=K,
        formulas=forms, contours=rows, contours_chosen_by_program=not all(from_file),
        structural_redundancy=s_sum, redundant_constraints=sum(r.redundant_constraints for r in rows),
        idle_mobilities=sum(r.idle_mobilities for r in rows),
        metric_constraints=t_sum, redundant_links=z_sum, constructive_redundancy=g_sum,
        degrees_of_mobility=h, degrees_of_mobility_exclusive=h_ex, degrees_of_mobility_expression=h_expr,
        mobility=mobility, mobility_source=source, declared_mobility=mech.mobility, actuated=actuated,
        notes=notes,
    )
    if _with_states and mech.states:
        result = _replace(result, states=_state_analyses(mech, mobility))
    return result


def _mobility_formulas(mech: Mechanism, pbc: dict, K: int, s_sum: int, g_sum: float) -> dict[str, F.Formula]:
    """Every mobility and redundancy formula of papers 002 and 003, numbers substituted."""
    n, N, p_total = mech.n_moving, len(mech.links), len(mech.joints)
    planar = mech.kind == "planar"
    p4 = sum(1 for j in mech.joints if j.is_higher)
    p5 = p_total - p4
    forms: dict[str, F.Formula] = {}
    if planar:
        forms["chebyshev"] = F.chebyshev(n, p5, p4)
        forms["grubler"] = F.grubler(N, p5, p4)
    else:
        forms["chebyshev"] = F.Formula(None, "n/a: spatial mechanism")
        forms["grubler"] = F.Formula(None, "n/a: spatial mechanism")
    forms["malyshev"] = F.malyshev(n, pbc)
    forms["somov_malyshev"] = F.somov_malyshev(n, pbc, s_sum, g_sum)
    forms["gokhman_contours"] = F.gokhman(n, p_total)
    forms["scheme_check"] = F.scheme_check(N, K, p_total)
    w = _ozol_mobility(mech, forms)
    freedoms = [_freedom(j, planar) for j in mech.joints]
    forms["ozol_redundant"] = F.ozol(int(w), K, freedoms, planar=planar)
    forms["redundant_from_mobility"] = F.redundant_from_mobility(int(w), n, pbc, planar=planar)
    return forms


def _ozol_mobility(mech: Mechanism, forms: dict[str, F.Formula]) -> Any:
    """The W Ozol's formula uses: the file's declared mobility, else the formulas' own."""
    if mech.mobility is not None:
        return mech.mobility
    return forms["chebyshev" if mech.kind == "planar" else "somov_malyshev"].value


def _degrees_of_mobility(n: int, K: int, rows: list) -> tuple[int, int, str]:
    """Paper 003's degrees of mobility H, sequential and by exclusive links, and its expression."""
    if K > 1:
        h = n - sum(r.A for r in rows)
        h_ex = n - sum(r.A_exclusive for r in rows)
        return h, h_ex, f"H = {n} - ({' + '.join(str(r.A) for r in rows)}) = {h}"
    if K == 1:
        h = n - rows[0].A
        return h, h, f"H = {n} - {rows[0].A} = {h}"
    return n, n, f"H = {n} (no closed contour)"


def _notes(mech: Mechanism, forms: dict[str, F.Formula], rows: list, from_file: list[bool], K: int, h: int,
           h_ex: int, mobility: Any) -> list[str]:
    """What the numbers mean where readings differ or the file leaves a choice to the program."""
    notes: list[str] = []
    if mech.mobility is not None:
        notes.append(f"W = {mech.mobility} as declared in the file is used by Ozol's formula and "
                     f"Somov-Malyshev solved for S.")
    if h != h_ex:
        notes.append(
            f"degrees of mobility: the sequential reading of A_j gives H = {h}, the reading by links "
            f"that belong to one contour only gives H = {h_ex}; paper 003's rule is ambiguous here, "
            f"the rank method (from the geometry) gives the number of drives exactly."
        )
    if K > 1:
        notes.append("n_k and the pairs of a contour follow the sequential reading: only links and pairs "
                     "not already counted in an earlier contour.")
    if any(not f for f in from_file):
        chosen = [i + 1 for i, f in enumerate(from_file) if not f]
        notes.append(f"contour{'s' if len(chosen) > 1 else ''} {', '.join(map(str, chosen))} chosen by the "
                     f"program (the file gives {'none' if not any(from_file) else 'fewer than K'}); "
                     f"per-contour results depend on the contours and their order: give `contours` to fix them.")
    idle = sum(r.idle_mobilities for r in rows)
    red = sum(r.redundant_constraints for r in rows)
    s_sum = sum(r.S for r in rows)
    if idle and red:
        notes.append(f"S_Σ = {s_sum} nets {red} redundant constraint{'s' if red != 1 else ''} against {idle} "
                     f"idle mobilit{'y' if idle == 1 else 'ies'}.")
    notes += _ozol_notes(mech, forms, rows)
    planar = mech.kind == "planar"
    if planar and forms["chebyshev"].value is not None and forms["chebyshev"].value <= 0 and K:
        notes.append(f"Chebyshev's W = {forms['chebyshev'].value}: a structure (no motion) unless the "
                     f"geometry is special (e.g. parallel links).")
    actuated = [j.id for j in mech.actuated_joints]
    if actuated and isinstance(mobility, (int, float)) and len(actuated) != h:
        notes.append(f"{len(actuated)} drive{'s' if len(actuated) != 1 else ''} declared ({', '.join(actuated)}); "
                     f"paper 003's rule gives H = {h}.")
    return notes


def _ozol_notes(mech: Mechanism, forms: dict[str, F.Formula], rows: list) -> list[str]:
    """Why Ozol's q and the per-contour S_Σ differ, when they do."""
    s_sum = sum(r.S for r in rows)
    g_sum = sum(r.T for r in rows) + sum(r.Z for r in rows)
    q = forms["ozol_redundant"].value
    if q == s_sum:
        return []
    if mech.mobility is not None:
        return [f"Ozol's q = {q} differs from the per-contour S_Σ = {s_sum}: q uses the declared "
                f"W = {mech.mobility} (idle mobilities included), the per-contour count nets idle "
                f"mobilities against redundant constraints."]
    planar = mech.kind == "planar"
    if q == s_sum + g_sum and not planar:
        return [f"Ozol's q = {q} = S_Σ + G_Σ = {s_sum} + {g_sum:g}: it also counts the metric "
                f"constraints and redundant links of paper 003 as redundant constraints."]
    if planar:
        return [f"Ozol's q = {q} is the planar reading (q = W + 3K - f); paper 003's per-contour "
                f"S_Σ = {s_sum} and G_Σ = {g_sum:g} are the spatial reading (each contour against "
                f"6 freedoms): they count different constraints and need not agree."]
    return [f"Ozol's q = {q} differs from S_Σ + G_Σ = {s_sum} + {g_sum:g} = {s_sum + g_sum:g}: "
            f"q counts every redundant constraint of the W it is given (W = {_ozol_mobility(mech, forms)}), "
            f"the per-contour S_j nets idle mobilities against redundant constraints."]


def _state_analyses(mech: Mechanism, mobility: Any) -> dict[str, StructuralAnalysis]:
    """Each state of a variable-structure mechanism, with paper 002's external constraints
    where the state declares them."""
    planar = mech.kind == "planar"
    states = {}
    for name, spec in mech.states.items():
        sub = analyze_structure(mech.in_state(name), _with_states=False)
        ext = None
        if spec.external is not None:
            e = spec.external
            s_a = e.S_a if e.S_a is not None else sum(
                (j.pair_class - 3 if planar else j.pair_class) for j in spec.add_joints)
            w_f = e.W_f if e.W_f is not None else int(mobility)
            s_i = sum((j.pair_class - 3 if planar else j.pair_class) for j in mech.joints)
            w_a = e.W_a if not planar else min(e.W_a, 3)
            ext = external_analysis(S_a=s_a, W_f=w_f, W_rob=e.W_rob, W_a=w_a, S_ai=e.S_ai,
                                    S_i=s_i, N=len(mech.links), lam=3 if planar else 6)
        states[name] = _with_external(sub, ext, spec.description)
    return states


def _replace(obj: StructuralAnalysis, **kw: Any) -> StructuralAnalysis:
    from dataclasses import replace

    return replace(obj, **kw)


def _with_external(sub: StructuralAnalysis, ext: ExternalAnalysis | None, description: str) -> StructuralAnalysis:
    notes = list(sub.notes)
    if description:
        notes.insert(0, description)
    return _replace(sub, external=ext, notes=notes)
