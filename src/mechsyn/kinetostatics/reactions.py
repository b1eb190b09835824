"""Kinetostatics: joint reactions and balancing forces/moments from the constraint equations.

With the links' D'Alembert loads gathered into the generalised force ``Q'`` (applied
forces and moments, gravity, inertia forces ``-m a_G`` at the centres of mass and
inertia moments ``-J_G alpha``), the Lagrange multipliers of the constraints solve

    Phi_q^T lambda = Q'                       (Haug 1989, eq. 6.6.2, with q'' known)

and the constraint force of every joint on its links is ``-Phi_q^T lambda`` restricted to
that joint's rows. A driver's multiplier gives the balancing moment (R) or force (P)
the actuator applies to the joint's second link: ``tau = -lambda``. The balance of
power ``sum tau_k u'_k + sum(applied + inertia power) = 0`` (virtual work) holds by
construction and is checked independently in the tests.

Redundant constraints make the reactions statically indeterminate: then the
least-squares (minimum-norm) multipliers are reported and ``indeterminate`` is set.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics.plane import cos_sin, cross, rotate
from mechsyn.kinematics.system import PlanarSystem

__all__ = ["MassModel", "mass_model", "Loads", "loads_from_file", "kinetostatics", "Reactions"]


@dataclass(frozen=True)
class MassModel:
    """Mass, local centre of mass and inertia about the centre of mass of each moving link."""

    mass: np.ndarray        # (nl,)
    com: np.ndarray         # (nl, 2) local coordinates
    inertia: np.ndarray     # (nl,)


def mass_model(S: PlanarSystem) -> MassModel:
    """From the file's ``links:`` objects (mass, com in the assembled configuration, inertia).

    A link without ``com`` has its centre of mass at the mean of its joint points.
    """
    nl = len(S.links)
    m = np.zeros(nl)
    c = np.zeros((nl, 2))
    J = np.zeros(nl)
    for i, name in enumerate(S.links):
        attrs = S.mech.link(name).attrs
        m[i] = float(attrs.get("mass") or 0.0)
        J[i] = float(attrs.get("inertia") or 0.0)
        com = attrs.get("com")
        if com is None:
            com = np.mean([j.point for j in S.mech.joints_of(name)], axis=0)
        com = np.asarray(com, float)
        if com.shape != (2,):
            raise MechsynInputError(f"link {name}: com must be [x, y]", source=S.mech.source,
                                    field=f"links.{name}.com")
        c[i] = S.to_local(name, com)
    return MassModel(m, c, J)


@dataclass(frozen=True)
class Loads:
    """External loads: forces (global directions) at local points, and moments, per link."""

    link: np.ndarray        # (k,) link index
    at: np.ndarray          # (k, 2) local point
    force: np.ndarray       # (k, 2)
    moment: np.ndarray      # (k,)


def loads_from_file(S: PlanarSystem, mm: MassModel) -> Loads:
    items = S.mech.attrs.get("loads") or []
    link, at, force, moment = [], [], [], []
    for ld in items:
        name = ld["link"]
        if name == S.mech.ground:
            continue  # loads on the frame do no work and need no balancing
        i = S.index(name)
        link.append(i)
        at.append(S.to_local(name, np.asarray(ld["at"], float)) if "at" in ld else mm.com[i])
        force.append(ld.get("force", [0.0, 0.0]))
        moment.append(ld.get("moment", 0.0))
    return Loads(np.array(link, int), np.array(at, float).reshape(-1, 2),
                 np.array(force, float).reshape(-1, 2), np.array(moment, float))


@dataclass
class Reactions:
    """Joint reactions and balancing efforts over N configurations.

    ``force[j]`` (N, 2): force exerted by the joint's first link on its second link;
    ``moment[j]`` (N,): the reaction moment about the joint point (P pairs; ~0 for R);
    ``effort[j]`` (N,): balancing moment (R input) or force (P input) applied by the
    actuator to the driven joint's second link.
    """

    force: dict[str, np.ndarray]
    moment: dict[str, np.ndarray]
    effort: dict[str, np.ndarray]
    effort_kind: dict[str, str]
    indeterminate: bool
    lam: np.ndarray = field(repr=False, default=None)
    #: belt pairs: tension of the straight run (N,); negative: the belt would have to
    #: push, so it goes slack and the computed motion does not happen.
    tension: dict[str, np.ndarray] = field(default_factory=dict)


def generalised_loads(S: PlanarSystem, q: np.ndarray, qdd: np.ndarray | None, qd: np.ndarray | None,
                      mm: MassModel, loads: Loads, gravity: np.ndarray) -> np.ndarray:
    """``Q'`` (N, n): applied loads, gravity and inertia (D'Alembert) per pose coordinate."""
    N = q.shape[0]
    Q = np.zeros((N, S.n))
    nl = len(S.links)
    for i in range(nl):
        r, phi = q[:, 3 * i:3 * i + 2], q[:, 3 * i + 2]
        c, s = cos_sin(phi)
        Ac = rotate(c, s, mm.com[i])
        F = np.broadcast_to(mm.mass[i] * gravity, (N, 2)).copy()
        M = np.zeros(N)
        if qdd is not None and (mm.mass[i] > 0 or mm.inertia[i] > 0):
            w = qd[:, 3 * i + 2]
            a, al = qdd[:, 3 * i:3 * i + 2], qdd[:, 3 * i + 2]
            aG = a + al[:, None] * np.stack([-Ac[:, 1], Ac[:, 0]], axis=1) - (w ** 2)[:, None] * Ac
            F -= mm.mass[i] * aG
            M -= mm.inertia[i] * al
        Q[:, 3 * i:3 * i + 2] += F
        Q[:, 3 * i + 2] += M + cross(Ac, F)
    for k in range(len(loads.link)):
        i = loads.link[k]
        phi = q[:, 3 * i + 2]
        c, s = cos_sin(phi)
        As = rotate(c, s, loads.at[k])
        F = np.broadcast_to(loads.force[k], (N, 2))
        Q[:, 3 * i:3 * i + 2] += F
        Q[:, 3 * i + 2] += loads.moment[k] + cross(As, F)
    return Q


def kinetostatics(S: PlanarSystem, q: np.ndarray, qd: np.ndarray | None = None, qdd: np.ndarray | None = None,
                  gravity: tuple[float, float] = (0.0, 0.0), mm: MassModel | None = None,
                  loads: Loads | None = None) -> Reactions:
    """Reactions in every joint and balancing efforts at the inputs (see the module doc).

    ``qd, qdd`` None: the static case (no inertia loads).
    """
    mm = mm or mass_model(S)
    loads = loads if loads is not None else loads_from_file(S, mm)
    N = q.shape[0]
    chunk = 20000
    if N > chunk:  # bounded memory: the Jacobians are (N, m, n)
        parts = [kinetostatics(S, q[k:k + chunk], None if qd is None else qd[k:k + chunk],
                               None if qdd is None else qdd[k:k + chunk], gravity, mm, loads)
                 for k in range(0, N, chunk)]
        cat = lambda name: {j: np.concatenate([getattr(p, name)[j] for p in parts])  # noqa: E731
                            for j in getattr(parts[0], name)}
        return Reactions(cat("force"), cat("moment"), cat("effort"), parts[0].effort_kind,
                         any(p.indeterminate for p in parts), np.concatenate([p.lam for p in parts]),
                         cat("tension"))
    ok = np.all(np.isfinite(q), axis=1)
    N = q.shape[0]
    lam = np.full((N, S.m), np.nan)
    idx = np.flatnonzero(ok)
    indeterminate = False
    J = np.zeros((N, S.m, S.n))
    if len(idx):
        qq = q[idx]
        Q = generalised_loads(S, qq, None if qdd is None else qdd[idx], None if qd is None else qd[idx],
                              mm, loads, np.asarray(gravity, float))
        J[idx] = Jq = S.jacobian(qq)  # (assembled once: the reactions below read its rows)
        JT = np.transpose(Jq, (0, 2, 1))
        if S.n == S.m:
            try:
                lam[idx] = np.linalg.solve(JT, Q[..., None])[..., 0]
            except np.linalg.LinAlgError:
                # singular positions (e.g. a flat, collinear linkage): the reactions are
                # not determined there; they stay NaN and the position counts as singular
                # (singular values of the dimensionless Jacobian: the same at any scale)
                sv = np.linalg.svd(S.unit_jacobian(Jq), compute_uv=False)
                regular = sv[:, -1] > 1e-12 * np.maximum(sv[:, 0], 1e-300)
                if np.any(regular):
                    lam[idx[regular]] = np.linalg.solve(JT[regular], Q[regular][..., None])[..., 0]
                ok[idx[~regular]] = False
        else:
            lam[idx] = np.einsum("nij,nj->ni", np.linalg.pinv(JT), Q)
        sv = np.linalg.svd(S.unit_jacobian(Jq[0]), compute_uv=False)
        indeterminate = bool(np.sum(sv > 1e-9 * sv.max()) < S.m)
    force, moment, effort, kinds = {}, {}, {}, {}
    rows_by_joint: dict[str, list[int]] = {}
    drive_rows: dict[str, int] = {}
    for row, con in S.blocks():
        if con.role in ("drive",):
            drive_rows[con.joint] = row
        else:
            rows_by_joint.setdefault(con.joint, []).extend(range(row, row + con.rows))
    for j in S.mech.joints:
        rows = rows_by_joint.get(j.id, [])
        a, b = (S.index(x) for x in j.links)
        side, sign = (b, 1.0) if b >= 0 else (a, -1.0)
        if rows:
            lam_j = np.where(ok[:, None], lam[:, rows], 0.0)
            g = -np.einsum("nr,nrc->nc", lam_j, J[:, rows, 3 * side:3 * side + 3])
            F, M_r = g[:, :2], g[:, 2]
            r = q[:, 3 * side:3 * side + 2]
            P = _joint_point(S, q, j.id, side)
            M_P = M_r - cross(P - r, F)
            F = sign * F
            M_P = sign * M_P
            F[~ok] = np.nan
            M_P[~ok] = np.nan
            force[j.id], moment[j.id] = F, M_P
        if j.id in drive_rows:
            effort[j.id] = -lam[:, drive_rows[j.id]]
            kinds[j.id] = "moment" if j.type == "R" else "force"
    tension = {}
    for row, con in S.blocks():
        if con.kind == "gear":
            _gear_tooth_force(S, con, q, force, moment)
        if con.kind == "belt":
            # the belt row's Jacobian is g (the unit run from anchor to tangent point) on the
            # pulley's link: the force there is -λ g, so the tension is λ
            tension[con.joint] = lam[:, row].copy()
    return Reactions(force, moment, effort, kinds, indeterminate, lam, tension)


def _gear_tooth_force(S: PlanarSystem, con, q: np.ndarray, force: dict, moment: dict) -> None:
    """Turn a gear pair's constraint couples into the tooth force at the pitch point.

    The ratio constraint ``(phi_b - phi_c) = k (phi_a - phi_c) + const`` only carries
    couples; physically the teeth push with a force ``F`` along the line of action
    (the joint's ``normal``, else the pitch-circle tangent) through the pitch point
    ``P``, with ``(P - O_b) x F`` equal to the couple on gear ``b``, and the axles carry
    ``-F`` more (gear ``b``) and ``+F`` more (gear ``a``). The totals on every link are
    unchanged.
    """
    j = S.mech.joint(con.joint)
    a_name, b_name = j.links
    c_name = S.mech.ground if con.c < 0 else S.links[con.c]
    axle = {}
    for g in (a_name, b_name):
        axle[g] = next(x for x in S.mech.joints if x.type == "R" and set(x.links) == {c_name, g})
    P = S.point(q, con.c, S.to_local(c_name, j.point))
    Oa = S.point(q, con.c, S.to_local(c_name, axle[a_name].point))
    Ob = S.point(q, con.c, S.to_local(c_name, axle[b_name].point))
    if j.normal is not None:
        n = rotate(*S.rotation(q, con.c), S.to_local_dir(c_name, j.normal))
    else:
        d = Ob - Oa
        n = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.linalg.norm(d, axis=1)[:, None]
    # the couple on gear b by gear a from the ratio constraint (the force part is zero)
    couple_b = moment[j.id]
    lever = cross(P - Ob, n)
    F = (couple_b / lever)[:, None] * n          # on gear b, by gear a
    force[j.id] = F
    moment[j.id] = np.where(np.isfinite(couple_b), 0.0, np.nan)
    for g, dF in ((b_name, -F), (a_name, F)):
        ax = axle[g]
        if ax.id not in force:
            continue
        # the axle's reported force is on its second link by its first
        force[ax.id] = force[ax.id] + (dF if ax.links[1] == g else -dF)


def _joint_point(S: PlanarSystem, q: np.ndarray, jid: str, side: int) -> np.ndarray:
    j = S.mech.joint(jid)
    name = S.mech.ground if side < 0 else S.links[side]
    return S.point(q, side, S.to_local(name, j.point))
