"""Batch kinematics: many designs of one topology over many input values in one call.

A *plan* is compiled once from a mechanism (a crank on the frame, then RRR dyads in
solving order: Assur groups of class II, Artobolevsky, *Theory of Mechanisms and
Machines*, ch. 4); the *parameters* of a design are the coordinates of its joints and
named points in its reference configuration (input offset 0). :func:`simulate_batch`
then evaluates ``K`` designs (a ``K x P`` array) over ``N`` input offsets in whole-array
passes, with planar points as complex numbers:

* crank about ``O`` (joint on the frame): a point ``p`` of the crank is at
  ``O + (p0 - O) exp(i u)``;
* RRR dyad with known end joints ``A``, ``C`` and lengths ``L1 = |B0 - A0|``,
  ``L2 = |B0 - C0|``: with ``d = C - A``, ``t = |d|^2``,
  ``alpha = (L1^2 - L2^2 + t) / (2 t)`` and ``beta^2 = L1^2 / t - alpha^2``,
  ``B = A + d (alpha + i sigma beta)`` (the kernel's one circle intersection,
  :func:`mechsyn.kinematics._kernel_numba.circle`); ``sigma`` is the assembly mode of the reference
  configuration (sign of ``(C0 - A0) x (B0 - A0)``), kept over the whole sweep;
* any other point ``p`` of a link known from two of its points ``A``, ``B`` is
  ``A + (B - A) (p0 - A0) / (B0 - A0)`` (a rigid motion as one complex ratio).

Where ``beta^2 < 0`` the dyad cannot be assembled: the sample is NaN and not
``assembled``. Per design the result flags a ``dead_point`` (some sample of the sweep is
not assembled: the input cannot run through the whole range) and a ``branch_jump`` (a
dyad's ``beta^2`` has a local minimum between samples whose parabola through the three
neighbouring samples dips below zero: the sampled sweep stepped over a dead point, so
the points on either side lie on different assembly branches), and gives the minimum
transmission angle of the RRR dyads (``sin mu = t beta / (L1 L2)``).

The answers equal :func:`mechsyn.kinematics.simulate` on the same mechanism with the
input ``reference + offset`` (tests check it on sampled designs).

How it is run: the plan is a *program* that places only the points the requested
outputs and the later dyads use (a dependency pass at compile time, see
:meth:`BatchPlan.describe`). Every point of a dyad's links is written as
``A + d (a + b w)`` with ``w = alpha + i sigma beta`` and per-design constants ``a``,
``b``, so it is placed straight from the dyad's ``d`` and ``w``; a dyad whose two end
joints lie on the links of one earlier dyad (the second dyad of a Watt six-bar) takes
``d = d_i (a + b w_i)`` without placing its ends. The designs run in blocks of about
16,000 samples whose work arrays are reused from block to block and stay in the
processor's cache (a fresh ``K x N`` temporary costs more in page faults than in
arithmetic). Where a dyad does not assemble ``beta`` is NaN and the NaN reaches every
point placed from it; outputs that do not depend on every dyad (and frame points) are
set to NaN where the mechanism is not assembled.

Examples
--------
>>> import numpy as np
>>> from mechsyn.io.load import mechanism_from_dict
>>> mech = mechanism_from_dict({"name": "crank-rocker", "kind": "planar", "ground": "f",
...     "links": ["f", "c", "k", "r"], "joints": [
...     {"id": "A", "type": "R", "links": ["f", "c"], "point": [0, 0], "actuated": True},
...     {"id": "B", "type": "R", "links": ["c", "k"], "point": [1, 0]},
...     {"id": "C", "type": "R", "links": ["k", "r"], "point": [3, 2]},
...     {"id": "D", "type": "R", "links": ["r", "f"], "point": [4, 0]}]})
>>> plan = compile_plan(mech, points=["C"])
>>> plan.describe()
['crank A: places B', 'RRR (B, C, D): places C']
>>> designs = np.stack([plan.parameters(mech)] * 3)
>>> designs[1] *= 2.0                                   # the same linkage, twice the size
>>> res = simulate_batch(plan, designs, np.arange(0.0, 360.0, 1.0))
>>> res.paths["C"].shape, bool(res.assembled.all()), res.dead_point.tolist()
((3, 360, 2), True, [False, False, False])
>>> bool(np.allclose(res.paths["C"][1], 2 * res.paths["C"][0]))
True
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.simulation import Motion, PointMotion
from mechsyn.kinematics.system import build_system
from mechsyn.model.mechanism import Mechanism

__all__ = ["BatchPlan", "BatchResult", "compile_plan", "simulate_batch", "design_parameters"]


@dataclass(frozen=True)
class BatchPlan:
    """A compiled solution plan for one topology (see the module doc).

    ``names``: the parameter points (joints then named points), each giving two
    parameters ``x, y`` in this order; ``ops``: the program (steps in solving order with
    the points each places, see :meth:`describe`);
    ``outputs``: the points whose paths are returned; ``input_joint`` and
    ``input_sign`` (+1 when the input turns the second link of the joint
    counter-clockwise relative to the first, as in the mechanism file);
    ``reference_input``: the input angle of the reference configuration in degrees,
    measured as :func:`mechsyn.kinematics.simulate` measures it.
    """

    names: tuple[str, ...]
    ops: tuple[tuple, ...]
    outputs: tuple[str, ...]
    input_joint: str
    input_sign: float
    n_dyads: int
    links: tuple[str, ...] = ()
    dyads: tuple[tuple[str, str, str], ...] = ()
    reference_input: float = 0.0
    crank_line: tuple[int, int] | None = None
    mechanism: str = field(default="", compare=False)  # the name of the mechanism it was compiled from

    def reference_inputs(self, designs: np.ndarray) -> np.ndarray:
        """Input angle (degrees) of each design's reference configuration, as
        :func:`mechsyn.kinematics.simulate` measures it: the direction of the crank's
        reference line (its first joint in file order to its first other joint), signed
        by the sense of the input joint."""
        X = np.atleast_2d(np.asarray(designs, float))
        if self.crank_line is None:
            return np.full(len(X), self.reference_input)
        a, b = self.crank_line
        d = X[:, 2 * b:2 * b + 2] - X[:, 2 * a:2 * a + 2]
        return self.input_sign * np.degrees(np.arctan2(d[:, 1], d[:, 0]))

    @property
    def n_parameters(self) -> int:
        return 2 * len(self.names)

    def parameters(self, mech: Mechanism) -> np.ndarray:
        """The parameter vector of a mechanism of this topology (its file coordinates)."""
        return design_parameters(self, mech)

    def describe(self) -> list[str]:
        """The program's steps in words, each with the points it places (the others are
        not computed)."""
        out = []
        for st in self.ops:
            placed = ", ".join(self.names[p] for p in _placed(st)) if st[0] != "mask" else ""
            if st[0] == "crank":
                out.append(f"crank {self.input_joint}")
            elif st[0] == "rrr":
                out.append(f"RRR ({', '.join(self.dyads[len(out) - 1])})")
                if st[4] is not None:
                    out[-1] += f", d from the ends on dyad {st[4][0] + 1}"
            else:
                continue
            out[-1] += f": places {placed}" if placed else ""
        return out


@dataclass
class BatchResult:
    """Paths of ``K`` designs over ``N`` inputs (see :func:`simulate_batch`)."""

    inputs: np.ndarray                      # (N,) input offsets, degrees
    paths: dict[str, np.ndarray]            # name -> (K, N, 2), NaN where not assembled
    assembled: np.ndarray                   # (K, N) bool
    dead_point: np.ndarray                  # (K,) bool: some sample not assembled
    branch_jump: np.ndarray                 # (K,) bool: a dead point stepped over between samples
    min_transmission_angle: np.ndarray | None = None   # (K,) degrees, 0..90
    sigmas: np.ndarray | None = None        # (K, n_dyads) assembly mode of each dyad (+1 / -1)
    notes: list[str] = field(default_factory=list)
    plan: BatchPlan | None = field(default=None, repr=False)
    reference_inputs: np.ndarray | None = None   # (K,) degrees: each design's drawn input (simulate's)

    @property
    def full_cycle(self) -> np.ndarray:
        """Designs assembled over the whole sweep without a stepped-over dead point."""
        return ~self.dead_point & ~self.branch_jump

    def motion(self, k: int = 0) -> Motion:
        """The rows of design ``k`` as a :class:`~mechsyn.kinematics.Motion`, the result
        every engine gives: the input joint's values as :func:`mechsyn.kinematics.simulate`
        measures them (the design's drawn input plus the offsets), the rows assembled, the
        plan's output points. The batch places positions only: the points' velocities and
        accelerations are NaN and there are no links or located events (the notes say so,
        and name a dead point or a stepped-over one).

        Examples
        --------
        >>> import mechsyn as ms
        >>> mech = ms.examples.load("crank_rocker")
        >>> plan = compile_plan(mech)
        >>> m = simulate_batch(plan, plan.parameters(mech), np.arange(0.0, 360.0, 10.0)).motion()
        >>> m.engine, m.assembled.shape, m.point("M").shape
        ('batch', (36,), (36, 2))
        """
        plan, u = self.plan, np.asarray(self.inputs, float)
        if plan is None or self.reference_inputs is None:
            raise MechsynInputError("this result keeps no plan: it was not made by simulate_batch",
                                    field="motion", hint="call simulate_batch")
        off = u[k] if u.ndim == 2 else u
        nan = np.full((off.shape[0], 2), np.nan)
        notes = ["the batch engine places positions only: velocities and accelerations are not computed (NaN); "
                 "ms.simulate gives them"]
        if self.dead_point[k]:
            notes.append("not assembled on every row: a dead point within the sweep (the batch does not locate it)")
        if self.branch_jump[k]:
            notes.append("a dead point stepped over between two rows: the rows on either side lie on different "
                         "assembly branches; refine the input step")
        return Motion(mechanism=plan.mechanism, inputs={plan.input_joint: float(self.reference_inputs[k]) + off},
                      input_types={plan.input_joint: "R"}, speeds={plan.input_joint: 1.0},
                      assembled=self.assembled[k], links={}, engine="batch", method="batch", notes=notes,
                      points={n: PointMotion(p[k], nan, nan.copy()) for n, p in self.paths.items()})


def compile_plan(mech: Mechanism, points: list[str] | None = None) -> BatchPlan:
    """Compile the batch plan of a one-input planar mechanism of R pairs.

    Parameters
    ----------
    mech : Mechanism
        Planar, R joints only, one actuated joint on the frame, decomposable into a
        crank and RRR dyads.
    points : list of str, optional
        Points whose paths are returned (named points or joint ids); default: the
        named points, or every joint when there are none.

    Raises
    ------
    MechsynInputError
        When the mechanism is not of this kind (the message names what is not).
    """
    src = mech.source or mech.name
    drv = _batch_driver(mech, src)
    names = tuple([j.id for j in mech.joints] + [p for p in mech.points if p not in {j.id for j in mech.joints}])
    index = {n: i for i, n in enumerate(names)}
    on_link: dict[str, list[str]] = {ln.name: [] for ln in mech.links}
    for j in mech.joints:
        for ln in j.links:
            on_link[ln].append(j.id)
    for p, spec in mech.points.items():
        if p in index and p not in on_link[spec.link]:
            on_link[spec.link].append(p)
    ops: list[tuple] = []
    known: dict[str, tuple[int, int] | None] = {mech.ground: None}  # link -> (anchor, second) | None
    have: set[int] = {index[j] for j in on_link[mech.ground]}
    ground_pts = tuple(sorted(have))
    crank = drv.links[1] if drv.links[0] == mech.ground else drv.links[0]
    sign = 1.0 if drv.links[0] == mech.ground else -1.0
    ops.append(("crank", index[drv.id], crank))
    known[crank] = (index[drv.id], -1)
    have.add(index[drv.id])
    used = {drv.id}

    def need(p: int, link: str) -> None:
        if p not in have:
            ops.append(("point", p, link))
            have.add(p)

    joints = {j.id: j for j in mech.joints}
    dyads = _dyad_ops(mech, joints, on_link, index, known, used, have, ops, need)
    missing = [ln.name for ln in mech.links if ln.name not in known]
    if missing:
        raise MechsynInputError(
            f"links {', '.join(missing)} are not found by a crank and RRR dyads", source=src, field="joints",
            hint="the batch engine needs a dyad-decomposable mechanism; use simulate")
    if set(joints) - used:
        raise MechsynInputError(
            f"joints {', '.join(sorted(set(joints) - used))} close extra loops (overconstrained here)",
            source=src, field="joints", hint="use simulate")
    points = _output_points(mech, points, joints, index, names, need)
    ref = _reference_input(mech)
    # the crank's reference line (simulate's link frame): first joint of the crank in file
    # order to the first other joint point
    cj = [j for j in mech.joints if crank in j.links]
    p0 = np.asarray(cj[0].point, float)
    size = float(np.ptp(np.array([j.point for j in mech.joints], float), axis=0).max())
    other = next((j for j in cj[1:] if np.linalg.norm(np.asarray(j.point, float) - p0) > 1e-12 * size), None)
    line = (index[cj[0].id], index[other.id]) if other is not None else None
    program = _schedule(ops, ground_pts, tuple(index[p] for p in points))
    return BatchPlan(names=names, ops=program, outputs=tuple(points),
                     input_joint=drv.id, input_sign=sign, n_dyads=len(dyads),
                     links=tuple(ln.name for ln in mech.links), dyads=tuple(dyads), reference_input=ref,
                     crank_line=line, mechanism=mech.name)


def _batch_driver(mech: Mechanism, src: str):
    """The one actuated joint, on the frame, of a planar mechanism of R pairs (else the
    error naming what is not so)."""
    if mech.kind != "planar":
        raise MechsynInputError("the batch engine handles planar mechanisms", source=src, field="kind")
    bad = [j.id for j in mech.joints if j.type != "R"]
    if bad:
        raise MechsynInputError(f"joint {bad[0]} is {mech.joint(bad[0]).type}: the batch engine handles R pairs",
                                source=src, field="joints", hint="use simulate for this mechanism")
    drivers = [j for j in mech.joints if j.actuated]
    if len(drivers) != 1:
        raise MechsynInputError(f"{len(drivers)} actuated joints: the batch engine needs exactly one",
                                source=src, field="joints")
    drv = drivers[0]
    if mech.ground not in drv.links:
        raise MechsynInputError(f"the actuated joint {drv.id} is not on the frame {mech.ground}",
                                source=src, field="joints", hint="drive a crank jointed to the frame")
    return drv


def _dyad_ops(mech: Mechanism, joints: dict, on_link: dict, index: dict, known: dict, used: set, have: set,
              ops: list, need) -> list[tuple[str, str, str]]:
    """RRR dyads in solving order (appended to ``ops``): links ``b1``, ``b2`` not yet
    known, joined by ``J2`` and to known links by ``J1``, ``J3``."""
    dyads: list[tuple[str, str, str]] = []
    progress = True
    while progress:
        progress = False
        for J2 in (j for j in mech.joints if j.id not in used):
            b1, b2 = J2.links
            if b1 in known or b2 in known:
                continue
            j1 = [j for j in on_link[b1] if j in joints and j not in used and j != J2.id
                  and (set(joints[j].links) - {b1}) <= set(known)]
            j3 = [j for j in on_link[b2] if j in joints and j not in used and j != J2.id
                  and (set(joints[j].links) - {b2}) <= set(known)]
            if not j1 or not j3:
                continue
            J1, J3 = j1[0], j3[0]
            k1 = (set(joints[J1].links) - {b1}).pop()
            k3 = (set(joints[J3].links) - {b2}).pop()
            need(index[J1], k1)
            need(index[J3], k3)
            ops.append(("rrr", index[J1], index[J2.id], index[J3], b1, b2))
            have.add(index[J2.id])
            known[b1] = (index[J1], index[J2.id])
            known[b2] = (index[J3], index[J2.id])
            used.update((J1, J2.id, J3))
            dyads.append((J1, J2.id, J3))
            progress = True
            break
    return dyads


def _output_points(mech: Mechanism, points: list[str] | None, joints: dict, index: dict, names: tuple,
                   need) -> list[str]:
    """The points whose paths are returned (default: the named points, else every joint),
    each placed on its link (``need``)."""
    if points is None:
        points = list(mech.points) or [j.id for j in mech.joints]
    for p in points:
        if p not in index:
            raise MechsynInputError(f"no point or joint named {p!r}", field="points",
                                    hint=f"known: {', '.join(names)}")
        link = mech.points[p].link if p in mech.points else next(
            ln for ln in joints[p].links if ln != mech.ground) if p in joints else None
        if p in joints and mech.ground in joints[p].links:
            continue  # a frame pivot: fixed
        need(index[p], link)
    return points


def _reference_input(mech: Mechanism) -> float:
    """The input value of the file's configuration as :func:`simulate` measures it."""
    S = build_system(mech)
    return float(np.degrees(S.drivers[0].assembled))


def design_parameters(plan: BatchPlan, mech: Mechanism) -> np.ndarray:
    """Coordinates ``x0, y0, x1, y1, ...`` of the plan's points in ``mech``."""
    out = np.empty(plan.n_parameters)
    for i, n in enumerate(plan.names):
        p = mech.points[n].at if n in mech.points else next(j.point for j in mech.joints if j.id == n)
        out[2 * i:2 * i + 2] = np.asarray(p, float)[:2]
    return out


def _schedule(ops: list[tuple], ground: tuple[int, ...], outputs: tuple[int, ...]) -> tuple[tuple, ...]:
    """The program :func:`simulate_batch` runs: the steps and the points each places.

    From the solving order ``ops`` (the crank, the RRR dyads and the points each needs)
    find where every point comes from: the frame, the crank, or a dyad (side 0: its
    middle joint; 1 / 2: a point of its first / second link). Then, last dyad first,
    keep only the points the outputs and the later dyads use. A dyad whose two end
    joints both lie on the links of one earlier dyad takes ``d = C - A`` from that
    dyad's ``d`` and ``w`` (``d_j = d_i (a + b w_i)``) without placing its ends, unless
    something else uses them.

    Returns ``(("crank", O, points), ("rrr", p1, p2, p3, fuse, points, shift, ok, slots)...,
    ("mask", outputs))``: ``points`` are ``(p, side)`` for a dyad; ``fuse`` is ``(i,
    side1, side3)`` or None; ``shift``: the dyad places only points of its second link
    and no later dyad uses its ``w``, so it keeps ``w - 1`` (``a + b w = 1 + b (w - 1)``
    there, a scalar instead of a per-design addition); ``ok``: 1 writes the assembled
    mask, 2 and-s into it, 0 leaves it to a later dyad whose ``d`` depends on this one
    (and is NaN where this one does not assemble); ``slots``: the work arrays of its ``d``
    and ``w`` (:func:`_buffer_slots`); ``mask`` lists the frame points among the outputs and the outputs
    that do not depend on every dyad (NaN does not reach them by itself where another
    dyad fails): they are set to NaN where the mechanism is not assembled.
    """
    src: dict[int, tuple] = {p: ("ground",) for p in ground}
    link_src: dict[str, tuple] = {}
    dyads: list[tuple[int, int, int]] = []
    crank_joint = -1
    for op in ops:
        if op[0] == "crank":
            crank_joint, link_src[op[2]] = op[1], ("crank",)
        elif op[0] == "point":
            src[op[1]] = link_src[op[2]]
        else:
            _, p1, p2, p3, b1, b2 = op
            src[p2] = ("rrr", len(dyads), 0)
            link_src[b1], link_src[b2] = ("rrr", len(dyads), 1), ("rrr", len(dyads), 2)
            dyads.append((p1, p2, p3))
    src.setdefault(crank_joint, ("ground",))
    needed = {p for p in outputs if src[p][0] != "ground"}
    steps = []
    for j in reversed(range(len(dyads))):
        p1, p2, p3 = dyads[j]
        pts = tuple(sorted((p, src[p][2]) for p in needed if src[p][:2] == ("rrr", j)))
        s1, s3 = src[p1], src[p3]
        fuse = (s1[1], s1[2], s3[2]) if s1[0] == s3[0] == "rrr" and s1[1] == s3[1] else None
        if fuse is None:
            needed.update(p for p in (p1, p3) if src[p][0] != "ground")
        elif pts:
            needed.add(p1)                       # the base of this dyad's points
        steps.append(["rrr", p1, p2, p3, fuse, pts, bool(pts) and all(sd == 2 for _, sd in pts)])
    crank_pts = tuple(sorted(p for p in needed if src[p][0] == "crank"))

    def depends(p: int) -> frozenset:
        if src[p][0] != "rrr":
            return frozenset()
        p1, _, p3 = dyads[src[p][1]]
        return frozenset({src[p][1]}) | depends(p1) | depends(p3)

    every = frozenset(range(len(dyads)))
    mask = tuple(p for p in outputs if depends(p) != every or src[p][0] == "ground")
    for st in steps:                             # w of a dyad used by a later one stays w
        if st[4] is not None:
            steps[len(dyads) - 1 - st[4][0]][6] = False
    # a dyad whose d depends on an earlier one gets NaN where that one does not assemble, so
    # the assembled mask needs the last dyads of each chain only: 1 writes it, 2 and-s into it
    upstream = frozenset().union(*(depends(p1) | depends(p3) for p1, _, p3 in dyads))
    leaves = [j for j in range(len(dyads)) if j not in upstream]
    for j in range(len(dyads)):
        steps[len(dyads) - 1 - j].append(0 if j in upstream else 1 if j == leaves[0] else 2)
    steps.reverse()
    for st, slots in zip(steps, _buffer_slots([st[4] for st in steps])):
        st.append(slots)
    return (("crank", crank_joint, crank_pts),) + tuple(tuple(st) for st in steps) + (("mask", mask),)


def _buffer_slots(fuses: list) -> list[tuple[int, int]]:
    """Work-array slots ``(d, w)`` of each dyad (``fuses``: each dyad's ``fuse``, in
    solving order): a dyad's ``d`` and ``w`` live until the last dyad that takes its ``d``
    from them has its own ``d``; then their slots serve later dyads (fewer arrays in the
    cache)."""
    last = list(range(len(fuses)))
    for j, fuse in enumerate(fuses):
        if fuse is not None:
            last[fuse[0]] = max(last[fuse[0]], j)
    free: list[int] = []
    n_slots = 0
    slots: list[tuple[int, int]] = []

    def take() -> int:
        nonlocal n_slots
        if free:
            return free.pop()
        n_slots += 1
        return n_slots - 1

    for j in range(len(fuses)):
        d = take()
        for i in range(j):                    # read by this d for the last time
            if last[i] == j:
                free.extend(slots[i])
        slots.append((d, take()))
        if last[j] == j:
            free.extend(slots[j])
    return slots


def simulate_batch(plan: BatchPlan, designs: np.ndarray, inputs: np.ndarray,
                   transmission: bool = False, flags: bool = True) -> BatchResult:
    """Point paths of ``K`` designs of one topology over ``N`` input offsets.

    Only the points the requested outputs and the dyads need are placed (the plan's
    program, see :func:`compile_plan`), and the designs are run in blocks small enough
    for their work arrays to stay in the processor's cache.

    Parameters
    ----------
    plan : BatchPlan
        From :func:`compile_plan`.
    designs : (K, P) array
        Reference coordinates of the plan's points (``plan.names``), ``x, y`` each.
    inputs : (N,) or (K, N) array
        Input offsets from the reference configuration, degrees, in the file's sense of
        the input joint (one row per design when 2-D).
    transmission : bool
        Also give the minimum transmission angle of each design (degrees).
    flags : bool
        Compute the ``branch_jump`` flags (a few extra array passes).

    Returns
    -------
    BatchResult
        ``paths[name]`` ``(K, N, 2)``, ``assembled`` ``(K, N)``, per-design flags.
    """
    designs = np.asarray(designs, dtype=float)
    if designs.ndim == 1:
        designs = designs[None, :]
    if designs.shape[1] != plan.n_parameters:
        raise MechsynInputError(f"designs have {designs.shape[1]} parameters, the plan {plan.n_parameters}",
                                source="designs", hint="one column per coordinate of plan.names")
    u = np.radians(np.asarray(inputs, dtype=float))
    X = designs[:, 0::2] + 1j * designs[:, 1::2]          # (K, M) reference points
    K, N = len(X), u.shape[-1]
    if u.ndim == 2 and u.shape[0] != K:
        raise MechsynInputError(f"inputs have {u.shape[0]} rows for {K} designs", source="inputs")
    index = {n: i for i, n in enumerate(plan.names)}
    paths = {name: np.empty((K, N, 2)) for name in plan.outputs}
    out = {index[name]: paths[name].view(complex)[..., 0] for name in plan.outputs}
    run = _Run(plan, X, u, out, transmission, flags and N >= 3)
    kc = max(1, _BLOCK // max(N, 1))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for k0 in range(0, K, kc):
            run.block(k0, min(K, k0 + kc))
    mu = None
    if transmission:
        mu = np.degrees(np.arcsin(np.clip(np.where(np.isfinite(run.sin_mu), run.sin_mu, np.nan), 0, 1)))
    sig = np.stack([c[2] for c in run.dyad_consts], axis=1) if run.dyad_consts else np.zeros((K, 0))
    return BatchResult(inputs=np.asarray(inputs, float), paths=paths, assembled=run.ok,
                       dead_point=~run.ok.all(axis=1), branch_jump=run.jump, min_transmission_angle=mu,
                       sigmas=sig, plan=plan, reference_inputs=plan.reference_inputs(designs))


_BLOCK = 1 << 14
"""Samples (designs x inputs) per block of :func:`simulate_batch`: a complex work array
of a block is 256 kB, so the arrays of a six-bar (three for the two dyads' ``d`` and
``w``, a placed point, three real work arrays, the output) stay within a 2 MB level-2
cache. Measured
(benchmarks/batch.py cases, load 2): 16k samples ran the Watt six-bar 4-7 % faster than
32k and the four-bar as fast; 8k and 64k were slower."""


class _Run:
    """The state of one :func:`simulate_batch` call: per-design constants of the
    program (``(K, 1)`` columns), the work arrays of one block (reused from block to
    block) and the results filled block by block."""

    def __init__(self, plan: BatchPlan, X: np.ndarray, u: np.ndarray, out: dict, transmission: bool,
                 flags: bool) -> None:
        K, N = len(X), u.shape[-1]
        self.plan, self.X, self.out, self.flags = plan, X, out, flags
        self.ok = np.ones((K, N), dtype=bool)
        self.jump = np.zeros(K, dtype=bool)
        self.sin_mu = np.full(K, np.inf) if transmission else None
        s = plan.input_sign
        self.rot = np.exp(1j * s * u)[None, :] if u.ndim == 1 else None
        self.u = u if u.ndim == 2 else None
        with np.errstate(divide="ignore", invalid="ignore"):
            self.dyad_consts, self.point_consts = _constants(plan.ops, X)
        kc = min(K, max(1, _BLOCK // max(N, 1)))
        n_slots = 1 + max((max(st[8]) for st in plan.ops if st[0] == "rrr"), default=-1)
        placed = [p for st in plan.ops if st[0] != "mask" for p in _placed(st) if p not in out]
        pool = [np.empty((kc, N), complex) for _ in range(n_slots)]
        self.d = [pool[st[8][0]] for st in plan.ops if st[0] == "rrr"]
        self.w = [pool[st[8][1]] for st in plan.ops if st[0] == "rrr"]
        self.pts = {p: np.empty((kc, N), complex) for p in placed}
        self.disc = np.empty((kc, N))

    def block(self, k0: int, k1: int) -> None:
        """Run the program on designs ``k0:k1``."""
        n = k1 - k0
        X, pos = self.X, {}

        def at(p: int) -> np.ndarray:
            return pos[p] if p in pos else X[k0:k1, p, None]

        def dest(p: int) -> np.ndarray:
            pos[p] = self.out[p][k0:k1] if p in self.out else self.pts[p][:n]
            return pos[p]

        j = 0
        for st in self.plan.ops:
            if st[0] == "crank":
                rot = self.rot if self.u is None else np.exp(1j * self.plan.input_sign * self.u[k0:k1])
                for p in st[2]:
                    z = np.multiply(self.point_consts[p][1][k0:k1], rot, out=dest(p))
                    z += X[k0:k1, st[1], None]
            elif st[0] == "rrr":
                self._dyad(st, j, k0, k1, at, dest)
                j += 1
            else:
                ok = self.ok[k0:k1]
                for p in st[1]:
                    z = self.out[p][k0:k1]
                    if p not in pos:              # a frame point
                        z[...] = at(p)
                    z[~ok] = complex(np.nan, np.nan)

    def _dyad(self, st: tuple, j: int, k0: int, k1: int, at, dest) -> None:
        """One RRR dyad on a block: ``d``, then ``w``, then the points of its links."""
        _, p1, p2, p3, fuse, pts, shift, mode, _ = st
        n = k1 - k0
        d = self.d[j][:n]
        if fuse is None:
            np.subtract(at(p3), at(p1), out=d)
        else:                                     # d = d_i (a + b w_i)
            a, b = self.point_consts[("d", j)]
            np.multiply(self.w[fuse[0]][:n], b[k0:k1], out=d)
            d += a[k0:k1]
            d *= self.d[fuse[0]][:n]
        w = self._w(j, d, k0, k1, shift, mode)
        A = at(p1)
        for p, side in pts:                       # p = A + d (a + b w)
            z = dest(p)
            if side == 0:
                np.multiply(d, w, out=z)          # B - A
            else:
                a, b = self.point_consts[p]
                np.multiply(w, b[k0:k1], out=z)
                if shift:                         # a + b w = 1 + b (w - 1) on the second link
                    z += 1.0
                elif side == 2:
                    z += a[k0:k1]
                z *= d
            z += A

    def _w(self, j: int, d: np.ndarray, k0: int, k1: int, shift: bool, mode: int) -> np.ndarray:
        """``w = alpha + i sigma beta`` of dyad ``j`` (``w - 1`` when ``shift``) from ``d``
        on a block, by the kernel's circle intersection
        (:func:`mechsyn.kinematics._kernel_numba.batch_dyad`); the assembled mask, the
        flags and the transmission angle on the way."""
        n = k1 - k0
        L1s, L2s, sigma, L12 = (c[k0:k1] for c in self.dyad_consts[j])
        w, disc = self.w[j][:n], self.disc[:n] if self.flags else _NO_DISC
        sin_mu = self.sin_mu[k0:k1] if self.sin_mu is not None else _NONE
        importlib.import_module("mechsyn.kinematics._kernel_numba").batch_dyad(
            d, L1s, L2s, sigma, L12, 1.0 if shift else 0.0, mode, self.ok[k0:k1], w, disc, sin_mu)
        if self.flags:
            self.jump[k0:k1] |= _stepped_over(disc)
        return w


_NONE, _NO_DISC = np.zeros(0), np.zeros((0, 0))


def _placed(step: tuple) -> list[int]:
    """The points a step of the program places."""
    if step[0] == "crank":
        return list(step[2])
    return [p for p, _ in step[5]]


def _constants(program: tuple, X: np.ndarray) -> tuple[list, dict]:
    """Per-design constants of the program: per dyad ``L1^2``, ``L2^2``, the assembly
    mode ``sigma`` and ``L1 L2`` (K,); per placed point as ``(K, 1)`` columns ``(a, b)`` with the point at ``A + d (a + b w)`` (crank points: ``(None, p0 - O)``);
    per fused dyad ``("d", j)`` the ``(a, b)`` of its ``d``."""
    dyads, points = [], {}
    geo = []
    for st in program:
        if st[0] == "crank":
            for p in st[2]:
                points[p] = (None, (X[:, p] - X[:, st[1]])[:, None])
        elif st[0] == "rrr":
            p1, p2, p3, fuse, pts = st[1:6]
            r1, r3 = X[:, p2] - X[:, p1], X[:, p2] - X[:, p3]
            L1s, L2s = (r1 * r1.conj()).real, (r3 * r3.conj()).real
            sigma = np.where(((X[:, p3] - X[:, p1]).conj() * r1).imag >= 0, 1.0, -1.0)
            dyads.append((L1s, L2s, sigma, np.sqrt(L1s * L2s)))
            geo.append((p1, p3, r1, r3))
            for p, side in pts:
                points[p] = tuple(c[:, None] for c in _side(X, geo[-1], p, side))
            if fuse is not None:
                a1, b1 = _side(X, geo[fuse[0]], p1, fuse[1])
                a3, b3 = _side(X, geo[fuse[0]], p3, fuse[2])
                points[("d", len(dyads) - 1)] = ((a3 - a1)[:, None], (b3 - b1)[:, None])
    return dyads, points


def _side(X: np.ndarray, geo: tuple, p: int, side: int) -> tuple[np.ndarray, np.ndarray]:
    """``(a, b)`` of point ``p`` on a dyad (``A``, ``C`` its ends, ``B`` its middle
    joint): ``p = A + d (a + b w)`` with ``d = C - A`` and ``B = A + d w``; on the
    first link ``p = A + (B - A) r``, on the second ``p = C + (B - C) r`` with ``r``
    the reference ratio ``(p0 - A0) / (B0 - A0)`` (or with ``C``)."""
    p1, p3, r1, r3 = geo
    K = len(X)
    if side == 0:
        return np.zeros(K, complex), np.ones(K, complex)
    if side == 1:
        return np.zeros(K, complex), (X[:, p] - X[:, p1]) / r1
    r = (X[:, p] - X[:, p3]) / r3
    return 1.0 - r, r


def _stepped_over(b: np.ndarray) -> np.ndarray:
    """Per row: a local minimum of ``b`` whose parabola through it and its two
    neighbours goes below zero (a zero of the discriminant between samples).

    The parabola is evaluated at the positive local minima only (a few per row), not
    over the whole array.
    """
    lo, mid, hi = b[:, :-2], b[:, 1:-1], b[:, 2:]
    cand = np.less_equal(mid, lo)
    cand &= np.less_equal(mid, hi)
    cand &= np.greater(mid, 0)
    r, c = np.divmod(np.flatnonzero(cand), cand.shape[1])   # (flat: faster than nonzero)
    lo, mid, hi = b[r, c], b[r, c + 1], b[r, c + 2]
    curv = hi - 2 * mid + lo
    with np.errstate(invalid="ignore", divide="ignore"):
        vmin = mid - (hi - lo) ** 2 / (8 * curv)
    out = np.zeros(len(b), dtype=bool)
    out[r[(curv > 0) & (vmin < 0)]] = True
    return out
