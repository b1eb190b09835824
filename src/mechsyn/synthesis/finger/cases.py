"""Paper 000's finger-design cases: the dataclasses and the loader of a case file.

A case names a mechanism file with variable-length links (VLL), the input joint, the
design variables with their bounds, the discrete target positions, the working region
and the output points; ``docs/finger_design.md`` describes every field.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError, input_boundary
from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.io.checks import numbers
from mechsyn.io.files import read_data, resolve_path
from mechsyn.synthesis.finger.vll import vll_ends

__all__ = ["FingerVariable", "FingerCase", "load_case", "case_from_dict"]


@dataclass(frozen=True)
class FingerVariable:
    """One design variable: ``kind`` joint (a joint point's x or y), point (a named
    point's x or y) or vll_angle (the VLL's direction in the drawn configuration, deg)."""

    name: str
    kind: str
    target: str
    coord: int          # 0: x, 1: y (unused for vll_angle)
    bounds: tuple[float, float]


@dataclass
class FingerCase:
    """A finger-design case: the mechanism (with its VLL) as a file dict, the input
    joint, the design variables, the targets (crank rotation -> phalanx rotations, deg),
    the working region, the output points, the VLL combinations to try, the force
    criterion's settings and the optimiser's budget (see ``docs/finger_design.md``)."""

    source: str
    mech_dict: dict
    input: str
    variables: list[FingerVariable]
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
        """``(l_min, l_max)`` of VLL ``jid``: its joint's ``limits`` in the file."""
        j = next(j for j in self.mech_dict["joints"] if j["id"] == jid)
        return float(j["limits"][0]), float(j["limits"][1])


def _err(msg: str, source: str, fld: str | None = None, hint: str | None = None) -> MechsynInputError:
    return MechsynInputError(msg, source=source, field=fld, hint=hint)


def load_case(path: str | Path) -> FingerCase:
    """Read a finger-design case (YAML or JSON); the mechanism path is relative to it."""
    path = resolve_path(path)  # a bundled case's name: its mechanism is beside the bundled file
    data, _text = read_data(path, "case file")
    return case_from_dict(data, str(path), base_dir=path.parent)


def _floats(v: Any, n: int | None, src: str, fld: str) -> list[float]:
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
    """Validate a finger-design case (see ``docs/finger_design.md``).

    Parameters
    ----------
    data : dict
        The case file's data: ``mechanism`` (path, relative to ``base_dir``), ``input``,
        ``variables``, ``targets``, ``region`` and the optional fields.
    source : str
        Name of the case in error messages.
    base_dir : Path, optional
        Directory the mechanism path is relative to.

    Returns
    -------
    FingerCase

    Raises
    ------
    MechsynInputError
        On bad input, naming the field.

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.synthesis.finger.cases import load_case
    >>> case = load_case(ms.examples.path("finger_design_case"))
    >>> case.input, [v.name for v in case.variables][:2], case.combinations
    ('E', ['D.x', 'D.y'], [('S',)])
    """
    src = source
    if not isinstance(data, dict):
        raise _err("the case must be a mapping", src)
    for key in ("mechanism", "input", "variables", "targets", "region"):
        if key not in data:
            raise _err(f"missing field {key!r}", src, key, hint="see docs/finger_design.md")
    md, mname = _mechanism(data, src, base_dir)
    _masses(md, data.get("masses") or {}, src)
    if "loads" in data:
        md["loads"] = _loads(md, data["loads"] or [], src)
    joints = {j["id"]: j for j in md["joints"]}
    inp = str(data["input"])
    if inp not in joints or not joints[inp].get("actuated") or joints[inp]["type"] != "R":
        raise _err(f"input {inp!r} is not an actuated R joint of {mname}", src, "input")
    vll_all = _vlls(md, mname, src)
    combos = _combinations(data.get("combinations"), vll_all, src)
    variables = _variables(data["variables"], md, vll_all, src)
    tin, tang = _targets(data["targets"], md, src)
    region, pts = _region_points(data, md, src)
    case = FingerCase(src, md, inp, variables, tin, tang, region, pts, combos)
    _options(case, data, src)
    return case


def _mechanism(data: dict, src: str, base_dir: Path | None) -> tuple[dict, str]:
    """The case's mechanism file as a dict, and its file name."""
    mpath = Path(str(data["mechanism"]))
    if not mpath.is_absolute() and base_dir is not None:
        mpath = base_dir / mpath
    if not mpath.is_file():
        raise _err(f"mechanism file not found: {mpath}", src, "mechanism")
    return mechanism_to_dict(load_mechanism(mpath)), mpath.name


def _link_names(md: dict) -> list[str]:
    return [x if isinstance(x, str) else x["name"] for x in md["links"]]


def _masses(md: dict, masses: Any, src: str) -> None:
    """Set the case's masses (``link -> {mass, com, inertia}``) on the links of ``md``."""
    names = _link_names(md)
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


def _loads(md: dict, loads: Any, src: str) -> list[dict]:
    """The case's loads, checked against the mechanism's links and named points."""
    names = _link_names(md)
    if not isinstance(loads, list):
        raise _err("loads must be a list like the mechanism file's", src, "loads")
    out = []
    for k, ld in enumerate(loads):
        if not isinstance(ld, dict) or ld.get("link") not in names:
            raise _err("each load names a link of the mechanism", src, f"loads[{k}]")
        ld = dict(ld)
        if "point" in ld:  # a named point: its drawn coordinates
            pt = (md.get("points") or {}).get(ld["point"])
            if pt is None or pt["link"] != ld["link"]:
                raise _err(f"loads[{k}].point must be a point of link {ld['link']}", src, f"loads[{k}]")
        for key in ("force", "at"):
            if key in ld:
                ld[key] = _floats(ld[key], 2, src, f"loads[{k}].{key}")
        out.append(ld)
    return out


def _vlls(md: dict, mname: str, src: str) -> list[str]:
    """The VLL joints of the mechanism, each checked (cylinder, piston, limits)."""
    joints = {j["id"]: j for j in md["joints"]}
    vll_all = [j["id"] for j in md["joints"] if j.get("vll")]
    if not vll_all:
        raise _err(f"{mname} has no variable-length link (a P joint with vll:)", src, "mechanism")
    for jid in vll_all:
        vll_ends(md, jid, src)
        lim = joints[jid].get("limits")
        if lim is None or not (0 < lim[0] < lim[1]):
            raise _err(f"VLL {jid} needs limits [min, max] with 0 < min < max", src, "mechanism",
                       hint="the min is the minimum constructible length (paper 000, step 7)")
    return vll_all


def _combinations(raw: Any, vll_all: list[str], src: str) -> list[tuple[str, ...]]:
    """The VLL combinations to try: the case's, or every non-empty subset of the VLL."""
    raw = raw or [list(c) for r in range(1, len(vll_all) + 1) for c in itertools.combinations(vll_all, r)]
    combos = []
    for c in raw:
        c = [c] if isinstance(c, str) else list(c)
        for jid in c:
            if jid not in vll_all:
                raise _err(f"combination names {jid!r}, not a VLL of the mechanism", src, "combinations",
                           hint=f"VLL joints: {', '.join(vll_all)}")
        combos.append(tuple(c))
    return combos


def _variables(raw: Any, md: dict, vll_all: list[str], src: str) -> list[FingerVariable]:
    """The design variables: joint or point coordinates, VLL directions."""
    if not isinstance(raw, list) or not raw:
        raise _err("variables must be a non-empty list", src, "variables")
    return [_variable(v, f"variables[{k}]", md, vll_all, src) for k, v in enumerate(raw)]


def _variable(v: Any, fld: str, md: dict, vll_all: list[str], src: str) -> FingerVariable:
    joints = {j["id"]: j for j in md["joints"]}
    if not isinstance(v, dict) or "bounds" not in v:
        raise _err("each variable needs bounds: [lo, hi]", src, fld)
    b = _floats(v["bounds"], 2, src, fld + ".bounds")
    if not b[0] < b[1]:
        raise _err("bounds must be [lo, hi] with lo < hi", src, fld + ".bounds")
    if "vll_angle" in v:
        tgt = str(v["vll_angle"])
        if tgt not in vll_all:
            raise _err(f"no VLL {tgt!r}", src, fld)
        return FingerVariable(f"{tgt}.angle", "vll_angle", tgt, 0, (b[0], b[1]))
    if "joint" not in v and "point" not in v:
        raise _err("a variable names a joint, a point or a vll_angle", src, fld)
    kind = "joint" if "joint" in v else "point"
    tgt = str(v[kind])
    if kind == "joint" and tgt not in joints:
        raise _err(f"no joint {tgt!r}", src, fld)
    if kind == "point" and tgt not in (md.get("points") or {}):
        raise _err(f"no point {tgt!r}", src, fld)
    if kind == "joint" and any(tgt == vll_ends(md, c, src)[1] for c in vll_all):
        raise _err(f"joint {tgt} is a VLL's piston pivot: vary the VLL's angle instead", src, fld,
                   hint="write {vll_angle: <VLL>, bounds: [lo, hi]}")
    coord = v.get("coord", "x")
    if coord not in ("x", "y"):
        raise _err("coord must be x or y", src, fld)
    return FingerVariable(f"{tgt}.{coord}", kind, tgt, 0 if coord == "x" else 1, (b[0], b[1]))


def _targets(tg: Any, md: dict, src: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """Crank rotations and, per link, the rotations to reach there (deg)."""
    if not isinstance(tg, list) or len(tg) < 2:
        raise _err("targets must list at least two positions (the extremes)", src, "targets")
    links = [lk for lk in tg[0] if lk != "input"] if isinstance(tg[0], dict) else []
    if not links:
        raise _err("a target gives the input and at least one link's rotation", src, "targets[0]")
    tin, tang = [], {lk: [] for lk in links}
    for k, t in enumerate(tg):
        if not isinstance(t, dict) or "input" not in t or set(t) - {"input"} != set(links):
            raise _err(f"each target gives input and rotations of {', '.join(links)}", src, f"targets[{k}]")
        tin.append(_floats([t["input"]], 1, src, f"targets[{k}].input")[0])
        for lk in links:
            if lk not in _link_names(md):
                raise _err(f"no link {lk!r}", src, f"targets[{k}]")
            tang[lk].append(_floats([t[lk]], 1, src, f"targets[{k}].{lk}")[0])
    return np.array(tin), {k: np.array(v) for k, v in tang.items()}


def _region_points(data: dict, md: dict, src: str) -> tuple[np.ndarray, list[str]]:
    """The working region (polygon) and the output points kept in it."""
    region = np.array([_floats(p, 2, src, "region") for p in data["region"]]) if isinstance(
        data["region"], list) else None
    if region is None or len(region) < 3:
        raise _err("region must be a polygon of at least 3 [x, y] points", src, "region")
    joints = {j["id"] for j in md["joints"]}
    pts = data.get("points") or list(md.get("points") or {})
    if not pts:
        raise _err("name the output points whose paths must stay in the region", src, "points")
    for p in pts:
        if p not in (md.get("points") or {}) and p not in joints:
            raise _err(f"no point or joint {p!r}", src, "points")
    return region, list(pts)


def _options(case: FingerCase, data: dict, src: str) -> None:
    """The force criterion's settings and the optimiser's budget."""
    from mechsyn.io.checks import numbers, whole_number

    for key in ("gravity", "weight_moment", "tolerance_deg", "step_deg"):
        if key in data:
            if isinstance(data[key], (list, dict)):
                raise _err(f"{key} must be one number", src, key)
            setattr(case, key, float(numbers(data[key], src, key)))
    opt = data.get("optimizer") or {}
    if not isinstance(opt, dict):
        raise _err("optimizer must be a mapping of settings (maxiter: 40, ...)", src, "optimizer")
    for key in ("maxiter", "popsize", "force_maxiter", "vll_steps", "candidates"):
        if key in opt:
            setattr(case, key, whole_number(opt[key], src, f"optimizer.{key}", 1, 1_000_000))
    if case.step_deg <= 0 or case.tolerance_deg <= 0:
        raise _err("step_deg and tolerance_deg must be positive", src)
