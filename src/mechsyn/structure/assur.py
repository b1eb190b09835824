"""Assur group decomposition of planar mechanisms (Assur 1914; Artobolevsky's classes).

A planar mechanism of mobility ``W`` is formed from ``W`` initial mechanisms (class I:
the frame and one input link jointed to it by a driven pair) by attaching, one after
another, *Assur groups*: sets of ``k`` moving links with ``p`` lower pairs (joints among
themselves and to links already formed) and zero mobility, ``3 k - 2 p = 0``, that
contain no smaller such set.

Decomposition (constructive, unique up to the order of independent groups): start from
the frame; repeatedly take the smallest set ``S`` of links not yet formed whose pairs to
``S`` and to the formed links weigh ``3 |S|``, each lower pair weighing 2 (its two
constraints) and a driven pair 3 (it fixes the relative motion). A one-link set with a
driven pair to the frame is an initial mechanism I(frame, input).

Class and order (Artobolevsky): the *order* of a group is the number of its external
pairs (its leashes' pairs to the links formed before); its *class* is the number of
pairs of the largest closed contour formed by its internal pairs, or, without such a
contour, the largest number of internal pairs on one link (a triad's base link: III); a
dyad is class II. The mechanism's class is the highest class of its groups.

Higher pairs (cam, gear, point or line contact) are replaced by their lower-pair
equivalent (a binary link with two lower pairs), and the result says so.

When fewer pairs are driven than the mobility ``W`` (an underactuated finger of paper 000),
the missing inputs are *imaginary input links*: links jointed to the frame chosen so
that the rest decomposes into groups (paper 000, step 5). Paper 000 turns the binary
imaginary input links and the binary links of class II groups that are neither output
nor frame links into ternary links to obtain free leashes: :attr:`leash_candidates`.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import networkx as nx

from mechsyn.errors import MechsynInputError

__all__ = ["AssurGroup", "AssurDecomposition", "assur_decomposition", "group_class"]

ROMAN = {1: "I", 2: "II", 3: "III", 4: "IV", 5: "V", 6: "VI", 7: "VII", 8: "VIII",
         9: "IX", 10: "X"}


def roman(k: int) -> str:
    return ROMAN.get(k, str(k))


@dataclass(frozen=True)
class _Pair:
    id: str
    a: str
    b: str
    weight: int  # 2: lower pair, 3: driven lower pair


@dataclass(frozen=True)
class AssurGroup:
    """An initial mechanism (``group_class`` 1) or an Assur group."""

    links: tuple[str, ...]
    internal_pairs: tuple[str, ...]
    external_pairs: tuple[str, ...]
    group_class: int
    order: int
    attached_to: tuple[str, ...]
    imaginary_input: bool = False
    redundant_constraints: int = 0

    @property
    def label(self) -> str:
        base = roman(self.group_class)
        inner = self.attached_to + self.links if self.group_class == 1 else self.links
        return f"{base}({','.join(inner)})"

    def to_dict(self) -> dict:
        return {
            "class": self.group_class,
            "class_roman": roman(self.group_class),
            "order": self.order,
            "links": list(self.links),
            "internal_pairs": list(self.internal_pairs),
            "external_pairs": list(self.external_pairs),
            "attached_to": list(self.attached_to),
            "imaginary_input": self.imaginary_input,
            "redundant_constraints": self.redundant_constraints,
            "label": self.label,
        }


@dataclass(frozen=True)
class AssurDecomposition:
    """The structure of a planar mechanism: inputs, Assur groups, class, formula."""

    name: str
    frame: str
    mobility: int
    input_links: tuple[str, ...]
    imaginary_input_links: tuple[str, ...]
    output_links: tuple[str, ...]
    groups: tuple[AssurGroup, ...]
    mechanism_class: int
    structural_formula: str
    leash_candidates: tuple[str, ...]
    replaced_higher_pairs: tuple[str, ...] = ()
    notes: tuple[str, ...] = field(default=())

    def to_dict(self) -> dict:
        return {
            "name": self.name,
            "frame": self.frame,
            "mobility": self.mobility,
            "input_links": list(self.input_links),
            "imaginary_input_links": list(self.imaginary_input_links),
            "output_links": list(self.output_links),
            "groups": [g.to_dict() for g in self.groups if g.group_class >= 2],
            "initial_mechanisms": [g.to_dict() for g in self.groups if g.group_class == 1],
            "mechanism_class": self.mechanism_class,
            "mechanism_class_roman": roman(self.mechanism_class),
            "structural_formula": self.structural_formula,
            "leash_candidates": list(self.leash_candidates),
            "replaced_higher_pairs": list(self.replaced_higher_pairs),
            "notes": list(self.notes),
        }


def group_class(links: tuple[str, ...], internal: list[tuple[str, str]]) -> int:
    """Artobolevsky's class of a group from its internal pairs (see module doc)."""
    if len(links) == 1:
        return 1
    g = nx.MultiGraph()
    g.add_nodes_from(links)
    g.add_edges_from(internal)
    longest = 0
    simple = nx.Graph(g)
    if simple.number_of_edges() >= simple.number_of_nodes():
        for cycle in nx.simple_cycles(simple):
            longest = max(longest, len(cycle))
    most = max((d for _, d in g.degree()), default=0)
    return max(2, longest, most if most >= 3 else 2)


def _pairs_of(mech) -> tuple[list[str], list[_Pair], list[str]]:
    """Moving links (with virtual links for higher pairs) and the lower pairs."""
    links = list(mech.moving_links)
    pairs: list[_Pair] = []
    replaced: list[str] = []
    for j in mech.joints:
        a, b = j.links
        if j.is_higher:
            virtual = f"~{j.id}"
            links.append(virtual)
            pairs.append(_Pair(f"{j.id}.1", a, virtual, 2))
            pairs.append(_Pair(f"{j.id}.2", virtual, b, 2))
            replaced.append(f"{j.id} ({j.type} between {a} and {b}) -> binary link "
                            f"{virtual} with two lower pairs {j.id}.1, {j.id}.2")
        else:
            pairs.append(_Pair(j.id, a, b, 3 if j.actuated else 2))
    return links, pairs, replaced


def _decompose(frame: str, links: list[str], pairs: list[_Pair], max_group: int):
    """Constructive decomposition; None when some links form no group."""
    formed = {frame}
    remaining = list(links)
    groups: list[tuple[tuple[str, ...], int, int]] = []  # (links, weight, 3k)
    while remaining:
        found = None
        for k in range(1, min(len(remaining), max_group) + 1):
            for subset in itertools.combinations(remaining, k):
                s = set(subset)
                allowed = s | formed
                weight = sum(p.weight for p in pairs
                             if (p.a in s or p.b in s) and p.a in allowed and p.b in allowed)
                if weight >= 3 * k:
                    found = (subset, weight)
                    break
            if found:
                break
        if not found:
            return None
        subset, weight = found
        groups.append((subset, weight, 3 * len(subset)))
        formed |= set(subset)
        remaining = [x for x in remaining if x not in formed]
    return groups


def assur_decomposition(
    mech,
    output_links: tuple[str, ...] | list[str] | None = None,
    max_group: int = 10,
) -> AssurDecomposition:
    """Decompose a planar mechanism into initial mechanisms and Assur groups.

    ``output_links``: the links whose motion is the mechanism's purpose (default: the
    links carrying the file's named points). Raises :class:`MechsynInputError` for a
    spatial mechanism, or when no choice of inputs decomposes it (e.g. redundant
    constraints making the mobility differ from Chebyshev's).

    Examples
    --------
    >>> import mechsyn as ms
    >>> d = assur_decomposition(ms.examples.load("fourbar"))
    >>> d.structural_formula, d.mechanism_class
    ('I(frame,crank) -> II(coupler,rocker)', 2)
    """
    if mech.kind != "planar":
        raise MechsynInputError(
            "Assur groups are defined here for planar mechanisms only",
            source=mech.name, field="kind", hint="give a planar mechanism file")
    frame = mech.ground
    links, pairs, replaced = _pairs_of(mech)
    if output_links is None:
        output_links = tuple(dict.fromkeys(p.link for p in mech.points.values()))
    output_links = tuple(output_links)
    w = _mobility(mech, pairs, output_links)
    choice, result, trial = _best_inputs(mech, frame, links, pairs, w, output_links, max_group)
    groups, inputs, imaginary_links, notes = _groups_of(frame, result, trial, {p.id for p in choice})
    return AssurDecomposition(
        name=mech.name, frame=frame, mobility=w, input_links=tuple(inputs),
        imaginary_input_links=tuple(imaginary_links), output_links=output_links,
        groups=tuple(groups), mechanism_class=max(g.group_class for g in groups),
        structural_formula=" -> ".join(g.label for g in groups),
        leash_candidates=tuple(_leash_candidates(mech, groups, output_links)),
        replaced_higher_pairs=tuple(replaced), notes=tuple(notes),
    )


def _mobility(mech, pairs: list[_Pair], output_links: tuple[str, ...]) -> int:
    """Chebyshev's W, refused when it is no mechanism's or below the driven pairs; the
    output links must be the file's."""
    p5 = sum(1 for j in mech.joints if not j.is_higher)
    p4 = sum(1 for j in mech.joints if j.is_higher)
    w = 3 * mech.n_moving - 2 * p5 - p4
    for o in output_links:
        if o not in mech.link_names:
            raise MechsynInputError(f"unknown output link {o!r}", field="output",
                                    hint="name a link of the file")
    driven = [p for p in pairs if p.weight == 3]
    if w <= 0:
        raise MechsynInputError(
            f"mobility W = 3·{mech.n_moving} - 2·{p5} - {p4} = {w}: a structure, not a "
            "mechanism", source=mech.name)
    if len(driven) > w:
        raise MechsynInputError(
            f"{len(driven)} driven pairs for mobility {w}", source=mech.name,
            hint="mark at most W joints actuated")
    return w


def _best_inputs(mech, frame: str, links, pairs: list[_Pair], w: int, output_links: tuple[str, ...],
                 max_group: int) -> tuple[tuple[_Pair, ...], list, list[_Pair]]:
    """The imaginary inputs (undriven lower pairs, those to the frame and away from the
    outputs preferred) giving the lowest-class decomposition: (choice, groups, pairs)."""
    driven = [p for p in pairs if p.weight == 3]
    candidates = [p for p in pairs if p.weight == 2 and not p.id.count(".")]

    def score(choice):
        moved = [p.b if p.a == frame else p.a for p in choice]
        return (sum(frame not in (p.a, p.b) for p in choice),
                sum(link in output_links for link in moved), [p.id for p in choice])

    best = None
    combos = sorted(itertools.combinations(candidates, w - len(driven)), key=score)
    for choice in combos:
        ids = {p.id for p in choice}
        trial = [_Pair(p.id, p.a, p.b, 3) if p.id in ids else p for p in pairs]
        result = _decompose(frame, links, trial, max_group)
        if result is None:
            continue
        top = max((_class_of(g, trial) for g, _, _ in result), default=1)
        key = (top, score(choice))
        if best is None or key < best[0]:
            best = (key, choice, result, trial)
            if top <= 2 and key[1][0] == 0:
                break
    if best is None:
        raise MechsynInputError(
            "the mechanism does not decompose into Assur groups for any choice of "
            f"{w - len(driven)} imaginary input(s)",
            source=mech.name,
            hint="check the actuated joints and that the mobility W is the real one")
    return best[1], best[2], best[3]


def _groups_of(frame: str, result: list, trial: list[_Pair],
               imaginary_ids: set[str]) -> tuple[list[AssurGroup], list[str], list[str], list[str]]:
    """The groups in the order they are formed, the input links, the imaginary ones and notes."""
    groups: list[AssurGroup] = []
    inputs: list[str] = []
    imaginary_links: list[str] = []
    notes: list[str] = []
    formed = {frame}
    for subset, weight, need in result:
        s = set(subset)
        internal = [p for p in trial if p.a in s and p.b in s]
        external = [p for p in trial if (p.a in s) != (p.b in s)
                    and (p.a in formed or p.b in formed)]
        attached = tuple(dict.fromkeys(p.a if p.a not in s else p.b for p in external))
        cls = group_class(subset, [(p.a, p.b) for p in internal])
        imaginary = bool(cls == 1 and any(p.id in imaginary_ids for p in external))
        if cls == 1:
            inputs.append(subset[0])
            if imaginary:
                imaginary_links.append(subset[0])
        groups.append(AssurGroup(
            links=tuple(subset), internal_pairs=tuple(p.id for p in internal),
            external_pairs=tuple(p.id for p in external), group_class=cls,
            order=len(external), attached_to=attached, imaginary_input=imaginary,
            redundant_constraints=weight - need,
        ))
        if weight > need:
            notes.append(f"group {','.join(subset)} has {weight - need} redundant "
                         "constraint(s)")
        formed |= s
    if imaginary_links:
        notes.append("imaginary input link(s) (mobility 1, no actuator of their own; "
                     f"paper 000 step 5): {', '.join(imaginary_links)}")
    return groups, inputs, imaginary_links, notes


def _leash_candidates(mech, groups: list[AssurGroup], output_links: tuple[str, ...]) -> list[str]:
    """Binary links of class 1 (imaginary) and 2 groups that are not outputs."""
    degree = {name: 0 for name in mech.link_names}
    for j in mech.joints:
        for x in j.links:
            degree[x] += 1
    out: list[str] = []
    for g in groups:
        if g.group_class == 1 and not g.imaginary_input:
            continue
        if g.group_class not in (1, 2):
            continue
        for link in g.links:
            if (link in mech.link_names and degree[link] == 2 and link not in output_links
                    and link != mech.ground):
                out.append(link)
    return out


def _class_of(subset, pairs) -> int:
    s = set(subset)
    internal = [(p.a, p.b) for p in pairs if p.a in s and p.b in s]
    return group_class(tuple(subset), internal)
