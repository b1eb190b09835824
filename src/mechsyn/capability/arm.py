"""Serial arm models: file schema, forward kinematics, Jacobians, inverse kinematics.

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
   Omsk State Technical University; journal and year are not in the project's copy
   ("paper 004"; see docs/references.md).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Annotated, Literal, Union

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, ValidationError, model_validator

from mechsyn.errors import MechsynInputError, input_boundary

JointType = Literal["R", "P"]


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


# --------------------------------------------------------------------------- runtime model
def _rot(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotation matrices (N, 3, 3) about unit ``axis`` by ``angle`` (N,) (Rodrigues)."""
    k = np.asarray(axis, float)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * (K @ K)


def _homog(R: np.ndarray | None = None, p=(0.0, 0.0, 0.0)) -> np.ndarray:
    T = np.eye(4)
    if R is not None:
        T[:3, :3] = R
    T[:3, 3] = p
    return T


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: R = Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
        [-sp, cp * sr, cp * cr],
    ])


@dataclass(frozen=True)
class SerialArm:
    """A serial arm, vectorised over configurations.

    ``kind`` is ``"planar"`` (task: end point (x, y)) or ``"spatial"`` (task: tool point
    (x, y, z)). Internal units: radians, rad/s; lengths and length/s as in the file.
    A spatial chain is ``T = F_0 M_1(q_1) F_1 ... M_n(q_n) F_n``: fixed transforms ``F``
    and joint motions ``M`` about / along unit ``axes`` (in the joint's own frame).

    Examples
    --------
    >>> import mechsyn as ms
    >>> arm = ms.examples.load("paper004_3r")     # planar 3R of paper 004
    >>> arm.n, arm.task_dim, arm.joint_names
    (3, 2, ('q1', 'q2', 'q3'))
    """

    name: str
    kind: Literal["planar", "spatial"]
    joint_types: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray
    qd_max: np.ndarray
    weights: np.ndarray
    link_lengths: np.ndarray | None = None  # planar
    base: np.ndarray | None = None  # planar
    fixed: tuple[np.ndarray, ...] = ()  # spatial: n + 1 homogeneous transforms
    axes: tuple[np.ndarray, ...] = ()  # spatial: n unit axes
    joint_names: tuple[str, ...] = field(default=())

    # ----------------------------------------------------------------- basic facts
    @property
    def n(self) -> int:
        return len(self.joint_types)

    @property
    def task_dim(self) -> int:
        return 2 if self.kind == "planar" else 3

    @property
    def is_revolute(self) -> np.ndarray:
        return np.array([t == "R" for t in self.joint_types])

    def to_user(self, q: np.ndarray) -> np.ndarray:
        """Joint values in file units: degrees for R, lengths for P."""
        q = np.asarray(q, float)
        return np.where(self.is_revolute, np.degrees(q), q)

    def from_user(self, q: np.ndarray) -> np.ndarray:
        q = np.asarray(q, float)
        return np.where(self.is_revolute, np.radians(q), q)

    def within_limits(self, q: np.ndarray, tol: float = 1e-9) -> np.ndarray:
        """Mask (N,) of configurations inside the joint position limits."""
        q = np.atleast_2d(q)
        return np.all((q >= self.lower - tol) & (q <= self.upper + tol), axis=-1)

    # ----------------------------------------------------------------- kinematics
    def fk(self, q: np.ndarray) -> np.ndarray:
        """Tool point, shape (N, task_dim), of configurations ``q`` (N, n)."""
        q = np.atleast_2d(np.asarray(q, float))
        if self.kind == "planar":
            theta, reach = self._planar_angles(q)
            return self.base + np.stack(
                [(reach * np.cos(theta)).sum(-1), (reach * np.sin(theta)).sum(-1)], -1)
        return self._frames(q)[1][-1]

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Jacobian of the tool point's velocity, shape (N, task_dim, n).

        Planar: column i of an R joint is ``sum_{k>=i} l_k (-sin th_k, cos th_k)`` with
        absolute link angles ``th_k = q_1 + ... + q_k``; of a P joint, the unit vector of
        its link. Spatial: ``z_i x (p - o_i)`` for R joints, ``z_i`` for P joints.
        """
        return self.fk_and_jacobian(q)[1]

    def fk_and_jacobian(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`fk` and :meth:`jacobian` together, the joint frames computed once.

        Returns the tool points (N, task_dim) and the Jacobians (N, task_dim, n); the
        inner loop of :func:`ik_numeric`.

        Examples
        --------
        >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 1.0],
        ...                      "joint_speed_limits_deg_s": [10, 10]})
        >>> p, J = arm.fk_and_jacobian(np.array([[0.0, np.pi / 2]]))
        >>> np.round(p, 12).tolist(), np.round(J[0], 12).tolist()
        ([[1.0, 1.0]], [[-1.0, -1.0], [1.0, 0.0]])
        """
        q = np.atleast_2d(np.asarray(q, float))
        if self.kind == "planar":
            theta, reach = self._planar_angles(q)
            vx, vy = -reach * np.sin(theta), reach * np.cos(theta)
            p = self.base + np.stack(
                [(reach * np.cos(theta)).sum(-1), (reach * np.sin(theta)).sum(-1)], -1)
            # suffix sums: column i gets links i..n-1 (all links move with an R joint i)
            cx = np.cumsum(vx[:, ::-1], axis=1)[:, ::-1]
            cy = np.cumsum(vy[:, ::-1], axis=1)[:, ::-1]
            J = np.stack([cx, cy], 1)
            prism = ~self.is_revolute
            if prism.any():
                J[:, 0, prism] = np.cos(theta[:, prism])
                J[:, 1, prism] = np.sin(theta[:, prism])
            return p, J
        J, p = self._geometric_jacobian(self._frames(q))
        return p, J[:, :3, :]

    def geometric_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Spatial arms: (N, 6, n) Jacobian, rows (v_x, v_y, v_z, w_x, w_y, w_z)."""
        if self.kind == "planar":
            raise ValueError("geometric_jacobian is for spatial arms")
        q = np.atleast_2d(np.asarray(q, float))
        return self._geometric_jacobian(self._frames(q))[0]

    def _geometric_jacobian(self, frames: tuple[list, list]) -> tuple[np.ndarray, np.ndarray]:
        """(N, 6, n) Jacobian from the joint frames (:meth:`_frames`), and the tool point."""
        Rs, ps = frames
        p = ps[-1]
        J = np.zeros((p.shape[0], 6, self.n))
        for i in range(self.n):
            z = Rs[i] @ self.axes[i]  # joint axis in the base frame
            if self.joint_types[i] == "R":
                r = p - ps[i]
                J[:, 0, i] = z[:, 1] * r[:, 2] - z[:, 2] * r[:, 1]  # z x (p - o)
                J[:, 1, i] = z[:, 2] * r[:, 0] - z[:, 0] * r[:, 2]
                J[:, 2, i] = z[:, 0] * r[:, 1] - z[:, 1] * r[:, 0]
                J[:, 3:, i] = z
            else:
                J[:, :3, i] = z
        return J, p

    def _planar_angles(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        rev = self.is_revolute
        theta = np.cumsum(np.where(rev, q, 0.0), axis=1)
        reach = self.link_lengths + np.where(rev, 0.0, q)
        return theta, reach

    @cached_property
    def _motion_terms(self) -> list[tuple[np.ndarray, ...]]:
        """Per joint, ``M_i(q) F_i`` as ``A0 + sin(q) A1 + (1 - cos q) A2`` (rotation
        and translation parts; Rodrigues with ``K`` the axis' cross-product matrix)."""
        terms = []
        for i in range(self.n):
            F = self.fixed[i + 1]
            k = self.axes[i]
            K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
            K2 = K @ K
            terms.append((F[:3, :3], K @ F[:3, :3], K2 @ F[:3, :3],
                          F[:3, 3], K @ F[:3, 3], K2 @ F[:3, 3]))
        return terms

    def _frames(self, q: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Rotations (N, 3, 3) and origins (N, 3) of the frames of joints 1..n (before
        their motion) and of the tool: ``T = F_0 M_1(q_1) F_1 ... M_n(q_n) F_n``."""
        N = q.shape[0]
        R = np.broadcast_to(self.fixed[0][:3, :3], (N, 3, 3))
        p = np.broadcast_to(self.fixed[0][:3, 3], (N, 3))
        Rs, ps = [], []
        for i, (A0, A1, A2, b0, b1, b2) in enumerate(self._motion_terms):
            Rs.append(R)
            ps.append(p)
            if self.joint_types[i] == "R":
                s = np.sin(q[:, i])[:, None]
                c = 1.0 - np.cos(q[:, i])[:, None]
                C = A0 + s[:, :, None] * A1 + c[:, :, None] * A2
                t = b0 + s * b1 + c * b2
            else:
                C = A0
                t = b0 + q[:, i][:, None] * self.axes[i]
            p = p + (R @ t[:, :, None])[:, :, 0]
            R = R @ C
        Rs.append(R)
        ps.append(p)
        return Rs, ps


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
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise MechsynInputError(f"cannot read URDF: {exc}", source=src,
                                hint="give a well-formed URDF file (its path is relative to the arm file)") from None
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
    if base is None:
        raise MechsynInputError("no base link (every link has a parent joint)", source=src,
                                hint="a URDF is a tree: remove the joint that closes a loop")
    tip = spec.tip_link
    if tip is None:  # follow the only chain
        tip = base
        while children.get(tip):
            if len(children[tip]) > 1:
                raise MechsynInputError(f"link {tip!r} branches", source=source, field="tip_link",
                                        hint="give tip_link: the URDF link that carries the tool")
            tip = children[tip][0]
    chain = []
    link = tip
    while link != base:
        if link not in joints:
            raise MechsynInputError(f"no chain from {base!r} to {tip!r}", source=src,
                                    hint=f"give as tip_link a link below {base!r} in the URDF")
        chain.append(joints[link])
        link = joints[link].find("parent").get("link")
    chain.reverse()
    s = spec.length_scale
    fixed = [np.eye(4)]
    axes, types, names, lims, vels = [], [], [], [], []
    for j in chain:
        o = j.find("origin")
        xyz = [float(v) * s for v in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()]
        rpy = [float(v) for v in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        fixed[-1] = fixed[-1] @ _homog(_rpy(*rpy), xyz)
        jtype = j.get("type")
        if jtype == "fixed":
            continue
        if jtype not in ("revolute", "continuous", "prismatic"):
            raise MechsynInputError(f"joint {j.get('name')!r}: type {jtype!r} not supported",
                                    source=src, hint="revolute, continuous, prismatic or fixed")
        ax = j.find("axis")
        axis = np.array([float(v) for v in (ax.get("xyz") if ax is not None else "1 0 0").split()])
        axes.append(axis / np.linalg.norm(axis))
        rev = jtype != "prismatic"
        types.append("R" if rev else "P")
        names.append(j.get("name"))
        lim = j.find("limit")
        f = 1.0 if rev else s
        if lim is not None and jtype != "continuous":
            lims.append((float(lim.get("lower", "-inf")) * f, float(lim.get("upper", "inf")) * f))
        else:
            lims.append((-np.inf, np.inf))
        vels.append(float(lim.get("velocity")) * f if lim is not None and lim.get("velocity") else None)
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


# --------------------------------------------------------------------------- inverse kinematics
def ik_planar_3r(arm: SerialArm, point, q1: np.ndarray, branch: int = -1) -> tuple[np.ndarray, np.ndarray]:
    """Exact IK of a planar 3R arm for given q1 (radians, shape (K,)) and elbow ``branch``.

    With q1 fixed, joint 2 sits at ``B = base + l1 (cos q1, sin q1)``; the 2R sub-chain
    reaches ``r = point - B`` with ``cos q3 = (|r|^2 - l2^2 - l3^2) / (2 l2 l3)``,
    ``q3 = branch * acos(.)`` (paper 004's table: branch -1, q3 < 0) and
    ``q2 = atan2(r) - q1 - atan2(l3 sin q3, l2 + l3 cos q3)``.

    ``point`` is (2,) or (K, 2). Returns ``q`` (K, 3) and ``reachable`` (K,); unreachable
    rows hold NaN.
    """
    if arm.kind != "planar" or arm.n != 3 or not arm.is_revolute.all():
        raise ValueError("ik_planar_3r needs a planar 3R arm")
    l1, l2, l3 = arm.link_lengths
    q1 = np.atleast_1d(np.asarray(q1, float))
    P = np.broadcast_to(np.asarray(point, float) - arm.base, (q1.size, 2))
    rx = P[:, 0] - l1 * np.cos(q1)
    ry = P[:, 1] - l1 * np.sin(q1)
    c3 = (rx**2 + ry**2 - l2**2 - l3**2) / (2 * l2 * l3) if l2 * l3 > 0 else np.full(q1.size, np.nan)
    ok = np.abs(c3) <= 1 + 1e-12
    q3 = branch * np.arccos(np.clip(c3, -1, 1))
    q2 = np.arctan2(ry, rx) - q1 - np.arctan2(l3 * np.sin(q3), l2 + l3 * np.cos(q3))
    q2 = (q2 + np.pi) % (2 * np.pi) - np.pi
    q = np.stack([q1, q2, q3], -1)
    q[~ok] = np.nan
    return q, ok


def ik_numeric(arm: SerialArm, point, seeds: np.ndarray, *, fixed_first: bool = False,
               respect_limits: bool = True, iterations: int = 200, tol: float = 1e-7
               ) -> tuple[np.ndarray, np.ndarray]:
    """Damped least squares IK of the tool point from many seeds at once (vectorised).

    ``q <- q + J^T (J J^T + lambda^2 I)^-1 (p* - p(q))``, clipped to the limits when
    ``respect_limits``; with ``fixed_first`` joint 1 keeps its seed value (the redundancy
    parameter of paper 004). ``point`` is one target (task_dim,) or one per seed
    (K, task_dim), so the seeds of many grid points run together.

    Every seed iterates on its own: it stops as soon as its end point error is below
    ``tol`` times the arm's size (or when an iteration no longer changes it, e.g. held
    by a joint limit), so its answer does not depend on the other seeds of the batch.

    Returns ``q`` (K, n) and ``converged`` (K,).

    Examples
    --------
    >>> arm = arm_from_dict({"kind": "planar_serial", "link_lengths": [1.0, 1.0],
    ...                      "joint_speed_limits_deg_s": [10, 10]})
    >>> q, ok = ik_numeric(arm, [[1.0, 1.0], [0.0, 1.5]], [[0.1, 1.0], [1.0, 0.5]])
    >>> bool(ok.all()), bool(np.abs(arm.fk(q) - [[1.0, 1.0], [0.0, 1.5]]).max() < 1e-6)
    (True, True)
    """
    q = np.array(np.atleast_2d(seeds), float)
    K = q.shape[0]
    target = np.broadcast_to(np.asarray(point, float), (K, arm.task_dim))
    scale = max(_arm_size(arm), 1e-12)
    lam = 1e-3 * scale
    lo = np.where(np.isfinite(arm.lower), arm.lower, -np.inf)
    hi = np.where(np.isfinite(arm.upper), arm.upper, np.inf)
    damping = lam**2 * np.eye(arm.task_dim)
    active = np.arange(K)
    for _ in range(iterations):
        p, J = arm.fk_and_jacobian(q[active])
        e = target[active] - p
        pending = np.linalg.norm(e, axis=1) >= tol * scale
        active, e, J = active[pending], e[pending], J[pending]
        if not active.size:
            break
        if fixed_first:
            J[:, :, 0] = 0.0
        JJt = J @ np.swapaxes(J, 1, 2) + damping
        dq = np.einsum("kmn,km->kn", J, np.linalg.solve(JJt, e[:, :, None])[:, :, 0])
        old = q[active]
        new = np.clip(old + dq, lo, hi) if respect_limits else old + dq
        q[active] = new
        active = active[np.any(new != old, axis=1)]  # a seed that no longer moves is done
        if not active.size:
            break
    err = np.linalg.norm(target - arm.fk(q), axis=1)
    return q, err < tol * scale


def _arm_size(arm: SerialArm) -> float:
    if arm.kind == "planar":
        return float(np.sum(np.abs(arm.link_lengths)))
    return float(sum(np.linalg.norm(F[:3, 3]) for F in arm.fixed))
