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
  ``B = A + d (alpha + i sigma beta)``; ``sigma`` is the assembly mode of the reference
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
>>> designs = np.stack([plan.parameters(mech)] * 3)
>>> designs[1] *= 2.0                                   # the same linkage, twice the size
>>> res = simulate_batch(plan, designs, np.arange(0.0, 360.0, 1.0))
>>> res.paths["C"].shape, bool(res.assembled.all()), res.dead_point.tolist()
((3, 360, 2), True, [False, False, False])
>>> bool(np.allclose(res.paths["C"][1], 2 * res.paths["C"][0]))
True
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.model.mechanism import Mechanism

__all__ = ["BatchPlan", "BatchResult", "compile_plan", "simulate_batch", "design_parameters"]


@dataclass(frozen=True)
class BatchPlan:
    """A compiled solution plan for one topology (see the module doc).

    ``names``: the parameter points (joints then named points), each giving two
    parameters ``x, y`` in this order; ``ops``: the kernels in solving order;
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
        out = [f"crank {self.input_joint}"]
        out += [f"RRR ({', '.join(d)})" for d in self.dyads]
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

    @property
    def full_cycle(self) -> np.ndarray:
        """Designs assembled over the whole sweep without a stepped-over dead point."""
        return ~self.dead_point & ~self.branch_jump


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
    other = next((j for j in cj[1:] if np.linalg.norm(np.asarray(j.point, float) - p0) > 1e-12), None)
    line = (index[cj[0].id], index[other.id]) if other is not None else None
    return BatchPlan(names=names, ops=tuple([("ground", ground_pts)] + ops), outputs=tuple(points),
                     input_joint=drv.id, input_sign=sign, n_dyads=len(dyads),
                     links=tuple(ln.name for ln in mech.links), dyads=tuple(dyads), reference_input=ref,
                     crank_line=line)


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
    from mechsyn.kinematics.system import build_system

    S = build_system(mech)
    return float(np.degrees(S.drivers[0].assembled))


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
    pos: dict[int, np.ndarray] = {}
    links: dict[str, tuple[np.ndarray, np.ndarray, int, np.ndarray | complex]] = {}
    ok = np.ones((K, N), dtype=bool)
    jump = np.zeros(K, dtype=bool)
    sigmas = []
    sin_mu = np.full(K, np.inf) if transmission else None
    for op in plan.ops:
        kind = op[0]
        if kind == "ground":
            for p in op[1]:
                pos[p] = X[:, p, None]
        elif kind == "crank":
            _, p, link = op
            rot = np.exp(1j * plan.input_sign * u)
            links[link] = (X[:, p, None], rot if rot.ndim == 2 else rot[None, :], p, 1.0 + 0j)
        elif kind == "point":
            _, p, link = op
            anchor, vec, a, ref = links[link]
            if callable(vec):
                vec = vec()
                links[link] = (anchor, vec, a, ref)
            P = vec * ((X[:, p] - X[:, a]) / ref)[:, None]  # (K, N): the anchor added in place
            P += anchor
            pos[p] = P
        else:  # rrr
            _, p1, p2, p3, b1, b2 = op
            A, C = pos[p1], pos[p3]
            r1, r3 = X[:, p2] - X[:, p1], X[:, p2] - X[:, p3]
            L1s, L2s = (r1 * r1.conj()).real, (r3 * r3.conj()).real
            d0 = X[:, p3] - X[:, p1]
            sigma = np.where((d0.conj() * r1).imag >= 0, 1.0, -1.0)
            sigmas.append(sigma)
            B, dw, beta, inv, good = _rrr(A, C, L1s, L2s, sigma, flags and N >= 3, jump)
            ok &= good
            pos[p2] = B
            links[b1] = (A, dw, p1, r1)
            links[b2] = (C, (lambda B=B, C=C: B - C), p3, r3)
            if transmission:
                with np.errstate(invalid="ignore", divide="ignore"):
                    s = beta / (inv * np.sqrt(L1s * L2s)[:, None])
                sin_mu = np.fmin(sin_mu, np.nanmin(np.where(good, s, np.inf), axis=1))
    paths = {}
    for name in plan.outputs:
        p = plan.names.index(name)
        z = np.array(np.broadcast_to(pos[p], (K, N)), dtype=complex, order="C")
        z[~ok] = complex(np.nan, np.nan)
        P = z.view(float).reshape(K, N, 2)
        paths[name] = P
    mu = None
    if transmission:
        mu = np.degrees(np.arcsin(np.clip(np.where(np.isfinite(sin_mu), sin_mu, np.nan), 0, 1)))
    return BatchResult(inputs=np.asarray(inputs, float), paths=paths, assembled=ok,
                       dead_point=~ok.all(axis=1), branch_jump=jump, min_transmission_angle=mu,
                       sigmas=np.stack(sigmas, axis=1) if sigmas else np.zeros((K, 0)))


def _rrr(A: np.ndarray, C: np.ndarray, L1s: np.ndarray, L2s: np.ndarray, sigma: np.ndarray, flags: bool,
         jump: np.ndarray) -> tuple:
    """The RRR kernel on (K, N) complex end points: ``B``, ``B - A``, the height ratio
    ``sigma beta`` (NaN where the dyad does not assemble), ``1 / |d|^2`` and the mask of
    assembled samples; ``jump`` or-ed with the stepped-over dead points when ``flags``.
    Written with few temporaries: each is a (K, N) array pass."""
    d = C - A
    inv = d.real * d.real
    tmp = d.imag * d.imag                      # a (K, N) scratch array, used twice
    inv += tmp
    with np.errstate(divide="ignore", invalid="ignore"):
        np.divide(1.0, inv, out=inv)
        alpha = inv * (0.5 * (L1s - L2s))[:, None]
        alpha += 0.5
        beta = inv * L1s[:, None]
        beta -= np.multiply(alpha, alpha, out=tmp)  # beta^2
        good = beta >= 0
        if flags:
            jump |= _stepped_over(beta / (inv * np.maximum(L1s, 1e-300)[:, None]))
        np.sqrt(beta, out=beta)                # NaN where the dyad does not assemble
    beta *= sigma[:, None]
    w = np.empty(d.shape, complex)
    w.real, w.imag = alpha, beta
    dw = np.multiply(d, w, out=w)              # B - A
    return A + dw, dw, beta, inv, good


def _stepped_over(b: np.ndarray) -> np.ndarray:
    """Per row: a local minimum of ``b`` whose parabola through it and its two
    neighbours goes below zero (a zero of the discriminant between samples)."""
    lo, mid, hi = b[:, :-2], b[:, 1:-1], b[:, 2:]
    curv = hi - 2 * mid + lo
    with np.errstate(invalid="ignore", divide="ignore"):
        vmin = mid - (hi - lo) ** 2 / (8 * curv)
        hit = (mid <= lo) & (mid <= hi) & (curv > 0) & (vmin < 0) & (mid > 0)
    return hit.any(axis=1)
