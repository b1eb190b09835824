"""Exact (precision-position) synthesis of four-bars: Freudenstein and Burmester.

Every produced linkage is verified by simulating it with the closed-form position
analysis of :mod:`mechsyn.synthesis.fourbar` on one assembly branch, and checked for

* **branch defect**: the precision positions need different assembly branches;
* **order defect**: the crank cannot pass through the positions in the given order by a
  monotonic motion of less than one turn that stays assembled (no dead position crossed).

Angles are radians here (the CLI converts degrees).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.fourbar import (
    TWO_PI,
    arc_cos_extremes,
    crank_cos_range,
    fourbar_position,
    grashof_excess,
)


def _wrap(a):
    return np.angle(np.exp(1j * np.asarray(a, float)))


def grashof_type(r1: float, r2: float, r3: float, r4: float) -> str:
    """Grashof classification of a four-bar (ground ``r1``, input ``r2``, output ``r4``)."""
    ex = float(grashof_excess(r1, r2, r3, r4))
    s = min(r1, r2, r3, r4)
    if ex > 1e-12 * max(r1, r2, r3, r4):
        return "non-Grashof (triple rocker)"
    if abs(ex) <= 1e-12 * max(r1, r2, r3, r4):
        return "change point"
    if s == r1:
        return "Grashof drag-link (double crank)"
    if s == r2:
        return "Grashof crank-rocker"
    if s == r4:
        return "Grashof rocker-crank"
    return "Grashof double rocker"


def order_defect(r1, r2, r3, r4, theta2: np.ndarray) -> tuple[bool, int]:
    """Whether the crank can visit ``theta2`` in order, monotonically, staying assembled.

    Tries counter-clockwise then clockwise motion (increments taken modulo one turn, the
    whole motion less than a turn); along each sweep ``cos(theta2)`` must stay within
    the assembly interval of :func:`crank_cos_range`. Returns ``(defect, direction)``
    with ``direction`` +1 (ccw) or -1 (cw) for the motion that works (0 when none).
    """
    th = np.asarray(theta2, float)
    c_lo, c_hi = crank_cos_range(r1, r2, r3, r4)
    for direction in (1, -1):
        inc = np.mod(direction * np.diff(th), TWO_PI)
        if inc.sum() > TWO_PI + 1e-9:
            continue
        cmin, cmax = arc_cos_extremes(th[:-1], direction * inc)
        if np.all(cmin >= c_lo - 1e-12) and np.all(cmax <= c_hi + 1e-12):
            return False, direction
    return True, 0


# ------------------------------------------------------------------ Freudenstein ----

@dataclass
class FunctionSynthesisResult:
    """Four-bar from Freudenstein's equation (lengths; angles from the ground line)."""

    r1: float
    r2: float
    r3: float
    r4: float
    K: np.ndarray
    phi: np.ndarray          # crank angles of the linkage at the precision positions
    psi: np.ndarray          # required rocker angles of the linkage
    psi_simulated: np.ndarray
    branch: int
    max_error: float         # max |psi_simulated - psi| [rad]
    branch_defect: bool
    order_defect: bool
    grashof: str
    crank_offset: float = 0.0   # pi when the solved crank length came out negative
    rocker_offset: float = 0.0  # pi when the solved rocker length came out negative
    notes: list[str] = field(default_factory=list)

    @property
    def design(self) -> dict[str, float]:
        return {"r1": self.r1, "r2": self.r2, "r3": self.r3, "r4": self.r4}

    @property
    def verified(self) -> bool:
        """Simulation meets every precision position (1e-8 rad) with neither a branch nor an
        order defect."""
        return bool(self.max_error < 1e-8 and not self.branch_defect and not self.order_defect)

    def to_dict(self) -> dict[str, Any]:
        """Design, Freudenstein coefficients, the angles in degrees, defects and notes
        (``mechsyn synth function --json``)."""
        return {"design": self.design, "K": self.K, "branch": self.branch, "phi_deg": np.degrees(self.phi),
                "psi_deg": np.degrees(self.psi), "psi_simulated_deg": np.degrees(self.psi_simulated),
                "max_error_deg": np.degrees(self.max_error), "branch_defect": self.branch_defect,
                "order_defect": self.order_defect, "grashof": self.grashof, "notes": self.notes,
                "verified": self.verified}


def freudenstein_coefficients(phi, psi) -> np.ndarray:
    """Solve Freudenstein's equation at three precision positions.

    ``K1 cos(psi_i) - K2 cos(phi_i) + K3 = cos(phi_i - psi_i)``, ``i = 1..3`` (Freudenstein
    1955; Norton, *Design of Machinery*, eq. 5.34), a 3x3 linear system in ``K``.
    """
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    if phi.shape != (3,) or psi.shape != (3,):
        raise MechsynInputError("Freudenstein's 3-position synthesis needs exactly 3 angle pairs",
                                field="phi/psi")
    A = np.column_stack([np.cos(psi), -np.cos(phi), np.ones(3)])
    rhs = np.cos(phi - psi)
    if abs(np.linalg.det(A)) < 1e-12:
        raise MechsynInputError("the three positions give a singular Freudenstein system",
                                field="phi/psi", hint="use three distinct, well separated positions")
    return np.linalg.solve(A, rhs)


def freudenstein_synthesis(phi, psi, ground: float = 1.0) -> FunctionSynthesisResult:
    """Four-bar generating ``psi_i = f(phi_i)`` at three positions, verified by simulation.

    Angles (radians) are Freudenstein's: the crank angle ``phi`` is the direction of the
    crank from its frame pivot A, the rocker angle ``psi`` the direction of the rocker from
    its frame pivot D (D to C), both counter-clockwise from the ground line, which runs from
    A to D (the +x axis of the written mechanism file).

    With ground ``d``: crank ``a = d / K1``, rocker ``c = d / K2``,
    coupler ``b = sqrt(a^2 + c^2 + d^2 - 2 a c K3)`` (from ``K3 = (a^2 - b^2 + c^2 + d^2)/(2ac)``).
    A negative ``a`` (or ``c``) means the link points the other way: its length is ``|a|``
    and its angles are offset by ``pi``. The linkage is then simulated at the crank angles
    on the branch of the first position and the rocker angles compared.
    """
    phi, psi = np.asarray(phi, float), np.asarray(psi, float)
    K = freudenstein_coefficients(phi, psi)
    d = float(ground)
    notes = []
    if abs(K[0]) < 1e-12 or abs(K[1]) < 1e-12:
        raise MechsynInputError("the positions need an infinitely long crank or rocker", field="phi/psi")
    a, c = d / K[0], d / K[1]
    b2 = a * a + c * c + d * d - 2 * a * c * K[2]
    if b2 <= 0:
        raise MechsynInputError("no real coupler length for these positions (b^2 <= 0)",
                                field="phi/psi", hint="change the positions or their spacing")
    b = float(np.sqrt(b2))
    crank_off = np.pi if a < 0 else 0.0
    rocker_off = np.pi if c < 0 else 0.0
    if a < 0:
        notes.append("crank length came out negative: crank angles are phi + 180 deg")
    if c < 0:
        notes.append("rocker length came out negative: rocker angles are psi + 180 deg")
    a, c = abs(a), abs(c)
    phi_l, psi_l = phi + crank_off, psi + rocker_off
    sims = {}
    for br in (-1, 1):
        pose = fourbar_position(d, a, b, c, phi_l, branch=br)
        sims[br] = (pose.theta4, pose.assembled)
    # the branch is the one matching the first position
    err1 = {br: abs(_wrap(sims[br][0][0] - psi_l[0])) if sims[br][1][0] else np.inf for br in sims}
    branch = min(err1, key=err1.get)
    psi_sim, ok = sims[branch]
    err = np.abs(_wrap(psi_sim - psi_l))
    err = np.where(ok, err, np.inf)
    other = -branch
    branch_defect = bool(np.any(err > 1e-6) and np.all(
        np.where(err > 1e-6, np.abs(_wrap(sims[other][0] - psi_l)) < 1e-6, True)))
    od, _ = order_defect(d, a, b, c, phi_l)
    return FunctionSynthesisResult(
        r1=d, r2=a, r3=b, r4=c, K=K, phi=phi_l, psi=psi_l, psi_simulated=psi_sim, branch=branch,
        max_error=float(np.max(err)), branch_defect=branch_defect, order_defect=od,
        grashof=grashof_type(d, a, b, c), crank_offset=crank_off, rocker_offset=rocker_off, notes=notes,
    )


def chebyshev_spacing(x0: float, xf: float, n: int = 3) -> np.ndarray:
    """Chebyshev precision points ``x_j = (x0+xf)/2 - (xf-x0)/2 cos((2j-1) pi / (2n))``."""
    j = np.arange(1, n + 1)
    return 0.5 * (x0 + xf) - 0.5 * (xf - x0) * np.cos((2 * j - 1) * np.pi / (2 * n))


# -------------------------------------------------------------------- Burmester ----

def _rot(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s], [s, c]])


def _poses(poses) -> np.ndarray:
    P = np.asarray(poses, float)
    if P.ndim != 2 or P.shape[1] != 3 or not 3 <= len(P) <= 5:
        raise MechsynInputError("motion generation needs 3, 4 or 5 poses [x, y, angle]", source="poses")
    return P


def burmester_matrix(poses, m) -> np.ndarray:
    """Rows ``j = 2..N`` of the Burmester condition, linear in the circle point ``p``.

    A body point ``p`` (coupler frame) has positions ``R_j p + d_j``; they lie on a circle
    about the fixed centre ``m`` iff for every ``j``
    ``2 [(d_j - m)^T R_j - (d_1 - m)^T R_1] p + |d_j|^2 - |d_1|^2 - 2 (d_j - d_1) . m = 0``
    (the ``|p|^2`` terms cancel). Returns ``(..., N-1, 3)`` acting on ``[p, 1]``; each row is
    linear in ``m``, so for four poses ``det = 0`` is the cubic centre-point curve.
    """
    P = _poses(poses)
    m = np.asarray(m, float)
    d = P[:, :2]
    R = np.stack([_rot(a) for a in P[:, 2]])
    rows = []
    for j in range(1, len(P)):
        gj = (d[j] - m) @ R[j] - (d[0] - m) @ R[0]  # (..., 2)
        const = d[j] @ d[j] - d[0] @ d[0] - 2 * (m @ (d[j] - d[0]))
        rows.append(np.concatenate([2 * gj, np.asarray(const)[..., None]], axis=-1))
    return np.stack(rows, axis=-2)


def circle_point(poses, m) -> np.ndarray:
    """The circle point (coupler frame) belonging to centre point ``m`` (least squares)."""
    M = burmester_matrix(poses, m)
    p, *_ = np.linalg.lstsq(M[:, :2], -M[:, 2], rcond=None)
    return p


def center_point(poses, p) -> np.ndarray:
    """Centre of the circle through the first three positions of body point ``p``."""
    P = _poses(poses)
    pts = np.array([_rot(a) @ np.asarray(p, float) + P[j, :2] for j, a in enumerate(P[:, 2])])[:3]
    (x1, y1), (x2, y2), (x3, y3) = pts
    A = np.array([[x2 - x1, y2 - y1], [x3 - x1, y3 - y1]])
    rhs = 0.5 * np.array([x2**2 - x1**2 + y2**2 - y1**2, x3**2 - x1**2 + y3**2 - y1**2])
    if abs(np.linalg.det(A)) < 1e-12:
        raise MechsynInputError("the three positions of this circle point are collinear", source="circle point")
    return np.linalg.solve(A, rhs)


def center_point_curve(poses, n_dir: int = 360, base=None) -> tuple[np.ndarray, np.ndarray]:
    """Points of the centre-point curve of four poses, and their circle points.

    Along every line ``m = b + t (cos beta, sin beta)`` through the base point ``b`` (the
    mean of the pose origins) ``det M(m)`` is a cubic in ``t``, found exactly from four
    samples; its real roots are curve points. Vectorised over ``n_dir`` directions.
    """
    P = _poses(poses)
    if len(P) != 4:
        raise MechsynInputError("the centre-point curve needs exactly 4 poses", source="poses")
    b = P[:, :2].mean(axis=0) if base is None else np.asarray(base, float)
    scale = np.ptp(P[:, :2], axis=0).max() + 1.0
    beta = np.linspace(0, np.pi, n_dir, endpoint=False)
    u = np.stack([np.cos(beta), np.sin(beta)], axis=-1)
    ts = np.array([-1.0, -1 / 3, 1 / 3, 1.0]) * scale
    V = np.vander(ts, 4)
    dets = np.stack([np.linalg.det(burmester_matrix(P, b + t * u)) for t in ts], axis=0)  # (4, n_dir)
    coef = np.linalg.solve(V, dets)  # (4, n_dir) highest power first
    pts = []
    for k in range(n_dir):
        roots = np.roots(coef[:, k]) if np.any(coef[:, k] != 0) else np.array([])
        for r in roots[np.abs(roots.imag) < 1e-9 * (1 + np.abs(roots.real))].real:
            pts.append(b + r * u[k])
    M = np.array(pts)
    Ps = np.array([circle_point(P, m) for m in M])
    return M, Ps


def burmester_points(poses) -> tuple[np.ndarray, np.ndarray]:
    """Burmester point pairs for five poses: centre points ``m`` (and circle points) whose
    five body-point positions lie on one circle (up to four real solutions).

    Intersections of the centre-point curves of poses 1234 and 1235, refined by
    least squares on both determinants; the poles (degenerate common points) are removed
    and each solution is checked on all five poses.
    """
    P = _poses(poses)
    if len(P) != 5:
        raise MechsynInputError("Burmester points need exactly 5 poses", source="poses")
    from scipy.optimize import least_squares

    Pa, Pb = P[[0, 1, 2, 3]], P[[0, 1, 2, 4]]
    curve, _ = center_point_curve(Pa, n_dir=720)
    scale = np.ptp(P[:, :2], axis=0).max() + 1.0

    def eqs(m):
        return [np.linalg.det(burmester_matrix(Pa, m)), np.linalg.det(burmester_matrix(Pb, m))]

    g = np.array([np.linalg.det(burmester_matrix(Pb, m)) for m in curve])
    order = np.argsort(np.abs(g))
    sols: list[np.ndarray] = []
    for i in order[:200]:
        res = least_squares(eqs, curve[i], xtol=1e-14, ftol=1e-14, gtol=1e-14)
        m = res.x
        p = circle_point(P, m)
        pts = np.array([_rot(a) @ p + P[j, :2] for j, a in enumerate(P[:, 2])])
        rad = np.linalg.norm(pts - m, axis=1)
        if np.ptp(rad) > 1e-7 * max(1.0, rad.mean()) or rad.mean() < 1e-6 * scale:
            continue  # not a solution or a degenerate (pole) one
        if all(np.linalg.norm(m - s) > 1e-6 * scale for s in sols):
            sols.append(m)
        if len(sols) >= 4:
            break
    M = np.array(sols).reshape(-1, 2)
    return M, np.array([circle_point(P, m) for m in M]).reshape(-1, 2)


@dataclass
class MotionSynthesisResult:
    """A four-bar from two Burmester dyads, verified by simulation."""

    O2: np.ndarray        # crank ground pivot (centre point a)
    O4: np.ndarray        # rocker ground pivot (centre point b)
    pA: np.ndarray        # crank moving pivot in the coupler frame (circle point a)
    pB: np.ndarray        # rocker moving pivot in the coupler frame (circle point b)
    r1: float
    r2: float
    r3: float
    r4: float
    theta0: float
    theta2: np.ndarray    # crank angles (from the ground line) at the poses
    branch: int
    position_error: float  # max distance between simulated and required coupler-frame origin
    angle_error: float     # max |simulated - required coupler angle| [rad]
    branch_defect: bool
    order_defect: bool
    direction: int
    grashof: str
    min_transmission_deg: float

    @property
    def ok(self) -> bool:
        return (not self.branch_defect and not self.order_defect and self.position_error < 1e-6 * max(1.0, self.r1)
                and self.angle_error < 1e-6)

    def design(self) -> dict[str, float]:
        """Design in the path-case variables: the coupler-frame origin as the coupler point."""
        u = self.pB - self.pA
        L = np.linalg.norm(u)
        u = u / L
        n = np.array([-u[1], u[0]])
        return {"x0": float(self.O2[0]), "y0": float(self.O2[1]), "theta0": float(self.theta0),
                "r1": self.r1, "r2": self.r2, "r3": self.r3, "r4": self.r4,
                "rcx": float(-self.pA @ u), "rcy": float(-self.pA @ n)}


def dyad_fourbar(poses, m_a, p_a, m_b, p_b) -> MotionSynthesisResult:
    """Assemble the four-bar of dyads ``(m_a, p_a)`` (crank) and ``(m_b, p_b)`` and verify it.

    The linkage is simulated at the crank angles of the poses on the branch of pose 1;
    the coupler frame is rebuilt from the simulated joints ``A``, ``B`` and compared with
    the required poses (position and angle errors), then checked for branch and order
    defects.
    """
    P = _poses(poses)
    m_a, p_a, m_b, p_b = (np.asarray(v, float) for v in (m_a, p_a, m_b, p_b))
    R = [_rot(a) for a in P[:, 2]]
    A = np.array([R[j] @ p_a + P[j, :2] for j in range(len(P))])
    B = np.array([R[j] @ p_b + P[j, :2] for j in range(len(P))])
    g = m_b - m_a
    r1 = float(np.linalg.norm(g))
    theta0 = float(np.arctan2(g[1], g[0]))
    r2 = float(np.linalg.norm(A[0] - m_a))
    r3 = float(np.linalg.norm(p_b - p_a))
    r4 = float(np.linalg.norm(B[0] - m_b))
    theta2 = np.arctan2(A[:, 1] - m_a[1], A[:, 0] - m_a[0]) - theta0
    # branch of each pose: B left of A -> O4 is branch -1
    ao4 = m_b - A
    ab = B - A
    cross = ao4[:, 0] * ab[:, 1] - ao4[:, 1] * ab[:, 0]
    branches = np.where(cross > 0, -1, 1)
    branch = int(branches[0])
    branch_defect = bool(np.any(branches != branch))
    pose = fourbar_position(r1, r2, r3, r4, theta2, branch=branch, x0=m_a[0], y0=m_a[1], theta0=theta0)
    ang0 = np.arctan2(*(p_b - p_a)[::-1])
    with np.errstate(invalid="ignore"):
        alpha = np.arctan2(pose.B[:, 1] - pose.A[:, 1], pose.B[:, 0] - pose.A[:, 0]) - ang0
        origin = pose.A - np.einsum("jik,k->ji", np.stack([_rot(a) for a in alpha]), p_a)
    pos_err = np.linalg.norm(origin - P[:, :2], axis=1)
    ang_err = np.abs(_wrap(alpha - P[:, 2]))
    pos_err = np.where(pose.assembled, pos_err, np.inf)
    ang_err = np.where(pose.assembled, ang_err, np.inf)
    od, direction = order_defect(r1, r2, r3, r4, theta2)
    mu = np.degrees(np.nanmin(np.minimum(pose.mu, np.pi - pose.mu))) if np.any(pose.assembled) else 0.0
    return MotionSynthesisResult(
        O2=m_a, O4=m_b, pA=p_a, pB=p_b, r1=r1, r2=r2, r3=r3, r4=r4, theta0=theta0, theta2=theta2,
        branch=branch, position_error=float(np.max(pos_err)), angle_error=float(np.max(ang_err)),
        branch_defect=branch_defect, order_defect=od, direction=direction,
        grashof=grashof_type(r1, r2, r3, r4), min_transmission_deg=float(mu),
    )


def motion_synthesis(poses, circle_points=None, center_points=None, max_pairs: int = 4000,
                     seed: int = 0) -> list[MotionSynthesisResult]:
    """Four-bars guiding a body through 3, 4 or 5 poses, best first, defect-free first.

    * 3 poses: give two ``circle_points`` (coupler frame; centres = circumcentres) or two
      ``center_points`` (ground; circle points solved); default: circle points at the
      body origin +- the pose spread along the body x axis.
    * 4 poses: candidate dyads sampled on the centre-point curve; pairs are assembled,
      simulated and ranked (no defect first, then by the smallest transmission angle along
      the motion, larger is better).
    * 5 poses: the (up to four) Burmester point pairs.

    Examples
    --------
    >>> import numpy as np, mechsyn as ms
    >>> poses = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, np.radians(20)], [2.0, 0.6, np.radians(45)]])
    >>> sols = ms.motion_synthesis(poses, circle_points=np.array([[-0.5, 0.0], [0.5, 0.0]]))
    >>> len(sols), bool(sols[0].position_error < 1e-6)
    (1, True)
    """
    P = _poses(poses)
    n = len(P)
    scale = np.ptp(P[:, :2], axis=0).max() + 1.0
    if n == 3:
        if center_points is not None:
            ms = [np.asarray(m, float) for m in center_points]
            ps = [circle_point(P, m) for m in ms]
        else:
            ps = [np.asarray(p, float) for p in (circle_points if circle_points is not None
                                                  else ([-0.5 * scale, 0.0], [0.5 * scale, 0.0]))]
            ms = [center_point(P, p) for p in ps]
        if len(ms) != 2:
            raise MechsynInputError("give exactly two circle points or two centre points", source="poses")
        return [dyad_fourbar(P, ms[0], ps[0], ms[1], ps[1])]
    if n == 4:
        M, Ps = center_point_curve(P)
        keep = np.all(np.isfinite(M), axis=1) & (np.linalg.norm(M - P[:, :2].mean(0), axis=1) < 20 * scale)
        M, Ps = M[keep], Ps[keep]
        keep = np.linalg.norm(Ps, axis=1) < 20 * scale
        M, Ps = M[keep], Ps[keep]
        idx = np.arange(len(M))
        rng = np.random.default_rng(seed)
        if len(idx) > 120:
            idx = np.sort(rng.choice(idx, 120, replace=False))
        pairs = [(i, j) for i in idx for j in idx if i != j]
        if len(pairs) > max_pairs:
            sel = rng.choice(len(pairs), max_pairs, replace=False)
            pairs = [pairs[k] for k in np.sort(sel)]
    else:
        M, Ps = burmester_points(P)
        pairs = [(i, j) for i in range(len(M)) for j in range(len(M)) if i != j]
    out = []
    for i, j in pairs:
        if np.linalg.norm(M[i] - M[j]) < 1e-6 * scale or np.linalg.norm(Ps[i] - Ps[j]) < 1e-6 * scale:
            continue
        out.append(dyad_fourbar(P, M[i], Ps[i], M[j], Ps[j]))
    out.sort(key=lambda r: (not r.ok, -r.min_transmission_deg, r.r1 + r.r2 + r.r3 + r.r4))
    return out


def to_jsonable_motion(r: MotionSynthesisResult) -> dict[str, Any]:
    return {"O2": r.O2, "O4": r.O4, "circle_point_A": r.pA, "circle_point_B": r.pB, "r1": r.r1, "r2": r.r2,
            "r3": r.r3, "r4": r.r4, "theta0_deg": np.degrees(r.theta0), "theta2_deg": np.degrees(r.theta2),
            "branch": r.branch, "position_error": r.position_error, "angle_error_deg": np.degrees(r.angle_error),
            "branch_defect": r.branch_defect, "order_defect": r.order_defect, "grashof": r.grashof,
            "min_transmission_angle_deg": r.min_transmission_deg, "verified": r.ok}
