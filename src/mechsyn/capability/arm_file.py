"""Arm files: their schema (pydantic) and building a :class:`~mechsyn.capability.arm.SerialArm`.

Three kinds of arm files (YAML or JSON), validated with pydantic:

* ``kind: planar_serial`` -- a planar chain of R (and P) joints given by link lengths, base
  at the origin, *relative* joint angles (paper 004: 3R arm, l1 = l2 = l3 = 900 mm)::

      {name: paper004, kind: planar_serial, link_lengths: [900, 900, 900],
       joint_limits_deg: [[0, 120], [-120, 120], [-120, 120]],
       joint_speed_limits_deg_s: [4, 4, 4]}

* ``kind: dh`` -- a spatial chain by classic Denavit-Hartenberg parameters, joint i
  contributing ``Rz(theta_i + q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)`` (``d_i + q_i`` for P).
* ``kind: urdf`` -- a simple chain read from a URDF file (revolute, continuous,
  prismatic and fixed joints between ``base_link`` and ``tip_link``).

Angles are degrees in files (R joints; P joint values and limits are lengths), lengths in
any unit (mm in the paper); speeds are then length/s. Inside, every function works on
arrays of many configurations at once: ``q`` has shape ``(N, n)`` in radians.

References
----------
.. [1] F. N. Pritykin, D. I. Nefedov, V. A. Zakharov and A. V. Rinsel'man, "A generalised
   method of studying the mobility of planar manipulator mechanisms" (in Russian),
   Omsk State Technical University ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Annotated, Literal, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError, model_validator

from mechsyn.capability.arm import JointType, SerialArm, _homog, _rot, _rpy
from mechsyn.errors import MechsynInputError, input_boundary

__all__ = ["ArmSpec", "PlanarSerialSpec", "DHSpec", "DHRow", "URDFSpec", "arm_from_dict", "load_arm"]


# --------------------------------------------------------------------------- file schema
class _Spec(BaseModel):
    model_config = ConfigDict(extra="forbid")

    name: str = "arm"
    joint_limits_deg: list[tuple[float, float]] | None = Field(
        None, description="[lower, upper] per joint: degrees for R joints, lengths for P"
    )
    joint_speed_limits_deg_s: list[float] | None = Field(
        None, description="|q_dot_i| <= value: deg/s for R joints, length/s for P joints"
    )
    weights: list[float] | None = Field(
        None, description="joint weights of the weighted minimum-norm solution (default 1)"
    )

    def _check_lengths(self, n: int) -> None:
        for key in ("joint_limits_deg", "joint_speed_limits_deg_s", "weights"):
            value = getattr(self, key)
            if value is not None and len(value) != n:
                raise ValueError(f"{key} has {len(value)} entries, the arm has {n} joints")
        if self.joint_limits_deg is not None:
            for i, (lo, hi) in enumerate(self.joint_limits_deg):
                if not lo <= hi:
                    raise ValueError(f"joint_limits_deg[{i}]: lower {lo} > upper {hi}")
        if self.joint_speed_limits_deg_s is not None:
            for i, v in enumerate(self.joint_speed_limits_deg_s):
                if not (v > 0 and math.isfinite(v)):
                    raise ValueError(f"joint_speed_limits_deg_s[{i}] must be positive, got {v}")
        if self.weights is not None and any(not (w > 0) for w in self.weights):
            raise ValueError("weights must be positive")


class PlanarSerialSpec(_Spec):
    kind: Literal["planar_serial"]
    link_lengths: list[float] = Field(min_length=1)
    joint_types: list[JointType] | None = None
    base: tuple[float, float] = (0.0, 0.0)

    @model_validator(mode="after")
    def _check(self) -> "PlanarSerialSpec":
        n = len(self.link_lengths)
        if self.joint_types is not None and len(self.joint_types) != n:
            raise ValueError(f"joint_types has {len(self.joint_types)} entries, "
                             f"link_lengths has {n}")
        if any(not math.isfinite(v) or v < 0 for v in self.link_lengths):
            raise ValueError("link_lengths must be finite and >= 0")
        self._check_lengths(n)
        return self


class DHRow(BaseModel):
    model_config = ConfigDict(extra="forbid")
    a: float = 0.0
    alpha_deg: float = 0.0
    d: float = 0.0
    theta_deg: float = 0.0
    type: JointType = "R"


class DHSpec(_Spec):
    kind: Literal["dh"]
    dh: list[DHRow] = Field(min_length=1)
    tool: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _check(self) -> "DHSpec":
        self._check_lengths(len(self.dh))
        return self


class URDFSpec(_Spec):
    kind: Literal["urdf"]
    urdf: str
    base_link: str | None = None
    tip_link: str | None = None
    tool: tuple[float, float, float] = (0.0, 0.0, 0.0)
    length_scale: float = Field(1000.0, description="URDF metres -> file units (mm)")


ArmSpec = Annotated[Union[PlanarSerialSpec, DHSpec, URDFSpec], Field(discriminator="kind")]
_ADAPTER: TypeAdapter = TypeAdapter(ArmSpec)


#: The fix of an arm-file error no check names more precisely.
ARM_HINT = "check the arm file against docs/capability.md (examples/capability/ has one of each kind)"


# --------------------------------------------------------------------------- building
@input_boundary("arm file")
def arm_from_dict(data: dict, source: str | None = None, base_dir: Path | None = None) -> SerialArm:
    """Validate an arm description (see module docstring) and build the model."""
    if not isinstance(data, dict):
        raise MechsynInputError("an arm file must be a mapping with a 'kind' key",
                                source=source, hint="kind: planar_serial | dh | urdf")
    try:
        spec = _ADAPTER.validate_python(data)
    except ValidationError as exc:
        err = exc.errors()[0]
        loc = ".".join(str(p) for p in err["loc"] if not (isinstance(p, str) and p in (
            "planar_serial", "dh", "urdf")))
        msg = err["msg"].removeprefix("Value error, ")
        hint = f"correct {loc or 'the value named'}: " + {
            "missing": "add it", "extra_forbidden": "delete it or check its spelling"}.get(
            err["type"], "see docs/capability.md and examples/capability/")
        if err["type"] == "union_tag_invalid" or err["type"] == "union_tag_not_found":
            msg = "unknown or missing 'kind'"
            loc = "kind"
            hint = "kind: planar_serial (link_lengths), dh (dh rows) or urdf (urdf path)"
        raise MechsynInputError(msg, source=source, field=loc or None, hint=hint) from None
    except ValueError as exc:
        raise MechsynInputError(str(exc), source=source, hint=ARM_HINT) from None
    try:
        _check_joint_count(len(spec.link_lengths) if isinstance(spec, PlanarSerialSpec)
                           else len(spec.dh) if isinstance(spec, DHSpec) else 0)
        if isinstance(spec, PlanarSerialSpec):
            return _build_planar(spec)
        if isinstance(spec, DHSpec):
            return _build_dh(spec)
        return _build_urdf(spec, source, base_dir or Path("."))
    except MechsynInputError as exc:
        raise exc.with_source(source) if source else exc from None
    except ValueError as exc:  # e.g. a URDF chain whose lengths do not fit the file's lists
        raise MechsynInputError(str(exc), source=source, hint=ARM_HINT) from None


def load_arm(path: str | Path) -> SerialArm:
    """Read an arm file (YAML or JSON); :class:`MechsynInputError` on bad input.

    Examples
    --------
    >>> import mechsyn as ms
    >>> ms.load_arm(ms.examples.path("ur5_dh")).n
    6
    """
    from mechsyn.io.files import parse_data, read_text

    path = Path(path)
    text = read_text(path, "arm file")
    if path.suffix.lower() == ".urdf" or text.lstrip().startswith("<"):
        return arm_from_dict({"kind": "urdf", "urdf": path.name, "name": path.stem},
                             source=str(path), base_dir=path.parent)
    data = parse_data(text, str(path), fmt="yaml")
    return arm_from_dict(data, source=str(path), base_dir=path.parent)


def _check_joint_count(n: int, source: str | None = None) -> None:
    """Refuse more joints than the limit ``arm_joints`` before any array is built (10^4
    joints tried to allocate 95 GiB)."""
    from mechsyn.limits import limit, limit_hint

    if n > limit("arm_joints"):
        raise MechsynInputError(f"{n:,} joints: more than the limit of {limit('arm_joints'):,}", source=source,
                                hint=limit_hint("arm_joints"))


def _urdf_root(path: Path) -> ET.Element:
    """The URDF's XML root: a regular file within ``file_bytes`` (:func:`mechsyn.io.files.read_limited`)."""
    from mechsyn.io.files import read_limited

    data = read_limited(path, "URDF file")
    try:
        return ET.fromstring(data)
    except ET.ParseError as exc:
        raise MechsynInputError(f"cannot read URDF: {exc}", source=str(path),
                                hint="give a well-formed URDF file (its path is relative to the arm file)") from None


def _urdf_chain(joints: dict, children: dict, base: str | None, tip: str | None, src: str,
                source: str | None) -> list:
    """The joints from ``base`` to ``tip`` (the only chain when ``tip`` is None); a joint
    cycle is refused naming the joint that closes it (it looped forever before)."""
    if tip is None:  # follow the only chain
        tip, seen = base, {base}
        while children.get(tip):
            if len(children[tip]) > 1:
                raise MechsynInputError(f"link {tip!r} branches", source=source, field="tip_link",
                                        hint="give tip_link: the URDF link that carries the tool")
            nxt = children[tip][0]
            if nxt in seen:
                raise _cycle(joints[nxt], src)
            tip = nxt
            seen.add(tip)
    chain, link, seen = [], tip, {tip}
    while link != base:
        if link not in joints and base is None:
            break
        if link not in joints:
            raise MechsynInputError(f"no chain from {base!r} to {tip!r}", source=src,
                                    hint=f"give as tip_link a link below {base!r} in the URDF")
        chain.append(joints[link])
        link = joints[link].find("parent").get("link")
        if link in seen:
            raise _cycle(chain[-1], src)
        seen.add(link)
    chain.reverse()
    return chain


def _cycle(joint: ET.Element, src: str) -> MechsynInputError:
    return MechsynInputError(f"joint {joint.get('name')!r} closes a cycle of joints", source=src,
                             hint="a URDF is a tree: remove the joint that closes the loop")


def _urdf_numbers(joint: ET.Element, tag: str, attr: str, default: str, src: str, count: int = 3) -> list[float]:
    """``count`` numbers of attribute ``attr`` of the joint's child ``tag`` (``default``
    when absent), each finite and within the limit ``coordinate`` (1e100): one line naming
    the joint and the attribute otherwise (no overflow in what is computed from them)."""
    from mechsyn.limits import limit, limit_hint

    el = joint.find(tag)
    text = el.get(attr, default) if el is not None else default
    where = f"joint {str(joint.get('name'))[:80]!r}: <{tag} {attr}=\"{text[:60]}\">"
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count:
        raise MechsynInputError(f"{where} is not {'a number' if count == 1 else f'{count} numbers'}", source=src,
                                hint="give one number" if count == 1 else f"give {count} numbers separated by spaces")
    big = limit("coordinate")
    if not all(math.isfinite(v) and abs(v) <= big for v in values):
        raise MechsynInputError(f"{where} holds a number that is not finite or beyond {big:g} in magnitude",
                                source=src, hint="give ordinary finite numbers; " + limit_hint("coordinate"))
    return values


def _urdf_axis(joint: ET.Element, src: str) -> np.ndarray:
    """The unit axis of a URDF joint (default x); a zero, non-finite or huge axis is
    refused (the norm is taken of the axis scaled by its largest component, so no square
    overflows)."""
    axis = np.array(_urdf_numbers(joint, "axis", "xyz", "1 0 0", src))
    big = float(np.abs(axis).max())
    unit = axis / big if big > 0 else axis
    norm = float(np.linalg.norm(unit))
    if not norm > 0:
        raise MechsynInputError(f"joint {str(joint.get('name'))[:80]!r}: axis {' '.join(map(str, axis))!r} has no "
                                "direction", source=src, hint="give <axis xyz=\"x y z\"/> with three numbers, not all zero")
    return unit / norm


def _limits(spec: _Spec, rev: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    if spec.joint_limits_deg is None:
        lower, upper = np.full(n, -np.inf), np.full(n, np.inf)
    else:
        lim = np.array(spec.joint_limits_deg, float)
        lower = np.where(rev, np.radians(lim[:, 0]), lim[:, 0])
        upper = np.where(rev, np.radians(lim[:, 1]), lim[:, 1])
    if spec.joint_speed_limits_deg_s is None:
        raise MechsynInputError("joint_speed_limits_deg_s is required for capability",
                                field="joint_speed_limits_deg_s",
                                hint="give one positive speed limit per joint, e.g. [4, 4, 4]")
    v = np.array(spec.joint_speed_limits_deg_s, float)
    qd_max = np.where(rev, np.radians(v), v)
    weights = np.ones(n) if spec.weights is None else np.array(spec.weights, float)
    return lower, upper, qd_max, weights


def _build_planar(spec: PlanarSerialSpec) -> SerialArm:
    n = len(spec.link_lengths)
    types = tuple(spec.joint_types or ["R"] * n)
    rev = np.array([t == "R" for t in types])
    lower, upper, qd_max, w = _limits(spec, rev, n)
    return SerialArm(spec.name, "planar", types, lower, upper, qd_max, w,
                     link_lengths=np.array(spec.link_lengths, float),
                     base=np.array(spec.base, float),
                     joint_names=tuple(f"q{i + 1}" for i in range(n)))


def _build_dh(spec: DHSpec) -> SerialArm:
    n = len(spec.dh)
    types = tuple(r.type for r in spec.dh)
    rev = np.array([t == "R" for t in types])
    lower, upper, qd_max, w = _limits(spec, rev, n)
    z = np.array([0.0, 0.0, 1.0])
    fixed = [np.eye(4)]
    for r in spec.dh:
        Rz0 = _homog(_rot(z, np.array([math.radians(r.theta_deg)]))[0])
        Tz0 = _homog(p=(0, 0, r.d))
        post = _homog(p=(r.a, 0, 0)) @ _homog(_rot(np.array([1.0, 0, 0]),
                                                   np.array([math.radians(r.alpha_deg)]))[0])
        if r.type == "R":  # Rz(theta0 + q) Tz(d) Tx(a) Rx(alpha) = Rz(theta0) . Rz(q) . Tz(d)...
            fixed[-1] = fixed[-1] @ Rz0
            fixed.append(Tz0 @ post)
        else:  # Rz(theta0) Tz(d0) . Tz(q) . Tx(a) Rx(alpha)
            fixed[-1] = fixed[-1] @ Rz0 @ Tz0
            fixed.append(post)
    fixed[-1] = fixed[-1] @ _homog(p=spec.tool)
    return SerialArm(spec.name, "spatial", types, lower, upper, qd_max, w,
                     fixed=tuple(fixed), axes=tuple(z for _ in range(n)),
                     joint_names=tuple(f"q{i + 1}" for i in range(n)))


def _build_urdf(spec: URDFSpec, source: str | None, base_dir: Path) -> SerialArm:
    path = (base_dir / spec.urdf) if not Path(spec.urdf).is_absolute() else Path(spec.urdf)
    src = str(path)
    root = _urdf_root(path)
    _check_joint_count(len(root.findall("joint")), src)
    joints = {}
    children = {}
    for j in root.findall("joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            raise MechsynInputError(f"joint {j.get('name')!r} lacks parent or child", source=src,
                                    hint="give the joint <parent link=\"...\"/> and <child link=\"...\"/>")
        joints[child.get("link")] = j
        children.setdefault(parent.get("link"), []).append(child.get("link"))
    links = [lk.get("name") for lk in root.findall("link")]
    base = spec.base_link or next((lk for lk in links if lk not in joints), None)
    if base is None and joints:  # every link has a parent: the chain of parents cycles
        _urdf_chain(joints, children, None, next(iter(joints)), src, source)
    if base is None:
        raise MechsynInputError("no base link (every link has a parent joint)", source=src,
                                hint="a URDF is a tree: remove the joint that closes a loop")
    chain = _urdf_chain(joints, children, base, spec.tip_link, src, source)
    s = spec.length_scale
    fixed = [np.eye(4)]
    axes, types, names, lims, vels = [], [], [], [], []
    for j in chain:
        xyz = [v * s for v in _urdf_numbers(j, "origin", "xyz", "0 0 0", src)]
        rpy = _urdf_numbers(j, "origin", "rpy", "0 0 0", src)
        fixed[-1] = fixed[-1] @ _homog(_rpy(*rpy), xyz)
        jtype = j.get("type")
        if jtype == "fixed":
            continue
        if jtype not in ("revolute", "continuous", "prismatic"):
            raise MechsynInputError(f"joint {j.get('name')!r}: type {jtype!r} not supported",
                                    source=src, hint="revolute, continuous, prismatic or fixed")
        axes.append(_urdf_axis(j, src))
        rev = jtype != "prismatic"
        types.append("R" if rev else "P")
        names.append(j.get("name"))
        lim = j.find("limit")
        f = 1.0 if rev else s
        if lim is not None and jtype != "continuous":
            lims.append(tuple(_urdf_numbers(j, "limit", k, "", src, 1)[0] * f if lim.get(k) is not None else inf
                              for k, inf in (("lower", -np.inf), ("upper", np.inf))))
        else:
            lims.append((-np.inf, np.inf))
        vels.append(_urdf_numbers(j, "limit", "velocity", "", src, 1)[0] * f
                    if lim is not None and lim.get("velocity") else None)
        fixed.append(np.eye(4))
    fixed[-1] = fixed[-1] @ _homog(p=spec.tool)
    n = len(types)
    if n == 0:
        raise MechsynInputError("the URDF chain has no moving joint", source=src,
                                hint="the chain to tip_link needs revolute, continuous or prismatic joints")
    rev = np.array([t == "R" for t in types])
    if spec.joint_limits_deg is not None or spec.joint_speed_limits_deg_s is not None:
        spec._check_lengths(n)
    lower, upper = np.array([l for l, _ in lims]), np.array([u for _, u in lims])
    if spec.joint_limits_deg is not None:
        lim = np.array(spec.joint_limits_deg, float)
        lower = np.where(rev, np.radians(lim[:, 0]), lim[:, 0])
        upper = np.where(rev, np.radians(lim[:, 1]), lim[:, 1])
    if spec.joint_speed_limits_deg_s is not None:
        v = np.array(spec.joint_speed_limits_deg_s, float)
        qd_max = np.where(rev, np.radians(v), v)
    else:
        if any(v is None or v <= 0 for v in vels):
            raise MechsynInputError("a joint has no <limit velocity=...>", source=src,
                                    hint="give joint_speed_limits_deg_s in the arm file")
        qd_max = np.array(vels, float)
    w = np.ones(n) if spec.weights is None else np.array(spec.weights, float)
    return SerialArm(spec.name, "spatial", tuple(types), lower, upper, qd_max, w,
                     fixed=tuple(fixed), axes=tuple(axes), joint_names=tuple(names))
