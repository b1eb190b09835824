"""A population of finger designs in the fully actuated mode, evaluated at once.

With every VLL locked, a cylinder-piston pair is one rigid binary link
(:func:`~mechsyn.synthesis.finger.vll.locked_model`) and the finger is a crank and RRR
dyads: the topology is the same for every design of a case, only the drawn coordinates
change. :func:`locked_population` compiles it once with
:func:`mechsyn.kinematics.batch.compile_plan`; :meth:`LockedPopulation.evaluate` maps
``K`` design vectors to the plan's parameters (joint and point coordinates, each VLL's
piston pivot ``L = K + l (cos a, sin a)`` as :func:`~mechsyn.synthesis.finger.evaluation.apply_design`
draws it) and solves all of them over the crank grid in whole-array passes
(:func:`mechsyn.kinematics.batch.simulate_batch`, assembly modes of the drawn
configuration, as the one-design closed form).

The evaluation is :func:`~mechsyn.synthesis.finger.evaluation.evaluate_locked`'s, term for
term: not assembled at ``n`` crank angles gives violation ``n``; otherwise the phalanx
rotations from the drawn configuration at the targets (each link's rotation from two of
its points, followed continuously along the crank grid), their RMS and largest error
(deg), and the distance by which the output paths leave the region. Tests check both
agree; a case it cannot compile (a P pair besides the VLL, a variable on a VLL's own
joint, a phalanx with fewer than two points) keeps the one-design path.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.batch import compile_plan, simulate_batch
from mechsyn.synthesis.finger.evaluation import apply_design
from mechsyn.synthesis.finger.vll import locked_model, points_in_region, region_excess, vll_ends

__all__ = ["LockedPopulation", "PopulationEvaluation", "locked_population"]


@dataclass
class PopulationEvaluation:
    """``K`` designs in the fully actuated mode (see :meth:`LockedPopulation.evaluate`)."""

    feasible: np.ndarray          # (K,) assembled over the crank grid and inside the region
    violation: np.ndarray         # (K,) 0 when feasible
    error_rms: np.ndarray         # (K,) deg (inf where not assembled)
    error_max: np.ndarray         # (K,) deg
    paths: dict[str, np.ndarray]  # output point -> (K, N, 2)


@dataclass
class _Vll:
    """Columns of one VLL's cylinder pivot K and piston pivot L in the plan's parameters."""

    pivot_k: int
    pivot_l: int
    drawn: np.ndarray          # the file's P point (direction and drawn length from K)
    angle: int                 # design-vector column of its direction, -1: the drawn one
    minimum: float | None      # l_min when the combination holds it, None: the drawn length


class LockedPopulation:
    """The compiled locked model of a case and a VLL combination (see the module doc)."""

    def __init__(self, case: Any, plan: Any, base: np.ndarray, columns: list[tuple[int, int]],
                 vlls: list[_Vll], link_points: dict[str, tuple[int, int]]) -> None:
        self.case, self.plan, self.base = case, plan, base
        self.columns, self.vlls, self.link_points = columns, vlls, link_points
        grid = case.sweep_inputs
        self.grid = grid
        self.targets = np.searchsorted(grid, case.target_inputs)
        self.zero = int(np.searchsorted(grid, 0.0))

    def designs(self, X: np.ndarray) -> np.ndarray:
        """The plan's parameters (K, P) of the design vectors ``X`` (K, n_variables)."""
        X = np.atleast_2d(np.asarray(X, float))
        P = np.tile(self.base, (len(X), 1))
        for i, col in self.columns:
            P[:, col] = X[:, i]
        for v in self.vlls:
            pk = P[:, 2 * v.pivot_k:2 * v.pivot_k + 2]
            u = v.drawn[None, :] - pk
            ang = np.radians(X[:, v.angle]) if v.angle >= 0 else np.arctan2(u[:, 1], u[:, 0])
            length = v.minimum if v.minimum is not None else np.linalg.norm(u, axis=1)
            P[:, 2 * v.pivot_l] = pk[:, 0] + length * np.cos(ang)
            P[:, 2 * v.pivot_l + 1] = pk[:, 1] + length * np.sin(ang)
        return P

    def evaluate(self, X: np.ndarray) -> PopulationEvaluation:
        """Assembly, target errors and region of every design of ``X`` (K, n_variables)."""
        P = self.designs(X)
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            res = simulate_batch(self.plan, P, self.grid, flags=False)
        K = len(P)
        bad = np.sum(~res.assembled, axis=1)
        assembled = bad == 0
        errs = [self._rotation(res.paths, P, link)[:, self.targets] - tgt[None, :]
                for link, tgt in self.case.target_angles.items()]
        e = np.concatenate(errs, axis=1)
        with np.errstate(invalid="ignore"):
            rms = np.where(assembled, np.sqrt(np.mean(e ** 2, axis=1)), np.inf)
            emax = np.where(assembled, np.max(np.abs(e), axis=1), np.inf)
        violation = bad.astype(float)
        paths = {p: res.paths[p] for p in self.case.points}
        outside = np.zeros(K, bool)
        for arr in paths.values():
            inside = points_in_region(arr.reshape(-1, 2), self.case.region).reshape(K, -1)
            outside |= ~inside.all(axis=1)
        for k in np.flatnonzero(outside & assembled):
            violation[k] = sum(region_excess(arr[k], self.case.region) for arr in paths.values())
        return PopulationEvaluation(feasible=violation == 0, violation=violation, error_rms=rms,
                                    error_max=emax, paths=paths)

    def _rotation(self, paths: dict[str, np.ndarray], P: np.ndarray, link: str) -> np.ndarray:
        """Rotation (K, N) of ``link`` from the drawn configuration, deg, followed along the grid."""
        a, b = self.link_points[link]
        na, nb = self.plan.names[a], self.plan.names[b]
        d = paths[nb] - paths[na]
        ang = np.unwrap(np.arctan2(d[..., 1], d[..., 0]), axis=1)
        d0 = P[:, 2 * b:2 * b + 2] - P[:, 2 * a:2 * a + 2]
        at_zero = ang[:, self.zero] - np.arctan2(d0[:, 1], d0[:, 0])
        at_zero = np.mod(at_zero + np.pi, 2 * np.pi) - np.pi     # 0 up to round-off
        return np.degrees(ang - ang[:, self.zero, None] + at_zero[:, None])


def locked_population(case: Any, combo: tuple[str, ...]) -> LockedPopulation | None:
    """The compiled locked model of ``case`` for the VLL combination ``combo`` (empty:
    every VLL at its minimum), or None when the case needs the one-design path.

    Parameters
    ----------
    case : FingerCase
        From :func:`mechsyn.synthesis.finger.cases.load_case`.
    combo : tuple of str
        The VLL held at their minimum constructible length.

    Returns
    -------
    LockedPopulation or None

    Examples
    --------
    >>> import numpy as np
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.finger.cases import load_case
    >>> case = load_case(ms.examples.path("finger_design_case"))
    >>> pop = locked_population(case, ("S",))
    >>> X = np.array([[14.0, 6.0, 8.0, 48.0, 123.69006753],   # the reference finger
    ...               [20.0, 12.0, 3.0, 42.0, 150.0]])        # does not assemble
    >>> ev = pop.evaluate(X)
    >>> ev.feasible.tolist(), bool(ev.error_rms[0] < 0.01), bool(ev.violation[1] > 0)
    ([True, False], True, True)
    """
    x0 = np.array([0.5 * (v.bounds[0] + v.bounds[1]) for v in case.variables])
    vll_ids = [j["id"] for j in case.mech_dict["joints"] if j.get("vll")]
    if any(v.kind == "joint" and v.target in vll_ids for v in case.variables):
        return None
    try:
        d = locked_model(apply_design(case, x0, combo or None), vll_ids, case.source)
        mech = mechanism_from_dict(d, source=case.source)
        link_points = {}
        for link in case.target_angles:
            pts = [j.id for j in mech.joints if link in j.links] + [
                p for p, spec in mech.points.items() if spec.link == link]
            if len(pts) < 2:
                return None
            link_points[link] = pts[:2]
        outputs = list(dict.fromkeys(list(case.points) + [p for ps in link_points.values() for p in ps]))
        plan = compile_plan(mech, points=outputs)
    except (MechsynInputError, ValueError, KeyError):
        return None
    if plan.input_joint != case.input:
        return None
    index = {n: i for i, n in enumerate(plan.names)}
    columns = [(i, 2 * index[v.target] + v.coord) for i, v in enumerate(case.variables) if v.kind != "vll_angle"]
    angle_of = {v.target: i for i, v in enumerate(case.variables) if v.kind == "vll_angle"}
    drawn = {j["id"]: j for j in case.mech_dict["joints"]}
    vlls = []
    for jid in vll_ids:
        _cyl, L, Kj, _pis = vll_ends(case.mech_dict, jid, case.source)
        vlls.append(_Vll(index[Kj], index[L], np.asarray(drawn[jid]["point"], float), angle_of.get(jid, -1),
                         case.vll_limits(jid)[0] if not combo or jid in combo else None))
    return LockedPopulation(case, plan, plan.parameters(mech), columns, vlls,
                            {k: (index[a], index[b]) for k, (a, b) in link_points.items()})
