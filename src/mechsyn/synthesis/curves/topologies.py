"""Candidate topologies for curve synthesis: chain, frame, input crank and tracing link.

From the atlas (:func:`mechsyn.synthesis.chains.synthesize_chains`) every 1-DOF planar
chain of R pairs with 4, 6 or 8 links; for each, every inequivalent frame and input
link (:func:`mechsyn.synthesis.mechanisms.distinct_mechanisms`, orbits of the chain's
automorphism group), and every inequivalent *tracing link*: orbits of the links under
the automorphisms that fix both the frame and the input link (nauty, with the frame
and the input coloured apart). Links jointed to the frame trace circular arcs and are
not offered as tracers. A choice is kept when the mechanism is found by a crank and
RRR dyads (:func:`mechsyn.kinematics.batch.compile_plan`), so every design of it is
evaluated in closed form by the batch engine; choices that need a triad (an Assur
group of class III) are left out: every Stephenson II inversion (a crank on the frame
leaves a triad) and a share of the 8-link choices.

Six-bar names follow which link is the frame (Watt chain: the two ternary links are
jointed to each other; Stephenson chain: they are not): Watt I, frame binary; Watt II,
frame ternary; Stephenson I, frame the binary link jointed to both ternary links;
Stephenson II, frame a binary link of the two-binary path; Stephenson III, frame
ternary (J. M. McCarthy and G. S. Soh, *Geometric Design of Linkages*, 2nd ed.,
Springer, 2011, ch. 1 and 11; authors differ on the numbering of Stephenson I and II,
the rule used here is the one stated).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.batch import BatchPlan, compile_plan
from mechsyn.synthesis import canonical
from mechsyn.synthesis.chains import KinematicChain, synthesize_chains

__all__ = ["CurveTopology", "curve_topologies", "six_bar_name", "chain_name"]

TRACER = "T"


@dataclass(frozen=True)
class CurveTopology:
    """One candidate: chain, frame, input (crank) link and tracing link."""

    key: str                       # stable id, e.g. "6-1-f0-i2-t3"
    chain: KinematicChain
    frame: int
    input: int
    tracer: int
    name: str | None               # Watt I/II, Stephenson I/II/III, four-bar
    template: dict                 # mechanism-file dict (layout geometry), tracer point "T"
    compiled: BatchPlan | None = field(default=None, compare=False, repr=False)

    @property
    def model(self):
        """The template as a :class:`~mechsyn.model.Mechanism` (read once, on first use)."""
        m = self.__dict__.get("_model")
        if m is None:
            from mechsyn.io.load import mechanism_from_dict

            m = mechanism_from_dict(self.template)
            object.__setattr__(self, "_model", m)
        return m

    @property
    def plan(self) -> BatchPlan:
        """The batch plan (tracer output), compiled from the template on first use."""
        if self.compiled is None:
            object.__setattr__(self, "compiled", compile_plan(self.model, points=[TRACER]))
        return self.compiled

    @property
    def n_links(self) -> int:
        return self.chain.n_links

    @property
    def label(self) -> str:
        """The topology's name: four-bar, Watt I/II, Stephenson I/III, or for an
        eight-bar its atlas chain and link assortment (e.g. ``8-bar chain 3 (4B+4T)``).

        Examples
        --------
        >>> sorted({t.label for t in curve_topologies(6)})[:2]
        ['Stephenson I', 'Stephenson III']
        """
        return self.name or str(self.template["name"]).split(", frame")[0]

    def mechanism(self, params: np.ndarray, name: str | None = None) -> dict:
        """The mechanism-file dict of a design (parameters in ``plan.names`` order)."""
        xy = np.asarray(params, float).reshape(-1, 2)
        where = {n: [float(v) for v in xy[i]] for i, n in enumerate(self.plan.names)}
        d = {k: v for k, v in self.template.items() if k not in ("joints", "points")}
        d["name"] = name or self.template["name"]
        d["joints"] = [{**j, "point": where[j["id"]]} for j in self.template["joints"]]
        d["points"] = {TRACER: {"link": f"L{self.tracer}", "at": where[TRACER]}}
        return d

    def links_of(self) -> dict[str, list[str]]:
        """Point names (joints and tracer) carried by each link."""
        out: dict[str, list[str]] = {}
        for j in self.template["joints"]:
            for ln in j["links"]:
                out.setdefault(ln, []).append(j["id"])
        out.setdefault(f"L{self.tracer}", []).append(TRACER)
        return out


def chain_name(chain: KinematicChain) -> str | None:
    """The chain's name in the literature: the four-bar chain, and the two six-bar chains of
    two ternary and four binary links, Watt's (the ternary links jointed to each other) and
    Stephenson's (not); None for the others.

    Examples
    --------
    >>> from mechsyn.synthesis.chains import synthesize_chains
    >>> sorted(chain_name(c) for c in synthesize_chains(6, 1))
    ['Stephenson chain', 'Watt chain']
    """
    deg = chain.degrees()
    if chain.n_links == 4 and deg == [2, 2, 2, 2]:
        return "four-bar chain"
    tern = [i for i, d in enumerate(deg) if d == 3]
    if chain.n_links != 6 or len(tern) != 2 or sorted(deg) != [2, 2, 2, 2, 3, 3]:
        return None
    return "Watt chain" if chain.graph().has_edge(*tern) else "Stephenson chain"


def six_bar_name(chain: KinematicChain, frame: int) -> str | None:
    """Watt I/II or Stephenson I/II/III by the frame link (see the module doc)."""
    if chain.n_links == 4:
        return "four-bar"
    if chain.n_links != 6:
        return None
    deg = chain.degrees()
    tern = [i for i, d in enumerate(deg) if d == 3]
    if len(tern) != 2 or sorted(deg) != [2, 2, 2, 2, 3, 3]:
        return None
    g = chain.graph()
    watt = g.has_edge(*tern)
    if deg[frame] == 3:
        return "Watt II" if watt else "Stephenson III"
    if watt:
        return "Watt I"
    return "Stephenson I" if all(g.has_edge(frame, t) for t in tern) else "Stephenson II"


def _tracer_orbits(chain: KinematicChain, frame: int, inp: int) -> list[list[int]]:
    colours = [0 if v == frame else 1 if v == inp else 2 for v in range(chain.n_links)]
    groups: dict[int, list[int]] = {}
    for v, o in enumerate(canonical.orbits(chain.n_links, chain.edges, colours)):
        groups.setdefault(int(o), []).append(v)
    return sorted(groups.values())


@lru_cache(maxsize=None)
def curve_topologies(max_links: int = 8) -> tuple[CurveTopology, ...]:
    """Every inequivalent (chain, frame, input, tracer) with 4..``max_links`` links whose
    mechanism is solved by a crank and RRR dyads (see the module doc).

    Examples
    --------
    >>> [t.name for t in curve_topologies(4)]
    ['four-bar']
    >>> sorted({t.name for t in curve_topologies(6)} - {'four-bar'})
    ['Stephenson I', 'Stephenson III', 'Watt I', 'Watt II']
    """
    if max_links not in (4, 6, 8):
        raise MechsynInputError(f"max links {max_links}: choose 4, 6 or 8", field="max_links")
    from mechsyn.synthesis.mechanisms import distinct_mechanisms, mechanism_dict   # here: it loads networkx

    out: list[CurveTopology] = []
    for n in range(4, max_links + 1, 2):
        for ci, chain in enumerate(synthesize_chains(n, 1)):
            if chain.degenerate or chain.fractionated:
                continue
            g = chain.graph()
            for choice in distinct_mechanisms(chain):
                frame, inp = choice.frame, choice.input
                base = mechanism_dict(chain, frame, inp)
                for orbit in _tracer_orbits(chain, frame, inp):
                    tr = orbit[0]
                    if tr in (frame, inp) or g.has_edge(tr, frame):
                        continue
                    tmpl = dict(base)
                    pts = np.array([j["point"] for j in base["joints"]
                                    if f"L{tr}" in j["links"]], float)
                    at = pts.mean(axis=0) + np.array([0.17, 0.23]) * 100.0 / max(n, 4)
                    tmpl["points"] = {TRACER: {"link": f"L{tr}", "at": [round(float(v), 2) for v in at]}}
                    name = six_bar_name(chain, frame)
                    label = name or f"{n}-bar chain {ci + 1} ({chain.assortment_label()})"
                    tmpl["name"] = f"{label}, frame L{frame}, input L{inp}, tracer on L{tr}"
                    from mechsyn.io.load import mechanism_from_dict

                    try:
                        plan = compile_plan(mechanism_from_dict(tmpl), points=[TRACER])
                    except MechsynInputError:
                        continue  # needs a triad: not in closed form by dyads
                    key = f"{n}-{ci + 1}-f{frame}-i{inp}-t{tr}"
                    out.append(CurveTopology(key, chain, frame, inp, tr, name, tmpl, plan))
    return tuple(out)


CACHE_FILE = "topologies.json"


def cached_topologies(directory: Path, max_links: int) -> tuple[CurveTopology, ...]:
    """:func:`curve_topologies` as stored in a curve database's directory (written on the
    first call, rewritten when it does not hold them all): the atlas is enumerated once
    per database, not on every load; the plans compile on first use. The file is keyed
    by the code's version of the enumeration (the keys in order and the templates)."""
    from mechsyn.errors import MechsynInputError
    from mechsyn.io.files import loads_json, read_limited

    f = Path(directory) / CACHE_FILE
    try:  # a regular file within the size limit, JSON of limited depth: anything else is damaged
        recs = loads_json(read_limited(f, "topology cache") if f.exists() else b"null", str(f))
        want = {n: k for n, k in recs["count"].items()}
        out = tuple(_from_record(r) for r in recs["topologies"] if r["chain"]["n_links"] <= max_links)
        if recs.get("version") == _CACHE_VERSION and all(str(n) in want for n in range(4, max_links + 1, 2)):
            return out
    except (OSError, ValueError, KeyError, TypeError, AttributeError, MechsynInputError, RecursionError):
        pass  # missing or damaged: enumerated again and rewritten
    topos = curve_topologies(max_links)
    counts = {str(n): sum(t.n_links == n for t in topos) for n in range(4, max_links + 1, 2)}
    data = {"version": _CACHE_VERSION, "count": counts,
            "topologies": [{"key": t.key, "frame": t.frame, "input": t.input, "tracer": t.tracer, "name": t.name,
                            "template": t.template, "chain": _chain_record(t.chain)} for t in topos]}
    from mechsyn.results import write_atomic

    try:
        write_atomic(f, json.dumps(data).encode())
    except OSError:   # a read-only database: enumerate on every load
        pass
    return topos


_CACHE_VERSION = 1


def _chain_record(c: KinematicChain) -> dict:
    d = asdict(c)
    d["assortment"] = {str(k): v for k, v in c.assortment.items()}
    return d


def _from_record(r: dict) -> CurveTopology:
    c = dict(r["chain"])
    c["edges"] = tuple(tuple(e) for e in c["edges"])
    c["assortment"] = {int(k): v for k, v in c["assortment"].items()}
    c["contracted"] = tuple(tuple(e) for e in c.get("contracted", ()))
    return CurveTopology(r["key"], KinematicChain(**c), r["frame"], r["input"], r["tracer"], r["name"],
                         r["template"])
