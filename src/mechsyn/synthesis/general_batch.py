"""Population evaluation of ``synth mechanism`` through the batch kinematics engine.

When a path-generation case's mechanism is a crank and RRR dyads (R pairs only, the
design variables are joint or point coordinates), a whole population of designs is
evaluated by :func:`mechsyn.kinematics.batch.simulate_batch` in a few array passes
instead of one engine sweep per design. The evaluation is the one of
:func:`mechsyn.synthesis.general.evaluate_mechanism_design`, term for term: the same dense input
grid from each design's drawn input value through the target inputs (padded to a common
length by repeating segment ends, which are not counted twice), assembly at every grid point, the assembly mode of
every dyad equal to the file's drawing, free-timing order, and the sum of squared
distances at the targets (tests check both agree). Other cases (motion generation, P
pairs, VLL lengths, mechanisms that do not decompose) keep the engine path.
"""

from __future__ import annotations

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.batch import compile_plan, simulate_batch
from mechsyn.synthesis.designs import MechanismEvaluation, infeasibility, start_vector

__all__ = ["BatchEvaluator", "batch_evaluator"]


class BatchEvaluator:
    """Evaluates populations of a :class:`~mechsyn.synthesis.cases.MechanismCase`."""

    def __init__(self, case, plan, base: np.ndarray, columns: np.ndarray, reference_sigmas: np.ndarray) -> None:
        self.case = case
        self.plan = plan
        self.base = base
        self.columns = columns
        self.reference_sigmas = reference_sigmas

    def designs(self, Z: np.ndarray) -> np.ndarray:
        Z = np.atleast_2d(np.asarray(Z, float))
        P = np.tile(self.base, (len(Z), 1))
        P[:, self.columns] = Z[:, :self.case.n_design]
        return P

    def evaluate(self, Z: np.ndarray) -> list:
        case = self.case
        Z = np.atleast_2d(np.asarray(Z, float))
        K, nd = len(Z), case.n_design
        values = Z[:, nd:] if case.free else np.tile(case.values_deg, (K, 1))
        viol_order = np.zeros(K)
        if case.free and values.shape[1] > 1:
            dv = np.diff(values, axis=1)
            sgn = np.where(values[:, -1] >= values[:, 0], 1.0, -1.0)[:, None]
            viol_order = np.sum(np.maximum(0.0, -sgn * dv), axis=1)
        P = self.designs(Z)
        u0 = self.plan.reference_inputs(P)
        u0 = u0 + 360.0 * np.round((values[:, 0] - u0) / 360.0)
        knots = np.concatenate([u0[:, None], values], axis=1)
        counts = np.maximum(1, np.ceil(np.abs(np.diff(knots, axis=1)) / case.step_deg).astype(int))
        out: list = [None] * K
        # one padded grid for the population: segment j of design k has its own counts[k, j]
        # points (as the engine's grid); the rest of the segment's slots repeat its end value
        # and are left out of the assembly count
        cmax = counts.max(axis=0)
        cols, valid = [u0[:, None]], [np.ones((K, 1), bool)]
        for j, mj in enumerate(cmax):
            a, b = knots[:, j, None], knots[:, j + 1, None]
            s = np.arange(1, mj + 1)[None, :]
            own = counts[:, j, None]
            cols.append(a + (b - a) * (np.minimum(s, own) / own))
            valid.append(s <= own)
        grid = np.concatenate(cols, axis=1)
        valid = np.concatenate(valid, axis=1)
        idx = np.cumsum(cmax)  # segment ends: the padded slots repeat them, so the last slot holds it
        with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
            res = simulate_batch(self.plan, P, grid - u0[:, None], flags=False)
        path = res.paths[case.point]
        n_grid = counts.sum(axis=1) + 1
        n_bad_all = np.sum(~res.assembled & valid, axis=1)
        branch_all = np.sum(np.sign(res.sigmas) != np.sign(self.reference_sigmas)[None, :], axis=1)
        for k in range(K):
            bad = infeasibility(int(n_bad_all[k]), int(n_grid[k]), float(branch_all[k]), float(viol_order[k]),
                                "batch")
            if bad is not None:
                out[k] = bad
                continue
            ach = path[k, idx]
            err = float(np.sum((ach - case.targets) ** 2))
            out[k] = MechanismEvaluation(True, "", err, achieved=ach, path=path[k][valid[k]],
                                         inputs_deg=np.asarray(values[k], float), method="batch",
                                         sigmas=res.sigmas[k].tolist())
        return out


def batch_evaluator(case) -> BatchEvaluator | None:
    """A batch evaluator for the case, or None when it needs the engine path."""
    if case.problem != "path" or case.method == "newton" or case.point is None:
        return None
    if any(v.kind not in ("joint", "point") for v in case.variables):
        return None
    try:
        mech = mechanism_from_dict(case.mech_dict, source=case.source)
        if mech.joint(case.input_joint).links[0] != mech.ground and mech.joint(case.input_joint).links[1] != mech.ground:
            return None
        plan = compile_plan(mech, points=[case.point])
    except (MechsynInputError, KeyError, ValueError):
        return None
    if plan.input_joint != case.input_joint:
        return None
    index = {n: i for i, n in enumerate(plan.names)}
    if any(v.target not in index for v in case.variables):
        return None
    columns = np.array([2 * index[v.target] + v.coord for v in case.variables], int)
    base = plan.parameters(mech)
    start = start_vector(case)
    P0 = base.copy()
    P0[columns] = start[:case.n_design]
    ref = simulate_batch(plan, P0, np.zeros(1), flags=False).sigmas[0]
    return BatchEvaluator(case, plan, base, columns, ref)
