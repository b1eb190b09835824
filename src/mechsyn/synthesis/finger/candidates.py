"""Paper 000, structural synthesis of adaptive fingers: attachment of a group of links.

Steps (spec ``structural.md`` section 4, paper 000 steps 1-7):

1. ``W0 = 3 n - 2 P5 - P4`` of the base; the group has ``W_f = -(W0 - A)``; the admissible
   ``(n_f, P_f, m_f)`` are :func:`mechsyn.synthesis.finger.groups.group_table`'s rows that meet
   the conditions ``P_f >= 2 (W0 - 1) + (n_f - 1)`` and ``m_f >= m_0``.
2. The base is split into Assur groups (:func:`mechsyn.structure.assur.assur_decomposition`);
   its *leash sites* are the binary links that are neither input (actuated), output nor
   frame links, among them the imaginary input links, plus any imaginary input link with
   a single pair (e.g. the distal phalanx of a three-phalanx finger). Each site receives
   one new pair (binary -> ternary: a free leash). The frame takes the group's remaining
   leashes.
3. The group is a tree of ``n_f`` links (``n_f - 1`` internal pairs, so ``m_f = P_f -
   (n_f - 1)`` leashes, as in the paper). Every tree and every assignment of its leashes
   to the sites (each site used once, the rest to the frame) is tried: the different
   attachment orders of the paper.
4. A result is kept when it is a simple chain with every link in a closed contour, no
   rigid sub-chain (every closed contour stays movable: the complete subset test of
   :func:`mechsyn.synthesis.chains.rigid_subchain`), mobility ``A`` by Chebyshev's formula
   and a decomposition into Assur groups driven by the actuated pair(s) alone (fully
   actuated with the VLL locked). Results isomorphic as mechanisms (same frame, actuated
   and output links) are merged (nauty certificates with those links coloured).
5. VLL candidates: the binary links of the attached group. Freeing ``k`` of them (each
   becomes two links and a prismatic pair: ``+3 - 2``) gives the underactuated mobility
   ``A + k``.

One group is attached, or with ``separate`` the paper's alternative of ``W0 - A``
groups of ``W_f = -1`` each (``W0 - 1`` for one drive).

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict, mechanism_to_dict
from mechsyn.structure.assur import assur_decomposition
from mechsyn.synthesis import canonical
from mechsyn.synthesis.chains import rigid_subchain
from mechsyn.synthesis.finger.groups import group_table
from mechsyn.synthesis.mechanisms import instantaneous_mobility

__all__ = ["FingerResult", "FingerSynthesis", "synthesize_fingers"]


@dataclass(frozen=True)
class VLLCombination:
    """VLL freed together and the finger's mobility with them free (underactuated)."""

    links: tuple[str, ...]
    underactuated_mobility: int
    expression: str


@dataclass(frozen=True)
class FingerResult:
    """One finger: the base with a group attached."""

    number: int
    n_f: int
    P_f: int
    group_links: tuple[str, ...]
    groups: tuple[tuple[int, int], ...]  # (n_f, P_f) of each attached group
    group_pairs: tuple[tuple[str, str], ...]  # (a, b) link pairs of the group's joints
    attachments: dict[str, list[str]]  # base link -> group links jointed to it
    mobility_locked: int
    mobility_expression: str
    structural_formula: str
    mechanism_class: int
    vll_candidates: tuple[str, ...]
    vll_combinations: tuple[VLLCombination, ...]
    mechanism: dict  # mechanism file data
    certificate: str = ""
    file: str | None = None


@dataclass(frozen=True)
class FingerSynthesis:
    """Every distinct finger of :func:`synthesize_fingers`, with the base's figures."""

    base_name: str
    W0: int
    actuators: int
    W_f: int
    m_0: int
    leash_sites: tuple[str, ...]
    base_formula: str
    groups: list  # the admissible (n_f, P_f, m_f) rows
    results: list[FingerResult]
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """The synthesis as JSON-ready data (``mechsyn synth finger --json``)."""
        from dataclasses import asdict

        out = asdict(self)
        out["groups"] = [asdict(r) for r in self.groups]
        return out


def _trees(n: int) -> list[list[tuple[int, int]]]:
    """All labelled trees on ``n`` vertices (Pruefer sequences)."""
    if n == 1:
        return [[]]
    if n == 2:
        return [[(0, 1)]]
    out = []
    for seq in itertools.product(range(n), repeat=n - 2):
        degree = [1] * n
        for x in seq:
            degree[x] += 1
        edges = []
        for x in seq:
            leaf = min(i for i in range(n) if degree[i] == 1)
            edges.append((leaf, x))
            degree[leaf] -= 1
            degree[x] -= 1
        u, v = [i for i in range(n) if degree[i] == 1]
        edges.append((u, v))
        out.append(edges)
    return out


def _certificate(names: list[str], edges: list[tuple[str, str]], colours: list[set[str]]) -> bytes:
    index = {n: i for i, n in enumerate(names)}
    colour = [len(colours)] * len(names)  # uncoloured vertices: a class of their own
    for k, c in enumerate(colours):
        for n in c:
            colour[index[n]] = k
    return canonical.certificate(len(names), [(index[a], index[b]) for a, b in edges], colour)


def synthesize_fingers(
    mech, actuators: int = 1, max_links: int = 5, max_results: int = 200,
    separate: bool = False,
) -> FingerSynthesis:
    """Every distinct way to make the finger ``mech`` fully actuated by ``actuators`` drives
    by attaching one group of links to its free leashes (paper 000), with VLL candidates.

    Parameters
    ----------
    mech : Mechanism
        The base finger: planar, lower pairs only, mobility ``W0 > actuators``.
    actuators : int
        Drives ``A``.
    max_links : int
        Largest group ``n_f``.
    max_results : int
        Stop after this many distinct fingers (a note says so).
    separate : bool
        Attach ``W0 - A`` groups of ``W_f = -1`` each instead (``max_links`` then bounds
        their total number of links).

    Returns
    -------
    FingerSynthesis

    Examples
    --------
    >>> import mechsyn as ms
    >>> syn = ms.synthesize_fingers(ms.examples.load("two_phalanx_base_000"), actuators=1, max_links=4)
    >>> syn.W0, syn.W_f, len(syn.results) > 0
    (2, -1, True)
    """
    if mech.kind != "planar":
        raise MechsynInputError("paper 000's synthesis is for planar fingers", source=mech.name)
    if any(j.is_higher for j in mech.joints):
        raise MechsynInputError("the base must have lower pairs only", source=mech.name,
                                hint="replace cams or gears by their lower-pair equivalents")
    dec = assur_decomposition(mech)
    w0 = dec.mobility
    if w0 <= actuators:
        raise MechsynInputError(
            f"W0 = {w0} is not larger than the {actuators} drive(s): nothing to attach",
            field="actuators")
    table = group_table(w0, actuators, max_links)
    rows = [r for r in table.rows if r.meets_conditions]
    sites = _leash_sites(mech, dec)
    notes = [f"leash sites (one new pair each): {', '.join(sites) or 'none'}; "
             f"the frame {mech.ground} takes the group's other leashes",
             "one group attached (--separate: W0 - A groups of W_f = -1)"]
    if len(sites) < table.m_0:
        notes.append(f"the base offers {len(sites)} leash site(s), fewer than m_0 = {table.m_0}")
    plans: list[tuple] = [(row,) for row in rows]
    if separate and w0 - actuators >= 2:
        unit = list(group_table(actuators + 1, actuators, max_links).rows)
        plans = [plan for plan in itertools.combinations_with_replacement(unit, w0 - actuators)
                 if sum(r.n_f for r in plan) <= max_links]
        notes[1] = f"{w0 - actuators} separate groups of W_f = -1 attached"
    base = mechanism_to_dict(mech)
    actuated_links = {x for j in mech.joints if j.actuated for x in j.links} - {mech.ground}
    colours = [{mech.ground}, actuated_links, set(dec.output_links) - actuated_links]
    seen: dict[bytes, FingerResult | None] = {}
    results: list[FingerResult] = []
    for plan in plans:
        for names, tree_edges, ext, deg in _attachments(mech, plan, sites):
            all_names = list(mech.link_names) + names
            edges = [tuple(j.links) for j in mech.joints] + tree_edges + ext
            cert = _certificate(all_names, edges, colours)
            if cert in seen:
                continue
            idx = {n: i for i, n in enumerate(all_names)}
            seen[cert] = None
            if rigid_subchain([(idx[a], idx[b]) for a, b in edges], len(all_names)):
                continue
            result = _build(mech, base, names, tree_edges, ext, plan, deg, actuators, len(results) + 1, cert)
            seen[cert] = result
            if result is not None:
                results.append(result)
                if len(results) >= max_results:
                    notes.append(f"stopped after {max_results} results")
                    break
        else:
            continue
        break
    return FingerSynthesis(mech.name, w0, actuators, table.W_f, table.m_0, tuple(sites),
                           dec.structural_formula, rows, results, tuple(notes))


def _leash_sites(mech, dec) -> list[str]:
    """Binary links that take one new pair each: the decomposition's leash candidates,
    plus imaginary input links with a single pair (e.g. a distal phalanx)."""
    degree = {n: 0 for n in mech.link_names}
    for j in mech.joints:
        for x in j.links:
            degree[x] += 1
    sites = list(dec.leash_candidates)
    for link in dec.imaginary_input_links:
        if link not in sites and degree[link] <= 2:
            sites.append(link)
    return sites


def _attachments(mech, plan: tuple, sites: list[str]):
    """Every attachment of the plan's groups (trees of their links, leashes to the sites
    and the frame) with no double pair and every link at least binary:
    ``(group link names, tree pairs, leash pairs, link degrees)``."""
    degree = {n: 0 for n in mech.link_names}
    for j in mech.joints:
        for x in j.links:
            degree[x] += 1
    base_pairs = {frozenset(j.links) for j in mech.joints}
    sizes = [r.n_f for r in plan]
    leashes = [r.m_f for r in plan]
    n_f, m_f = sum(sizes), sum(leashes)
    names = [f"g{i + 1}" for i in range(n_f)]
    starts = list(itertools.accumulate([0] + sizes))
    component = [c for c, n in enumerate(sizes) for _ in range(n)]
    k = min(m_f, len(sites))
    forests = [sum(([(names[starts[c] + a], names[starts[c] + b]) for a, b in t]
                    for c, t in enumerate(trees)), [])
               for trees in itertools.product(*[_trees(n) for n in sizes])]
    for used in itertools.combinations(sites, k):
        targets = list(used) + [mech.ground] * (m_f - k)
        for tree_edges in forests:
            for assign in itertools.product(range(n_f), repeat=m_f):
                if len(plan) > 1 and any(sum(component[g] == c for g in assign) != leashes[c]
                                         for c in range(len(plan))):
                    continue  # each group keeps its own number of leashes
                ext = [(targets[t], names[g]) for t, g in enumerate(assign)]
                new = [frozenset(e) for e in tree_edges + ext]
                if len(set(new)) < len(new) or base_pairs & set(new):
                    continue  # two pairs between the same links
                deg = dict(degree, **{g: 0 for g in names})
                for a, b in tree_edges + ext:
                    deg[a] += 1
                    deg[b] += 1
                if any(deg[g] < 2 for g in names) or any(
                        deg[x] < 2 for x in mech.link_names if x != mech.ground):
                    continue
                yield names, tree_edges, ext, deg


def _build(mech, base, names, tree_edges, ext, plan, deg, actuators, number, cert):
    """The mechanism data of one attachment, or None when it is not fully actuated."""
    pts = _points(mech, names, tree_edges, ext)
    joints = list(base["joints"])
    new_pairs = tree_edges + ext
    for i, (a, b) in enumerate(new_pairs):
        joints.append({"id": f"N{i + 1}", "type": "R", "links": [a, b],
                       "point": [round(float(pts[i][0]), 2), round(float(pts[i][1]), 2)]})
    vll = tuple(g for g in names if deg[g] == 2)
    links = list(base["links"]) + [
        {"name": g, "group": True, **({"vll_candidate": True} if g in vll else {})}
        for g in names]
    data = {k: v for k, v in base.items() if k not in ("links", "joints", "contours",
                                                     "mobility", "name")}
    attach_text = ", ".join(f"{g}-{t}" for t, g in ext)
    n_f, P_f = sum(r.n_f for r in plan), sum(r.P_f for r in plan)
    label = " + ".join(f"group n_f={r.n_f}, P_f={r.P_f}" for r in plan)
    data = {"name": f"{mech.name} + {label} ({attach_text})",
            **data, "links": links, "joints": joints}
    try:
        result_mech = mechanism_from_dict(data)
        dec2 = assur_decomposition(result_mech)
    except MechsynInputError:
        return None
    if dec2.mobility != actuators or dec2.imaginary_input_links:
        return None
    n = result_mech.n_moving
    p5 = len(result_mech.joints)
    expr = f"W = 3·{n} - 2·{p5} = {3 * n - 2 * p5}"
    combos = []
    for r in range(1, len(vll) + 1):
        for c in itertools.combinations(vll, r):
            combos.append(VLLCombination(
                c, 3 * (n + r) - 2 * (p5 + r),
                f"W = 3·{n + r} - 2·{p5 + r} = {3 * (n + r) - 2 * (p5 + r)}"))
    attachments: dict[str, list[str]] = {}
    for t, g in ext:
        attachments.setdefault(t, []).append(g)
    return FingerResult(
        number=number, n_f=n_f, P_f=P_f, group_links=tuple(names),
        groups=tuple((r.n_f, r.P_f) for r in plan),
        group_pairs=tuple(new_pairs), attachments=attachments,
        mobility_locked=dec2.mobility, mobility_expression=expr,
        structural_formula=dec2.structural_formula, mechanism_class=dec2.mechanism_class,
        vll_candidates=vll, vll_combinations=tuple(combos), mechanism=data,
        certificate=cert.hex(),
    )


def _points(mech, names, tree_edges, ext) -> np.ndarray:
    """Joint points for the new pairs: a leash point on each base link (off its joints),
    group links placed between their leashes; perturbed (seeded) until the geometry is
    generic (instantaneous mobility = Chebyshev's)."""
    jp = {j.id: (np.asarray(j.point, float) if j.point is not None else None) for j in mech.joints}
    if any(p is None for p in jp.values()):
        base_pts = {x: np.zeros(2) for x in mech.link_names}
        span = 50.0
    else:
        allp = np.array(list(jp.values()))
        span = float(np.ptp(allp, axis=0).max()) or 50.0
        base_pts = {}
        for x in mech.link_names:
            ps = [jp[j.id] for j in mech.joints if x in j.links]
            base_pts[x] = np.mean(ps, axis=0) if ps else allp.mean(axis=0)
    rng = np.random.default_rng(7)
    used: dict[str, int] = {}
    ext_pts = []
    centre = np.mean(list(base_pts.values()), axis=0)
    for t, _ in ext:  # leash points beside the finger (+x), spread along it
        k = used.get(t, 0)
        used[t] = k + 1
        ext_pts.append(base_pts[t] + span * np.array([0.22 + 0.08 * k, 0.06 * k]))
    anchor = {}
    for g in names:
        ps = [ext_pts[i] for i, (_, gg) in enumerate(ext) if gg == g]
        anchor[g] = (np.mean(ps, axis=0) + np.array([0.15 * span, 0.0])) if ps \
            else centre + 0.3 * span
    # links without leashes: between their neighbours
    for _ in range(3):
        for g in names:
            if not any(gg == g for _, gg in ext):
                nb = [anchor[b if a == g else a] for a, b in tree_edges if g in (a, b)]
                anchor[g] = np.mean(nb, axis=0) + np.array([0.1 * span, 0.0])
    tree_pts = [(anchor[a] + anchor[b]) / 2 + np.array([0.05 * span, 0.0]) for a, b in tree_edges]
    new = np.array(tree_pts + ext_pts, dtype=float).reshape(-1, 2)
    all_names = list(mech.link_names) + names
    idx = {n: i for i, n in enumerate(all_names)}
    edges = [(idx[a], idx[b]) for j in mech.joints for a, b in [j.links]]
    edges += [(idx[a], idx[b]) for a, b in tree_edges + ext]
    base_arr = np.array([jp[j.id] if jp[j.id] is not None else rng.normal(size=2) * span
                         for j in mech.joints], dtype=float)
    target = 3 * (len(all_names) - 1) - 2 * len(edges)
    for _ in range(30):
        pts = np.vstack([base_arr, new])
        if instantaneous_mobility(len(all_names), edges, pts, frame=idx[mech.ground]) == target:
            break
        new = new + rng.normal(scale=0.05 * span, size=new.shape)
    return new
