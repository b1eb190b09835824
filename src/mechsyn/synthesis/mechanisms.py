"""From kinematic chains to mechanisms: choice of frame and input link, geometry, files.

* :func:`frame_orbits` / :func:`distinct_mechanisms`: a chain gives as many distinct
  mechanisms (inversions) as its automorphism group has orbits on the links; for each
  frame, the distinct input links (links jointed to the frame) are the orbits of the
  frame's neighbours under the frame's stabiliser. Both from the automorphism group's
  generators (bliss or nauty, :mod:`mechsyn.synthesis.canonical`). Watt's six-bar chain gives 2
  inversions, Stephenson's 3.
* :func:`chain_layout`: positions of the joints of a chain (for drawing and for
  mechanism files): the links are laid out as a graph (Kamada-Kawai from a planar
  embedding when there is one), each joint sits between its two links, and the
  geometry is checked to be generic: the instantaneous mobility (rank of the velocity
  constraints of the rigid bodies) equals Gruebler's ``F``; otherwise the points are
  perturbed.
* :func:`mechanism_dict`: the mechanism in the file format of the foundation issue
  (planar, R joints, the frame-input joint actuated).
"""

from __future__ import annotations

from dataclasses import dataclass

import networkx as nx
import numpy as np

from mechsyn.synthesis import canonical
from mechsyn.synthesis.chains import KinematicChain

__all__ = [
    "MechanismChoice",
    "frame_orbits",
    "distinct_mechanisms",
    "chain_layout",
    "instantaneous_mobility",
    "mechanism_dict",
]


def _orbit_ids(chain: KinematicChain, fixed: int | None = None) -> list[int]:
    """Orbits of the links under the chain's automorphisms (fixing link ``fixed``)."""
    colours = None if fixed is None else [0 if v == fixed else 1 for v in range(chain.n_links)]
    return canonical.orbits(chain.n_links, chain.edges, colours)


def _orbits(orbit_ids) -> list[list[int]]:
    groups: dict[int, list[int]] = {}
    for v, o in enumerate(orbit_ids):
        groups.setdefault(int(o), []).append(v)
    return sorted(groups.values())


def frame_orbits(chain: KinematicChain) -> list[list[int]]:
    """Orbits of the chain's automorphism group on its links (equivalent frames)."""
    return _orbits(_orbit_ids(chain))


@dataclass(frozen=True)
class MechanismChoice:
    """A mechanism from a chain: its frame link, input link (jointed to the frame, or
    ``None`` when only frames are asked for) and how many equivalent choices it stands for."""

    frame: int
    input: int | None
    equivalent_frames: int
    equivalent_inputs: int


def distinct_mechanisms(chain: KinematicChain, with_input: bool = True) -> list[MechanismChoice]:
    """The distinct mechanisms of a chain by choice of frame (and of input link)."""
    neighbours = chain.graph()
    out: list[MechanismChoice] = []
    for orbit in frame_orbits(chain):
        frame = orbit[0]
        if not with_input:
            out.append(MechanismChoice(frame, None, len(orbit), 0))
            continue
        stab = _orbits(_orbit_ids(chain, fixed=frame))
        adjacent = set(neighbours[frame])
        for sub in stab:
            inputs = [v for v in sub if v in adjacent]
            if inputs:
                out.append(MechanismChoice(frame, inputs[0], len(orbit), len(inputs)))
    return out


# ------------------------------------------------------------------------- geometry


def instantaneous_mobility(
    n_links: int, edges, points: np.ndarray, frame: int = 0
) -> int:
    """Mobility of the pin-jointed rigid bodies at this configuration.

    Body ``k`` has velocity ``(u_k, v_k, w_k)``; a pin at ``p`` between ``a`` and ``b``
    gives two equations ``(u_a - w_a p_y) - (u_b - w_b p_y) = 0`` and
    ``(v_a + w_a p_x) - (v_b + w_b p_x) = 0`` (velocities of the coincident points).
    Mobility = ``3 (n - 1) - rank``, the frame's velocity being zero.
    """
    rows = []
    for (a, b), p in zip(edges, np.asarray(points, dtype=float)):
        for comp in (0, 1):
            r = np.zeros(3 * n_links)
            if comp == 0:
                r[3 * a:3 * a + 3] = (1.0, 0.0, -p[1])
                r[3 * b:3 * b + 3] = (-1.0, 0.0, p[1])
            else:
                r[3 * a:3 * a + 3] = (0.0, 1.0, p[0])
                r[3 * b:3 * b + 3] = (0.0, -1.0, -p[0])
            rows.append(r)
    keep = [i for i in range(3 * n_links) if i // 3 != frame]
    jac = np.array(rows)[:, keep] if rows else np.zeros((0, len(keep)))
    rank = np.linalg.matrix_rank(jac, tol=1e-8 * max(1.0, np.abs(jac).max(initial=1.0)))
    return 3 * (n_links - 1) - int(rank)


def link_positions(chain: KinematicChain, iterations: int = 60) -> np.ndarray:
    """Positions of the links as graph nodes, scaled into ``[-1, 1]^2``.

    Stress majorisation (SMACOF, Gansner-Koren-North 2004) on the graph distances,
    started from classical multidimensional scaling: deterministic, vectorised.
    """
    n = chain.n_links
    dist = np.asarray(nx.floyd_warshall_numpy(chain.graph(), nodelist=range(n)), dtype=float)
    # classical MDS start
    j = np.eye(n) - 1.0 / n
    b = -0.5 * j @ (dist ** 2) @ j
    vals, vecs = np.linalg.eigh(b)
    xy = vecs[:, -2:] * np.sqrt(np.maximum(vals[-2:], 1e-9))
    xy += 1e-3 * np.cos(np.arange(2 * n).reshape(n, 2))  # break exact symmetry
    w = np.where(dist > 0, 1.0 / np.maximum(dist, 1e-12) ** 2, 0.0)
    lap = -w.copy()
    lap[np.diag_indices(n)] = w.sum(axis=1)
    lap_pinv = np.linalg.pinv(lap)
    for _ in range(iterations):
        diff = xy[:, None, :] - xy[None, :, :]
        norm = np.linalg.norm(diff, axis=2)
        bz = np.where(norm > 1e-12, -w * dist / np.maximum(norm, 1e-12), 0.0)
        bz[np.diag_indices(n)] = -bz.sum(axis=1)
        xy = lap_pinv @ (bz @ xy)
    xy -= xy.mean(axis=0)
    scale = np.abs(xy).max()
    return xy / (scale if scale > 0 else 1.0)


def chain_layout(chain: KinematicChain, scale: float = 100.0, seed: int = 0):
    """Link-node positions and joint points (joint = midpoint between its two links).

    Returns ``(link_xy, joint_xy)`` scaled to about ``scale`` (mm). The joint points are
    perturbed (seeded) until the geometry is generic: instantaneous mobility = ``F``.
    """
    link_xy = link_positions(chain) * scale
    joints = np.zeros((len(chain.edges), 2))
    for k, (a, b) in enumerate(chain.edges):
        # midpoint, or nearby along the edge when it would coincide with another joint
        for t in (0.5, 0.35, 0.65, 0.25, 0.75):
            p = link_xy[a] + t * (link_xy[b] - link_xy[a])
            if k == 0 or np.min(np.linalg.norm(joints[:k] - p, axis=1)) > 0.08 * scale:
                break
        joints[k] = p
    rng = np.random.default_rng(seed)
    for _ in range(20):
        if instantaneous_mobility(chain.n_links, chain.edges, joints) == chain.mobility:
            break
        joints = joints + rng.normal(scale=0.03 * scale, size=joints.shape)
    return link_xy, joints


def mechanism_dict(
    chain: KinematicChain,
    frame: int | None = None,
    input_link: int | None = None,
    name: str | None = None,
    scale: float = 100.0,
) -> dict:
    """The mechanism (chain with a frame) as a file dict of the foundation issue's format.

    Links are named ``L0``... after the chain's numbers; joints ``J0``... in the chain's
    edge order, all ``R``, with points from :func:`chain_layout` (rounded to 0.01).
    ``links: [a, b]`` lists the frame side first along a breadth-first tree from the
    frame. The joints between the frame and the input link(s) are actuated: ``F`` of
    them, the input link first.
    """
    if frame is None or input_link is None:
        choice = distinct_mechanisms(chain)[0]
        frame = choice.frame if frame is None else frame
        input_link = choice.input if input_link is None else input_link
    _, points = chain_layout(chain, scale)
    depth = nx.single_source_shortest_path_length(chain.graph(), frame)
    frame_joints = [k for k, e in enumerate(chain.edges) if frame in e]
    frame_joints.sort(key=lambda k: (input_link not in chain.edges[k], k))
    actuated = set(frame_joints[: chain.mobility])
    joints = []
    for k, (a, b) in enumerate(chain.edges):
        if (depth[b], b) < (depth[a], a):
            a, b = b, a
        joint = {"id": f"J{k}", "type": "R", "links": [f"L{a}", f"L{b}"],
                 "point": [round(float(points[k][0]), 2), round(float(points[k][1]), 2)]}
        if k in actuated:
            joint["actuated"] = True
        joints.append(joint)
    label = chain.assortment_label()
    return {
        "name": name or f"{chain.n_links}-link chain ({label}), frame L{frame}",
        "kind": "planar",
        "ground": f"L{frame}",
        "links": [f"L{i}" for i in range(chain.n_links)],
        "joints": joints,
    }
