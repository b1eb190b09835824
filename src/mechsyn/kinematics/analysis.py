"""Simulation of a planar mechanism over input values: the library's main entry points.

:func:`simulate` runs the Assur-group closed form when the mechanism decomposes into
drivers and dyads (vectorised over all inputs), otherwise the Newton continuation, and
returns every link's angle, angular velocity and acceleration and every requested
point's position, velocity and acceleration, with NaN (JSON ``null``) where the
mechanism is not assembled and the events of the sweep (dead points, reassembly,
singular crossings, VLL limits).

Units: R inputs and link angles in degrees, angular velocities in rad/s and angular
accelerations in rad/s^2 (the driven joint turns at 1 rad/s unless a speed is given);
P inputs and lengths in the file's length unit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mechsyn.errors import EngineDeclined, MechsynInputError
from mechsyn.kinematics.engines import (ENGINES, PLANAR_ENGINES, SPATIAL_ENGINE, engine_named,  # noqa: F401
                                        first_sweep)
from mechsyn.kinematics.groups import Plan, decompose
from mechsyn.kinematics.solve import assemble, drawn_checks, require_drives_given, singular_configuration
from mechsyn.kinematics.simulation import (LinkMotion, Motion, PointMotion, Simulation,  # noqa: F401
                                          input_grid, resolve_points)
from mechsyn.kinematics.sweep import Event, Sweep, by_row
from mechsyn.kinematics.refill import joint_points, point_xy, with_geometry
from mechsyn.kinematics.system import VLL_MODES, PlanarSystem, build_system, frame_points, points_state_array
from mechsyn.kinematics.topology import CACHE, Topology, topology_of
from mechsyn.model.mechanism import Mechanism, fields_replaced
from mechsyn.progress import ProgressCallback

__all__ = ["ENGINES", "Motion", "Simulation", "PointMotion", "LinkMotion", "simulate", "input_grid", "resolve_points",
           "KinematicPlan", "compile_plan", "cached_plan", "drawn_inputs"]


def simulate(mech: Mechanism, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None = None,
             points: list[str] | None = None, vll: dict[str, str] | None = None,
             method: str = "auto", progress: ProgressCallback | None = None, change_points: str = "keep") -> Simulation:
    """Positions, velocities and accelerations over a sweep of the inputs.

    ``inputs``: joint id -> values (degrees for R, length for P), all of the same
    length; drivers not listed keep their value of the file. ``method``: ``"auto"``
    (closed-form Assur groups when the mechanism decomposes, else Newton),
    ``"assur"`` or ``"newton"``. ``change_points``: ``"keep"`` (the drawn branch, whose
    velocity is continuous, through change and branch points: a parallelogram stays a
    parallelogram) or ``"switch"`` (the other branch there; closed form only).

    A ``kind: spatial`` file goes to the spatial engine
    (:func:`mechsyn.kinematics.spatial.simulate_spatial`: inputs measured from the drawn
    assembly, a :class:`~mechsyn.kinematics.spatial_result.SpatialSimulation` back).

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> m = ms.examples.load("crank_rocker")
    >>> s = ms.simulate(m, {"A": np.linspace(0, 180, 7)})
    >>> s.link("crank").angle.round(6).tolist()
    [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0]
    """
    engine = SPATIAL_ENGINE if mech.kind == "spatial" and method == "auto" else \
        None if method in ("auto", "assur") else engine_named(method)
    if hasattr(engine, "simulate"):  # an engine of whole mechanisms (the spatial one)
        return engine.simulate(mech, inputs, speeds=speeds, points=points, progress=progress)
    if mech.kind == "spatial":
        raise EngineDeclined(method, mech.name, "it takes planar mechanisms; this one is spatial")
    return _simulate_plan(cached_plan(mech, vll=vll, inputs=tuple(inputs)), inputs, speeds, points, method, progress,
                          change_points)  # KinematicPlan.simulate without its call


def _geometry_key(mech: Mechanism) -> tuple:
    """What a compiled plan depends on besides its topology: the joint points and axes,
    joint attributes (cam profiles, belts) and named points. The arrays are mutable, so
    their bytes are part of the key."""
    def arr(a: Any) -> bytes | None:  # the bytes of the float64 array (a native one read as it is)
        if a.__class__ is np.ndarray and a.dtype is _F64:
            return a.tobytes()
        return None if a is None else np.asarray(a, float).tobytes()

    nd = np.ndarray  # a joint's float64 point (the common case) read inline, one call less per joint
    joints = tuple([(p.tobytes() if (p := j.point).__class__ is nd and p.dtype is _F64 else arr(p),
                     None if j.axis is None else arr(j.axis), repr(j.attrs) if j.attrs else "") for j in mech.joints])
    named = tuple([(k, p.link, arr(p.at)) for k, p in mech.points.items()])
    return joints, named


_F64 = np.dtype(float)


def cached_plan(mech: Mechanism, vll: dict[str, str] | None = None, inputs: tuple = ()) -> KinematicPlan:
    """:func:`compile_plan`, reusing the plan compiled for the same mechanism object with
    the same geometry and options (a moved joint point or a new VLL mode compiles anew),
    kept in the kinematics' one cache (:data:`~mechsyn.kinematics.topology.CACHE`) under
    the mechanism's identity (a frozen mechanism: its topology too), the options and its
    geometry's numbers, never under its topology alone.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism
    >>> m = load_mechanism("examples/kinematics/crank_rocker.yaml")
    >>> cached_plan(m, inputs=("A",)) is cached_plan(m, inputs=("A",))
    True
    """
    prescribed = _prescribed(mech, vll, inputs)
    key = ("plan", id(mech), tuple(sorted(vll.items())) if vll else (), prescribed, _geometry_key(mech))
    kp = CACHE.get(key)
    if kp is None or kp.mechanism is not mech:  # (an id of a mechanism gone, reused)
        kp = _compiled(mech, vll, prescribed)
        CACHE.put(key, kp)
    return kp


def drawn_inputs(mech: Mechanism) -> dict[str, float]:
    """Every drive's value at the drawn pose, in the engine's convention: a planar R drive's
    angle (deg) and P drive's slide as the file draws them, 0 for a spatial file's drives
    (its inputs are measured from the drawn assembly). The pose-level analyses
    (:mod:`mechsyn.kinematics.inverse`, :mod:`mechsyn.kinematics.centres`) start there.

    Examples
    --------
    >>> import mechsyn as ms
    >>> {k: round(v, 6) for k, v in drawn_inputs(ms.examples.load("crank_rocker")).items()}
    {'A': 60.0}
    """
    drives = [j.id for j in mech.joints if j.actuated]
    if mech.kind != "planar":
        return {d: 0.0 for d in drives}
    S = cached_plan(mech, inputs=tuple(drives)).system
    return {d.joint: (math.degrees(d.assembled) if d.type == "R" else float(d.assembled))
            for d in S.drivers if d.joint in drives}


@dataclass(frozen=True, eq=False)
class KinematicPlan:
    """A mechanism compiled for repeated simulation: its constraint system and its
    solution plan (drivers, then Assur groups in solving order; ``groups`` is None when
    the mechanism does not split into dyads and Newton continuation is used).

    Build it once with :func:`compile_plan`; :meth:`simulate` sweeps its inputs.
    :meth:`with_joint_points` is the incremental re-simulation of an editor's drag loop:
    the same topology with moved joints (new link dimensions and a new drawn
    configuration) keeps the solution plan and rebuilds only the geometry.

    Examples
    --------
    >>> from mechsyn.io import load_mechanism
    >>> from mechsyn.kinematics.analysis import compile_plan, input_grid
    >>> plan = compile_plan(load_mechanism("examples/kinematics/crank_rocker.yaml"), inputs=("A",))
    >>> [s.kind for s in plan.groups.steps]
    ['drive_R', 'RRR']
    >>> moved = plan.with_joint_points({"C": (3.1, 2.9)})   # the user drags joint C
    >>> sim = moved.simulate({"A": input_grid(0, 360, 1)})
    >>> bool(sim.assembled.all())
    True
    """

    mechanism: Mechanism
    system: PlanarSystem
    groups: "Plan | None"
    vll: dict | None = None
    prescribed: tuple = ()

    def with_joint_points(self, points: dict[str, Any]) -> "KinematicPlan":
        """The same mechanism with some joints moved (``{joint id: (x, y)}``), reusing the
        solution plan: only the geometry (link frames, lengths, drawn configuration) is
        rebuilt. Named points keep their drawn positions."""
        return self.refilled(self.mechanism.with_joint_points(points))

    @property
    def topology(self) -> Topology:
        """The mechanism's :class:`~mechsyn.kinematics.topology.Topology` (its system's),
        which every plan :meth:`refilled` from this one holds."""
        return self.system.topology

    def refilled(self, mech: Mechanism) -> "KinematicPlan":
        """The plan of ``mech``, a mechanism of this plan's topology
        (:func:`~mechsyn.kinematics.topology.topology_key`) with other numbers: the
        constraint system refilled with its geometry
        (:func:`~mechsyn.kinematics.refill.with_geometry`, built anew for cams, gears and
        belts) and the same decomposition, found anew only where it depends on the
        geometry (a double joint is two R pairs at one point: :func:`_decomposition`)."""
        S = with_geometry(self.system, mech)
        if S is None:
            S = build_system(mech, vll=self.vll, prescribed=self.prescribed)
        groups = self.groups
        if groups is not None and groups.geometry_free:
            return fields_replaced(self, mechanism=mech, system=S)
        return KinematicPlan(mech, S, _decomposition(S), self.vll, self.prescribed)

    def simulate(self, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None = None,
                 points: list[str] | None = None, method: str = "auto", progress: ProgressCallback | None = None,
                 change_points: str = "keep") -> Simulation:
        """The sweep of :func:`simulate` with this plan."""
        return _simulate_plan(self, inputs, speeds, points, method, progress, change_points)


def _decomposition(S: PlanarSystem) -> Plan | None:
    """:func:`~mechsyn.kinematics.groups.decompose` of ``S``, kept by its topology under
    which of its pairs of R joints sharing a link are at one point (within 1e-9 of the
    size, as ``decompose`` tests for a double joint): the only geometry a decomposition
    depends on."""
    def pairs() -> tuple[np.ndarray, np.ndarray]:
        joints = S.mech.joints
        r = [k for k, j in enumerate(joints) if j.type == "R"]
        ab = [(a, b) for i, a in enumerate(r) for b in r[i + 1:] if set(joints[a].links) & set(joints[b].links)]
        return tuple(np.array(ab, int).reshape(-1, 2).T)

    ia, ib = S.topology.product("R joint pairs", pairs)
    pts = np.array([j.point for j in S.mech.joints], float)
    one = (np.abs(pts[ia] - pts[ib]).max(axis=1) <= 1e-9 * S.scale).tobytes()
    return S.topology.product(("decomposition", one), lambda: decompose(S))


def compile_plan(mech: Mechanism, vll: dict[str, str] | None = None, inputs: tuple = ()) -> KinematicPlan:
    """Compile a mechanism for :func:`simulate` (``inputs``: the joints that will be given
    input values, which decides whether a passive VLL is prescribed)."""
    return _compiled(mech, vll, _prescribed(mech, vll, inputs))


def _compiled(mech: Mechanism, vll: dict[str, str] | None, prescribed: tuple) -> KinematicPlan:
    """:func:`compile_plan` with the prescribed inputs found: the template of the
    mechanism's topology (a plan of it whose numbers are replaced, never an answer)
    refilled with its numbers, or built and kept as the template."""
    T = topology_of(mech, vll, prescribed)
    template = CACHE.get((T, "template"))
    if template is not None:  # (a point or a P axis missing: refilled builds it anew, and reports it)
        return template.refilled(mech)
    S = build_system(mech, vll=vll, prescribed=prescribed)
    kp = KinematicPlan(mech, S, _decomposition(S), vll, prescribed)
    seed = fields_replaced(mech)  # (the template holds no mechanism of the caller's)
    CACHE.put((T, "template"), fields_replaced(kp, mechanism=seed, system=fields_replaced(S, mech=seed, cache={})))
    return kp


#: The factors of ``np.radians`` and ``np.degrees`` (a product by them is bit for bit
#: theirs, and a plain multiplication is several times faster).
_RAD, _DEG = math.pi / 180.0, 180.0 / math.pi


def _simulate_plan(kp: KinematicPlan, inputs: dict[str, np.ndarray], speeds: dict[str, float] | None,
                   points: list[str] | None, method: str, progress: ProgressCallback | None,
                   change_points: str = "keep") -> Simulation:
    if change_points not in ("keep", "switch"):
        raise MechsynInputError(f"change_points must be 'keep' or 'switch', not {change_points!r}",
                                field="change_points")
    if not inputs:
        raise MechsynInputError("no input given", field="inputs", hint="give the driven joint's values, e.g. A=0:360:1 on the command line")
    spec = _input_spec(kp, tuple(inputs))
    if spec.prescribed != kp.prescribed:
        kp = compile_plan(kp.mechanism, kp.vll, tuple(inputs))
        spec = _input_spec(kp, tuple(inputs))
    mech, S = kp.mechanism, kp.system
    vals, U = _input_rows(S, spec, inputs)
    sp, speed_of = _input_speeds(spec, inputs, speeds)
    named = _named_points(S, mech, points)
    plan, engines = kp.groups, PLANAR_ENGINES
    if method not in ("auto", "assur"):
        engines = (engine_named(method),)
        if engines[0].name == "newton":
            plan = None
    if method == "assur" and plan is None:
        raise MechsynInputError("the mechanism does not decompose into drivers and dyads", field="method",
                                hint="use the Newton method")
    if change_points == "switch" and plan is None:
        raise MechsynInputError("change_points='switch' needs the closed form (a mechanism of drivers and dyads)",
                                field="change_points", hint="keep the drawn branch (change_points='keep')")
    if plan is not None and not drawn_checks(S, plan):
        assemble(S)  # checks the file configuration and the mobility
    require_drives_given(S, spec.names)  # a drive in excess held still: nothing would assemble
    sw = first_sweep(engines, S, plan, U, sp, change_points=change_points, progress=progress)
    if sw is None:  # one engine asked for by name, and it declined
        raise EngineDeclined(engines[0].name, mech.name, engines[0].declined(S, plan, change_points))
    ok = sw.assembled
    complete = sw.links is not None and sw.rates_ok is None
    if complete:  # the regular pass without folds: every row assembled with finite rates
        rates_ok, singular_rows = ok, []
    else:
        rates_ok = sw.rates_ok if sw.rates_ok is not None else _finite_rows(sw.qd) & _finite_rows(sw.qdd)
        singular_rows = sw.singular_rows if sw.singular_rows is not None else np.flatnonzero(ok & ~rates_ok).tolist()
    events = _with_singular_rows(S, sw, singular_rows) if sw.events or singular_rows else []
    deg = np.multiply(sw.q.T[2::3], _DEG, order="C")  # np.degrees' product, every link in one call
    qdT, qddT = sw.qd.T, sw.qdd.T  # rows of coordinates: a row is the view sw.qd[:, k]
    links = {name: LinkMotion(deg[i], qdT[3 * i + 2], qddT[3 * i + 2]) for i, name in enumerate(S.links)}
    pm = _point_motions(S, sw, named, ok, rates_ok, complete)
    notes = list(S.notes)
    if singular_configuration(S):
        notes.append("the file's configuration is singular (a dead centre or a folded / change-point "
                     "position): the assembly branch chosen from it is arbitrary")
    if spec.limited:
        events.extend(_limit_events(S, sw))
    return Simulation(
        mechanism=mech.name, inputs=vals, input_types=spec.types, speeds=speed_of, assembled=ok, points=pm,
        links=links, events=events, method=sw.method, engine=sw.engine, notes=notes, vll=dict(S.vll), sweep=sw,
        system=S)


def _finite_rows(x: np.ndarray) -> np.ndarray:
    """The rows (N,) of ``x`` (N, n) whose entries are all finite, reduced along the axis
    that is contiguous in memory (an engine's poses are often a transposed array)."""
    return np.isfinite(x.T).all(axis=0) if x.T.flags.c_contiguous else np.isfinite(x).all(axis=1)


def _with_singular_rows(S: PlanarSystem, sw: Sweep, singular_rows: list[int]) -> list[Event]:
    """The sweep's events, a ``singular`` event added at every assembled row whose rates
    are not defined and that no event flags yet, by row, in input units."""
    units = _units(S)
    events = [e.with_(input=units(e.input)) if e.input is not None else e for e in sw.events]
    flagged = {e.index for e in events if e.kind == "singular" and not e.before_sweep}
    for k in singular_rows:
        if k not in flagged:  # made in input units (one object, not one and a copy)
            events.append(Event(k, "singular", "singular configuration: assembled, but the velocities and "
                                "accelerations are not defined here (null)", units(sw.inputs[k].tolist())))
    events.sort(key=by_row)
    return events



@dataclass(frozen=True)
class _InputSpec:
    """What a plan's sweep needs to know of the joints given input values (``names``),
    found once per plan and names (:func:`_input_spec`): the prescribed passive VLLs among
    them, each one's driver index, type and limits (P) or the error it is (not a joint,
    not driven), the drivers' joints and drawn values; ``limited``: a P joint of the
    mechanism has limits (its VLL events are looked for)."""

    names: tuple
    prescribed: tuple
    index: tuple          # per name: driver index, or the MechsynInputError to raise
    types: dict
    limits: tuple         # per name: (lo, hi) of a P input with limits, else None
    drivers: tuple
    u0: tuple             # the drivers' drawn values (empty when one driver is given: not read)
    limited: bool
    driven: bool          # every input is a driven joint
    limited_inputs: bool  # an input is a P joint with limits
    unit_speeds: tuple    # the drivers' speeds when none is given: 1 for an input, else 0


def _input_spec(kp: KinematicPlan, names: tuple) -> _InputSpec:
    """The :class:`_InputSpec` of ``kp`` for the inputs ``names``, kept with its system:
    what the topology decides (:func:`_input_shape`, shared by the systems of one
    topology) with this mechanism's drawn input values and P limits."""
    mech, S = kp.mechanism, kp.system
    key = ("input spec", names)
    hit = S.cache.get(key)
    if hit is not None and hit[0] is mech and hit[1] is kp.vll:
        return hit[2]
    shape, p_inputs, p_joints = S.topology.product(("input shape", names), lambda: _input_shape(kp, names),
                                                 kp.groups)
    if p_joints is None:  # no number of the geometry in it
        return shape
    joints = mech.joints
    limits = list(shape.limits)
    for n, k in p_inputs:  # the P inputs' limits (not part of the topology)
        lim = joints[k].limits
        limits[n] = None if lim is None else (float(lim[0]), float(lim[1]))
    spec = fields_replaced(shape, limits=tuple(limits), u0=tuple([float(d.assembled) for d in S.drivers]),
                           limited=any(joints[k].limits is not None for k in p_joints),
                           limited_inputs=any(lim is not None for lim in limits))
    S.cache[key] = (mech, kp.vll, spec)
    return spec


def _input_shape(kp: KinematicPlan, names: tuple) -> tuple[_InputSpec, list, list]:
    """What :func:`_input_spec` takes from the topology: the spec without the numbers
    (drawn values, limits), the P inputs (position in ``names``, joint index) and the P
    joints (their indices), whose limits each mechanism of the topology gives; None for
    them when the spec is whole without numbers (no P joint, one driver and it is
    given: the drawn values are not read, ``u0`` is empty)."""
    mech, S = kp.mechanism, kp.system
    drivers = tuple(d.joint for d in S.drivers)
    where = {j.id: k for k, j in enumerate(mech.joints)}
    index, types, p_inputs = [], {}, []
    for n, jid in enumerate(names):
        if jid in drivers:
            k = drivers.index(jid)
            index.append(k)
            types[jid] = S.drivers[k].type
            if types[jid] == "P":
                p_inputs.append((n, where[jid]))
        else:
            index.append(_not_driven(mech, jid, drivers))
    shape = _InputSpec(names, tuple(j for j in names if _is_passive(mech, j, kp.vll)), tuple(index), types,
                       (None,) * len(names), drivers, (), False, all(isinstance(k, int) for k in index), False,
                       tuple(1.0 if k in index else 0.0 for k in range(len(drivers))))
    p_joints = [k for k, j in enumerate(mech.joints) if j.type == "P"]
    if not p_joints and len(drivers) == 1 and shape.driven:  # the one driver given: no drawn value, no limit read
        return shape, p_inputs, None
    return shape, p_inputs, p_joints


def _not_driven(mech: Mechanism, jid: str, drivers: tuple) -> MechsynInputError:
    """The error of an input given for ``jid``, which is not a driven joint."""
    try:
        j = mech.joint(jid)
    except KeyError:
        return MechsynInputError(f"no joint {jid!r}", field="inputs",
                                 hint=f"driven joints: {', '.join(drivers) or '(none)'}")
    return MechsynInputError(
        f"joint {jid} ({j.type}) is not driven", field="inputs",
        hint=f"mark it `actuated: true` in the file; driven joints: {', '.join(drivers) or '(none)'}")


def _input_rows(S: PlanarSystem, spec: _InputSpec, inputs: dict) -> tuple[dict, np.ndarray]:
    """The input values as float arrays by joint and the engines' input rows ``U`` (N, k):
    radians (R) or lengths (P), drivers without input at their drawn value. Checks them
    (the same number of values, not none, driven joints, finite, P within its limits)."""
    if len(inputs) == 1:  # (one input: no set of lengths)
        (jid, v), = inputs.items()
        a = np.asarray(v, float)
        vals, N = {jid: a}, a.shape[0] if a.ndim else 1
    else:
        vals = {jid: np.asarray(v, float) for jid, v in inputs.items()}
        lengths = {a.shape[0] if a.ndim else 1 for a in vals.values()}
        if len(lengths) != 1:
            raise MechsynInputError("all inputs need the same number of values", field="inputs")
        N = lengths.pop()
    if N == 0:
        raise MechsynInputError("the input range is empty", field="inputs")
    if not spec.driven:
        _check_inputs(S, spec, vals)  # raises: an input that is not a driven joint
    if len(spec.drivers) == 1:  # the one driver's values (radians: np.radians' product, one call)
        a = vals[spec.names[0]]
        U = (np.multiply(a, _RAD) if spec.types[spec.names[0]] == "R" else a.copy()).reshape(N, 1)
    else:
        U = np.empty((N, len(spec.drivers)))
        U[:] = spec.u0
        for jid, k in zip(spec.names, spec.index):
            if spec.types[jid] == "R":
                np.multiply(vals[jid], _RAD, out=U[:, k])
            else:
                U[:, k] = vals[jid]
    if np.count_nonzero(np.isfinite(U)) != U.size or spec.limited_inputs:  # (faster than .all())
        _check_inputs(S, spec, vals)
    return vals, U


def _check_inputs(S: PlanarSystem, spec: _InputSpec, vals: dict) -> None:
    """Raise the first input's error, input by input: not a driven joint, values not
    finite, a P input outside its limits."""
    for jid, k, lim in zip(spec.names, spec.index, spec.limits):
        if not isinstance(k, int):
            raise k
        a = vals[jid]
        if not np.isfinite(a).all():
            raise MechsynInputError(f"input values of {jid} must be finite numbers", field="inputs")
        if lim is not None and (a.min() < lim[0] - 1e-12 * S.scale or a.max() > lim[1] + 1e-12 * S.scale):
            raise MechsynInputError(
                f"input of {jid} goes outside its limits [{lim[0]:g}, {lim[1]:g}]", field="inputs",
                hint="keep the VLL length within its limits")


def _input_speeds(spec: _InputSpec, inputs: dict, speeds: dict[str, float] | None) -> tuple[np.ndarray, dict]:
    """The drivers' speeds (k,) (1 for an input without one, 0 for a driver without input)
    and the inputs' speeds by joint."""
    if not speeds:
        return np.array(spec.unit_speeds), dict.fromkeys(spec.names, 1.0)
    sp = [0.0] * len(spec.drivers)
    given = dict(speeds)
    for jid in given:
        if jid not in inputs:
            raise MechsynInputError(f"a speed is given for {jid}, which has no input", field="speeds")
    for jid, k in zip(spec.names, spec.index):
        sp[k] = float(given.get(jid, 1.0))
    if not all(math.isfinite(v) for v in sp):
        raise MechsynInputError("input speeds must be finite numbers", field="speeds",
                                hint="give each driven joint's speed in rad/s (R) or length/s (P)")
    return np.array(sp), {jid: sp[k] for jid, k in zip(spec.names, spec.index)}


def _named_points(S: PlanarSystem, mech: Mechanism, names: list[str] | None) -> tuple:
    """The named points asked for (:func:`resolve_points`) as ``(rows, moving, idx,
    local)``: rows ``(name, link, link index, the local point of a point of the frame,
    else None)``, the rows on moving links, their link indices and local points (m, 2),
    kept with the system (a cached plan's call resolves them and carries them into the
    link frames once). Which points, on which links, is the topology's
    (:func:`_named_shape`, shared by its systems, the rows too when every point is on a
    moving link); the local points are this geometry's
    (:func:`~mechsyn.kinematics.system.frame_points` on floats:
    :meth:`~mechsyn.kinematics.system.PlanarSystem.to_locals`' numbers)."""
    key = ("named points", None if names is None else tuple(names))
    hit = S.cache.get(key)
    if hit is None:
        rows, li, moving, idx, where = S.topology.product(key, lambda: _named_shape(S, mech, names))
        joints, points = mech.joints, mech.points
        pts = joint_points(S)  # a refilled system's: its joints' then its named points' floats
        if len(pts) == len(joints) + len(points):
            xy = [pts[k] for _, _, k in where]
        else:
            xy = [point_xy(points[name].at if j < 0 else joints[j].point) for name, j, _ in where]
        loc = frame_points(S.frames(), li, xy)
        if len(moving) == len(loc):  # every point on a moving link (the common case): the topology's rows
            local = np.array(loc, float).reshape(-1, 2)
        else:
            local = np.array([loc[k] for k in moving], float).reshape(-1, 2)
            rows = [(name, link, i, None if i >= 0 else np.array(loc[k], float))
                    for k, (name, link, i, _) in enumerate(rows)]
        hit = S.cache[key] = (rows, moving, idx, local)
    return hit


def _named_shape(S: PlanarSystem, mech: Mechanism, names: list[str] | None) -> tuple:
    """What :func:`_named_points` takes from the topology: its rows without the frame's
    points (``(name, link, link index, None)``), the links' indices, the rows on moving
    links and their indices (an array), and
    where each point's drawn coordinates are (``(name, -1, n)``: a named point, the
    ``n``-th of a refilled system's :func:`~mechsyn.kinematics.refill.joint_points`;
    ``(name, k, k)``: joint ``k``'s point)."""
    pts = resolve_points(mech, names)
    li = [S.index(link) for link, _ in pts.values()]
    moving = [k for k, i in enumerate(li) if i >= 0]
    index = {j.id: k for k, j in enumerate(mech.joints)}
    named = {name: len(index) + n for n, name in enumerate(mech.points)}  # (after the joints)
    where = [(name, -1, named[name]) if name in named else (name, index[name], index[name]) for name in pts]
    rows = tuple([(name, link, i, None) for (name, (link, _)), i in zip(pts.items(), li)])
    return rows, li, moving, np.array([li[k] for k in moving], int), where


def _point_motions(S: PlanarSystem, sw: Sweep, named: tuple, ok: np.ndarray, rates_ok: np.ndarray,
                   complete: bool) -> dict:
    """Position, velocity, acceleration of every named point (``named``: see
    :func:`_named_points`; NaN where not assembled, rates NaN where not defined): the
    points on moving links in one batch, from the links' complex states when the regular
    pass gave them (``complete``: every row assembled with finite rates), else from the
    poses (:meth:`~mechsyn.kinematics.system.PlanarSystem.points_state`)."""
    rows, moving, idx, local = named
    N = sw.q.shape[0]
    nok = bad = None  # rows where the positions (not assembled) or the rates (not defined) are set NaN
    if not complete and (len(moving) < len(rows) or not sw.nan_rows):
        nok = None if ok.all() else ~ok
        bad = None if rates_ok.all() else ~rates_ok
    states: dict[int, tuple] = {}
    if moving:
        if sw.links is not None:  # the links' states: NaN where the poses are
            P, V, A = sw.links.points(idx, local.view(complex)[:, 0])
            if len(moving) == 1:
                states[moving[0]] = (P[0], V[0], A[0])
        else:  # NaN rows stay NaN row by row (and rows not assembled or singular are set NaN)
            PVA = points_state_array(sw.q, sw.qd, sw.qdd, idx, local)
            if not sw.nan_rows:  # else NaN already: every number of a point's row depends on its row
                _set_nan(PVA, nok, bad)
            P, V, A = PVA
        if not states:
            states = dict(zip(moving, zip(P, V, A)))
    pm = {}
    for k, (name, link, i, at) in enumerate(rows):
        if k in states:
            pm[name] = PointMotion(*states[k], link)
            continue
        # a point of the frame: at rest (A(0) at + 0: the point with -0 as +0, as point_state gives it)
        PVA = np.zeros((3, N, 2))
        PVA[0] += at
        _set_nan(PVA, nok, bad)
        pm[name] = PointMotion(*PVA, link)
    return pm


def _set_nan(PVA: np.ndarray, nok: np.ndarray | None, bad: np.ndarray | None) -> None:
    """NaN the rows ``nok`` (not assembled) of positions, velocities and accelerations
    ``PVA`` (3, ..., N, 2) and the rows ``bad`` of the rates (one call each)."""
    if nok is not None:  # through the transpose the rows are its second axis (the fastest mask)
        PVA.T[:, nok] = np.nan
    if bad is not None and (nok is None or bad.tobytes() != nok.tobytes()):  # often the same rows
        PVA[1:].T[:, bad] = np.nan


def _prescribed(mech: Mechanism, vll: dict[str, str] | None, inputs: tuple) -> tuple:
    """The inputs that are passive VLLs (prescribed, :func:`_is_passive`)."""
    return tuple([j for j in inputs if _is_passive(mech, j, vll)])


def _is_passive(mech: Mechanism, jid: str, vll: dict[str, str] | None) -> bool:
    mode = (vll or {}).get(jid)
    if mode is not None:
        return VLL_MODES.get(mode) == "passive"
    try:
        return mech.joint(jid).vll == "passive"
    except KeyError:
        return False


def _units(S: PlanarSystem) -> Any:
    """The function that gives an event's input values (a sequence, radians or lengths)
    by joint, in degrees (R: ``math.degrees``, np.degrees' product) or lengths (P)."""
    conv = [(d.joint, math.degrees if d.type == "R" else float) for d in S.drivers]
    return lambda u: {j: f(v) for (j, f), v in zip(conv, u)}


def _limit_events(S: PlanarSystem, sw: Sweep) -> list[Event]:
    """Where a VLL's length leaves its limits."""
    out = []
    for j in S.mech.joints:
        if j.type != "P" or j.limits is None:
            continue
        s = S.coordinate(np.nan_to_num(sw.q), j.id)
        bad = sw.assembled & ((s < j.limits[0] - 1e-9 * S.scale) | (s > j.limits[1] + 1e-9 * S.scale))
        if bad.any():
            k = int(np.argmax(bad))
            out.append(Event(k, "limit", f"VLL {j.id} length {s[k]:.6g} is outside its limits "
                             f"[{j.limits[0]:g}, {j.limits[1]:g}] at {int(bad.sum())} input value(s)",
                             joint=j.id, value=float(s[k])))
    return out
