"""Design vectors of a :class:`~mechsyn.synthesis.cases.MechanismCase` and the record of
one evaluated design, shared by the engine evaluation (:mod:`mechsyn.synthesis.general`)
and the population evaluation (:mod:`mechsyn.synthesis.general_batch`).

A design vector holds the case's design variables (:class:`~mechsyn.synthesis.cases.DesignVariable`:
a joint point's or named point's coordinate, a VLL's length) in the case's order, then
the free timing values (degrees) when the timing is free.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.synthesis.cases import load_mechanism_case
>>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
>>> x = start_vector(case)
>>> apply_mechanism_design(case, x) == case.mech_dict
True

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from mechsyn.synthesis.cases import MechanismCase
from mechsyn.synthesis.finger.vll import vll_ends

__all__ = ["start_vector", "design_numbers", "apply_mechanism_design", "MechanismEvaluation", "infeasibility"]


def start_vector(case: MechanismCase) -> np.ndarray:
    """The file's geometry as a design vector (the starting design)."""
    md = case.mech_dict
    joints = {j["id"]: j for j in md["joints"]}
    x = []
    for v in case.variables:
        if v.kind == "joint":
            x.append(float(joints[v.target]["point"][v.coord]))
        elif v.kind == "point":
            x.append(float(md["points"][v.target]["at"][v.coord]))
        else:
            _c, _L, K, _p = vll_ends(md, v.target, case.source)
            x.append(float(np.linalg.norm(np.subtract(joints[v.target]["point"], joints[K]["point"]))))
    if case.free:
        x += list(case.values_deg)
    return np.array(x, float)


def design_numbers(case: MechanismCase, x: np.ndarray) -> tuple[dict, dict, dict]:
    """The numbers design vector ``x`` (design part) changes in the case's mechanism file:
    joint points ``{id: [x, y]}``, P axes ``{id: [dx, dy]}`` (a VLL's cylinder direction)
    and named points ``{name: [x, y]}``, the file's other numbers unchanged. A VLL's length
    moves its piston pivot along the cylinder's direction (paper 000's drawing, as in
    :func:`mechsyn.synthesis.finger.design.apply_design`).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.cases import load_mechanism_case
    >>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    >>> pts, axes, named = design_numbers(case, start_vector(case))
    >>> sorted(pts), axes, sorted(named)
    (['B', 'C'], {}, ['M'])
    """
    md = case.mech_dict
    base = {j["id"]: j for j in md["joints"]}
    pts: dict[str, list] = {}
    axes: dict[str, list] = {}
    named: dict[str, list] = {}
    for v, val in zip(case.variables, np.asarray(x, float)):
        if v.kind == "joint":
            pts.setdefault(v.target, list(base[v.target]["point"]))[v.coord] = float(val)
        elif v.kind == "point":
            named.setdefault(v.target, list(md["points"][v.target]["at"]))[v.coord] = float(val)
    for v, val in zip(case.variables, np.asarray(x, float)):
        if v.kind == "length":
            view = {**md, "joints": [{**j, "point": pts.get(j["id"], j["point"])} for j in md["joints"]]}
            _c, L, K, _p = vll_ends(view, v.target, case.source)
            pk = np.asarray(pts.get(K, base[K]["point"]), float)
            u = np.asarray(pts.get(v.target, base[v.target]["point"]), float) - pk
            u = u / np.linalg.norm(u)
            p = (pk + float(val) * u).tolist()
            pts[v.target] = pts[L] = p
            axes[v.target] = u.tolist()
    return pts, axes, named


def apply_mechanism_design(case: MechanismCase, x: np.ndarray) -> dict:
    """The mechanism dict of design vector ``x`` (design part; timing values ignored):
    the file's dict with the numbers of :func:`design_numbers`."""
    pts, axes, named = design_numbers(case, x)
    d = copy.deepcopy(case.mech_dict)
    for j in d["joints"]:
        if j["id"] in pts:
            j["point"] = pts[j["id"]]
        if j["id"] in axes:
            j["axis"] = axes[j["id"]]
    for n, at in named.items():
        d["points"][n]["at"] = at
    return d


@dataclass
class MechanismEvaluation:
    """One design: feasibility, error and the achieved path / angles at the targets."""

    feasible: bool
    reason: str
    error: float = np.inf
    violation: float = 0.0
    achieved: np.ndarray | None = None         # (N, 2)
    achieved_angles_deg: np.ndarray | None = None
    path: np.ndarray | None = None             # dense sweep path of the point
    inputs_deg: np.ndarray | None = None       # the target inputs used
    method: str = ""
    sigmas: list[float] | None = None


def infeasibility(n_bad: int, n_grid: int, branch_viol: float, viol_order: float,
                  method: str) -> MechanismEvaluation | None:
    """The infeasible evaluation (violation and reasons) of a swept design, or None."""
    viol = n_bad / n_grid + branch_viol + viol_order
    if viol <= 0:
        return None
    why = []
    if n_bad:
        why.append(f"not assembled at {n_bad} of {n_grid} inputs of the sweep")
    if branch_viol:
        why.append("off the file's assembly branch")
    if viol_order:
        why.append("input angles out of order")
    return MechanismEvaluation(False, "; ".join(why), violation=1.0 + viol, method=method)
