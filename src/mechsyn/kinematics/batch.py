"""Batch kinematics: many designs of one topology over many input values in one call.

A *plan* is compiled once from a mechanism (a crank on the frame, then RRR dyads in
solving order: Assur groups of class II, Artobolevsky, *Theory of Mechanisms and
Machines*, ch. 4); the *parameters* of a design are the coordinates of its joints and
named points in its reference configuration (input offset 0). :func:`simulate_batch`
then evaluates ``K`` designs (a ``K x P`` array) over ``N`` input offsets, with planar
points as complex numbers:

* crank about ``O`` (joint on the frame): a point ``p`` of the crank is at
  ``O + (p0 - O) exp(i s u)`` (``s`` the sense of the input joint);
* RRR dyad with known end joints ``A``, ``C`` and lengths ``L1 = |B0 - A0|``,
  ``L2 = |B0 - C0|``: with ``d = C - A``, ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)`` and
  ``g^2 = L1^2 / |d|^2 - f^2``, ``B = A + d (f + i sigma g)`` (the kernel's one circle
  intersection, :func:`mechsyn.kinematics._kernel_numba.circle`); ``sigma`` is the
  assembly mode of the reference configuration (sign of ``(C0 - A0) x (B0 - A0)``),
  kept over the whole sweep;
* any other point ``p`` of a link is ``P_a + z (p0 - a0)``, ``P_a`` the link's anchor
  joint and ``z`` the link's rotation from its reference configuration.

Where ``g^2 < 0`` the dyad cannot be assembled: the sample is NaN and not
``assembled``. Per design the result flags a ``dead_point`` (some sample of the sweep is
not assembled: the input cannot run through the whole range) and a ``branch_jump`` (a
dyad's normalised discriminant ``g^2 |d|^2 / L1^2`` has a positive local minimum whose
parabola through the two neighbouring samples dips below zero: the sampled sweep stepped
over a dead point, so the points on either side lie on different assembly branches), and
gives the minimum transmission angle of the RRR dyads (``sin mu = |d| g / L2``, the
angle at the middle joint).

The answers equal :func:`mechsyn.kinematics.simulate` on the same mechanism with the
input ``reference + offset`` (tests check it on sampled designs).

How it is run: the plan is the regular pass's program
(:func:`mechsyn.kinematics.kernel.program`: drive ops and RRR group ops, built once for
the topology, :func:`mechsyn.kinematics.kernel.layout`). Each design's numbers (squared
lengths, drawn assembly modes, rotation vectors, local points) are filled for all ``K``
designs at once by the kernel's one fill (:func:`mechsyn.kinematics.kernel.numbers`),
in each design's reference frame: a link's local points are its points' reference
coordinates, so its rotation is 1 at offset 0 and the crank turns by the offset itself.
One compiled pass (:func:`mechsyn.kinematics._kernel_numba.batch_pass`) then runs the
program's ops design by design over the input rows, positions only (the regular
pass's placement, :func:`mechsyn.kinematics._kernel_numba._positions`), writing only
the link rotations and joints the outputs need (``keep``, found once by
:func:`compile_plan`: a store per row is a fifth of the pass), and from the same pass's
discriminants and joints the assembled rows, the flags, the transmission angle and the
named output points (NaN where the mechanism is not assembled).

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
['crank A', 'RRR (B, C, D)']
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
from mechsyn.kinematics import kernel
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.kinematics.simulation import Motion, PointMotion
from mechsyn.model.mechanism import Mechanism

__all__ = ["BatchPlan", "BatchResult", "compile_plan", "simulate_batch", "design_parameters"]


@dataclass(frozen=True)
class BatchPlan:
    """A compiled solution plan for one topology (see the module doc).

    ``names``: the parameter points (joints then named points), each giving two
    parameters ``x, y`` in this order; ``program``: the regular pass's program of the
    topology (its integers, the table its numbers are filled by, the parameter points of
    its (link, joint) pairs, its groups' steps, the outputs' links and parameter points);
    ``outputs``: the points whose paths are returned; ``input_joint`` and
    ``input_sign`` (+1 when the input turns the second link of the joint
    counter-clockwise relative to the first, as in the mechanism file); ``dyads``: the
    RRR groups' joints in solving order; ``reference_input``: the input angle of the
    reference configuration in degrees, measured as :func:`mechsyn.kinematics.simulate`
    measures it.
    """

    names: tuple[str, ...]
    program: tuple = field(compare=False, repr=False)
    outputs: tuple[str, ...] = ()
    input_joint: str = ""
    input_sign: float = 1.0
    n_dyads: int = 0
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
        """The program's steps in words: the crank, then the RRR dyads in solving order."""
        return [f"crank {self.input_joint}"] + [f"RRR ({', '.join(d)})" for d in self.dyads]


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
    kp = cached_plan(mech)
    S, plan = kp.system, kp.groups
    if plan is None or not plan.closed_form_rates:
        raise MechsynInputError("the mechanism is not solved by a crank and RRR dyads in closed form", source=src,
                                field="joints", hint="the batch engine needs a dyad-decomposable mechanism; use simulate")
    _, pj, (ip, anc_j, _, nj, groups), (fi, anc_p), _ = kernel.layout(S, plan)
    points = list(mech.points) or [j.id for j in mech.joints] if points is None else list(points)
    for p in points:
        if p not in index:
            raise MechsynInputError(f"no point or joint named {p!r}", field="points", hint=f"known: {', '.join(names)}")
    on = [S.index(mech.points[p].link) if p in mech.points else
          max((S.index(ln) for ln in mech.joint(p).links), default=-1) for p in points]  # a frame pivot: -1, fixed
    # the crank's reference line (simulate's link frame): its first joint in file order to the first other joint
    crank = drv.links[1] if drv.links[0] == mech.ground else drv.links[0]
    cj = [j for j in mech.joints if crank in j.links]
    p0 = np.asarray(cj[0].point, float)
    size = float(np.ptp(np.array([j.point for j in mech.joints], float), axis=0).max())
    other = next((j for j in cj[1:] if np.linalg.norm(np.asarray(j.point, float) - p0) > 1e-12 * size), None)
    # what the outputs need: their links, the links later joints are placed from, those links' anchors and
    # every group's end joints (the rest is not written)
    links = sorted(({*on} | {st[2] for st in ip if st[0] == 0} | {st[1] for st in ip if st[0] and st[8]}
                    | {st[2] for st in ip if st[0] and st[9]}) - {-1})
    keep = np.zeros(len(anc_j) + nj, np.int8)
    keep[links] = 1
    keep[len(anc_j) + np.r_[anc_j[links], ip[groups][:, [5, 7]].ravel()].astype(int)] = 1
    prog = (ip, anc_j, nj, fi, anc_p, np.array(pj, np.int64), groups, np.array(on, np.int64),
            np.array([index[p] for p in points], np.int64), keep)
    dyads = tuple(plan.steps[k].joints for k in groups)
    return BatchPlan(names=names, program=prog, outputs=tuple(points), input_joint=drv.id,
                     input_sign=1.0 if drv.links[0] == mech.ground else -1.0, n_dyads=len(dyads),
                     links=tuple(ln.name for ln in mech.links), dyads=dyads,
                     reference_input=float(np.degrees(S.drivers[0].assembled)),
                     crank_line=(index[cj[0].id], index[other.id]) if other is not None else None,
                     mechanism=mech.name)


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


def design_parameters(plan: BatchPlan, mech: Mechanism) -> np.ndarray:
    """Coordinates ``x0, y0, x1, y1, ...`` of the plan's points in ``mech``."""
    out = np.empty(plan.n_parameters)
    for i, n in enumerate(plan.names):
        p = mech.points[n].at if n in mech.points else next(j.point for j in mech.joints if j.id == n)
        out[2 * i:2 * i + 2] = np.asarray(p, float)[:2]
    return out


def simulate_batch(plan: BatchPlan, designs: np.ndarray, inputs: np.ndarray,
                   transmission: bool = False, flags: bool = True) -> BatchResult:
    """Point paths of ``K`` designs of one topology over ``N`` input offsets.

    The plan's program is run by one compiled pass over the designs and the inputs
    (see the module doc).

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
        Compute the ``branch_jump`` flags (one more loop over each group's rows).

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
    X = np.ascontiguousarray(designs).view(complex)          # (K, M) reference points
    K, N = len(X), u.shape[-1]
    if u.ndim == 2 and u.shape[0] != K:
        raise MechsynInputError(f"inputs have {u.shape[0]} rows for {K} designs", source="inputs")
    ip, anc_j, nj, fi, anc_p, pairs, groups, out_l, out_p, keep = plan.program
    P = np.empty((len(out_l), K, N), complex)
    ok, jump = np.empty((K, N), bool), np.zeros(K, bool)
    sin_mu = np.full(K, np.inf) if transmission else _NONE
    CS, SN = (a[None] for a in kernel.trig([u[:, None]])) if u.ndim == 1 else (np.cos(u)[..., None],
                                                                               np.sin(u)[..., None])
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        fp, anc_s = kernel.numbers((fi, anc_p), X[:, pairs], X)
        importlib.import_module("mechsyn.kinematics._kernel_numba").batch_pass(
            ip, fp, anc_j, anc_s, nj, keep, CS, SN, out_l, X[:, out_p], P, ok, jump, sin_mu, flags and N >= 3)
    mu = None
    if transmission:
        mu = np.degrees(np.arcsin(np.clip(np.where(np.isfinite(sin_mu), sin_mu, np.nan), 0, 1)))
    paths = {name: P[i].view(float).reshape(K, N, 2) for i, name in enumerate(plan.outputs)}
    return BatchResult(inputs=np.asarray(inputs, float), paths=paths, assembled=ok, dead_point=~ok.all(axis=1),
                       branch_jump=jump, min_transmission_angle=mu, sigmas=fp[:, groups, 2].real.copy(), plan=plan,
                       reference_inputs=plan.reference_inputs(designs))


_NONE = np.zeros(0)
