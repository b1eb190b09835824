"""The atlas of planar kinematic chains: number synthesis (link assortments), topological
synthesis (non-isomorphic chains) and the distinct mechanisms of each chain, as one report.

``mechsyn atlas --json`` prints :meth:`Atlas.to_dict`.

References
----------
T. S. Mruthyunjaya, "Kinematic structure of mechanisms revisited", *Mechanism and Machine
Theory* 38 (2003) 279-320; L. W. Tsai, *Mechanism Design: Enumeration of Kinematic
Structures According to Function*, CRC Press, 2001, ch. 4-5 (see
:mod:`mechsyn.synthesis.chains` for the enumeration itself).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

from mechsyn._result import Result
from mechsyn.progress import ProgressCallback
from mechsyn.synthesis.chains import (KinematicChain, link_assortments, synthesize_chains,
                                      synthesize_chains_to_file)
from mechsyn.synthesis.mechanisms import distinct_mechanisms, frame_orbits, mechanism_dict

__all__ = ["Atlas", "chain_atlas"]

_DEGREE_NAMES = {2: "B", 3: "T", 4: "Q", 5: "P", 6: "H"}


def assortment_label(assortment: dict[int, int]) -> str:
    """``"4B 2T"`` for 4 binary and 2 ternary links.

    >>> assortment_label({3: 2, 2: 4})
    '4B 2T'
    """
    return " ".join(f"{c}{_DEGREE_NAMES.get(d, f'd{d}')}" for d, c in sorted(assortment.items()))


def _key(assortment: dict[int, int]) -> str:
    return ",".join(f"{d}:{c}" for d, c in sorted(assortment.items()))


def _row(assortment: dict[int, int], label: str) -> dict[str, Any]:
    return {"assortment": {str(d): c for d, c in sorted(assortment.items())}, "label": label, "chains": 0,
            "non_planar": 0, "fractionated": 0, "degenerate": 0, "mechanisms": 0}


def _record(number: int, chain: KinematicChain, inputs: bool) -> dict[str, Any]:
    rec = {"number": number, **chain.to_dict()}
    if not chain.degenerate:
        rec["frames"] = [o[0] for o in frame_orbits(chain)]
        if inputs:
            rec["mechanisms"] = [{"frame": m.frame, "input": m.input} for m in distinct_mechanisms(chain)]
    return rec


def _by_assortment(n_links: int, mobility: int, chains: list[KinematicChain], records: list[dict],
                   inputs: bool) -> dict[str, dict[str, Any]]:
    rows = {_key(a): _row(a, assortment_label(a)) for a in link_assortments(n_links, mobility)}
    for chain, rec in zip(chains, records):
        row = rows.setdefault(_key(chain.assortment), _row(chain.assortment, chain.assortment_label()))
        if chain.degenerate:
            row["degenerate"] += 1
            continue
        row["chains"] += 1
        row["non_planar"] += not chain.planar_graph
        row["fractionated"] += chain.fractionated
        row["mechanisms"] += len(rec["mechanisms"] if inputs else rec["frames"])
    return rows


@dataclass(repr=False)
class Atlas(Result):
    """All non-isomorphic chains with ``n_links`` links and mobility ``mobility``.

    ``count`` chains that are not degenerate, of which ``non_planar`` have a non-planar
    graph and ``fractionated`` are fractionated; ``mechanisms`` distinct mechanisms
    (choices of frame, or of frame and input link when ``mechanisms_by`` says so);
    ``assortments``: one row per link assortment, in number-synthesis order; ``chains``:
    one record per chain (edges, assortment, frames, mechanisms).

    Examples
    --------
    >>> from mechsyn.synthesis.atlas import chain_atlas
    >>> a = chain_atlas(6, 1)
    >>> a.count, a.mechanisms
    (2, 5)
    >>> [row["label"] for row in a.assortments]
    ['5B 1Q', '4B 2T']
    """

    n_links: int
    mobility: int
    n_joints: int
    count: int
    non_planar: int
    fractionated: int
    degenerate_listed: int
    mechanisms: int
    mechanisms_by: str
    assortments: list[dict[str, Any]]
    chains: list[dict[str, Any]]
    kinematic_chains: list[KinematicChain] = field(default_factory=list, metadata={"json": False})

    def mechanism_files(self) -> dict[str, dict[str, Any]]:
        """File name -> mechanism file dict, one per chain that is not degenerate (its first
        distinct mechanism; see :func:`mechsyn.synthesis.mechanisms.mechanism_dict`)."""
        out = {}
        for i, chain in enumerate(self.kinematic_chains, start=1):
            if not chain.degenerate:
                name = (f"Chain {i} of the {self.n_links}-link atlas, F = {self.mobility} "
                        f"({chain.assortment_label()})")
                out[f"chain_{self.n_links}_{self.mobility}_{i:04d}.yaml"] = mechanism_dict(chain, name=name)
        return out

    def plot(self, fig: Any = None, **kwargs: Any) -> Any:
        """Draw every chain, numbered, on one sheet (see :func:`mechsyn.plot.atlas.plot_atlas`)."""
        from mechsyn.plot.atlas import plot_atlas

        title = (f"Planar kinematic chains: {self.n_links} links, mobility {self.mobility}: "
                 f"{self.count} chains")
        return plot_atlas(self.kinematic_chains, title, fig=fig, **kwargs)


def chain_atlas(n_links: int, mobility: int = 1, *, include_degenerate: bool = False, inputs: bool = False,
                stream: str | os.PathLike[str] | None = None, force: bool = False, workers: int = 1,
                scheduler: Any = None, progress: ProgressCallback | None = None) -> Atlas:
    """Number and topological synthesis of planar simple-jointed kinematic chains.

    Parameters
    ----------
    n_links : int
        Number of links, frame included.
    mobility : int
        Degrees of freedom of the chain.
    include_degenerate : bool
        Also list (flagged) degenerate chains.
    inputs : bool
        Count the distinct mechanisms by frame and input link (else by frame).
    stream : path, optional
        Stream the chains to this JSON-lines file and resume from it (see
        :func:`mechsyn.synthesis.chains.synthesize_chains_to_file`); ``force`` lets it
        overwrite a file that is not a chain stream.
    workers, scheduler, progress
        As for :func:`mechsyn.synthesis.chains.synthesize_chains`.

    Returns
    -------
    Atlas

    Examples
    --------
    >>> from mechsyn.synthesis.atlas import chain_atlas
    >>> chain_atlas(4, 1, inputs=True).chains[0]["mechanisms"]
    [{'frame': 0, 'input': 1}]
    """
    run = dict(progress=progress, workers=workers, scheduler=scheduler)
    if stream is not None:
        chains = synthesize_chains_to_file(stream, n_links, mobility, include_degenerate, force=force, **run)
    else:
        chains = synthesize_chains(n_links, mobility, include_degenerate, **run)
    records = [_record(i, c, inputs) for i, c in enumerate(chains, start=1)]
    rows = _by_assortment(n_links, mobility, chains, records, inputs)
    good = [c for c in chains if not c.degenerate]
    return Atlas(n_links, mobility, (3 * (n_links - 1) - mobility) // 2, len(good),
                 sum(not c.planar_graph for c in good), sum(c.fractionated for c in good),
                 len(chains) - len(good), sum(r["mechanisms"] for r in rows.values()),
                 "frame and input link" if inputs else "frame", list(rows.values()), records, chains)
