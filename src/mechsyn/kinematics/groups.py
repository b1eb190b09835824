"""Assur groups of class II (dyads): the plan of a mechanism (drivers, then groups in
solving order), its decomposition, the look-ups every engine shares, and the kernels of
the group kinds written once.

A mechanism of R and P pairs whose links can be found one driver at a time and then two
at a time (a *dyad*: two links, three pairs, joined to links already known) is solved in
closed form (Artobolevsky, *Theory of Mechanisms and Machines*, ch. 4; the dyads RRR,
RRP, PRR, RPR, RPP, PRP). :func:`decompose` finds the plan; :func:`circle_circle` is the
RRR group's kernel on arrays (the intersection of two circles, with its normalised
discriminant): the kernel's one implementation (:mod:`mechsyn.kinematics._kernel_numba`,
which the regular pass runs row by row) over arrays, for the generic steps
(:mod:`mechsyn.kinematics.positions`), the tracked chain (:mod:`mechsyn.kinematics.chain`)
and synthesis.

References
----------
.. [1] I. I. Artobolevsky, *Theory of Mechanisms and Machines*, Nauka, Moscow, 1988, ch. 4.
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from mechsyn.kinematics.plane import cross, dot
from mechsyn.kinematics.system import Con, PlanarSystem

__all__ = ["Chooser", "Sigma", "Plan", "Step", "circle_circle", "circle_middle", "decompose"]


#: Chooses the assembly sign of a branched group per input row from the group's
#: normalised discriminant (per row) and its drawn mode (+1 or -1).
Chooser = Callable[[np.ndarray, float], np.ndarray | float]
#: The assembly mode asked of a branched group: one sign for every row (+1 or -1), one
#: sign per row (an array), the drawn mode (None) or a :data:`Chooser`.
Sigma = float | np.ndarray | Chooser | None


@dataclass(frozen=True)
class Step:
    kind: str                 # "drive_R", "drive_P", "RRR", "RRP", "RPR", "RPP", "PRP"
    links: tuple[int, ...]    # new links
    known: tuple[int, ...]    # known links used
    joints: tuple[str, ...]
    data: dict
    sigma: float = 1.0


@dataclass(frozen=True)
class Plan:
    steps: tuple[Step, ...]

    @cached_property
    def closed_form_rates(self) -> bool:
        """A driver-R + RRR chain (asked on every sweep and per dead point: kept)."""
        return all(s.kind in ("drive_R", "RRR") for s in self.steps)

    @cached_property
    def geometry_free(self) -> bool:
        """The steps hold for every geometry of the topology (no double joint: two R pairs
        found at one point)."""
        return not any(s.data for s in self.steps)

    def describe(self) -> list[str]:
        return [f"{s.kind} ({', '.join(s.joints)})" for s in self.steps]


def cons_of(S: PlanarSystem, jid: str) -> list[Con]:
    """The constraints of ``S`` that joint ``jid`` writes (in ``S.cons`` order), kept in
    :func:`geometry_memo`.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.system import build_system
    >>> [(c.kind, c.role) for c in cons_of(build_system(ms.examples.load("crank_rocker")), "A")]
    [('R', 'pair'), ('angle', 'drive')]
    """
    memo = geometry_memo(S)
    key = ("cons", jid)
    out = memo.get(key)
    if out is None:
        out = memo[key] = [c for c in S.cons if c.joint == jid]
    return out


def _jtype(S: PlanarSystem, jid: str) -> str:
    return S.mech.joint(jid).type


def decompose(S: PlanarSystem) -> Plan | None:
    """Drivers and dyads in solving order, or None when the mechanism does not decompose."""
    mech = S.mech
    if any(c.kind in ("gear", "curve", "belt") or c.role in ("lock", "idle") for c in S.cons):
        return None
    known = {-1}
    steps: list[Step] = []
    used: set[str] = set()
    joints = {j.id: j for j in mech.joints}
    link_joints: dict[int, list[str]] = {}
    for j in mech.joints:
        for ln in j.links:
            link_joints.setdefault(S.index(ln), []).append(j.id)
    drivers = {d.joint for d in S.drivers}

    def ends(jid: str) -> tuple[int, int]:
        a, b = joints[jid].links
        return S.index(a), S.index(b)

    def other(jid: str, link: int) -> int:  # the link joint ``jid`` joins to ``link``
        return (set(ends(jid)) - {link}).pop()

    def closing(link: int, skip: str | None = None) -> list[str]:
        """The joints of ``link`` (not used, not driven, not ``skip``) to a known link."""
        return [j for j in link_joints.get(link, []) if j not in used and j != skip
                and (set(ends(j)) - {link}) <= known and j not in drivers]

    progress = True
    while progress and len(known) < len(S.links) + 1:
        progress = False
        for jid in drivers - used:
            a, b = ends(jid)
            if (a in known) == (b in known):
                continue
            k, new = (a, b) if a in known else (b, a)
            steps.append(Step("drive_" + _jtype(S, jid), (new,), (k,), (jid,), {}))
            known.add(new)
            used.add(jid)
            progress = True
        if progress:
            continue
        # dyads: b1, b2 unknown, J2 between them, J1: known-b1, J3: b2-known
        for b1 in range(len(S.links)):
            if b1 in known:
                continue
            j1s = closing(b1)
            if len(j1s) != 1:
                continue
            J1 = j1s[0]
            for J2 in link_joints.get(b1, []):
                if J2 in used or J2 == J1 or J2 in drivers:
                    continue
                b2 = other(J2, b1)
                j3s = [] if b2 in known else closing(b2, J2)
                if len(j3s) != 1:
                    continue
                J3 = j3s[0]
                types = "".join(_jtype(S, j) for j in (J1, J2, J3))
                if types not in ("RRR", "RRP", "PRR", "RPR", "RPP", "PPR", "PRP"):
                    continue  # PPP: not a dyad of a planar mechanism
                steps.append(Step(types, (b1, b2), (other(J1, b1), other(J3, b2)), (J1, J2, J3), {}))
                known.update((b1, b2))
                used.update((J1, J2, J3))
                progress = True
                break
            if progress:
                break
        if not progress:
            progress = _double_joint_dyad(S, known, used, drivers, link_joints, other, closing, steps)
    if len(known) < len(S.links) + 1:
        return None
    if set(j.id for j in mech.joints) - used:
        return None  # closing constraints left over (redundant): Newton handles them
    return Plan(tuple(steps))


def _double_joint_dyad(S: PlanarSystem, known: set, used: set, drivers: set, link_joints: dict, other, closing,
                       steps: list) -> bool:
    """A dyad whose middle joint is a *double joint*: links ``b1`` and ``b2`` both pinned to
    a third link ``m`` at one point (two R pairs ``b1-m``, ``b2-m`` at the same place).

    The point is the intersection of the circles about ``b1``'s and ``b2``'s known joints,
    as in an RRR dyad; ``m`` is placed later through the pair ``b1-m`` (the pair ``b2-m``
    is then satisfied, being at the same point). Appends the step and returns True when
    one is found."""
    mech = S.mech
    pts = {j.id: np.asarray(j.point, float) for j in mech.joints}
    for b1 in range(len(S.links)):
        if b1 in known:
            continue
        j1s = closing(b1)
        if len(j1s) != 1 or _jtype(S, j1s[0]) != "R":
            continue
        for J2a in link_joints.get(b1, []):
            if J2a in used or J2a in drivers or _jtype(S, J2a) != "R":
                continue
            m = other(J2a, b1)
            if m in known:
                continue
            for J2b in link_joints.get(m, []):
                if J2b == J2a or J2b in used or J2b in drivers or _jtype(S, J2b) != "R":
                    continue
                b2 = other(J2b, m)
                if b2 in known or b2 == b1 or np.abs(pts[J2a] - pts[J2b]).max() > 1e-9 * S.scale:
                    continue
                j3s = closing(b2, J2b)
                if len(j3s) != 1 or _jtype(S, j3s[0]) != "R":
                    continue
                J1, J3 = j1s[0], j3s[0]
                steps.append(Step("RRR", (b1, b2), (other(J1, b1), other(J3, b2)), (J1, J2a, J3), {"double": J2b}))
                known.update((b1, b2))
                used.update((J1, J3, J2b))
                return True
    return False


def geometry_memo(S: PlanarSystem) -> dict:
    """The look-ups of ``S``'s geometry that a plan evaluated many times (events, drags)
    reuses: local joint points, constraints of a joint, the filled programs. Kept with
    the system (a field of it: a new geometry starts with an empty one); what the
    topology alone decides is kept by ``S.topology``
    (:meth:`~mechsyn.kinematics.topology.Topology.product`)."""
    return S.cache.setdefault("groups", {})


def local_point(S: PlanarSystem, i: int, jid: str) -> np.ndarray:
    """Joint ``jid``'s drawn point in the frame of link ``i`` (-1: the frame, the point
    itself), kept in :func:`geometry_memo`.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.system import build_system
    >>> S = build_system(ms.examples.load("crank_rocker"))
    >>> local_point(S, 0, "A").tolist()   # the crank's frame has its origin at A
    [0.0, 0.0]
    """
    memo = geometry_memo(S)
    key = ("local", i, jid)
    out = memo.get(key)
    if out is None:
        j = S.mech.joint(jid)
        name = S.mech.ground if i < 0 else S.links[i]
        out = memo[key] = S.to_local(name, j.point)
    return out


def rel_angle(S: PlanarSystem, jid: str, frm: int, to: int) -> float:
    """The constant angle ``phi_to - phi_frm`` between the links ``frm`` and ``to`` of the
    P joint ``jid`` (its rotation constraint's drawn value, radians)."""
    con = next(c for c in cons_of(S, jid) if c.kind == "angle" and c.role == "rotation")
    return con.c0 if (con.a, con.b) == (frm, to) else -con.c0


def pair_line(S: PlanarSystem, jid: str) -> Con:
    """The line constraint of the P joint ``jid`` (its pair: the slide's direction and
    local points)."""
    return next(c for c in cons_of(S, jid) if c.kind == "line" and c.role == "pair")


COINCIDENT = 1e-24
"""Squared distance, over the sum of an RRR group's squared lengths, below which its two
circle centres are one point (:func:`circle_circle`)."""


def circle_circle(dx: np.ndarray | float, dy: np.ndarray | float, L1s: np.ndarray | float,
                  L2s: np.ndarray | float) -> tuple:
    """The RRR group's kernel on arrays (or floats): the intersection of the circles
    ``|B - A| = L1``, ``|B - C| = L2`` with ``d = C - A = (dx, dy)``, run by the kernel's
    one implementation (:func:`mechsyn.kinematics._kernel_numba.circle`, compiled, over
    every row; the lengths broadcast).

    Returns ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)``, ``g^2 = L1^2 / |d|^2 - f^2`` (``B =
    A + f d + sigma g R90 d``) and the group's normalised discriminant ``g^2 |d|^2 /
    L1^2`` (below zero the circles do not meet; 1 when the first link stands square on
    ``d``, 0 when the group is folded flat), in the shape of the arguments broadcast
    (floats when they are numbers).

    Centres closer than ``1e-12 sqrt(L1^2 + L2^2)`` (:data:`COINCIDENT`, relative to the
    group's own lengths) are coincident: the middle joint is then indeterminate (a circle
    of solutions, or none), and ``f``, ``g^2`` and the discriminant are NaN, whatever the
    last bits of ``d`` (the Peaucellier cell at its dead point puts A and B on one spot:
    ``|d|`` came out 0 or 4e-16 depending on the machine's rounding, and the group's
    discriminant NaN or 1).

    Examples
    --------
    >>> f, g2, disc = circle_circle(4.0, 0.0, 9.0, 9.0)   # |d| = 4, L1 = L2 = 3
    >>> f, round(g2 * 16, 12), round(disc, 6)
    (0.5, 5.0, 0.555556)
    """
    dx, dy, L1, L2 = (np.asarray(v, float) for v in (dx, dy, L1s, L2s))
    shape = np.broadcast_shapes(dx.shape, dy.shape, L1.shape, L2.shape)
    n = math.prod(shape)
    rows = [np.ascontiguousarray(np.broadcast_to(v, shape)).reshape(n) for v in (dx, dy)]
    lens = [v.reshape(1) if v.size == 1 else np.ascontiguousarray(np.broadcast_to(v, shape)).reshape(n)
            for v in (L1, L2)]
    out = np.empty((3, n))
    importlib.import_module("mechsyn.kinematics._kernel_numba").circles(*rows, *lens, *out)
    if not shape:
        return float(out[0, 0]), float(out[1, 0]), float(out[2, 0])
    return tuple(out.reshape((3,) + shape))


def circle_middle(d: np.ndarray, f: np.ndarray, g2: np.ndarray, disc: np.ndarray,
                  sigma: np.ndarray | float) -> np.ndarray:
    """The RRR group's middle joint on arrays: ``B - A = f d + sigma g R90 d`` (N, 2)
    from ``d = C - A`` (N, 2) and :func:`circle_circle`'s ``f``, ``g^2`` and normalised
    discriminant (N,) in the assembly modes ``sigma`` (a number or (N,)), by the
    kernel's one implementation (:func:`mechsyn.kinematics._kernel_numba.place`: a fold
    within round-off taken flat, NaN where the circles do not meet).

    Examples
    --------
    >>> d = np.array([[4.0, 0.0]])
    >>> f, g2, disc = circle_circle(d[:, 0], d[:, 1], 9.0, 9.0)
    >>> circle_middle(d, f, g2, disc, -1.0).round(6).tolist()   # B = (2, -sqrt 5)
    [[2.0, -2.236068]]
    """
    sig = np.ascontiguousarray(np.broadcast_to(np.asarray(sigma, float), (1,) if np.ndim(sigma) == 0 else f.shape))
    out = np.empty((2, d.shape[0]))
    importlib.import_module("mechsyn.kinematics._kernel_numba").places(
        np.ascontiguousarray(d[:, 0]), np.ascontiguousarray(d[:, 1]), *(np.ascontiguousarray(v, float)
                                                                        for v in (f, g2, disc)), sig, *out)
    return out.T
