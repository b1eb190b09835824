"""A planar mechanism as a system of constraint equations on link poses.

Every moving link ``i`` has the pose ``q_i = (x_i, y_i, phi_i)``: the position of its
origin and the absolute angle of its reference line (Haug's *body coordinates*,
E. J. Haug, *Computer-Aided Kinematics and Dynamics of Mechanical Systems*, 1989,
ch. 3). The frame is fixed at ``(0, 0, 0)``. A point with local coordinates ``s`` on
link ``i`` is at ``P = r_i + A(phi_i) s``.

Link frames come from the file's assembled configuration: a link's origin is its first
joint's point (file order), its reference line points to the first other joint point (a
crank's angle is the crank line's direction); the frame keeps the global frame.

Joints become constraint rows ``Phi(q, u) = 0`` (``u``: the input coordinates):

* R pair: ``P_a - P_b = 0`` (2 rows);
* P pair: ``phi_b - phi_a = const`` and ``n_a . (P_b - P_a) = 0`` (2 rows);
* driven R: ``phi_b - phi_a - theta = 0``; driven or locked P (``vll``):
  ``u_a . (P_b - O_a) - s = 0`` with ``O_a`` the origin of link ``a``;
* gear pair (ratio ``k``, carrier ``c``): ``(phi_b - phi_c) - k (phi_a - phi_c) = const``;
* cam with a roller (or knife edge) on link ``b``: the roller centre stays on the
  profile's offset curve ``O(t)`` fixed on the cam ``a``:
  ``P_b - r_a - A_a O(t) = 0`` (2 rows, one extra unknown ``t``);
* belt (paper 001; chain, band, rope): anchored at ``E`` on link ``a``, wrapping a pulley
  of radius ``r`` centred at ``P`` on link ``b`` in the sense ``σ`` (+1 ccw, -1 cw). With
  ``D = P - E``, ``d = |D|``, ``δ = arg D``, free length ``b = sqrt(d² - r²)`` and tangent
  point at ``τ = δ - σ atan2(b, -r)``, the belt length ``b + σ r (φ_b - τ)`` (straight run
  plus ``r`` times the angle wrapped, measured in the pulley's frame) is constant:
  ``b - r atan(b/r) + σ r (φ_b - δ) = const`` (1 row). Its Jacobian row is
  ``g·dD + σ r dφ_b`` with ``g`` the unit belt direction (the tension's line of action).

The Jacobian ``Phi_q`` is analytic; ``gamma`` is the right-hand side of the
acceleration equation ``Phi_q q'' = gamma`` (Haug eq. 3.3.11). All functions work on a
batch of configurations: ``q`` has shape ``(N, n)``.

References
----------
.. [1] I. I. Borisov, R. A. Zashchitin, O. V. Borisova and S. A. Kolyubin, "Algorithm of
   structural-parametric synthesis of adaptive gripper mechanisms with variable-length
   links" (in Russian), ITMO University, St. Petersburg ("paper 000"; see docs/references.md).
.. [2] "A new basic mechanism of a manipulator for servicing technological machines" (in
   Bulgarian; a manipulator with a flexible element, by the method of V. Galabov et
   al., 2012) ("paper 001"; see docs/references.md).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from itertools import accumulate
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.cams import CamCurve, cam_curve
from mechsyn.kinematics.plane import cos_sin, dot, perp, rotate, to_frame
from mechsyn.kinematics.topology import Topology, topology_of
from mechsyn.model.mechanism import Joint, Mechanism
from mechsyn.model.pairs import BELT_WRAPS

__all__ = ["PlanarSystem", "build_system", "VLL_MODES", "CamCurve"]

#: Accepted spellings of the VLL modes on the command line.
VLL_MODES = {"active": "active", "driven": "active", "passive": "passive", "free": "passive",
             "locked": "locked", "rigid": "locked"}


# --------------------------------------------------------------------------- constraints
@dataclass(frozen=True)
class Con:
    """One constraint block. ``kind``: R, angle, line, gear, curve."""

    kind: str
    joint: str
    rows: int
    a: int                   # link indices (-1: frame)
    b: int
    sa: np.ndarray | None = None
    sb: np.ndarray | None = None
    w: np.ndarray | None = None   # local unit direction on a (line)
    c0: float = 0.0
    driver: int | None = None     # index into the input vector u
    c: int = -1                   # gear carrier
    k: float = 0.0                # gear ratio
    tvar: int = -1                # cam contact parameter's column
    curve: CamCurve | None = None
    role: str = ""                # "pair", "drive", "lock", "rotation", "idle"
    radius: float = 0.0           # belt: pulley radius
    sigma: float = 0.0            # belt: wrap sense, +1 ccw, -1 cw
    ref: float = 0.0              # belt: phi_b - delta in the file's configuration


@dataclass(frozen=True)
class Driver:
    """An input coordinate: a driven (or prescribed passive) joint."""

    joint: str
    type: str            # "R" (radians) or "P" (length)
    assembled: float     # its value in the file's configuration
    role: str            # "drive" (actuated / active VLL) or "prescribed" (passive VLL)


@dataclass(frozen=True, eq=False)
class PlanarSystem:
    """A compiled planar mechanism: unknowns, constraints, inputs (see the module doc)."""

    mech: Mechanism
    links: tuple[str, ...]             # moving links; link i has columns 3i..3i+2
    origin0: np.ndarray                # (nl, 2) assembled origins
    angle0: np.ndarray                 # (nl,) assembled reference angles
    cons: tuple[Con, ...]
    drivers: tuple[Driver, ...]
    n: int                             # unknowns
    m: int                             # equations
    q0: np.ndarray                     # file configuration
    scale: float                       # characteristic length
    vll: dict[str, str] = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    #: the length of every equation (``scale`` for the rows of point and line constraints,
    #: 1 for angle and gear rows) and of every unknown (``scale`` for link origins, 1 for
    #: angles and cam parameters): ``Phi_q * col_scale / row_scale`` is dimensionless
    row_scale: np.ndarray | None = None
    col_scale: np.ndarray | None = None
    #: what the engines compute once per system and reuse (the assembled configuration,
    #: the groups' look-ups, the equations gathered by kind): this geometry's
    #: answers, a field of the compiled system, so a new geometry starts with an empty one
    cache: dict = field(default_factory=dict, repr=False, compare=False)
    #: the mechanism's :class:`~mechsyn.kinematics.topology.Topology` (with the VLL modes
    #: and prescribed inputs compiled): what the systems of one topology share is kept by it
    topology: Topology | None = field(default=None, repr=False, compare=False)

    def unit_jacobian(self, J: np.ndarray) -> np.ndarray:
        """``Phi_q`` (..., m, n) made dimensionless by the mechanism's length scale: rows of
        length equations divided by ``scale``, columns of link origins multiplied by it.
        Its rank, singular values and pivots do not change when the mechanism is scaled, so
        tolerances on them are relative to the mechanism's size."""
        return J * (self.col_scale / self.row_scale[:, None])

    # -- geometry helpers ----------------------------------------------------------
    def index(self, link: str) -> int:
        return -1 if link == self.mech.ground else self.links.index(link)

    def frames(self) -> tuple[list, list, list]:
        """``cos(-phi0)``, ``sin(-phi0)`` and the origin of every link's drawn frame, as
        Python numbers (one point carried into a frame costs a few float products)."""
        f = self.cache.get("frames")
        if f is None:
            f = self.cache["frames"] = (np.cos(-self.angle0).tolist(), np.sin(-self.angle0).tolist(),
                                        self.origin0.tolist())
        return f

    def to_local(self, link: str, p: np.ndarray) -> np.ndarray:
        i = self.index(link)
        if i < 0:
            return np.asarray(p, float)
        cos, sin, org = self.frames()
        return to_frame(cos[i], sin[i], p[0] - org[i][0], p[1] - org[i][1])

    def to_locals(self, idx: np.ndarray, pts: np.ndarray) -> np.ndarray:
        """:meth:`to_local` of the points ``pts`` (m, 2) on the links ``idx`` (m,; -1: the
        frame, the point itself) at once (m, 2): :func:`frame_points`, the same numbers.

        Examples
        --------
        >>> import numpy as np, mechsyn as ms
        >>> S = build_system(ms.examples.load("crank_rocker"))
        >>> pts = np.array([[1.0, 2.0], [0.5, -0.3]])
        >>> loc = S.to_locals(np.array([1, -1]), pts)
        >>> bool(np.array_equal(loc[0], S.to_local(S.links[1], pts[0]))), loc[1].tolist()
        (True, [0.5, -0.3])
        """
        return np.array(frame_points(self.frames(), idx.tolist(), pts.tolist()), float).reshape(-1, 2)

    def pose(self, q: np.ndarray, i: int) -> tuple[np.ndarray, np.ndarray]:
        """(r (N,2), phi (N,)) of link ``i`` (frame: zeros)."""
        if i < 0:
            z = np.zeros(q.shape[0])
            return np.zeros((q.shape[0], 2)), z
        return q[:, 3 * i:3 * i + 2], q[:, 3 * i + 2]

    def rotation(self, q: np.ndarray, i: int) -> tuple[np.ndarray, np.ndarray]:
        """``cos phi, sin phi`` (N,) of link ``i`` (the frame: 1 and 0)."""
        return cos_sin(self.pose(q, i)[1])

    def point(self, q: np.ndarray, i: int, s: np.ndarray) -> np.ndarray:
        r, phi = self.pose(q, i)
        c, sn = cos_sin(phi)
        return r + rotate(c, sn, s)

    def link_angle(self, q: np.ndarray, link: str) -> np.ndarray:
        """Angles (N,) of link ``link`` (the frame: zeros)."""
        return self.pose(q, self.index(link))[1]

    def driver_index(self, joint: str) -> int:
        for k, d in enumerate(self.drivers):
            if d.joint == joint:
                return k
        raise KeyError(joint)

    def coordinate(self, q: np.ndarray, joint: str) -> np.ndarray:
        """The joint coordinate: relative angle (R, rad) or slide coordinate (P)."""
        j = self.mech.joint(joint)
        a, b = self.index(j.links[0]), self.index(j.links[1])
        if j.type == "R":
            return self.link_angle(q, j.links[1]) - self.link_angle(q, j.links[0])
        u_loc = self.to_local_dir(j.links[0], _axis(j))
        sb = self.to_local(j.links[1], j.point)
        ra, pa = self.pose(q, a)
        c, s = cos_sin(pa)
        return dot(rotate(c, s, u_loc), self.point(q, b, sb) - ra)

    def coordinate_rate(self, q: np.ndarray, qd: np.ndarray, joint: str) -> np.ndarray:
        """Time derivative of :meth:`coordinate` (by the Jacobian of the coordinate)."""
        h = 1e-7
        # the coordinate is smooth in q: a central difference along qd is exact to O(h^2)
        qa, qb = np.nan_to_num(q - h * qd), np.nan_to_num(q + h * qd)
        return (self.coordinate(qb, joint) - self.coordinate(qa, joint)) / (2 * h)

    def to_local_dir(self, link: str, u: np.ndarray) -> np.ndarray:
        i = self.index(link)
        if i < 0:
            return np.asarray(u, float)
        cos, sin, _ = self.frames()
        return to_frame(cos[i], sin[i], u[0], u[1])

    # -- equations -----------------------------------------------------------------
    def residual(self, q: np.ndarray, u: np.ndarray) -> np.ndarray:
        """``Phi(q, u)``, shape (N, m); ``u`` has shape (N, n_inputs)."""
        eqs = self.equations()
        E, out = _At(self, eqs, q), np.empty((q.shape[0], self.m))
        u = np.concatenate([u, np.zeros((q.shape[0], 1))], axis=1)  # input column -1: none
        for G in eqs.kinds:
            out[:, G.idx] = G.residual(E, u)
        return out

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """``Phi_q``, shape (N, m, n)."""
        eqs = self.equations()
        E, J = _At(self, eqs, q), np.zeros((q.shape[0], self.m, self.n + 3))  # the last 3 columns: the frame's
        for G in eqs.kinds:
            G.jacobian(J, E)
        return J[..., :self.n]

    def input_matrix(self) -> np.ndarray:
        """``B`` with ``Phi_q q' = B u'`` (rows of drivers are 1 in their input column)."""
        B = np.zeros((self.m, len(self.drivers)))
        for row, con in self.blocks():
            if con.driver is not None:
                B[row, con.driver] = 1.0
        return B

    def gamma(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Velocity-dependent right-hand side of ``Phi_q q'' = gamma + B u''``."""
        eqs = self.equations()
        E, out = _At(self, eqs, q, qd), np.empty((q.shape[0], self.m))
        for G in eqs.kinds:
            out[:, G.idx] = G.gamma(E)
        return out

    def rates(self, q: np.ndarray, speeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Velocities and accelerations (N, n) of the configurations ``q`` (N, n) at the
        input speeds ``speeds`` (k,): ``Phi_q q' = B u'`` and ``Phi_q q'' = gamma``
        (Haug 1989, eqs. 3.3.9-3.3.11) solved for every configuration at once (a redundant
        system: the least-squares rates, by the pseudo-inverse)."""
        N = q.shape[0]
        J = self.jacobian(q)
        rhs = np.broadcast_to(self.input_matrix() @ np.asarray(speeds, float), (N, self.m))
        if self.m == self.n:
            qd = np.linalg.solve(J, rhs[..., None])[..., 0]
            return qd, np.linalg.solve(J, self.gamma(q, qd)[..., None])[..., 0]
        pinv = np.linalg.pinv(J)
        qd = np.einsum("nij,nj->ni", pinv, rhs)
        return qd, np.einsum("nij,nj->ni", pinv, self.gamma(q, qd))

    def rows_of(self, joint: str) -> list[int]:
        return [r for row, con in self.blocks() if con.joint == joint for r in range(row, row + con.rows)]

    def equations(self) -> _Equations:
        """The constraint equations gathered by kind (:class:`_Equations`), kept in :attr:`cache`."""
        eqs = self.cache.get("equations")
        if eqs is None:
            eqs = self.cache["equations"] = _Equations(self)
        return eqs

    def blocks(self) -> Iterator[tuple[int, Con]]:
        """Every constraint block with its first row of ``Phi``: ``(row, con)`` in
        ``cons`` order (the rows of a block are ``row .. row + con.rows - 1``; the first
        rows kept in :attr:`cache`)."""
        rows = self.cache.get("block rows")
        if rows is None:
            rows = self.cache["block rows"] = [0, *accumulate(c.rows for c in self.cons)]
        return zip(rows, self.cons)


def frame_points(frames: tuple, idx: list, xy: list) -> list:
    """Points ``xy`` in the frames of links ``idx`` (-1: frame): :func:`to_frame` on floats."""
    cos, sin, org = frames  # (c dx - s dy, s dx + c dy), dx and dy named as they are first used
    return [(x, y) if i < 0 else (cos[i] * (dx := x - org[i][0]) - sin[i] * (dy := y - org[i][1]),
                                  sin[i] * dx + cos[i] * dy) for i, (x, y) in zip(idx, xy)]


def _axis(j: Joint) -> np.ndarray:
    return np.asarray(j.axis, float)  # given: build_system refuses a P pair without axis


# ------------------------------------------------------------------ the equations, kind by kind
class _Equations:
    """The constraint blocks of a system gathered by kind (:class:`_Blocks`), once per system
    (:meth:`PlanarSystem.equations`), and the table of every local vector they turn with a
    link (joint points, line directions): its links ``link`` (M,; -1 the frame), vectors
    ``vec`` (M, 2) and their quarter turns ``vec_perp``. An evaluation turns the whole
    table at once (:class:`_At`) and each kind reads its blocks' rows of it, so the
    equations of a kind are a few whole-array operations over all its blocks and a batch of
    configurations, one configuration of Newton's method as well as a sweep."""

    def __init__(self, S: PlanarSystem, blocks: Any = None) -> None:
        self.links: list = []
        self.vecs: list = []
        by: dict = {}
        for row, con in S.blocks() if blocks is None else blocks:
            by.setdefault(_KINDS[con.kind], []).append((row, con))
        self.kinds = [kind(S, self, items) for kind, items in by.items()]
        self.link = np.array(self.links, int)
        self.vec = np.array(self.vecs, float).reshape(-1, 2)
        self.vec_perp = perp(self.vec)

    def add(self, links: np.ndarray, vecs: list) -> slice:
        """Rows of the table for the vectors ``vecs`` (None: zero) on the links ``links``."""
        start = len(self.links)
        self.links += links.tolist()
        self.vecs += [(0.0, 0.0) if v is None else tuple(v) for v in vecs]
        return slice(start, len(self.links))


class _At:
    """The poses of a batch of configurations ``q`` (N, n) (and their rates ``qd``) and the
    table of :class:`_Equations` turned with them: ``T`` (N, M, 2) the vectors ``A(phi) s``,
    ``R`` their links' origins, ``P = R + T`` the points; the frame (pose zero) is the last
    link, so that link -1 is the frame. ``phi``, ``cos``, ``sin`` (N, nl + 1) are the links'
    angles; with ``qd``, ``v`` (N, M, 2) and ``w`` (N, M) are the velocities and angular
    velocities of the table's links."""

    def __init__(self, S: PlanarSystem, eqs: _Equations, q: np.ndarray, qd: np.ndarray | None = None) -> None:
        self.q, self.qd = q, qd
        r, self.phi = _poses(S, q)
        self.cos, self.sin = cos_sin(self.phi)
        c, s = self.cos[:, eqs.link, None], self.sin[:, eqs.link, None]
        self.R, self.T = r[:, eqs.link], c * eqs.vec + s * eqs.vec_perp
        self.P = self.R + self.T
        if qd is not None:
            v, w = _poses(S, qd)
            self.v, self.w = v[:, eqs.link], w[:, eqs.link]

    def turned(self, i: np.ndarray, s: np.ndarray) -> np.ndarray:
        """``A(phi_i) s`` (N, K, 2) of local vectors ``s`` (N, K, 2) outside the table (cam curves)."""
        return rotate(self.cos[:, i], self.sin[:, i], s)


def _poses(S: PlanarSystem, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The origins (N, nl + 1, 2) and angles (N, nl + 1) of the links in ``q``, the frame last."""
    nl = len(S.links)
    P = np.zeros((q.shape[0], nl + 1, 3))
    P[:, :nl] = q[:, :3 * nl].reshape(-1, nl, 3)
    return P[..., :2], P[..., 2]


class _Blocks:
    """The constraint blocks of one kind gathered into arrays (K blocks of ``rows`` rows):
    their rows of ``Phi`` (``idx``), links (``a``, ``b``, a gear's carrier ``c``; -1 the
    frame), the first columns of those links in ``Phi_q`` (``ca``, ``cb``, ``cc``: the
    three columns of each, the frame's ``n`` and after, dropped), the rows of their local
    vectors ``sa`` (on ``a``), ``sb`` (on ``b``) and ``w`` (on ``a``) in the table of
    :class:`_Equations`, constants ``c0``, gear ratios ``k`` (1 for an angle), input
    columns ``drv`` (-1: none), and the blocks themselves (``cons``: cam curves)."""

    def __init__(self, S: PlanarSystem, eqs: _Equations, items: list) -> None:
        self.cons = [c for _, c in items]
        first = np.array([r for r, _ in items])
        self.idx = first if self.cons[0].rows == 1 else first[:, None] + np.arange(self.cons[0].rows)
        shape = first.shape + (1,) * (self.idx.ndim - 1)  # (K,) for one-row blocks, else (K, 1)
        self.a, self.b, self.c, self.tvar = (np.array([getattr(c, f) for c in self.cons])
                                             for f in ("a", "b", "c", "tvar"))
        self.ca, self.cb, self.cc = (tuple(np.where(i < 0, S.n, 3 * i).reshape(shape) + d for d in range(3))
                                     for i in (self.a, self.b, self.c))
        self.sa, self.sb, self.w = (eqs.add(i, [getattr(c, f) for c in self.cons])
                                    for i, f in ((self.a, "sa"), (self.b, "sb"), (self.a, "w")))
        self.c0, self.radius, self.sigma, self.ref = (np.array([getattr(c, f) for c in self.cons], float)
                                                      for f in ("c0", "radius", "sigma", "ref"))
        self.k = np.array([c.k if c.kind == "gear" else 1.0 for c in self.cons])
        self.drv = np.array([-1 if c.driver is None else c.driver for c in self.cons])

    def put(self, J: np.ndarray, cols: tuple, dr: Any, dphi: Any) -> None:
        """A link's entries in the blocks' rows of ``J``: ``dr`` (..., 2) at the columns of its
        origin (None: none; a number: that times the identity of a point's two rows, only its
        diagonal written), ``dphi`` at its angle's (``cols``: the three, ``ca``, ``cb`` or ``cc``)."""
        if isinstance(dr, float):
            J[:, self.idx, cols[0] + (0, 1)] = dr
        elif dr is not None:
            J[:, self.idx, cols[0]] = dr[..., 0]
            J[:, self.idx, cols[1]] = dr[..., 1]
        J[:, self.idx, cols[2]] = dphi

    def gamma(self, E: _At) -> Any:
        """The blocks' rows of ``gamma`` (0: none, as for angles and gears)."""
        return 0.0

    def curve(self, t: np.ndarray, der: int) -> np.ndarray:
        """The cam curves ``O(t)`` (or a derivative) of the blocks at their parameters (N, K, 2)."""
        return np.stack([c.curve.eval(t[:, k], der) for k, c in enumerate(self.cons)], axis=1)


class _Pins(_Blocks):
    """R pair: ``P_a - P_b`` (2 rows)."""

    def residual(self, E: _At, u: np.ndarray) -> np.ndarray:
        return E.P[:, self.sa] - E.R[:, self.sb] - E.T[:, self.sb]

    def jacobian(self, J: np.ndarray, E: _At) -> None:
        self.put(J, self.ca, 1.0, perp(E.T[:, self.sa]))
        self.put(J, self.cb, -1.0, -perp(E.T[:, self.sb]))

    def gamma(self, E: _At) -> np.ndarray:
        return E.w[:, self.sa, None] ** 2 * E.T[:, self.sa] - E.w[:, self.sb, None] ** 2 * E.T[:, self.sb]


class _Turns(_Blocks):
    """Angle (drive, P pair's rotation, idle roller) and gear pair (ratio ``k``, carrier
    ``c``; an angle: ``k = 1``, ``c`` the frame): ``(phi_b - phi_c) - k (phi_a - phi_c) - c0 - u``."""

    def residual(self, E: _At, u: np.ndarray) -> np.ndarray:
        pa, pb, pc = E.phi[:, self.a], E.phi[:, self.b], E.phi[:, self.c]
        return (pb - pc) - self.k * (pa - pc) - (self.c0 + u[:, self.drv])

    def jacobian(self, J: np.ndarray, E: _At) -> None:
        self.put(J, self.cc, None, self.k - 1.0)
        self.put(J, self.cb, None, 1.0)
        self.put(J, self.ca, None, -self.k)


class _Lines(_Blocks):
    """Line (P pair, driven or locked slide): ``w . (P_b - P_a) - c0 - u`` with ``w = A_a w_loc``."""

    def d(self, E: _At) -> np.ndarray:
        """``P_b - P_a`` (N, K, 2)."""
        return E.P[:, self.sb] - E.R[:, self.sa] - E.T[:, self.sa]

    def residual(self, E: _At, u: np.ndarray) -> np.ndarray:
        return dot(E.T[:, self.w], self.d(E)) - (self.c0 + u[:, self.drv])

    def jacobian(self, J: np.ndarray, E: _At) -> None:
        w = E.T[:, self.w]
        self.put(J, self.ca, -w, dot(perp(w), self.d(E)) - dot(w, perp(E.T[:, self.sa])))
        self.put(J, self.cb, w, dot(w, perp(E.T[:, self.sb])))

    def gamma(self, E: _At) -> np.ndarray:
        w, Asa, Asb, wa, wb = E.T[:, self.w], E.T[:, self.sa], E.T[:, self.sb], E.w[:, self.sa], E.w[:, self.sb]
        dd = E.v[:, self.sb] + wb[..., None] * perp(Asb) - E.v[:, self.sa] - wa[..., None] * perp(Asa)
        return (wa ** 2 * dot(w, E.P[:, self.sb] - E.P[:, self.sa]) - 2 * wa * dot(perp(w), dd)
                + wb ** 2 * dot(w, Asb) - wa ** 2 * dot(w, Asa))


class _Curves(_Blocks):
    """Cam (roller centre on the offset curve ``O(t)`` of cam ``a``): ``P_b - r_a - A_a O(t)``
    (2 rows; ``t`` the unknown ``tvar``)."""

    def residual(self, E: _At, u: np.ndarray) -> np.ndarray:
        return E.P[:, self.sb] - E.R[:, self.sa] - E.turned(self.a, self.curve(E.q[:, self.tvar], 0))

    def jacobian(self, J: np.ndarray, E: _At) -> None:
        t = E.q[:, self.tvar]
        self.put(J, self.cb, 1.0, perp(E.T[:, self.sb]))
        self.put(J, self.ca, -1.0, -perp(E.turned(self.a, self.curve(t, 0))))
        J[:, self.idx, self.tvar[:, None]] = -E.turned(self.a, self.curve(t, 1))

    def gamma(self, E: _At) -> np.ndarray:
        t, td, wa, wb = E.q[:, self.tvar], E.qd[:, self.tvar, None], E.w[:, self.sa, None], E.w[:, self.sb, None]
        O, O1, O2 = (E.turned(self.a, self.curve(t, d)) for d in (0, 1, 2))
        return wb ** 2 * E.T[:, self.sb] - wa ** 2 * O + 2 * wa * td * perp(O1) + td ** 2 * O2


class _Belts(_Blocks):
    """Belt (see the module doc): ``b - r atan(b / r) + σ r (φ_b - δ) - const`` (1 row)."""

    def terms(self, E: _At) -> tuple:
        """``D = P - E`` (N, K, 2), ``d²``, the free length ``b`` (NaN where ``d <= r``), the
        unit belt direction ``g = (b D - σ r R90 D) / d²`` and ``σ r``."""
        D = E.P[:, self.sb] - E.P[:, self.sa]
        d2, r = dot(D, D), self.radius
        with np.errstate(invalid="ignore"):
            b = np.sqrt(np.where(d2 > r * r, d2 - r * r, np.nan))  # NaN: belt not taut and straight
        return D, d2, b, (b[..., None] * D - (self.sigma * r)[:, None] * perp(D)) / d2[..., None], self.sigma * r

    def residual(self, E: _At, u: np.ndarray) -> np.ndarray:
        D, _, b, _, sr = self.terms(E)
        rel = E.phi[:, self.b] - np.arctan2(D[..., 1], D[..., 0]) - self.ref
        rel = np.mod(rel + np.pi, 2 * np.pi) - np.pi  # continuous within half a turn
        return b - self.radius * np.arctan2(b, self.radius) + sr * rel - self.c0

    def jacobian(self, J: np.ndarray, E: _At) -> None:
        _, _, _, g, sr = self.terms(E)
        self.put(J, self.ca, -g, -dot(g, perp(E.T[:, self.sa])))
        self.put(J, self.cb, g, dot(g, perp(E.T[:, self.sb])) + sr)

    def gamma(self, E: _At) -> np.ndarray:
        # Phi'' = dg/dt . D' + g . D'' + σ r phi_b'' with D'' = (terms in q'') - w_b² A_b s_b
        # + w_a² A_a s_a, and dg/dt = w_g R90 g, w_g = (R90 D . D')/d² + σ r (D . D')/(d² b)
        # (g turns with D's direction less the tangent offset arcsin(r/d)).
        D, d2, b, g, sr = self.terms(E)
        Asa, Asb, wa, wb = E.T[:, self.sa], E.T[:, self.sb], E.w[:, self.sa], E.w[:, self.sb]
        Dd = E.v[:, self.sb] + wb[..., None] * perp(Asb) - E.v[:, self.sa] - wa[..., None] * perp(Asa)
        wg = dot(perp(D), Dd) / d2 + sr * dot(D, Dd) / (d2 * b)
        return wb ** 2 * dot(g, Asb) - wa ** 2 * dot(g, Asa) - wg * dot(perp(g), Dd)


#: The blocks of every kind of constraint (an angle is a gear of ratio 1 about the frame).
_KINDS = {"R": _Pins, "angle": _Turns, "gear": _Turns, "line": _Lines, "curve": _Curves, "belt": _Belts}


# --------------------------------------------------------------------------- building
def build_system(mech: Mechanism, vll: dict[str, str] | None = None,
                 prescribed: tuple[str, ...] = ()) -> PlanarSystem:
    """Compile a planar mechanism with joint points into a :class:`PlanarSystem`.

    Parameters
    ----------
    vll: joint id -> mode (``active``/``passive``/``locked``; ``free`` = passive),
        overriding the file's ``vll`` modes (paper 000's fully actuated mode is the
        VLL locked, the underactuated one the VLL free).
    prescribed: passive joints whose coordinate is given as an input (their
        actuator force is then reported as the force a spring or stop must supply).
    """
    src = mech.source or "<mechanism>"
    _check_joints(mech, src)
    modes = _vll_modes(mech, vll)
    moving = mech.moving_links
    origin0, angle0, scale = _link_frames(mech)
    n_links = len(moving)
    partial = PlanarSystem(mech, tuple(moving), origin0, angle0, (), (), 3 * n_links, 0,
                           np.zeros(3 * n_links), scale)
    q0 = np.zeros(3 * n_links)
    q0[0::3], q0[1::3], q0[2::3] = origin0[:, 0], origin0[:, 1], angle0
    b = _Builder(partial, q0, modes, prescribed, src)
    for j in mech.joints:
        b.add(j)
    for jid in prescribed:
        if jid not in [d.joint for d in b.drivers]:
            raise MechsynInputError(f"joint {jid} cannot be given an input", field="inputs",
                                    hint="inputs go to actuated joints and to free (passive) VLL joints")
    q0 = np.concatenate([q0, b.extra_q])
    m = sum(c.rows for c in b.cons)
    rows = np.concatenate([np.full(c.rows, 1.0 if c.kind in ("angle", "gear") else scale) for c in b.cons]
                          ) if b.cons else np.zeros(0)
    cols = np.ones(len(q0))
    cols[0:3 * n_links:3] = cols[1:3 * n_links:3] = scale
    return PlanarSystem(mech, tuple(moving), origin0, angle0, tuple(b.cons), tuple(b.drivers), len(q0), m, q0,
                        scale, vll=modes, notes=tuple(b.notes), row_scale=rows, col_scale=cols,
                        topology=topology_of(mech, vll, prescribed))


def _check_joints(mech: Mechanism, src: str) -> None:
    """A planar mechanism whose joints have points (and P joints axes) of known types."""
    if mech.kind != "planar":
        raise MechsynInputError("kinematics needs a planar mechanism", source=src, field="kind",
                                hint="set kind: planar (spatial kinematics is not implemented)")
    for j in mech.joints:
        if j.point is None:
            raise MechsynInputError(f"joint {j.id} has no point", source=src, field=f"joints.{j.id}.point",
                                    hint="give every joint a point, e.g. point: [0, 0], in the assembled configuration")
        if j.type == "P" and j.axis is None:
            raise MechsynInputError(f"joint {j.id} (P) has no axis: its sliding direction is not assumed",
                                    source=src, field=f"joints.{j.id}.axis",
                                    hint="add axis: [dx, dy], e.g. axis: [1, 0] to slide along x")
        if j.type not in ("R", "P", "cam", "gear", "belt"):
            raise MechsynInputError(f"joint {j.id}: pair type {j.type} is not supported by planar kinematics",
                                    source=src, field=f"joints.{j.id}.type", hint="use R, P, cam, gear or belt")


def _vll_modes(mech: Mechanism, vll: dict[str, str] | None) -> dict[str, str]:
    """The VLL mode of every P joint that has one: the file's, overridden by ``vll``."""
    modes: dict[str, str] = {j.id: j.vll for j in mech.joints if j.vll}
    for jid, mode in (vll or {}).items():
        try:
            j = mech.joint(jid)
        except KeyError:
            raise MechsynInputError(f"no joint {jid!r}", field="vll",
                                    hint=f"joints are: {', '.join(x.id for x in mech.joints)}") from None
        if j.type != "P":
            raise MechsynInputError(f"joint {jid} is a {j.type} pair; a variable-length link is a P pair",
                                    field="vll")
        if mode not in VLL_MODES:
            raise MechsynInputError(f"unknown VLL mode {mode!r}", field="vll",
                                    hint="use locked, free (passive) or active")
        modes[jid] = VLL_MODES[mode]
    return modes


def _link_frames(mech: Mechanism) -> tuple[np.ndarray, np.ndarray, float]:
    """Every moving link's frame in the drawn configuration (origin at its first joint,
    x axis towards its first other joint) and the mechanism's size."""
    moving = mech.moving_links
    origin0 = np.zeros((len(moving), 2))
    angle0 = np.zeros(len(moving))
    allpts = np.array([j.point for j in mech.joints] + [p.at for p in mech.points.values()]
                      + [np.asarray(j.attrs["anchor"], float) for j in mech.joints if j.type == "belt"])
    scale = float(max(np.ptp(allpts, axis=0).max(), 1e-9)) if len(allpts) > 1 else 1.0
    for i, name in enumerate(moving):
        # a belt's point (the pulley centre) is on its second link; its first has the anchor
        pts = [np.asarray(j.attrs["anchor"], float) if j.type == "belt" and j.links[0] == name else j.point
               for j in mech.joints_of(name)]
        origin0[i] = pts[0]
        d = next((p - pts[0] for p in pts[1:] if math.hypot(*(p - pts[0])) > 1e-12 * scale), (0.0, 0.0))
        angle0[i] = np.arctan2(d[1], d[0])  # towards the first other joint point away from the origin
    return origin0, angle0, scale


class _Builder:
    """The constraints, drivers, extra unknowns and notes of :func:`build_system`, joint by
    joint."""

    def __init__(self, partial: PlanarSystem, q0: np.ndarray, modes: dict, prescribed: tuple, src: str) -> None:
        self.partial, self.q0, self.modes, self.prescribed, self.src = partial, q0, modes, prescribed, src
        self.mech = partial.mech
        self.cons: list[Con] = []
        self.drivers: list[Driver] = []
        self.notes: list[str] = []
        self.extra_q: list[float] = []

    def add_driver(self, j: Joint, typ: str, value: float, role: str) -> int:
        self.drivers.append(Driver(j.id, typ, value, role))
        return len(self.drivers) - 1

    def angle(self, b: int, a: int) -> float:
        """``phi_b - phi_a`` in the drawn configuration."""
        p, q0 = self.partial, self.q0[None]
        return float(p.pose(q0, b)[1][0] - p.pose(q0, a)[1][0])

    def add(self, j: Joint) -> None:
        getattr(self, "_" + j.type)(j)

    def _R(self, j: Joint) -> None:
        a_name, b_name = j.links
        idx, loc = self.partial.index, self.partial.to_local
        a, b = idx(a_name), idx(b_name)
        self.cons.append(Con("R", j.id, 2, a, b, sa=loc(a_name, j.point), sb=loc(b_name, j.point), role="pair"))
        if j.actuated:
            k = self.add_driver(j, "R", self.angle(b, a), "drive")
            self.cons.append(Con("angle", j.id, 1, a, b, driver=k, role="drive"))

    def _P(self, j: Joint) -> None:
        a_name, b_name = j.links
        p = self.partial
        a, b = p.index(a_name), p.index(b_name)
        u = _axis(j)
        u_loc = p.to_local_dir(a_name, u)
        n_loc = np.array([-u_loc[1], u_loc[0]])
        self.cons.append(Con("angle", j.id, 1, a, b, c0=self.angle(b, a), role="rotation"))
        self.cons.append(Con("line", j.id, 1, a, b, sa=p.to_local(a_name, j.point), sb=p.to_local(b_name, j.point),
                             w=n_loc, role="pair"))
        o_a = np.zeros(2) if a < 0 else p.origin0[a]
        s0 = float(u @ (j.point - o_a))
        mode = self.modes.get(j.id)
        if mode is None:
            mode = "active" if j.actuated else None
        if mode == "active" or (mode == "passive" and j.id in self.prescribed):
            k = self.add_driver(j, "P", s0, "drive" if mode == "active" else "prescribed")
            self.cons.append(Con("line", j.id, 1, a, b, sa=np.zeros(2), sb=p.to_local(b_name, j.point), w=u_loc,
                                 driver=k, role="drive"))
        elif mode == "locked":
            self.cons.append(Con("line", j.id, 1, a, b, sa=np.zeros(2), sb=p.to_local(b_name, j.point), w=u_loc,
                                 c0=s0, role="lock"))
        elif j.actuated and mode == "passive":
            self.notes.append(f"joint {j.id} is marked actuated but its VLL is free (passive)")

    def _gear(self, j: Joint) -> None:
        a_name, b_name = j.links
        mech, idx = self.mech, self.partial.index
        carriers = [c for c in mech.link_names
                    if any(x.type == "R" and set(x.links) == {c, a_name} for x in mech.joints)
                    and any(x.type == "R" and set(x.links) == {c, b_name} for x in mech.joints)]
        if not carriers:
            raise MechsynInputError(f"gear pair {j.id}: no link carries both gears' axes", source=self.src,
                                    field=f"joints.{j.id}", hint="join both gears by R pairs to one carrier link")
        cname = carriers[0]
        ra = next(x for x in mech.joints if x.type == "R" and set(x.links) == {cname, a_name})
        rb = next(x for x in mech.joints if x.type == "R" and set(x.links) == {cname, b_name})
        if j.ratio is not None:
            ratio = float(j.ratio)
        else:
            r1 = float(np.linalg.norm(j.point - ra.point))
            r2 = float(np.linalg.norm(j.point - rb.point))
            if r2 <= 1e-12 * (r1 + r2):
                raise MechsynInputError(f"gear pair {j.id}: the pitch point is on a gear's axis",
                                        source=self.src, field=f"joints.{j.id}.point", hint="give ratio")
            between = (j.point - ra.point) @ (j.point - rb.point) < 0
            ratio = -r1 / r2 if between else r1 / r2
        a, b, c = idx(a_name), idx(b_name), idx(cname)
        q0a = self.q0[None]
        pa_, pb_, pc_ = (self.partial.pose(q0a, i)[1][0] for i in (a, b, c))
        self.cons.append(Con("gear", j.id, 1, a, b, c=c, k=ratio,
                             c0=float((pb_ - pc_) - ratio * (pa_ - pc_)), role="pair"))

    def _cam(self, j: Joint) -> None:
        a_name, b_name = j.links
        mech, idx, loc = self.mech, self.partial.index, self.partial.to_local
        a, b = idx(a_name), idx(b_name)
        profile = j.attrs.get("profile")
        if profile is None:
            raise MechsynInputError(
                f"cam joint {j.id} has no profile", source=self.src, field=f"joints.{j.id}.profile",
                hint="add e.g. profile: {center: [0, 0], radius: 1}, or a polar function r(t), or a list "
                     f"of points [[1, 0], [0, 1], [-1, 0], [0, -1]] on the cam link {a_name}")
        others = [x for x in mech.joints_of(b_name) if x.id != j.id and x.type == "R"]
        if others:
            centre = others[0].point
            rho = float(np.linalg.norm(centre - j.point))
        else:
            centre, rho = j.point, 0.0
        tvar = len(self.q0) + len(self.extra_q)
        curve = cam_curve(profile, loc(a_name, centre), rho, loc(a_name, j.point),
                           lambda p, _a=a_name: loc(_a, p), self.src, j.id)
        self.extra_q.append(curve.closest(loc(a_name, centre)))
        self.cons.append(Con("curve", j.id, 2, a, b, sb=loc(b_name, centre), tvar=tvar, curve=curve, role="pair"))
        if others and len(mech.joints_of(b_name)) == 2 and not any(
                p.link == b_name for p in mech.points.values()):
            f = idx(others[0].other(b_name))
            self.cons.append(Con("angle", j.id, 1, f, b, c0=self.angle(b, f), role="idle"))
            self.notes.append(f"roller {b_name}: its spin about {others[0].id} is an idle mobility, held fixed")

    def _belt(self, j: Joint) -> None:
        a_name, b_name = j.links
        p = self.partial
        a, b = p.index(a_name), p.index(b_name)
        sa, sb = p.to_local(a_name, np.asarray(j.attrs["anchor"], float)), p.to_local(b_name, j.point)
        con = Con("belt", j.id, 1, a, b, sa=sa, sb=sb, radius=float(j.attrs["radius"]),
                  sigma=BELT_WRAPS[j.attrs["wrap"]], role="pair")
        D = j.point - np.asarray(j.attrs["anchor"], float)
        con = replace(con, ref=float(p.pose(self.q0[None], b)[1][0] - np.arctan2(D[1], D[0])))
        eqs = _Equations(p, [(0, con)])
        c0 = float(eqs.kinds[0].residual(_At(p, eqs, self.q0[None]), None)[0, 0])
        self.cons.append(replace(con, c0=c0))
        if not any(x.type == "R" and set(x.links) & {b_name} and x.id != j.id
                   and np.linalg.norm(x.point - j.point) < 1e-9 * p.scale for x in self.mech.joints):
            self.notes.append(f"belt {j.id}: the pulley centre is on no R pair of {b_name} "
                              "(a pulley usually turns on its carrier there)")


def points_state_array(q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, idx: np.ndarray, s: np.ndarray) -> np.ndarray:
    """:meth:`PlanarSystem.points_state` as one array (3, m, N, 2): the positions,
    velocities and accelerations of the points ``s`` (m, 2; local) of the links ``idx``
    (m,) over the configurations ``q`` and their rates ``qd``, ``qdd`` (N, n), so that a
    caller masks all three at once.

    Examples
    --------
    >>> import numpy as np
    >>> q = np.array([[1.0, 2.0, np.pi / 2]]); qd = np.array([[0.0, 0.0, 1.0]]); qdd = np.zeros((1, 3))
    >>> (points_state_array(q, qd, qdd, np.array([0]), np.array([[1.0, 0.0]])).round(12)[:, 0, 0] + 0.0).tolist()
    [[1.0, 3.0], [-1.0, 0.0], [0.0, -1.0]]
    """
    m, N, qT, qdT, qddT = len(idx), q.shape[0], q.T, qd.T, qdd.T  # q.T (n, N): rows are coordinates
    if m == 1:  # one point: views of its link's rows, its local point as two floats
        i = 3 * int(idx[0])
        xy, a, sx, sy = (slice(i, i + 2), None), slice(i + 2, i + 3), float(s[0, 0]), float(s[0, 1])
    else:
        i3 = 3 * np.asarray(idx)
        xy, a, sx, sy = np.stack([i3, i3 + 1]), i3 + 2, s[:, 0, None], s[:, 1, None]
    cs, R = np.empty((2, m, N)), np.empty((3, m, N))  # cos, sin; -ay, ax, ay: perp(A s) is R[:2], A s R[1:]
    np.cos(qT[a], out=cs[0])
    np.sin(qT[a], out=cs[1])
    X, Y = cs * sx, cs * sy  # (c sx, sn sx), (c sy, sn sy): the products of rotate
    np.subtract(X[0], Y[1], out=R[1])  # A(phi) s, as rotate
    np.add(X[1], Y[0], out=R[2])
    np.negative(R[2], out=R[0])
    w, al, out = qdT[a], qddT[a], np.empty((3, m, N, 2))
    T = out.transpose(0, 3, 1, 2)  # (3, 2, m, N): x and y as rows
    np.add(qT[xy], R[1:], out=T[0])
    np.add(qdT[xy], w * R[:2], out=T[1])
    np.subtract(qddT[xy] + al * R[:2], (w ** 2) * R[1:], out=T[2])
    return out
