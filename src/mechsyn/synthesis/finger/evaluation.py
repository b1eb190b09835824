"""Designs of paper 000's adaptive finger and their evaluation in the fully actuated mode
(steps 8-9 of :mod:`mechsyn.synthesis.finger.design`).

A design is a vector ``x`` of the case's variables (:class:`~mechsyn.synthesis.finger.cases.FingerVariable`:
joint and point coordinates of the drawn configuration, the VLL's directions);
:func:`apply_design` draws it as a mechanism dict, each VLL of the combination at its
minimum constructible length. :func:`evaluate_drawn` solves the locked model (every VLL
one rigid link: a chain of driver and RRR dyads) in closed form over the crank grid and
measures the target angle errors and the working-region excess. The population
evaluation (:mod:`mechsyn.synthesis.finger.population`) computes the same terms for many
designs at once.

Examples
--------
>>> import mechsyn as ms
>>> from mechsyn.synthesis.finger.cases import load_case
>>> case = load_case(ms.examples.path("finger_design_case"))
>>> [v.name for v in case.variables]
['D.x', 'D.y', 'C.x', 'C.y', 'S.angle']
>>> ev = evaluate_locked(case, [14, 6, 8, 48, 123.69006753], ("S",))   # the paper's design
>>> ev.feasible, ev.error_rms < 1e-3                                    # RMS angle error, deg
(True, True)
>>> evaluate_locked(case, [20, 12, 3, 42, 150], ("S",)).reason
'not assembled at 6 of 21 crank angles (dead point between the targets)'

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics import dyads
from mechsyn.kinematics.analysis import resolve_points
from mechsyn.kinematics.system import build_system
from mechsyn.synthesis.finger.cases import FingerCase
from mechsyn.synthesis.finger.vll import copy_mechanism, locked_model, region_excess, vll_ends
from mechsyn.synthesis.templates import DictTemplate, structure_key

__all__ = ["INFEASIBLE", "Objective", "apply_design", "FingerEvaluation", "evaluate_locked", "evaluate_drawn"]

#: a design that cannot be built, is not assembled or leaves the region scores ``INFEASIBLE + violation``
INFEASIBLE = 1e6
Objective = Callable[[np.ndarray], float]


def apply_design(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] | None = None) -> dict:
    """The mechanism dict of design ``x``: joint / point coordinates set; each VLL of the
    combination ``combo`` (default: every VLL) drawn at its minimum constructible length
    along its direction, the other VLL (plain rigid links in this variant) at their drawn
    length."""
    d = copy_mechanism(case.mech_dict)
    joints = {j["id"]: j for j in d["joints"]}
    angles: dict[str, float] = {}
    for v, val in zip(case.variables, np.asarray(x, float)):
        if v.kind == "joint":
            joints[v.target]["point"][v.coord] = float(val)
        elif v.kind == "point":
            d["points"][v.target]["at"][v.coord] = float(val)
        else:
            angles[v.target] = float(val)
    for jid, j in joints.items():
        if not j.get("vll"):
            continue
        _cyl, L, K, _pis = vll_ends(d, jid, case.source)
        pk = np.asarray(joints[K]["point"], float)
        u = np.asarray(j["point"], float) - pk
        ang = np.radians(angles[jid]) if jid in angles else np.arctan2(u[1], u[0])
        length = case.vll_limits(jid)[0] if combo is None or jid in combo else float(np.linalg.norm(u))
        u = np.array([np.cos(ang), np.sin(ang)])
        p = pk + length * u
        j["point"] = p.tolist()
        j["axis"] = u.tolist()
        joints[L]["point"] = p.tolist()
    return d


@dataclass
class FingerEvaluation:
    """A design in the fully actuated (VLL locked) mode over the dense crank grid."""

    feasible: bool
    reason: str
    error_rms: float = np.inf          # deg, over targets and links
    error_max: float = np.inf
    achieved: dict[str, np.ndarray] = field(default_factory=dict)
    paths: dict[str, np.ndarray] = field(default_factory=dict)
    inputs: np.ndarray | None = None
    q: np.ndarray | None = None
    system: Any = None
    violation: float = 0.0


def evaluate_locked(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] = ()) -> FingerEvaluation:
    """Closed-form positions of design ``x`` (VLL locked at their minimum) over
    ``case.sweep_inputs``, with the target errors and the region check."""
    try:
        d = apply_design(case, x, combo or None)
    except (MechsynInputError, ValueError, KeyError) as exc:
        return FingerEvaluation(False, f"cannot build: {exc}", violation=1e3)
    return evaluate_drawn(case, d)


def evaluate_drawn(case: FingerCase, d: dict) -> FingerEvaluation:
    """Closed-form positions of the mechanism dict ``d`` with every VLL locked at its
    drawn length (the locked model), over the crank grid ``case.sweep_inputs``."""
    vlls = [j["id"] for j in case.mech_dict["joints"] if j.get("vll")]
    try:
        d = locked_model(d, vlls, case.source)
        mech, S, plan = _locked_system(case, d)
    except (MechsynInputError, ValueError, KeyError, ZeroDivisionError) as exc:
        return FingerEvaluation(False, f"cannot build: {exc}", violation=1e3)
    if plan is None:
        return FingerEvaluation(False, "the locked model does not decompose into dyads", violation=1e3)
    k = [dr.joint for dr in S.drivers].index(case.input)
    grid = case.sweep_inputs
    U = np.tile([dr.assembled for dr in S.drivers], (len(grid), 1)).astype(float)
    U[:, k] = S.drivers[k].assembled + np.radians(grid)
    with np.errstate(invalid="ignore", divide="ignore"):
        q, _ = dyads.solve_positions(S, plan, U)
    ok = np.all(np.isfinite(q), axis=1)
    if not ok.all():
        return FingerEvaluation(False, f"not assembled at {int((~ok).sum())} of {len(grid)} crank angles "
                                 "(dead point between the targets)", violation=float((~ok).sum()))
    ev = FingerEvaluation(True, "", inputs=grid, q=q, system=S)
    idx = np.searchsorted(grid, case.target_inputs)
    errs = []
    for link, tgt in case.target_angles.items():
        i = S.index(link)
        rot = np.degrees(q[:, 3 * i + 2] - S.q0[3 * i + 2])
        ev.achieved[link] = rot[idx]
        errs.append(rot[idx] - tgt)
    e = np.concatenate(errs)
    ev.error_rms = float(np.sqrt(np.mean(e ** 2)))
    ev.error_max = float(np.max(np.abs(e)))
    viol = 0.0
    for name, (link, at) in resolve_points(mech, case.points).items():
        P = S.point(q, S.index(link), S.to_local(link, at))
        ev.paths[name] = P
        viol += region_excess(P, case.region)
    if viol > 0:
        ev.feasible, ev.reason, ev.violation = False, "a path leaves the working region", viol
    return ev


#: The parsed locked models of the last cases and structures (kept with the case object).
_TEMPLATES: "OrderedDict[tuple[int, str], tuple[FingerCase, DictTemplate]]" = OrderedDict()


def _template(case: FingerCase, d: dict) -> DictTemplate | None:
    """The parsed locked model (:class:`~mechsyn.synthesis.templates.DictTemplate`) of
    the case with the structure of the locked dict ``d``, made from the first such dict
    that parses; None until then."""
    key = structure_key(d)
    if key is None:
        return None
    entry = _TEMPLATES.get((id(case), key))
    if entry is not None and entry[0] is case:
        return entry[1]
    try:
        tpl = DictTemplate(d, case.source)
    except MechsynInputError:
        return None
    _TEMPLATES[(id(case), key)] = (case, tpl)
    while len(_TEMPLATES) > 16:
        _TEMPLATES.popitem(last=False)
    return tpl


def _locked_system(case: FingerCase, d: dict) -> tuple[Any, Any, Any]:
    """(mechanism, constraint system, decomposition) of the locked dict ``d``: its numbers
    filled into the case's parsed locked model of its structure and the compiled plan (no
    parsing per design), else parsed and built."""
    tpl = _template(case, d)
    mech = tpl.mechanism(d, tpl.key) if tpl is not None else None
    if mech is not None:
        kp = tpl.plan(mech)
        return mech, kp.system, kp.groups
    mech = mechanism_from_dict(d, source=case.source)
    S = build_system(mech)
    return mech, S, dyads.decompose(S)
