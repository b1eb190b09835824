"""Paper 000's parametric synthesis of an adaptive finger with variable-length links (VLL).

Steps 8-13 of paper 000 (spec ``structural.md`` section 4), for every VLL combination:

1. **Stage 1 (step 8)**: fix the combination's VLL at their minimum constructible length
   ``l_min`` (the joint's ``limits[0]``) and optimise the design variables (joint
   coordinates of the drawn configuration, point positions, the VLL's direction) in the
   fully actuated mode (VLL locked) on discrete positions: at crank rotations
   ``dtheta_i`` from the drawn configuration the output links must have turned by
   ``dphi_i``. Objective: the RMS angle error (deg) over positions and links.
2. **VLL range (step 9)**: with the design fixed, each VLL of the combination is freed
   (underactuated mode, its length prescribed as a second input) and its length swept
   from ``l_min`` upwards over the whole crank range; ``l_max`` is the largest length
   such that every output point's path for every length in ``[l_min, l_max]`` stays in
   the working region (a polygon) and the finger stays assembled.
3. **Force stage (steps 10-12)**: static force analysis (gravity, the file's loads) in
   both modes; a second optimisation (seeded with the stage-1 design) minimises
   ``peak |R| + w * peak |M_in|`` (largest joint reaction and balancing moment over the
   crank range) of both modes (the VLL held at stage 1's ``l_max``) subject to the
   accuracy ``max(tolerance_deg, stage-1 RMS error)``, the region and the stage-1 VLL
   range (see :func:`force_objective`); its best few distinct designs are then checked in both
   modes (VLL range found again, forces at ``l_min`` and ``l_max``) and one replaces the
   stage-1 design only if its peak reaction is not higher and its criterion lower.
4. **Best variant (step 13)**: the combination with the smallest force criterion.

**Objective interface** (``scipy.optimize.differential_evolution``, seeded): a design
is a vector ``x`` of the case's variables; ``objective(x) -> float``. Feasible designs
get their criterion (``>= 0``, below ``INFEASIBLE``); a design that cannot be built, is
not assembled on one branch over the whole crank range (closed-form Assur dyads with the
drawn configuration's assembly modes, checked on a dense grid: no dead point between
targets) or leaves the region gets ``INFEASIBLE + violation``: never rewarded.

Fast evaluation: with its VLL locked, a cylinder-piston pair is one rigid binary link;
the locked model merges the two (masses and centres of mass combined), which makes the
finger a chain of driver + RRR dyads solved in closed form by ``kinematics.dyads``. The
VLL range and the final checks use the full file in the kinematics engine's passive
mode (Newton continuation), an independent method.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg; journal, volume and year are
   not in the project's copy ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import copy
import itertools
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from mechsyn.errors import MechsynInputError, input_boundary
from mechsyn.interrupt import BestSoFar

__all__ = ["FingerCase", "Variable", "load_case", "case_from_dict", "apply_design", "locked_model",
           "Evaluation", "evaluate_locked", "stage1_objective", "vll_range", "mode_forces",
           "design_finger", "FingerDesign", "VariantResult", "INFEASIBLE", "points_in_region",
           "underactuated_paths", "redraw", "evaluate_drawn"]

INFEASIBLE = 1e6
Objective = Callable[[np.ndarray], float]


# --------------------------------------------------------------------------- case
@dataclass(frozen=True)
class Variable:
    """One design variable: ``kind`` joint (a joint point's x or y), point (a named
    point's x or y) or vll_angle (the VLL's direction in the drawn configuration, deg)."""

    name: str
    kind: str
    target: str
    coord: int          # 0: x, 1: y (unused for vll_angle)
    bounds: tuple[float, float]


@dataclass
class FingerCase:
    source: str
    mech_dict: dict
    input: str
    variables: list[Variable]
    target_inputs: np.ndarray             # crank rotation from the drawn configuration, deg
    target_angles: dict[str, np.ndarray]  # link -> rotation from the drawn configuration, deg
    region: np.ndarray                    # (k, 2) polygon
    points: list[str]
    combinations: list[tuple[str, ...]]
    gravity: float = 9.81
    weight_moment: float = 1.0
    tolerance_deg: float = 1.0
    step_deg: float = 2.0
    vll_steps: int = 20
    maxiter: int = 60
    popsize: int = 12
    force_maxiter: int = 15
    candidates: int = 3

    @property
    def sweep_inputs(self) -> np.ndarray:
        """Dense crank grid over the targets' range, the targets included."""
        lo, hi = min(0.0, float(self.target_inputs.min())), max(0.0, float(self.target_inputs.max()))
        n = max(2, int(np.ceil((hi - lo) / self.step_deg)) + 1)
        return np.unique(np.concatenate([np.linspace(lo, hi, n), self.target_inputs, [0.0]]))

    def vll_limits(self, jid: str) -> tuple[float, float]:
        j = next(j for j in self.mech_dict["joints"] if j["id"] == jid)
        return float(j["limits"][0]), float(j["limits"][1])


def _err(msg: str, source: str, fld: str | None = None, hint: str | None = None) -> MechsynInputError:
    return MechsynInputError(msg, source=source, field=fld, hint=hint)


def load_case(path: str | Path) -> FingerCase:
    """Read a finger-design case (YAML or JSON); the mechanism path is relative to it."""
    from mechsyn.io.files import read_data

    path = Path(path)
    data, _text = read_data(path, "case file")
    return case_from_dict(data, str(path), base_dir=path.parent)


def _floats(v: Any, n: int | None, src: str, fld: str) -> list[float]:
    from mechsyn.io.checks import numbers

    if not isinstance(v, (list, tuple)):
        raise _err(f"{fld} must be a list of numbers", src, fld)
    out = numbers(v, src, fld).reshape(-1).tolist()
    if n is not None and len(out) != n:
        raise _err(f"{fld} must have {n} numbers", src, fld)
    if not all(np.isfinite(out)):
        raise _err(f"{fld} must be finite", src, fld)
    return out


@input_boundary("finger-design case")
def case_from_dict(data: Any, source: str = "<case>", base_dir: Path | None = None) -> FingerCase:
    """Validate a case (see ``docs/finger_design.md``); MechsynInputError on bad input."""
    from mechsyn.io import load_mechanism, mechanism_to_dict

    src = source
    if not isinstance(data, dict):
        raise _err("the case must be a mapping", src)
    for key in ("mechanism", "input", "variables", "targets", "region"):
        if key not in data:
            raise _err(f"missing field {key!r}", src, key, hint="see docs/finger_design.md")
    mpath = Path(str(data["mechanism"]))
    if not mpath.is_absolute() and base_dir is not None:
        mpath = base_dir / mpath
    if not mpath.is_file():
        raise _err(f"mechanism file not found: {mpath}", src, "mechanism")
    mech = load_mechanism(mpath)
    md = mechanism_to_dict(mech)
    joints = {j["id"]: j for j in md["joints"]}
    names = [x if isinstance(x, str) else x["name"] for x in md["links"]]
    masses = data.get("masses") or {}
    if not isinstance(masses, dict):
        raise _err("masses must map link names to {mass, com, inertia}", src, "masses")
    for name, attrs in masses.items():
        if name not in names or name == md["ground"] or not isinstance(attrs, dict) \
                or set(attrs) - {"mass", "com", "inertia"}:
            raise _err(f"masses.{name}: a moving link of the mechanism with mass, com, inertia", src,
                       f"masses.{name}", hint=f"links: {', '.join(n for n in names if n != md['ground'])}")
        k = names.index(name)
        entry = {"name": name} if isinstance(md["links"][k], str) else md["links"][k]
        for key, val in attrs.items():
            entry[key] = _floats(val, 2, src, f"masses.{name}.com") if key == "com" else \
                _floats([val], 1, src, f"masses.{name}.{key}")[0]
        md["links"][k] = entry
    if "loads" in data:
        loads = data["loads"] or []
        if not isinstance(loads, list):
            raise _err("loads must be a list like the mechanism file's", src, "loads")
        out_loads = []
        for k, ld in enumerate(loads):
            if not isinstance(ld, dict) or ld.get("link") not in names:
                raise _err("each load names a link of the mechanism", src, f"loads[{k}]")
            ld = dict(ld)
            if "point" in ld:  # a named point: its drawn coordinates
                pt = (md.get("points") or {}).get(ld["point"])
                if pt is None or pt["link"] != ld["link"]:
                    raise _err(f"loads[{k}].point must be a point of link {ld['link']}", src, f"loads[{k}]")
            if "force" in ld:
                ld["force"] = _floats(ld["force"], 2, src, f"loads[{k}].force")
            if "at" in ld:
                ld["at"] = _floats(ld["at"], 2, src, f"loads[{k}].at")
            out_loads.append(ld)
        md["loads"] = out_loads
    inp = str(data["input"])
    if inp not in joints or not joints[inp].get("actuated") or joints[inp]["type"] != "R":
        raise _err(f"input {inp!r} is not an actuated R joint of {mpath.name}", src, "input")
    vll_all = [j["id"] for j in md["joints"] if j.get("vll")]
    if not vll_all:
        raise _err(f"{mpath.name} has no variable-length link (a P joint with vll:)", src, "mechanism")
    for jid in vll_all:
        _vll_ends(md, jid, src)
        lim = joints[jid].get("limits")
        if lim is None or not (0 < lim[0] < lim[1]):
            raise _err(f"VLL {jid} needs limits [min, max] with 0 < min < max", src, "mechanism",
                       hint="the min is the minimum constructible length (paper 000, step 7)")
    combos_raw = data.get("combinations") or [list(c) for r in range(1, len(vll_all) + 1)
                                              for c in itertools.combinations(vll_all, r)]
    combos = []
    for c in combos_raw:
        c = [c] if isinstance(c, str) else list(c)
        for jid in c:
            if jid not in vll_all:
                raise _err(f"combination names {jid!r}, not a VLL of the mechanism", src, "combinations",
                           hint=f"VLL joints: {', '.join(vll_all)}")
        combos.append(tuple(c))
    variables = []
    if not isinstance(data["variables"], list) or not data["variables"]:
        raise _err("variables must be a non-empty list", src, "variables")
    for k, v in enumerate(data["variables"]):
        fld = f"variables[{k}]"
        if not isinstance(v, dict) or "bounds" not in v:
            raise _err("each variable needs bounds: [lo, hi]", src, fld)
        b = _floats(v["bounds"], 2, src, fld + ".bounds")
        if not b[0] < b[1]:
            raise _err("bounds must be [lo, hi] with lo < hi", src, fld + ".bounds")
        if "joint" in v or "point" in v:
            kind = "joint" if "joint" in v else "point"
            tgt = str(v[kind])
            if kind == "joint" and tgt not in joints:
                raise _err(f"no joint {tgt!r}", src, fld)
            if kind == "point" and tgt not in (md.get("points") or {}):
                raise _err(f"no point {tgt!r}", src, fld)
            if kind == "joint" and any(tgt == _vll_ends(md, c, src)[1] for c in vll_all):
                raise _err(f"joint {tgt} is a VLL's piston pivot: vary the VLL's angle instead", src, fld,
                           hint=f"write {{vll_angle: <VLL>, bounds: [lo, hi]}}")
            coord = v.get("coord", "x")
            if coord not in ("x", "y"):
                raise _err("coord must be x or y", src, fld)
            variables.append(Variable(f"{tgt}.{coord}", kind, tgt, 0 if coord == "x" else 1, (b[0], b[1])))
        elif "vll_angle" in v:
            tgt = str(v["vll_angle"])
            if tgt not in vll_all:
                raise _err(f"no VLL {tgt!r}", src, fld)
            variables.append(Variable(f"{tgt}.angle", "vll_angle", tgt, 0, (b[0], b[1])))
        else:
            raise _err("a variable names a joint, a point or a vll_angle", src, fld)
    tg = data["targets"]
    if not isinstance(tg, list) or len(tg) < 2:
        raise _err("targets must list at least two positions (the extremes)", src, "targets")
    links = [lk for lk in tg[0] if lk != "input"]
    if not links:
        raise _err("a target gives the input and at least one link's rotation", src, "targets[0]")
    tin, tang = [], {lk: [] for lk in links}
    for k, t in enumerate(tg):
        if not isinstance(t, dict) or "input" not in t or set(t) - {"input"} != set(links):
            raise _err(f"each target gives input and rotations of {', '.join(links)}", src, f"targets[{k}]")
        tin.append(_floats([t["input"]], 1, src, f"targets[{k}].input")[0])
        for lk in links:
            if lk not in [x if isinstance(x, str) else x["name"] for x in md["links"]]:
                raise _err(f"no link {lk!r}", src, f"targets[{k}]")
            tang[lk].append(_floats([t[lk]], 1, src, f"targets[{k}].{lk}")[0])
    region = np.array([_floats(p, 2, src, "region") for p in data["region"]]) if isinstance(
        data["region"], list) else None
    if region is None or len(region) < 3:
        raise _err("region must be a polygon of at least 3 [x, y] points", src, "region")
    pts = data.get("points") or list(md.get("points") or {})
    if not pts:
        raise _err("name the output points whose paths must stay in the region", src, "points")
    for p in pts:
        if p not in (md.get("points") or {}) and p not in joints:
            raise _err(f"no point or joint {p!r}", src, "points")
    opt = data.get("optimizer") or {}
    case = FingerCase(src, md, inp, variables, np.array(tin), {k: np.array(v) for k, v in tang.items()},
                      region, list(pts), combos)
    for key, typ in (("gravity", float), ("weight_moment", float), ("tolerance_deg", float),
                     ("step_deg", float)):
        if key in data:
            setattr(case, key, typ(data[key]))
    for key in ("maxiter", "popsize", "force_maxiter", "vll_steps", "candidates"):
        if key in opt:
            val = int(opt[key])
            if val < 1:
                raise _err(f"optimizer.{key} must be >= 1", src, f"optimizer.{key}")
            setattr(case, key, val)
    if case.step_deg <= 0 or case.tolerance_deg <= 0:
        raise _err("step_deg and tolerance_deg must be positive", src)
    return case


def _vll_ends(md: dict, jid: str, src: str) -> tuple[str, str, str, str]:
    """(cylinder link, piston pivot joint L, cylinder pivot joint K, piston link) of a VLL."""
    joints = md["joints"]
    j = next(x for x in joints if x["id"] == jid)
    cyl, pis = j["links"]
    k_j = [x for x in joints if cyl in x["links"] and x["id"] != jid]
    l_j = [x for x in joints if pis in x["links"] and x["id"] != jid]
    if len(k_j) != 1 or len(l_j) != 1 or k_j[0]["type"] != "R" or l_j[0]["type"] != "R" \
            or np.linalg.norm(np.subtract(l_j[0]["point"], j["point"])) > 1e-9:
        raise _err(f"VLL {jid}: expected a cylinder and a piston, each binary with one R pivot, the P "
                   "point at the piston's pivot", src, f"joints.{jid}")
    return cyl, l_j[0]["id"], k_j[0]["id"], pis


# --------------------------------------------------------------------------- designs
def apply_design(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] | None = None) -> dict:
    """The mechanism dict of design ``x``: joint / point coordinates set; each VLL of the
    combination ``combo`` (default: every VLL) drawn at its minimum constructible length
    along its direction, the other VLL (plain rigid links in this variant) at their drawn
    length."""
    d = copy.deepcopy(case.mech_dict)
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
        _cyl, L, K, _pis = _vll_ends(d, jid, case.source)
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


def _link_entry(d: dict, name: str) -> dict:
    for k, e in enumerate(d["links"]):
        if (e if isinstance(e, str) else e["name"]) == name:
            if isinstance(e, str):
                d["links"][k] = {"name": e}
            return d["links"][k]
    raise KeyError(name)


def locked_model(d: dict, vlls: list[str], source: str = "<case>") -> dict:
    """The fully actuated model: each locked VLL's cylinder and piston merged into one
    rigid binary link (mass summed, centre of mass mass-weighted; inertia summed about
    the combined centre, parallel-axis theorem)."""
    d = copy.deepcopy(d)
    for jid in vlls:
        cyl, L, K, pis = _vll_ends(d, jid, source)
        pts = {j["id"]: np.asarray(j["point"], float) for j in d["joints"]}
        ec, ep = _link_entry(d, cyl), _link_entry(d, pis)
        mc, mp = float(ec.get("mass") or 0.0), float(ep.get("mass") or 0.0)
        cc = np.asarray(ec.get("com", (pts[K] + pts[jid]) / 2), float)
        cp = np.asarray(ep.get("com", (pts[jid] + pts[L]) / 2), float)
        m = mc + mp
        if m > 0:
            com = (mc * cc + mp * cp) / m
            ec["mass"] = m
            ec["com"] = com.tolist()
            ec["inertia"] = float(ec.get("inertia") or 0.0) + float(ep.get("inertia") or 0.0) \
                + mc * float(np.sum((cc - com) ** 2)) + mp * float(np.sum((cp - com) ** 2))
        d["links"] = [e for e in d["links"] if (e if isinstance(e, str) else e["name"]) != pis]
        d["joints"] = [j for j in d["joints"] if j["id"] != jid]
        for j in d["joints"]:
            if j["id"] == L:
                j["links"] = [cyl if lk == pis else lk for lk in j["links"]]
        for p in (d.get("points") or {}).values():
            if p["link"] == pis:
                p["link"] = cyl
        for ld in d.get("loads") or []:
            if ld.get("link") == pis:
                ld["link"] = cyl
    return d


def points_in_region(P: np.ndarray, region: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Which points (N, 2) lie inside the polygon or within ``tol`` of its boundary (NaN rows:
    outside). Even-odd ray casting, vectorised over points and edges."""
    P = np.asarray(P, float).reshape(-1, 2)
    region = np.asarray(region, float)
    ok = np.all(np.isfinite(P), axis=1)
    out = np.zeros(len(P), bool)
    if not ok.any():
        return out
    Q = P[ok]
    a, b = region, np.roll(region, -1, axis=0)
    x, y = Q[:, :1], Q[:, 1:]
    crosses = (a[:, 1] > y) != (b[:, 1] > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = a[:, 0] + (y - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
    inside = np.count_nonzero(crosses & (x < xc), axis=1) % 2 == 1
    ab = b - a
    t = np.clip(np.einsum("nkj,kj->nk", Q[:, None] - a[None], ab) / np.maximum(np.sum(ab * ab, axis=1), 1e-300), 0, 1)
    dist = np.linalg.norm(Q[:, None] - (a[None] + t[..., None] * ab[None]), axis=2).min(axis=1)
    out[ok] = inside | (dist <= tol)
    return out


def _region_excess(P: np.ndarray, region: np.ndarray) -> float:
    """Sum of distances of the points outside the polygon to it (0 when all inside)."""
    inside = points_in_region(P, region)
    bad = P[~inside & np.all(np.isfinite(P), axis=1)]
    if not len(bad):
        return 0.0
    a, b = region, np.roll(region, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("nkj,kj->nk", bad[:, None] - a[None], ab) / np.sum(ab * ab, axis=1), 0, 1)
    proj = a[None] + t[..., None] * ab[None]
    return float(np.sum(np.min(np.linalg.norm(bad[:, None] - proj, axis=2), axis=1)))


@dataclass
class Evaluation:
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


def evaluate_locked(case: FingerCase, x: np.ndarray, combo: tuple[str, ...] = ()) -> Evaluation:
    """Closed-form positions of design ``x`` (VLL locked at their minimum) over
    ``case.sweep_inputs``, with the target errors and the region check."""
    try:
        d = apply_design(case, x, combo or None)
    except (MechsynInputError, ValueError, KeyError) as exc:
        return Evaluation(False, f"cannot build: {exc}", violation=1e3)
    return evaluate_drawn(case, d)


def evaluate_drawn(case: FingerCase, d: dict) -> Evaluation:
    """Closed-form positions of the mechanism dict ``d`` with every VLL locked at its
    drawn length (the locked model), over the crank grid ``case.sweep_inputs``."""
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics import dyads
    from mechsyn.kinematics.system import build_system

    vlls = [j["id"] for j in case.mech_dict["joints"] if j.get("vll")]
    try:
        d = locked_model(d, vlls, case.source)
        mech = mechanism_from_dict(d, source=case.source)
        S = build_system(mech)
        plan = dyads.decompose(S)
    except (MechsynInputError, ValueError, KeyError, ZeroDivisionError) as exc:
        return Evaluation(False, f"cannot build: {exc}", violation=1e3)
    if plan is None:
        return Evaluation(False, "the locked model does not decompose into dyads", violation=1e3)
    k = [dr.joint for dr in S.drivers].index(case.input)
    grid = case.sweep_inputs
    U = np.tile([dr.assembled for dr in S.drivers], (len(grid), 1)).astype(float)
    U[:, k] = S.drivers[k].assembled + np.radians(grid)
    with np.errstate(invalid="ignore", divide="ignore"):
        q, _ = dyads.solve_positions(S, plan, U)
    ok = np.all(np.isfinite(q), axis=1)
    if not ok.all():
        return Evaluation(False, f"not assembled at {int((~ok).sum())} of {len(grid)} crank angles "
                                 "(dead point between the targets)", violation=float((~ok).sum()))
    ev = Evaluation(True, "", inputs=grid, q=q, system=S)
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
    from mechsyn.kinematics.analysis import resolve_points

    viol = 0.0
    for name, (link, at) in resolve_points(mech, case.points).items():
        P = S.point(q, S.index(link), S.to_local(link, at))
        ev.paths[name] = P
        viol += _region_excess(P, case.region)
    if viol > 0:
        ev.feasible, ev.reason, ev.violation = False, "a path leaves the working region", viol
    return ev


def stage1_objective(case: FingerCase, combo: tuple[str, ...]) -> Objective:
    """RMS target error (deg) of a feasible design; ``INFEASIBLE + violation`` otherwise."""
    def f(x: np.ndarray) -> float:
        ev = evaluate_locked(case, x, combo)
        return ev.error_rms if ev.feasible else INFEASIBLE + ev.violation
    return f


# --------------------------------------------------------------------------- VLL range
def redraw(case: FingerCase, design: dict, lengths: dict[str, float]) -> dict | None:
    """The mechanism dict redrawn at the same crank angle with the VLL lengths
    ``lengths``: the underactuated mode (VLL free, length prescribed) solved by the
    kinematics engine's Newton continuation from the drawn lengths; None when it cannot
    be assembled. Joint points, named points, centres of mass and P axes follow their
    links; a VLL's ``limits`` are kept."""
    from mechsyn.io import mechanism_from_dict
    from mechsyn.kinematics.solve import assemble
    from mechsyn.kinematics.system import _rot, build_system

    d = copy.deepcopy(design)
    for j in d["joints"]:  # the engine refuses lengths outside limits: widen them for the solve
        if j["id"] in lengths:
            lim = j.get("limits") or [lengths[j["id"]]] * 2
            j["limits"] = [min(lim[0], lengths[j["id"]]), max(lim[1], lengths[j["id"]])]
    mech = mechanism_from_dict(d, source=case.source)
    free = tuple(lengths)
    try:
        S = build_system(mech, vll={jid: "free" for jid in free}, prescribed=free)
        u = np.array([lengths[dr.joint] if dr.joint in lengths else dr.assembled for dr in S.drivers])
        q = assemble(S, u)[None]  # Newton continuation from the drawn lengths (crank held)
    except MechsynInputError:
        return None
    ground = mech.ground

    def moved(link: str, p: Any) -> list[float]:
        if link == ground:
            return [float(v) for v in p]
        return S.point(q, S.index(link), S.to_local(link, np.asarray(p, float)))[0].tolist()

    def turned(link: str, u: Any) -> list[float]:
        if link == ground:
            return [float(v) for v in u]
        i = S.index(link)
        c, sn = _rot(q[:, 3 * i + 2] - S.q0[3 * i + 2])
        u = np.asarray(u, float)
        return [float(c[0] * u[0] - sn[0] * u[1]), float(sn[0] * u[0] + c[0] * u[1])]

    for j in d["joints"]:
        link = j["links"][1] if j["links"][1] != ground else j["links"][0]
        if j.get("axis") is not None:
            j["axis"] = turned(j["links"][0], j["axis"])
        j["point"] = moved(link, j["point"])
    for p in (d.get("points") or {}).values():
        p["at"] = moved(p["link"], p["at"])
    for k, e in enumerate(d["links"]):
        name = e if isinstance(e, str) else e["name"]
        if name == ground:
            continue
        if isinstance(e, str):
            e = d["links"][k] = {"name": e}
        if e.get("com") is None:  # the file's default (its joints' mean, drawn), fixed on the link
            e["com"] = np.mean([j["point"] for j in design["joints"] if name in j["links"]], axis=0).tolist()
        e["com"] = moved(name, e["com"])
    for ld in d.get("loads") or []:
        if ld.get("at") is not None:
            ld["at"] = moved(ld["link"], ld["at"])
    for j in d["joints"]:
        if j["id"] in lengths:
            j["limits"] = next(x for x in design["joints"] if x["id"] == j["id"]).get("limits")
    return d


def underactuated_paths(case: FingerCase, design: dict, jid: str, lengths: np.ndarray
                        ) -> dict[str, np.ndarray]:
    """Output paths over the crank grid in the underactuated mode with VLL ``jid`` held
    at each length: point -> (n_lengths, n_inputs, 2), NaN where not assembled. Each
    length: :func:`redraw`, then the closed-form locked model."""
    n = len(case.sweep_inputs)
    out = {p: np.full((len(lengths), n, 2), np.nan) for p in case.points}
    for r, length in enumerate(lengths):
        d = redraw(case, design, {jid: float(length)})
        if d is None:
            continue
        ev = evaluate_drawn(case, d)
        for p, P in ev.paths.items():
            out[p][r] = P
    return out


def vll_range(case: FingerCase, design: dict, jid: str, rel_tol: float = 1e-3
              ) -> tuple[float, float, dict[str, np.ndarray], np.ndarray]:
    """(l_min, l_max, paths, lengths): the largest ``l_max`` in the VLL's limits such that
    every output path (whole crank range) for the lengths ``l_min ... l_max`` is
    assembled and inside the region (grid of ``case.vll_steps`` lengths, then bisection
    to ``rel_tol`` of the limits' range)."""
    lo, hi = case.vll_limits(jid)
    lengths = np.linspace(lo, hi, case.vll_steps + 1)
    paths = underactuated_paths(case, design, jid, lengths)

    def inside(P: dict[str, np.ndarray], r: int) -> bool:
        return all(points_in_region(arr[r], case.region).all() for arr in P.values())

    ok = np.array([inside(paths, r) for r in range(len(lengths))])
    if not ok[0]:
        return lo, lo, paths, lengths
    last = int(np.argmin(ok)) - 1 if not ok.all() else len(ok) - 1
    l_max = float(lengths[last])
    if last < len(lengths) - 1:  # bisection between the last good and the first bad length
        a, b = l_max, float(lengths[last + 1])
        while b - a > rel_tol * (hi - lo):
            m = 0.5 * (a + b)
            if inside(underactuated_paths(case, design, jid, np.array([m])), 0):
                a = m
            else:
                b = m
        l_max = a
    return lo, l_max, paths, lengths


# --------------------------------------------------------------------------- forces
def _peaks(S: Any, q: np.ndarray, case: FingerCase, skip: tuple[str, ...] = ()) -> tuple[float, float, str]:
    from mechsyn.kinematics.forces import kinetostatics

    R = kinetostatics(S, q, None, None, gravity=(0.0, -case.gravity))
    peak, where = 0.0, ""
    for j, F in R.force.items():
        if j in skip:
            continue
        m = float(np.nanmax(np.linalg.norm(F, axis=1)))
        if m > peak:
            peak, where = m, j
    return peak, float(np.nanmax(np.abs(R.effort[case.input]))), where


def mode_forces(case: FingerCase, design: dict, combo: tuple[str, ...],
                ranges: dict[str, tuple[float, float]]) -> dict[str, Any]:
    """Peak joint reaction and peak balancing moment at the input over the crank range,
    statically (gravity along -y, the file's loads), in the fully actuated mode (VLL
    locked at ``l_min``) and in the underactuated mode (VLL free, held at each end of
    its range by a spring or stop: the axial force at the piston's pivot is reported as
    ``vll_force_peak``; the spring force differs from it by at most the piston's weight). Closed-form locked models (``kinetostatics`` on the merged
    cylinder-piston link); the tests compare them with the engine's Newton solution of
    the full file in both modes."""
    out: dict[str, Any] = {"fully_actuated": _static_summary(case, design, ())}
    if not out["fully_actuated"]["assembled"]:
        raise MechsynInputError("the design does not assemble over the crank range", source=case.source)
    worst = {"peak_reaction": out["fully_actuated"]["peak_reaction"],
             "peak_input_moment": out["fully_actuated"]["peak_input_moment"]}
    out["underactuated"] = []
    for jid in combo:
        lo, hi = ranges[jid]
        for length in sorted({lo, hi}):
            d = design if length == lo else redraw(case, design, {jid: length})
            s = _static_summary(case, d, (jid,)) if d is not None else {"assembled": False}
            if not s["assembled"]:
                raise MechsynInputError(f"the design does not assemble with {jid} = {length:g}",
                                        source=case.source)
            s["vll_length"] = length
            out["underactuated"].append(s)
            for k in worst:
                worst[k] = max(worst[k], s[k])
    out.update(worst)
    modes = [out["fully_actuated"]] + out["underactuated"]
    out["peak_joint"] = max(modes, key=lambda m: m["peak_reaction"])["peak_joint"]
    out["criterion"] = out["peak_reaction"] + case.weight_moment * out["peak_input_moment"]
    return out


def _static_summary(case: FingerCase, d: dict, vlls: tuple[str, ...]) -> dict[str, Any]:
    from mechsyn.kinematics.forces import kinetostatics

    ev = evaluate_drawn(case, d)
    if ev.q is None:
        return {"assembled": False}
    S, q = ev.system, ev.q
    R = kinetostatics(S, q, None, None, gravity=(0.0, -case.gravity))
    mags = {j: float(np.max(np.linalg.norm(F, axis=1))) for j, F in R.force.items()}
    j = max(mags, key=mags.get)
    out = {"peak_reaction": mags[j], "peak_joint": j,
           "peak_input_moment": float(np.max(np.abs(R.effort[case.input]))), "assembled": True}
    for jid in vlls:  # axial force in the merged VLL link, at the piston's pivot L
        _cyl, L, K, _pis = _vll_ends(case.mech_dict, jid, case.source)
        jl, jk = S.mech.joint(L), S.mech.joint(K)
        cyl = jl.links[0]
        pl = S.point(q, S.index(cyl), S.to_local(cyl, jl.point))
        pk = S.point(q, S.index(cyl), S.to_local(cyl, jk.point))
        u = (pl - pk) / np.linalg.norm(pl - pk, axis=1)[:, None]
        out["vll_force_peak"] = float(np.max(np.abs(np.sum(R.force[L] * u, axis=1))))
    return out


def _drawn_input(case: FingerCase, mech: Any) -> float:
    from mechsyn.kinematics.system import build_system

    S = build_system(mech)
    return float(np.degrees(next(dr.assembled for dr in S.drivers if dr.joint == case.input)))


def force_objective(case: FingerCase, combo: tuple[str, ...], tol: float,
                    hold: dict[str, float] | None = None, bound: float = np.inf) -> Objective:
    """Stage 2: ``peak |R| + w peak |M_in|`` (static, closed form), feasible only when the
    target error stays within ``tol`` (deg RMS) and the paths in the region.

    The locked mode is evaluated first; its value is a lower bound of the both-mode
    criterion, so only a design whose locked value is below ``bound`` (the stage-1
    design's both-mode criterion) is also evaluated in the underactuated mode with the
    VLL held at ``hold`` (stage 1's ``l_max``): there it must assemble over the crank
    range and keep the paths in the region (the force stage keeps the adaptive range),
    and its value becomes the both-mode criterion.
    """
    def f(x: np.ndarray) -> float:
        ev = evaluate_locked(case, x, combo)
        if not ev.feasible:
            return INFEASIBLE + ev.violation
        if ev.error_rms > tol:
            return INFEASIBLE + (ev.error_rms - tol)
        try:
            pr, pm, _ = _peaks(ev.system, ev.q, case)
        except Exception:  # noqa: BLE001 - a singular design is infeasible, never rewarded
            return INFEASIBLE + 1.0
        if not (np.isfinite(pr) and np.isfinite(pm)):
            return INFEASIBLE + 1.0
        value = pr + case.weight_moment * pm
        if not hold or value >= bound:
            return value
        d = redraw(case, apply_design(case, x, combo), hold)
        ev2 = evaluate_drawn(case, d) if d is not None else None
        if ev2 is None or not ev2.feasible:
            return INFEASIBLE + (ev2.violation if ev2 is not None else 1.0)
        try:
            pr2, pm2, _ = _peaks(ev2.system, ev2.q, case)
        except Exception:  # noqa: BLE001
            return INFEASIBLE + 1.0
        return max(pr, pr2) + case.weight_moment * max(pm, pm2)
    return f


# --------------------------------------------------------------------------- driver
@dataclass
class VariantResult:
    combination: tuple[str, ...]
    stage1_design: dict[str, float]
    stage1_error_rms: float
    stage1_error_max: float
    design: dict[str, float]
    error_rms: float
    error_max: float
    achieved: dict[str, list[float]]
    vll_ranges: dict[str, tuple[float, float]]
    stage1_forces: dict[str, Any]
    forces: dict[str, Any]
    force_stage_improved: bool
    assembled_at_all_targets: bool = False
    mechanism: dict = field(repr=False, default_factory=dict)
    underactuated: dict[str, Any] = field(repr=False, default_factory=dict)
    evaluations: int = 0

    def to_dict(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in (
            "combination", "stage1_design", "stage1_error_rms", "stage1_error_max", "design", "error_rms",
            "error_max", "achieved", "vll_ranges", "stage1_forces", "forces", "force_stage_improved",
            "assembled_at_all_targets", "evaluations")}


@dataclass
class FingerDesign:
    case: str
    seed: int
    variants: list[VariantResult]
    best: int
    targets: dict[str, Any]
    tolerance_deg: float
    seconds: float
    stopped_by_time_limit: bool = False
    notes: list[str] = field(default_factory=list)
    interrupted: bool = False    # Ctrl-C ended the search: the best design so far

    @property
    def best_variant(self) -> VariantResult:
        return self.variants[self.best]

    def to_dict(self) -> dict[str, Any]:
        b = self.best_variant
        return {"case": self.case, "seed": self.seed, "best": {
                    "combination": b.combination, "design": b.design, "error_rms_deg": b.error_rms,
                    "error_max_deg": b.error_max, "vll_ranges": b.vll_ranges,
                    "peak_reaction": b.forces["peak_reaction"], "peak_input_moment": b.forces["peak_input_moment"],
                    "assembled_at_all_targets": b.assembled_at_all_targets},
                "targets": self.targets, "tolerance_deg": self.tolerance_deg,
                "variants": [v.to_dict() for v in self.variants], "seconds": self.seconds,
                "stopped_by_time_limit": self.stopped_by_time_limit, "interrupted": self.interrupted,
                "notes": self.notes,
                "units": {"angles": "deg", "lengths": "file unit", "forces": "file force unit",
                          "moments": "force x length"}}


def _de(f: Objective, bounds: list[tuple[float, float]], seed: int, maxiter: int, popsize: int,
        deadline: float, init: Any = "latinhypercube", report: Callable[[int, float], None] | None = None,
        state: dict | None = None) -> tuple[np.ndarray, float, int, bool, list]:
    """Seeded differential evolution; stops at ``deadline``; ``report(generation, best)``.

    Ctrl-C (:class:`KeyboardInterrupt`) ends it with the best design evaluated so far and
    sets ``state["interrupted"]``; it propagates when nothing was evaluated yet.
    """
    from scipy.optimize import differential_evolution

    stopped = [False]
    gen = [0]
    best = BestSoFar()

    def tracked(x: np.ndarray) -> float:
        value = f(x)
        best.offer(np.atleast_2d(x), np.array([value]))
        return value

    def cb(intermediate_result: Any) -> bool:
        gen[0] += 1
        if report is not None:
            report(gen[0], float(intermediate_result.fun))
        if time.monotonic() > deadline:
            stopped[0] = True
            return True
        return False

    try:
        r = differential_evolution(tracked, bounds, seed=seed, maxiter=maxiter, popsize=popsize, tol=1e-10,
                                   mutation=(0.5, 1.0), recombination=0.9, polish=False, init=init,
                                   callback=cb, updating="deferred")
    except KeyboardInterrupt:
        if best.x is None or state is None:
            raise
        state["interrupted"] = True
        return best.x, best.f, 0, False, [(best.x, best.f)]
    pop = sorted(zip(np.asarray(r.population), np.asarray(r.population_energies)), key=lambda t: t[1])
    return np.asarray(r.x), float(r.fun), int(r.nfev), stopped[0], pop


def design_finger(case: FingerCase, seed: int = 0, time_limit: float = 60.0,
                  progress: Callable[[str], None] | None = None) -> FingerDesign:
    """Run paper 000's steps 8-13 on ``case`` (see the module doc).

    Ctrl-C (:class:`KeyboardInterrupt`, also raised by ``progress``) ends the search: the
    variant being searched keeps its best design so far (its force stage is skipped),
    later variants are not searched, and the result has ``interrupted=True``.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.finger_design import load_case
    >>> res = ms.design_finger(load_case(ms.examples.path("finger_design_case")), seed=1, time_limit=20)
    >>> res.best_variant.error_rms < 1.0       # degrees, on the case's target positions
    True
    """
    t0 = time.monotonic()
    deadline = t0 + time_limit
    bounds = [v.bounds for v in case.variables]
    names = [v.name for v in case.variables]
    variants = []
    notes: list[str] = []
    stopped = False
    state = {"interrupted": False}
    for combo in case.combinations:
        if state["interrupted"]:
            notes.append(f"VLL {'+'.join(combo)}: not searched (interrupted)")
            continue
        if progress:
            progress(f"VLL {'+'.join(combo)}: stage 1 (targets, VLL locked at l_min)")
        label = "+".join(combo)

        def report1(g: int, best: float, label: str = label) -> None:
            if progress:
                progress(f"VLL {label}: stage 1, generation {g}/{case.maxiter}, best " + (
                    f"RMS error {best:.4g} deg" if best < INFEASIBLE else "design still infeasible"))

        x1, f1, n1, st1, _ = _de(stage1_objective(case, combo), bounds, seed, case.maxiter, case.popsize,
                                 deadline, report=report1, state=state)
        if f1 >= INFEASIBLE:
            notes.append(f"VLL {'+'.join(combo)}: no feasible design (every tried design fails to assemble over "
                         "the crank range or leaves the region)")
            continue
        ev1 = evaluate_locked(case, x1, combo)
        tol = max(case.tolerance_deg, ev1.error_rms)  # stage 2 keeps stage 1's accuracy
        d1 = apply_design(case, x1, combo)
        if progress:
            progress("VLL ranges and forces of the stage-1 design")
        ranges1 = {j: vll_range(case, d1, j)[:2] for j in combo}
        forces1 = mode_forces(case, d1, combo, ranges1)
        # stage 2: forces, starting from a population that holds the stage-1 design
        rng = np.random.default_rng(seed)
        npop = max(5, case.popsize * len(bounds))
        lo, hi = np.array(bounds).T
        init = lo + rng.random((npop, len(bounds))) * (hi - lo)
        init[0] = x1
        for k in range(1, min(npop, 1 + npop // 3)):  # a third of it near the stage-1 design
            init[k] = np.clip(x1 + 0.05 * (hi - lo) * rng.standard_normal(len(bounds)), lo, hi)
        if progress:
            progress("stage 2: forces (both modes)")
        x2, f2, n2, st2, pop = (x1, f1, 0, False, []) if state["interrupted"] else _de(force_objective(case, combo, tol, {j: r[1] for j, r in ranges1.items()},
                                                   forces1["criterion"]), bounds, seed, case.force_maxiter,
                                   case.popsize, deadline, init=init,
                                   report=(lambda g, best: progress(
                                       f"VLL {label}: force stage, generation {g}/{case.force_maxiter}, best "
                                       f"criterion {best:.4g}")) if progress else None, state=state)
        stopped = stopped or st1 or st2
        chosen, ranges, forces_, improved = x1, ranges1, forces1, False
        # the locked-mode criterion steers the search; the best few distinct members are
        # then checked in both modes (VLL range and forces) and one is accepted only if
        # the peak reaction does not rise and the criterion falls
        uniq: list[np.ndarray] = []
        for x, e in pop:
            if e < INFEASIBLE and not np.allclose(x, x1) and not any(
                    np.allclose(x, u, rtol=0, atol=1e-6) for u in uniq):
                uniq.append(x)
        for x in uniq[:case.candidates]:
            if time.monotonic() > deadline:
                stopped = True
                break
            d2 = apply_design(case, x, combo)
            try:
                ranges2 = {j: vll_range(case, d2, j)[:2] for j in combo}
                forces2 = mode_forces(case, d2, combo, ranges2)
            except MechsynInputError:
                continue
            if all(r[1] > r[0] for r in ranges2.values()) and forces2["peak_reaction"] <= forces_["peak_reaction"] \
                    and forces2["criterion"] < forces_["criterion"]:
                chosen, ranges, forces_, improved = x, ranges2, forces2, True
        ev = evaluate_locked(case, chosen, combo)
        d = apply_design(case, chosen, combo)
        for j in d["joints"]:
            if j["id"] in ranges:
                j["limits"] = list(ranges[j["id"]])
        under = {}
        for jid in combo:
            lens = np.linspace(ranges[jid][0], ranges[jid][1], 5)
            under[jid] = {"lengths": lens, "paths": underactuated_paths(case, d, jid, lens)}
        variants.append(VariantResult(
            combination=combo, stage1_design=dict(zip(names, x1.tolist())), stage1_error_rms=ev1.error_rms,
            stage1_error_max=ev1.error_max, design=dict(zip(names, chosen.tolist())), error_rms=ev.error_rms,
            error_max=ev.error_max, achieved={k: v.tolist() for k, v in ev.achieved.items()},
            vll_ranges=ranges, stage1_forces=forces1, forces=forces_, force_stage_improved=improved,
            assembled_at_all_targets=bool(ev.q is not None and np.isfinite(ev.q).all()),
            mechanism=d, underactuated=under, evaluations=n1 + n2))
    if not variants and state["interrupted"]:
        raise KeyboardInterrupt  # nothing feasible to keep
    if not variants:
        raise MechsynInputError(
            "no feasible design: " + "; ".join(notes), source=case.source, field="variables",
            hint="widen the bounds or the region, or move the targets")
    crit = [v.forces["criterion"] if all(r[1] > r[0] for r in v.vll_ranges.values()) else np.inf
            for v in variants]
    best = int(np.argmin(crit))
    return FingerDesign(case.source, seed, variants, best,
                        {"inputs": case.target_inputs.tolist(),
                         "rotations": {k: v.tolist() for k, v in case.target_angles.items()}},
                        case.tolerance_deg, time.monotonic() - t0, stopped, notes,
                        interrupted=state["interrupted"])
