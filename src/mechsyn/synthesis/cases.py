"""Synthesis case files: the case dataclasses and their loaders (no solver runs here).

Two formats, one error style (:func:`_err`, :func:`_floats`: every error names the file,
the field and the fix):

* :class:`PathCase` -- four-bar path generation (``mechsyn synth path``), the schema of
  ``spec/data/synthesis_cases_public.json``; solved by :mod:`mechsyn.synthesis.path` and
  :mod:`mechsyn.synthesis.optimize`. :func:`load_cases` reads one case or a
  ``{"cases": [...]}`` collection.
* :class:`MechanismCase` -- path or motion generation with any planar mechanism file
  (``mechsyn synth mechanism``, docs/synthesis.md "Any planar mechanism"); solved by
  :mod:`mechsyn.synthesis.general`. :func:`load_mechanism_case` reads a YAML/JSON case.

Loading validates and returns data only: the assembly modes of the file's drawing (the
branch a design must keep) are found by the solver when it first needs them
(:func:`mechsyn.synthesis.general.reference_branch`).

Examples
--------
>>> case = PathCase.from_dict({"targets": [[0, 1], [1, 1], [1, 0]],
...     "timing": {"type": "prescribed", "theta2": [0.0, 0.5, 1.0]},
...     "variables": [{"name": k, "lower": 0.1, "upper": 5} for k in LENGTHS + ("rcx", "rcy")]})
>>> case.n, case.timing, case.fixed
(3, 'prescribed', {'x0': 0.0, 'y0': 0.0, 'theta0': 0.0})
>>> PathCase.from_dict({"targets": [[0, 1]], "timing": {"type": "sometimes"}}, "c.json")
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: c.json: timing.type: unknown timing type 'sometimes' (fix: one of prescribed, prescribed_increment, free)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError, input_boundary
from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.io.checks import flag, numbers
from mechsyn.io.files import read_data, resolve_path
from mechsyn.limits import limit, limit_hint

__all__ = ["Variable", "PathCase", "load_cases", "DesignVariable", "MechanismCase", "load_mechanism_case",
           "mechanism_case_from_dict", "LINKAGE_NAMES", "LENGTHS", "TIMING_TYPES"]

LINKAGE_NAMES = ("x0", "y0", "theta0", "r1", "r2", "r3", "r4", "rcx", "rcy")
LENGTHS = ("r1", "r2", "r3", "r4")
TIMING_TYPES = ("prescribed", "prescribed_increment", "free")
TRANSMISSION_ANGLE_MIN_DEG = 20.0  # default margin of force transmission over the motion
FOLD_MARGIN_DEG = 5.0  # default distance of a Grashof design from folding flat


def _err(msg: str, source: str | None, fld: str | None = None, hint: str | None = None) -> MechsynInputError:
    """The one error of a case file: ``source: field: msg (hint)``."""
    return MechsynInputError(msg, source=source, field=fld, hint=hint)


def _floats(v: Any, src: str | None, fld: str, n: int | None = None) -> np.ndarray:
    """Finite numbers of field ``fld`` as an array (``n`` per entry when given)."""
    a = numbers(v, src, fld)
    if n is not None and a.shape[-1:] != (n,):
        raise _err(f"{fld} must be finite numbers" + (f", {n} per entry" if n else ""), src, fld)
    return a


# =========================================================================== path cases
@dataclass(frozen=True)
class Variable:
    """A design variable of a :class:`PathCase` with its bounds."""

    name: str
    lower: float
    upper: float


@dataclass(frozen=True)
class PathCase:
    """A path-generation case (see :mod:`mechsyn.synthesis.path` for the schema)."""

    id: str
    targets: np.ndarray
    timing: str
    theta2: np.ndarray | None  # prescribed angles, or increments from theta2_1
    fixed: dict[str, float]
    variables: tuple[Variable, ...]
    branch: int = -1
    grashof: bool | str = False
    order: str = "ccw"
    transmission_angle_min_deg: float | None = TRANSMISSION_ANGLE_MIN_DEG
    fold_margin_deg: float = FOLD_MARGIN_DEG
    link_ratio_max: float | None = None
    max_size: float | None = None  # as the case states it (None: not stated; 0: no bound)
    title: str = ""
    published: tuple[dict, ...] = ()
    best_known: float | None = None
    raw: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def n(self) -> int:
        return len(self.targets)

    def bounds(self) -> dict[str, tuple[float, float]]:
        return {v.name: (v.lower, v.upper) for v in self.variables}

    @classmethod
    @input_boundary("path-synthesis case")
    def from_dict(cls, data: Any, source: str | None = None) -> "PathCase":
        """Validate a case object; :class:`MechsynInputError` naming the field on bad input."""
        if not isinstance(data, dict):
            raise _err("a case must be a JSON object", source, "(top level)")
        targets = _path_targets(data, source)
        n = len(targets)
        ttype, theta2 = _path_timing(data.get("timing") or {}, n, source)
        fixed = _path_fixed(data.get("fixed") or {}, source)
        variables = _path_variables(data.get("variables") or [], ttype, n, fixed, source)
        best = data.get("best_known", {})
        return cls(
            id=str(data.get("id", "case")), title=str(data.get("title", "")), targets=targets,
            timing=ttype, theta2=theta2, fixed=fixed, variables=variables, **_path_options(data, source),
            published=tuple(data.get("published_solutions") or ()),
            best_known=_best_known(best, source), raw=data,
        )


def _path_targets(data: dict, source: str | None) -> np.ndarray:
    if "targets" not in data:
        raise _err("missing", source, "targets", "give a list of [x, y] points")
    targets = numbers(data["targets"], source, "targets")
    if targets.ndim != 2 or targets.shape[1] != 2 or len(targets) < 1:
        raise _err(f"must be a list of [x, y] points, got shape {targets.shape}", source, "targets")
    if not np.all(np.isfinite(targets)):
        raise _err("must be finite numbers", source, "targets")
    return targets


def _path_timing(timing: Any, n: int, source: str | None) -> tuple[str, np.ndarray | None]:
    """The timing type and its angles: prescribed ``theta2``, or the offsets from
    ``theta2_1`` of ``prescribed_increment`` (None for free timing)."""
    ttype = timing.get("type") if isinstance(timing, dict) else None
    if ttype not in TIMING_TYPES:
        raise _err(f"unknown timing type {ttype!r}", source, "timing.type", "one of " + ", ".join(TIMING_TYPES))
    if ttype == "prescribed":
        try:
            theta2 = np.asarray(timing["theta2"], dtype=float)
        except (KeyError, TypeError, ValueError):
            raise _err("prescribed timing needs a list of n angles [rad]", source, "timing.theta2") from None
        if theta2.shape != (n,):
            raise _err(f"expected {n} angles, got {theta2.size}", source, "timing.theta2")
        return ttype, theta2
    if ttype == "free":
        return ttype, None
    if "increments" in timing:
        inc = np.asarray(timing["increments"], dtype=float)
        if inc.shape != (n - 1,):
            raise _err(f"expected {n - 1} increments", source, "timing.increments")
    elif "step" in timing:
        inc = np.full(n - 1, float(timing["step"]))
    else:
        raise _err("needs 'step' or 'increments' [rad]", source, "timing")
    return ttype, np.concatenate([[0.0], np.cumsum(inc)])


def _path_fixed(fixed_raw: Any, source: str | None) -> dict[str, float]:
    if not isinstance(fixed_raw, dict):
        raise _err("must be an object name -> value", source, "fixed")
    fixed: dict[str, float] = {}
    for k, v in fixed_raw.items():
        if k not in LINKAGE_NAMES:
            raise _err(f"unknown design name {k!r}", source, f"fixed.{k}", "one of " + ", ".join(LINKAGE_NAMES))
        if np.ndim(v) != 0:
            raise _err("must be a number", source, f"fixed.{k}")
        fixed[k] = float(numbers(v, source, f"fixed.{k}").reshape(-1)[0])
    return fixed


def _timing_names(ttype: str, n: int) -> set[str]:
    """The crank-angle variables a timing type needs."""
    if ttype == "free":
        return {f"theta2_{i + 1}" for i in range(n)}
    return {"theta2_1"} if ttype == "prescribed_increment" else set()


def _path_variables(items: Any, ttype: str, n: int, fixed: dict[str, float],
                    source: str | None) -> tuple[Variable, ...]:
    """The variables with their bounds; completes ``fixed`` with the pivot's defaults
    (``x0 = y0 = theta0 = 0``) and refuses a linkage name that is neither."""
    allowed = set(LINKAGE_NAMES) | _timing_names(ttype, n)
    variables = []
    for i, v in enumerate(items):
        if not isinstance(v, dict) or not {"name", "lower", "upper"} <= set(v):
            raise _err("needs name, lower and upper", source, f"variables[{i}]")
        name = v["name"]
        lo, hi = (float(b) for b in numbers([v["lower"], v["upper"]], source, f"variables[{i}]"))
        if name not in allowed:
            raise _err(f"unknown or unusable variable {name!r} for timing {ttype!r}", source,
                       f"variables[{i}].name")
        if name in fixed:
            raise _err(f"{name!r} is both fixed and variable", source, f"variables[{i}].name")
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise _err(f"bounds [{lo}, {hi}] are not an interval", source, f"variables[{i}]")
        variables.append(Variable(name, lo, hi))
    names = [v.name for v in variables]
    if len(set(names)) != len(names):
        raise _err("a variable is listed twice", source, "variables")
    defaults = {"x0": 0.0, "y0": 0.0, "theta0": 0.0}
    for k in LINKAGE_NAMES:
        if k not in fixed and k not in names:
            if k not in defaults:
                raise _err(f"{k!r} is neither fixed nor a variable", source, "variables", f"add {k} with bounds")
            fixed[k] = defaults[k]
    missing = sorted(_timing_names(ttype, n) - set(names))
    if missing:
        raise _err(f"timing {ttype!r} needs variables {missing}", source, "variables")
    return tuple(variables)


def _path_options(data: dict, source: str | None) -> dict[str, Any]:
    """Branch, Grashof, order, angle margins and link ratio of a case."""
    branch = (data.get("kinematics") or {}).get("branch", -1)
    if branch not in (-1, 1):
        raise _err("must be -1 or +1", source, "kinematics.branch")
    options = data.get("options") or {}
    grashof: bool | str = any(str(c).strip().lower().startswith("grashof") for c in data.get("constraints") or [])
    if "grashof" in options:
        grashof = options["grashof"]
        if grashof not in (True, False, "crank-rocker"):
            raise _err("must be true, false or \"crank-rocker\"", source, "options.grashof")
    order = options.get("order", "ccw")
    if order not in ("ccw", "cw"):
        raise _err("must be \"ccw\" or \"cw\"", source, "options.order")
    out = {"branch": int(branch), "grashof": grashof, "order": order,
           "link_ratio_max": options.get("link_ratio_max"), "max_size": options.get("max_size")}
    size = out["max_size"]
    if size is not None and (isinstance(size, bool) or not isinstance(size, (int, float)) or not size >= 0):
        raise _err("must be a number of target diagonals >= 0 (0: no bound)", source, "options.max_size")
    for key, default in (("transmission_angle_min_deg", TRANSMISSION_ANGLE_MIN_DEG),
                         ("fold_margin_deg", FOLD_MARGIN_DEG)):
        value = options.get(key, default)
        if value is None and key == "transmission_angle_min_deg":
            value = 0.0
        if not isinstance(value, (int, float)) or not 0.0 <= float(value) < 90.0:
            raise _err("must be an angle in degrees in [0, 90)", source, f"options.{key}")
        out[key] = float(value)
    return out


def _best_known(best: Any, source: str) -> float | None:
    """The published best error of a case (``best_known.value``), a finite number or absent."""
    value = best.get("value") if isinstance(best, dict) else None
    if value is None:
        return None
    if isinstance(value, (list, dict)):
        raise MechsynInputError("best_known.value must be one number", source=source, field="best_known.value")
    return float(numbers(value, source, "best_known.value"))


def load_cases(path: str | Path) -> list[PathCase]:
    """Load one case object, or every case of a ``{"cases": [...]}`` collection."""
    path = Path(path)
    data, _ = read_data(path, "case file", fmt="json")
    if isinstance(data, dict) and "cases" in data:
        items = data["cases"]
        if not isinstance(items, list) or not all(isinstance(c, dict) for c in items):
            raise MechsynInputError("cases must be a list of case objects", source=str(path), field="cases",
                                    hint='write "cases": [{"id": ..., "targets": ...}, ...]')
        return [PathCase.from_dict(c, source=f"{path}#cases[{i}]") for i, c in enumerate(items)]
    return [PathCase.from_dict(data, source=str(path))]


# ====================================================================== mechanism cases
@dataclass(frozen=True)
class DesignVariable:
    """One coordinate of the drawn configuration: ``kind`` is ``joint`` / ``point`` (x or
    y: ``coord`` 0 / 1) or ``length`` (a VLL's length, ``coord`` None)."""

    kind: str
    target: str
    coord: int | None
    lower: float
    upper: float

    @property
    def name(self) -> str:
        return f"{self.target}.length" if self.kind == "length" else f"{self.target}.{'xy'[self.coord]}"


@dataclass
class MechanismCase:
    """A synthesis case of any planar mechanism file (see :func:`mechanism_case_from_dict`).

    ``reference``: the assembly modes (one sign per closed-form dyad) of the file's drawing,
    the branch every design must keep; None until the solver first needs it
    (:func:`mechsyn.synthesis.general.reference_branch`).
    """

    source: str
    mechanism_path: str
    mech_dict: dict
    input_joint: str
    values_deg: np.ndarray
    variables: list[DesignVariable]
    problem: str                       # "path" | "motion"
    targets: np.ndarray                # (N, 2) positions
    point: str | None = None
    link: str | None = None
    angles_deg: np.ndarray | None = None   # motion: (N,)
    angle_weight: float = 1.0
    free: bool = False
    range_deg: tuple[float, float] | None = None
    step_deg: float = 2.0
    name: str = "mechanism synthesis"
    method: str = "auto"                   # "auto" (closed form when it decomposes) | "newton"
    reference: list[float] | None = field(default=None, repr=False, compare=False)

    @property
    def n_targets(self) -> int:
        return len(self.values_deg)

    @property
    def n_design(self) -> int:
        return len(self.variables)

    @property
    def lower(self) -> np.ndarray:
        lo = [v.lower for v in self.variables]
        if self.free:
            lo += [self.range_deg[0]] * self.n_targets
        return np.array(lo, float)

    @property
    def upper(self) -> np.ndarray:
        hi = [v.upper for v in self.variables]
        if self.free:
            hi += [self.range_deg[1]] * self.n_targets
        return np.array(hi, float)

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.variables] + (
            [f"{self.input_joint}_{i + 1}" for i in range(self.n_targets)] if self.free else [])


def load_mechanism_case(path: str | Path) -> MechanismCase:
    """Read a case YAML/JSON (see docs/synthesis.md, "Any planar mechanism").

    Examples
    --------
    >>> import mechsyn as ms
    >>> case = load_mechanism_case(ms.examples.path("slider_crank_path_case"))
    >>> case.problem, case.n_targets, case.names
    ('path', 8, ['B.x', 'B.y', 'C.x', 'C.y', 'M.x', 'M.y'])
    """
    p = resolve_path(path)  # a bundled case's name: its mechanism is beside the bundled file
    data, _ = read_data(p, "case file", fmt="yaml")
    return mechanism_case_from_dict(data, source=str(p), base_dir=p.parent)


_CASE_KEYS = {"name", "mechanism", "input", "point", "targets", "link", "poses", "variables",
              "angle_weight", "step_deg", "method"}


@input_boundary("synthesis case")
def mechanism_case_from_dict(data: Any, source: str = "<case>", base_dir: Path | None = None) -> MechanismCase:
    """Validate a case mapping; the mechanism file path is relative to ``base_dir``."""
    src = source
    if not isinstance(data, dict):
        raise _err("the case must be a mapping", src)
    extra = sorted(set(data) - _CASE_KEYS)
    if extra:
        raise _err(f"unknown key(s): {', '.join(extra)}", src, extra[0], hint="keys: " + ", ".join(sorted(_CASE_KEYS)))
    mpath, mech, md = _case_mechanism(data, src, base_dir)
    jid, values, free, rng = _case_input(data.get("input"), mech, src)
    step = _case_step(data.get("step_deg", 2.0), values, src)
    method = str(data.get("method", "auto"))
    if method not in ("auto", "newton"):
        raise _err("method must be auto or newton", src, "method")
    kw = _case_targets(data, md, src)
    if len(kw["targets"]) != len(values):
        raise _err(f"{len(values)} input values but {len(kw['targets'])} targets", src, "input.values_deg",
                   hint="one input value per target (the start values with free: true)")
    variables = _case_variables(data.get("variables"), md, src)
    return MechanismCase(source=src, mechanism_path=str(mpath), mech_dict=md, input_joint=jid,
                         values_deg=values, variables=variables, free=free, range_deg=rng, step_deg=step,
                         name=str(data.get("name", mech.name)), method=method, **kw)


def _case_mechanism(data: dict, src: str, base_dir: Path | None) -> tuple[Path, Any, dict]:
    """The case's planar mechanism: its path, the model and its dict."""
    if "mechanism" not in data:
        raise _err("missing `mechanism:` (path to a planar mechanism file)", src, "mechanism")
    mpath = Path(str(data["mechanism"]))
    if not mpath.is_absolute() and base_dir is not None:
        mpath = base_dir / mpath
    mech = load_mechanism(mpath)
    if mech.kind != "planar":
        raise _err(f"{mpath}: a planar mechanism is needed", src, "mechanism")
    return mpath, mech, mechanism_to_dict(mech)


def _case_input(inp: Any, mech: Any, src: str) -> tuple[str, np.ndarray, bool, tuple[float, float] | None]:
    """The input joint, its values at the targets [deg], free timing and its range."""
    if not isinstance(inp, dict) or "joint" not in inp or "values_deg" not in inp:
        raise _err("`input:` needs `joint` and `values_deg`", src, "input",
                   hint="input: {joint: A, values_deg: [0, 30, 60]}")
    jid = str(inp["joint"])
    try:
        j = mech.joint(jid)
    except KeyError:
        raise _err(f"no joint {jid!r} in the mechanism", src, "input.joint") from None
    if j.type != "R" or not j.actuated:
        raise _err(f"input joint {jid} must be an actuated R pair", src, "input.joint",
                   hint="mark it `actuated: true` in the mechanism file")
    values = _floats(inp["values_deg"], src, "input.values_deg").ravel()
    if len(values) < 1:
        raise _err("input.values_deg is empty", src, "input.values_deg")
    free = flag(inp.get("free", False), src, "input.free")
    if not free:
        return jid, values, free, None
    r = _floats(inp.get("range_deg", [float(values.min()), float(values.max())]), src, "input.range_deg")
    if r.shape != (2,) or not r[0] < r[1]:
        raise _err("input.range_deg must be [lower, upper] with lower < upper", src, "input.range_deg")
    return jid, values, free, (float(r[0]), float(r[1]))


def _case_step(value: Any, values: np.ndarray, src: str) -> float:
    """The sweep's step [deg], refused when one design's sweep would exceed the limit."""
    step = _floats(value, src, "step_deg").reshape(-1)
    if step.shape != (1,) or not step[0] > 0:
        raise _err("step_deg must be a positive number", src, "step_deg")
    step = float(step[0])
    sweep = (float(np.sum(np.abs(np.diff(values)))) + 360.0) / step  # at most this many positions
    if sweep > limit("sweep_points"):
        raise _err(f"step_deg {step:g} makes a sweep of up to {sweep:,.0f} positions per design, more than "
                   f"the limit of {limit('sweep_points'):,}", src, "step_deg",
                   "use step_deg of about 0.5 to 5; " + limit_hint("sweep_points"))
    return step


def _case_targets(data: dict, md: dict, src: str) -> dict[str, Any]:
    """The problem (path: ``point`` + ``targets``; motion: ``link`` + ``poses``) as
    :class:`MechanismCase` fields."""
    if ("point" in data or "targets" in data) == ("link" in data or "poses" in data):
        raise _err("give either `point` + `targets` (path) or `link` + `poses` (motion)", src,
                   hint="path: point: P, targets: [[x, y], ...]")
    if "point" in data:
        names_pts = set(md.get("points") or {})
        pt = str(data.get("point"))
        if pt not in names_pts and pt not in {x["id"] for x in md["joints"]}:
            raise _err(f"no point or joint {pt!r} in the mechanism", src, "point",
                       hint="points: " + ", ".join(sorted(names_pts) or ["(none)"]))
        T = _floats(data.get("targets"), src, "targets", 2)
        if T.ndim != 2:
            raise _err("targets must be [[x, y], ...]", src, "targets")
        return {"problem": "path", "point": pt, "targets": T}
    lk = str(data.get("link"))
    if lk not in {(e if isinstance(e, str) else e["name"]) for e in md["links"]} or lk == md["ground"]:
        raise _err(f"no moving link {lk!r} in the mechanism", src, "link")
    P = _floats(data.get("poses"), src, "poses", 3)
    if P.ndim != 2:
        raise _err("poses must be [[x, y, angle_deg], ...]", src, "poses")
    w = float(data.get("angle_weight", 1.0))
    if not w >= 0:
        raise _err("angle_weight must be >= 0", src, "angle_weight")
    return {"problem": "motion", "link": lk, "targets": P[:, :2], "angles_deg": P[:, 2], "point": None,
            "angle_weight": w}


def _case_variables(vs: Any, md: dict, src: str) -> list[DesignVariable]:
    if not isinstance(vs, list) or not vs:
        raise _err("`variables:` must be a non-empty list", src, "variables",
                   hint="- {joint: B, coord: x, lower: 0, upper: 2}")
    variables = [_design_variable(v, f"variables[{k}]", md, src) for k, v in enumerate(vs)]
    if len({x.name for x in variables}) != len(variables):
        raise _err("a coordinate is listed twice in variables", src, "variables")
    return variables


def _design_variable(v: Any, f: str, md: dict, src: str) -> DesignVariable:
    """One entry of ``variables:`` (field ``f``): a joint's or point's x or y, or a VLL's length."""
    if not isinstance(v, dict) or "lower" not in v or "upper" not in v:
        raise _err("a variable needs `lower` and `upper`", src, f)
    lo, hi = _floats([v["lower"], v["upper"]], src, f)
    if not lo < hi:
        raise _err("a variable needs finite bounds with lower < upper", src, f)
    if max(abs(lo), abs(hi)) > limit("coordinate"):
        raise _err(f"bounds [{lo:g}, {hi:g}] are beyond ±{limit('coordinate'):g}: distances would overflow",
                   src, f, "give bounds of the size of the mechanism")
    if "point" in v:
        kind, tgt = "point", str(v["point"])
        if tgt not in set(md.get("points") or {}):
            raise _err(f"no point {tgt!r} in the mechanism", src, f)
    elif "joint" in v:
        tgt = str(v["joint"])
        jj = next((x for x in md["joints"] if x["id"] == tgt), None)
        if jj is None:
            raise _err(f"no joint {tgt!r} in the mechanism", src, f)
        kind = "length" if flag(v.get("length", False), src, f"{f}.length") else "joint"
        if kind == "length" and not jj.get("vll"):
            raise _err(f"joint {tgt} is not a variable-length link (vll)", src, f,
                       hint="`length: true` needs a P pair with `vll:`")
        if kind == "joint" and jj.get("point") is None:
            raise _err(f"joint {tgt} has no point", src, f)
    else:
        raise _err("a variable names a `joint` or a `point`", src, f)
    coord = None
    if kind != "length":
        c = str(v.get("coord", ""))
        if c not in ("x", "y"):
            raise _err("coord must be x or y", src, f)
        coord = "xy".index(c)
    return DesignVariable(kind, tgt, coord, lo, hi)
