"""The regular sweep: a chain of a driver and RRR dyads clear of folds, in one pass of
complex arithmetic.

Points of the plane are complex numbers ``z = x + i y`` (the vector-loop notation of
Raven, "Velocity and acceleration analysis of plane and space mechanisms by means of
independent-position equations", *Journal of Applied Mechanics* 25, 1958; Erdman and
Sandor, *Mechanism Design*, 1984, ch. 3), so a rotation is one product and a vector
equation one array operation instead of two:

* a link ``i`` turned by ``e^{i phi_i}`` carries its local point ``s`` to
  ``P = P_a + e^{i phi_i} (s - s_a)`` from its anchor joint ``a``, with
  ``V = V_a + i omega_i (P - P_a)`` and ``A = A_a + (i alpha_i - omega_i^2) (P - P_a)``;
* an RRR dyad with known joints ``A``, ``C`` (``d = C - A``) places its middle joint at
  ``B = A + d (f + i sigma g)``, ``f = 1/2 + (L1^2 - L2^2) / (2 |d|^2)``,
  ``g = sqrt(L1^2 / |d|^2 - f^2)`` (``g^2 |d|^2 / L1^2`` is the group's normalised
  discriminant of :func:`mechsyn.kinematics.tracking.solve_tracked`); with ``e1 = B - A``,
  ``e2 = B - C`` its links turn at ``omega_1 = Re((v_C - v_A) conj(e2)) / (e1 x e2)``,
  ``omega_2 = Re((v_C - v_A) conj(e1)) / (e1 x e2)`` and likewise for the accelerations.

:func:`sweep_through_folds` evaluates the sweep and the connecting paths from the drawn
input values together in one pass. When no group's discriminant falls below
:data:`mechsyn.kinematics.sweep.REGULAR_DISC`, no group folds, touches a change point
or reassembles, every group keeps its drawn mode and the answer is that of the tracked
outward sweeps (tests check both agree). Else it goes on through the folds when no
group's discriminant has a local minimum under 0.05 (no change or branch point near:
every group keeps its drawn mode), and reads the folds, reassembly and singular rows of
the tracked sweeps off the discriminant arrays
(:func:`mechsyn.kinematics.folds.pass_fold_events`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mechsyn.kinematics import kernel
from mechsyn.kinematics.groups import Plan, geometry_memo
from mechsyn.kinematics.system import PlanarSystem
from mechsyn.kinematics.folds import pass_fold_events
from mechsyn.kinematics.sweep import REGULAR_DISC, tracking_path

__all__ = ["sweep_through_folds", "Folded", "LinkStates"]


def _pass(S: PlanarSystem, plan: Plan, X: np.ndarray | list, speeds: np.ndarray, folds: bool) -> tuple | None:
    """One pass of the regular program over the input rows ``X`` (or the blocks of rows
    ``X``, a list, one after the other) by the kernel: its record ``(C, W, AL, D, near,
    Z)`` (:func:`mechsyn.kinematics.kernel.run`, the rotations' planes of the first
    block's rows). None when a group comes near a fold and ``folds`` is false."""
    rec = kernel.run(kernel.program(S, plan), X, speeds, REGULAR_DISC,
                     planes=(X[0] if isinstance(X, list) else X).shape[0])
    return None if rec[4] and not folds else rec


def sweep_through_folds(S: PlanarSystem, plan: Plan, U: np.ndarray, speeds: np.ndarray,
                        split: int | None) -> tuple | Folded | None:
    """The regular pass of a driver-R + RRR chain through its folds (dead points, gaps).

    One pass over the sweep's rows and the connecting paths from the drawn input values
    (those of :func:`mechsyn.kinematics.tracking.solve_tracked_rates`) gives every group's
    normalised discriminant as an array. When no group comes near a fold the answer is
    ``(q, qd, qdd, links)``: poses and rates (N, n) and the links' complex states
    (:class:`LinkStates`). Else, when no group's discriminant
    has a local minimum under 0.05 (no change or branch point can be near, so every group
    keeps its drawn mode on every row and the pass's rows are the tracked ones), the
    events of each sweep (the one sweep, or forwards and backwards from the drawn
    configuration when ``split`` is a row) come from the discriminants by the branch
    rules of :func:`mechsyn.kinematics.tracking.solve_tracked` (folds found and refined
    on the group's discriminant, reassembly, singular rows): a :class:`Folded` (the
    poses, and per sweep its singular rows and events), the tracked chain's answer. None
    when a group's discriminant has such a minimum (the tracked chain decides what happens
    there) or the plan is not such a chain.

    Examples
    --------
    A crank-rocker clear of folds:

    >>> import numpy as np
    >>> import mechsyn as ms
    >>> from mechsyn.kinematics.analysis import cached_plan, input_grid
    >>> kp = cached_plan(ms.examples.load("crank_rocker"), inputs=("A",))
    >>> U = np.radians(input_grid(0, 360, 1))[:, None]
    >>> q, qd, qdd, links = sweep_through_folds(kp.system, kp.groups, U, np.ones(1), None)
    >>> q.shape, bool(np.allclose(links.z, np.exp(1j * q[:, 2::3].T)))
    ((361, 9), True)

    A textbook four-bar (crank sqrt(5), coupler and rocker sqrt(10), frame 5) from 100 to
    260 degrees, one sweep (the drawn crank angle, 63.4 degrees, lies outside it): its
    working range ends and starts again at the law-of-cosines angles 116.565 and 243.435
    degrees, the 31 rows between them not assembled.

    >>> kp = cached_plan(ms.examples.load("fourbar"), inputs=("A",))
    >>> res = sweep_through_folds(kp.system, kp.groups, np.radians(np.arange(100.0, 261.0, 4.0))[:, None],
    ...                           np.ones(1), None)
    >>> (singular, events), = res.parts
    >>> [(e.kind, e.index, round(float(np.degrees(e.input[0])), 9)) for e in events]
    [('dead point', 5, 116.565051177), ('dead point', 36, 243.434948823), ('reassembled', 36, 244.0)]
    >>> int(np.isnan(res.q[:, 0]).sum())
    31
    """
    if not plan.closed_form_rates or S.n != 3 * len(S.links):
        return None
    paths = _tracking_paths(S, U, split)
    st = _pass(S, plan, [U] + [path for path, _ in paths], speeds, folds=True)
    if not st[4]:
        return _poses(S, plan, U, st, split)
    out = pass_fold_events(S, plan, st[3], U, split, paths)
    if out is None:
        return None
    q, qd, qdd, ok, rates_ok, singular = kernel.link_poses(S, plan, st[:3] + st[5:], U, split, True, out)
    return Folded(q.T, qd.T, qdd.T, out, LinkStates(st[0][:, :, :U.shape[0]], qd[2::3], qdd[2::3]), ok, rates_ok,
                  singular)


def _tracking_paths(S: PlanarSystem, U: np.ndarray, split: int | None) -> list:
    """The connecting paths (:func:`mechsyn.kinematics.sweep.tracking_path`) of the
    tracked sweeps of the inputs ``U`` (forwards from row ``split``, backwards from row
    ``split - 1``, or the one sweep from row 0): the last answer is kept with ``S`` by
    the first rows' bytes (a drag or a design loop sweeps the same grid again)."""
    firsts = [U[0]] if split is None else [U[split], U[split - 1]]
    key = (split, *[f.tobytes() for f in firsts])
    memo = geometry_memo(S)
    hit = memo.get("tracking paths")
    if hit is not None and hit[0] == key:
        return hit[1]
    u0 = np.array([d.assembled for d in S.drivers], float)
    paths = [tracking_path(S, f, u0) for f in firsts]
    memo["tracking paths"] = (key, paths)
    return paths


@dataclass
class Folded:
    """A sweep through folds in one pass (:func:`sweep_through_folds`): poses and rates (N,
    n) with NaN rows where the mechanism is not assembled and NaN rates where they are
    not defined (the group folded flat), and per tracked sweep (the one sweep, or the
    sweeps forwards from the drawn input values and backwards) its singular rows and
    events (rows counted along that sweep); the links' states (:class:`LinkStates`, NaN
    where the poses are: ``qd``'s and ``qdd``'s angle rows are its rates, so rows
    blanked later are blanked there too), the rows assembled (``assembled``, N), the rows
    whose rates are defined (``rates_ok``, N: the singular rows of ``parts`` already
    blanked) and the number of assembled rows whose rates are not (``singular``)."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    parts: list
    links: LinkStates
    assembled: np.ndarray
    rates_ok: np.ndarray
    singular: int


def _poses(S: PlanarSystem, plan: Plan, U: np.ndarray, st: tuple, split: int | None) -> tuple:
    """The pose rows ``q, qd, qdd`` (N, n) of the first N rows of a pass clear of folds
    (every link's origin is its first joint, its angle continuous from the drawn one) and
    the links' complex states."""
    q, qd, qdd, *_ = kernel.link_poses(S, plan, st[:3] + st[5:], U, split, False)
    return q.T, qd.T, qdd.T, LinkStates(st[0][:, :, :U.shape[0]], qd[2::3], qdd[2::3])


class LinkStates:
    """Every link's rotation ``e^{i phi}`` and the complex position, velocity and
    acceleration of its origin (``C`` (4, n_links, N)), with its angular velocity and
    acceleration (n_links, N): the motion of any point of a link in a few products."""

    def __init__(self, C: np.ndarray, w: np.ndarray, al: np.ndarray) -> None:
        self.C, self.w, self.al = C, w, al

    @property
    def z(self) -> np.ndarray:
        """The links' rotations ``e^{i phi}`` (n_links, N)."""
        return self.C[0]

    def point(self, i: int, s: complex | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (N, 2) of the local point ``s`` (x, y, or a
        complex number) of link ``i``: :meth:`points` of one point."""
        P, V, A = self.points(np.array([i]), np.array([s if isinstance(s, complex) else complex(s[0], s[1])]))
        return P[0], V[0], A[0]

    def points(self, idx: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, velocity, acceleration (m, N, 2) of the local points ``s`` (m,
        complex) of the links ``idx`` (m,, moving links only): :meth:`point` for all of
        them in the same few array operations (the same arithmetic, so the same bits).

        Examples
        --------
        >>> import numpy as np
        >>> from mechsyn.io import load_mechanism
        >>> from mechsyn.kinematics.analysis import compile_plan
        >>> kp = compile_plan(load_mechanism("examples/kinematics/crank_rocker.yaml"), inputs=("A",))
        >>> U = np.radians(np.arange(0.0, 360.0, 30.0))[:, None]
        >>> *_, links = sweep_through_folds(kp.system, kp.groups, U, np.ones(1), None)
        >>> P, V, A = links.points(np.array([0, 1]), np.array([1 + 0j, 0.5 + 0.2j]))
        >>> P.shape, bool(np.array_equal(A[1], links.point(1, (0.5, 0.2))[2]))
        ((2, 12, 2), True)
        """
        got = kernel.point_states(self.C, self.w, self.al, np.asarray(idx, np.int64), np.asarray(s, complex))
        P, V, A = got.view(float).reshape(3, *got.shape[1:], 2)
        return P, V, A
