"""The kernel of the planar closed-form sweep (issue 30, one kernel since issue 37): the
regular pass's program run by Numba-compiled functions
(:mod:`mechsyn.kinematics._kernel_numba`), row by row in compiled code.

The regular pass (:func:`mechsyn.kinematics.regular.sweep_through_folds`) is a program of
drive ops and RRR group ops (:func:`program` gives it as integer and complex
arrays); :func:`run` runs it over the input rows and returns one record: every link's
rotation and its origin's position, velocity and acceleration, the links' rates, the
groups' normalised discriminants and whether one came near a fold. The fold scan
(:func:`fold_scan`), the links' poses (:func:`link_poses`) and named points
(:func:`point_states`) read that record. The program's integers are the topology's
(:func:`layout`); its numbers are filled by one compiled function for one system or
for many designs at once (:func:`numbers`), and the batch engine
(:func:`mechsyn.kinematics.batch.simulate_batch`) runs the same program's placement
over many designs (positions only). There is one implementation: the compiled
functions are plain Python functions under ``NUMBA_DISABLE_JIT=1`` (CI measures their
line coverage that way, .ci/steps/25-kernel.sh).

Numba is a required dependency. It is imported on the first sweep, not when mechsyn
is imported: it compiles the kernel on its first use on a machine (a few seconds) and
keeps the machine code beside the module (``__pycache__``); later processes load it
(about 0.1 s, plus 0.3 s to import Numba).

Examples
--------
The crank-rocker's program is a driver and one RRR group; run over two crank angles it
gives the group's normalised discriminant per row:

>>> import numpy as np
>>> import mechsyn as ms
>>> from mechsyn.kinematics.analysis import cached_plan
>>> kp = cached_plan(ms.examples.load("crank_rocker"))
>>> prog = program(kp.system, kp.groups)
>>> prog[0][0][:, 0].tolist()  # the steps' ops: 0 a driver, 1 an RRR group
[0, 1]
>>> out = run(prog, np.radians([[0.0], [90.0]]), np.ones(1), 0.05)
>>> out[3].shape, out[4]
((1, 2), False)
"""

from __future__ import annotations

import importlib
import types
from itertools import chain
from types import ModuleType

import numpy as np

from mechsyn.kinematics.groups import Plan, cons_of, geometry_memo, local_point
from mechsyn.kinematics.refill import joint_points
from mechsyn.kinematics.system import PlanarSystem, frame_points
from mechsyn.kinematics.topology import CACHE

__all__ = ["fold_scan", "layout", "link_poses", "numbers",
           "point_states", "program", "run", "scalar_disc", "scan_sweep", "trig", "warm"]


def _nb() -> ModuleType:
    """The compiled functions (:mod:`mechsyn.kinematics._kernel_numba`), imported on the
    first sweep: importing Numba costs a one-shot command that runs no sweep nothing."""
    return importlib.import_module("mechsyn.kinematics._kernel_numba")


#: A four-bar with two dead points and a coupler point (crank sqrt 5, coupler and rocker
#: sqrt 10, frame 5): one sweep of it calls every compiled function (:func:`warm`).
_WARM_FOURBAR = {
    "name": "warm-up four-bar", "kind": "planar", "ground": "frame", "links": ["frame", "crank", "coupler", "rocker"],
    "joints": [{"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
               {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": [1, 2]},
               {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4, 3]},
               {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [5, 0]}],
    "points": {"M": {"link": "coupler", "at": [3, 4]}},
}


def warm() -> bool:
    """Import Numba and compile (or load from its cache) the kernel's functions now, by
    sweeping a four-bar through its dead points, so that the first sweep a user asks for
    does not wait for them (the studio calls this while it starts). Returns True."""
    from mechsyn.io import mechanism_from_dict

    mechanism_from_dict(_WARM_FOURBAR, source="kernel.warm").simulate(A=(0, 360, 30))
    return True


def program(S: PlanarSystem, plan: Plan) -> tuple:
    """The regular pass's program of ``S`` as the kernel's arrays, kept with ``S``:
    :func:`_shape`'s integers (the topology's) and the numbers ``fp`` (steps, 7)
    complex (a driver's sign and joint point; a group's squared lengths, assembly mode,
    rotation vectors and known joints' local points, :func:`numbers`) and the anchors'
    local points ``anc_s`` (links,) complex (:func:`numbers` of ``S``'s local points)."""
    memo = geometry_memo(S)
    hit = memo.get(("kernel", id(plan)))
    if hit is not None and hit[0] is plan:
        return hit[1]
    li, pj, ints, table, _ = layout(S, plan)
    pts = joint_points(S)
    loc = frame_points(S.frames(), li, [pts[k] for k in pj])
    fp, anc_s = numbers(table, *(np.fromiter(chain.from_iterable(a), float).view(complex)[None] for a in (loc, pts)))
    out = ints, fp[0], anc_s[0]
    memo[("kernel", id(plan))] = (plan, out)
    return out


def layout(S: PlanarSystem, plan: Plan) -> tuple:
    """The program's topology (:func:`_shape`), the topology's product ``"kernel"``
    (:meth:`~mechsyn.kinematics.topology.Topology.product`): built once per topology and
    plan, shared by every system of that topology (a refilled one too) and by the batch
    engine's designs."""
    return S.topology.product("kernel", lambda: _shape(S, plan), plan)


def numbers(table: tuple, loc: np.ndarray, pt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The program's numbers ``fp`` (K, steps, 7) and ``anc_s`` (K, links) of ``K``
    designs of one topology (:func:`mechsyn.kinematics._kernel_numba.fill`, the one
    implementation): ``table`` the topology's (:func:`_shape`'s),
    ``loc`` (K, pairs) the local points of the (link, joint) pairs it names, ``pt`` (K,
    joints) the drawn joint points in file order (complex, C-contiguous)."""
    fi, anc_p = table
    fp = np.empty((loc.shape[0], fi.shape[0], 7), complex)
    anc_s = np.empty((loc.shape[0], anc_p.shape[0]), complex)
    _nb().fill(fi, anc_p, loc, pt, fp, anc_s)
    return fp, anc_s


def _shape(S: PlanarSystem, plan: Plan) -> tuple:
    """The topology of :func:`program`: the (link, joint) pairs whose local points the
    numbers take, as index lists (link, joint's index in the file); the program's
    integers: per step ``ip`` (op, links, joints by their index in the program, which
    joints to place from a link's point first, the group's row in the discriminants),
    each link's anchor joint and origin joint (-1: found from its anchor), the number of
    joints and the steps of the RRR groups; the table :func:`numbers` fills the
    numbers by (``fi``: per step a driver's pair and sign, a group's pairs ``s1, s2, t2,
    t3, k1, k3`` and its joints' indices in the file (its drawn assembly mode), the op
    last; each link's anchor pair, -1: none); and the links' angles of
    :func:`link_poses` (each link's frame driver's input column, -1: none, the input's
    sign, and the runs ``(first, end)`` of the other links). A link's anchor is the
    joint that places it: a drive's joint, an RRR group's end joint on it; its origin
    is its first joint."""
    pairs: dict[tuple[int, str], int] = {}
    order: dict[str, int] = {}

    def at(i: int, jid: str) -> int:
        return pairs.setdefault((i, jid), len(pairs))

    def jx(jid: str) -> int:
        return order.setdefault(jid, len(order))

    nl = len(S.links)
    index = {j.id: k for k, j in enumerate(S.mech.joints)}
    anchors, placed, groups = {}, set(), []
    dcol, dsgn = np.full(nl, -1, np.int64), np.ones(nl)
    ip, fi = np.zeros((len(plan.steps), 11), np.int64), np.zeros((len(plan.steps), 10), np.int64)
    for s, step in enumerate(plan.steps):
        if step.kind == "drive_R":  # the joint's local point on k (the frame: its fixed point)
            (new,), (k,), (jid,) = step.links, step.known, step.joints
            con = next(c for c in cons_of(S, jid) if c.role == "drive")
            sign = 1.0 if con.b == new else -1.0
            ip[s, :6] = (0, new, k, jx(jid), con.driver, int(k >= 0 and jid not in placed))
            fi[s, :2] = (at(k, jid), sign)
            if k < 0:
                dcol[new], dsgn[new] = con.driver, sign
            anchors[new] = (jid, at(new, jid))
            placed.add(jid)
            continue
        (k1, k3), (b1, b2), (J1, J2, J3) = step.known, step.links, step.joints
        ip[s] = (1, k1, k3, b1, b2, jx(J1), jx(J2), jx(J3), int(J1 not in placed), int(J3 not in placed), len(groups))
        fi[s] = (at(b1, J1), at(b1, J2), at(b2, J2), at(b2, J3), at(k1, J1), at(k3, J3), index[J1], index[J2],
                 index[J3], 1)
        anchors[b1], anchors[b2] = (J1, at(b1, J1)), (J3, at(b2, J3))
        placed.update((J1, J2, J3))
        groups.append(s)
    origin = [next((j.id for j in S.mech.joints_of(name) if not np.any(local_point(S, i, j.id))), None)
              for i, name in enumerate(S.links)]  # the joint at every link's origin (its first joint), by link
    anc_j = np.array([jx(anchors[i][0]) if i in anchors else -1 for i in range(nl)], np.int64)
    anc_p = np.array([anchors[i][1] if i in anchors else -1 for i in range(nl)], np.int64)
    org_j = np.array([jx(j) if j is not None and j in placed else -1 for j in origin], np.int64)
    free = np.flatnonzero(dcol < 0)  # the links no frame driver turns, as runs of consecutive links
    cuts = np.flatnonzero(np.diff(free) != 1) + 1
    runs = tuple((int(r[0]), int(r[-1]) + 1) for r in np.split(free, cuts) if r.size)
    return ([i for i, _ in pairs], [index[jid] for _, jid in pairs], (ip, anc_j, org_j, len(order), groups),
            (fi, anc_p), (dcol, dsgn, runs))


def run(program: tuple, X: np.ndarray | list, speeds: np.ndarray, least: float, planes: int = 0,
        signs: np.ndarray | None = None) -> tuple:
    """The compiled pass over the input rows ``X`` (M, k), or over the blocks of rows
    ``X`` (a list: the sweep, then the connecting paths) one after the other: ``(C, W,
    AL, D, near)``, every link's rotation and its origin's position, velocity,
    acceleration (4, links, M), its angular velocity and acceleration (links, M), the
    groups' normalised discriminants (groups, M), and whether one falls below ``least``;
    with ``planes`` (a number of rows, at most M) also the rotations' real and imaginary
    parts in the first ``planes`` rows (2, links, planes) (contiguous rows for
    :func:`link_poses`' ``arctan2``); ``signs`` (steps, M): every group's assembly mode
    by row (the tracked chain's), else the drawn modes. The inputs' cosines and sines are
    :func:`trig`'s."""
    (ip, anc_j, org_j, nj, groups), fp, anc_s = program
    CS, SN = trig(X if isinstance(X, list) else [X])
    M, nl = CS.shape[0], anc_j.shape[0]
    C = np.empty((4, nl, M), complex)
    R = np.empty((2 * nl + len(groups), M))  # W, AL and D: rows of one block (contiguous views)
    W, AL, D = R[:nl], R[nl:2 * nl], R[2 * nl:]
    Z = np.empty((2, nl, min(planes, M)) if planes else (2, 0, 0))
    near = _nb().regular_pass(ip, fp, anc_j, anc_s, org_j, CS, SN, np.ascontiguousarray(speeds, float), nj,
                            least, C, W, AL, D, Z, _NO_SIGNS if signs is None else signs)
    return (C, W, AL, D, bool(near), Z) if planes else (C, W, AL, D, bool(near))


#: The largest block of input rows (numbers) whose cosines and sines :func:`trig` keeps,
#: and the smallest (a connecting path from the drawn input, new with each drawn crank
#: angle, is computed, not looked for).
_TRIG_ROWS, _SMALL = 1 << 13, 64


def trig(blocks: list) -> tuple[np.ndarray, np.ndarray]:
    """NumPy's cosines and sines of the input rows ``blocks`` (float arrays (m, k))
    stacked: the numbers the regular pass turns its drivers by. A studio's drag, a design
    loop and a cached call sweep the same inputs again and again, with other link
    lengths: the answers for blocks of up to 8,192 numbers and for stacks of blocks are
    kept in the one cache (:data:`mechsyn.kinematics.topology.CACHE`, under ``("trig",
    bytes, shape, type)`` of the blocks: at most 128 kB an entry), so only new inputs
    cost their trigonometry (a tenth of a six-bar's compiled pass); a small block is
    computed, not looked for. Each block's numbers are ``np.cos``, ``np.sin`` of that
    block, whatever is kept.

    Examples
    --------
    >>> X = np.radians([[0.0], [30.0], [90.0]])
    >>> c, s = trig([X[:2], X[2:]])
    >>> bool(np.array_equal(c, np.cos(X)) and np.array_equal(s, np.sin(X)))
    True
    """
    if sum(b.size for b in blocks) > _TRIG_ROWS:
        return tuple(np.concatenate([f(b) for b in blocks]) for f in (np.cos, np.sin))
    keys = tuple([(b.tobytes(), b.shape, b.dtype.char) for b in blocks])
    if len(blocks) == 1:
        return _block_trig(blocks[0], keys[0])
    hit = CACHE.get(("trig", keys))
    if hit is None:
        parts = [_block_trig(b, k) for b, k in zip(blocks, keys)]
        hit = np.concatenate([c for c, _ in parts]), np.concatenate([s for _, s in parts])
        CACHE.put(("trig", keys), hit)
    return hit


def _block_trig(b: np.ndarray, key: tuple) -> tuple[np.ndarray, np.ndarray]:
    """:func:`trig` of one block (``key``: its bytes, shape and type), kept unless small."""
    if b.size < _SMALL:
        return np.cos(b), np.sin(b)
    hit = CACHE.get(("trig", key))
    if hit is None:
        hit = np.cos(b), np.sin(b)
        CACHE.put(("trig", key), hit)
    return hit


def link_poses(S: PlanarSystem, plan: Plan, pass_: tuple, U: np.ndarray, split: int | None, folds: bool,
               parts: list | None = None) -> tuple:
    """The pose rows ``q, qd, qdd`` (n, N; component-major) of the first N rows (``U``
    (N, k) their inputs) of a pass of ``S``'s program (``pass_``: ``(C, W, AL)`` of
    :func:`run`, and its planes when it gave them) and the rows assembled, the links'
    angles continuous from the drawn ones (a link a frame driver turns takes its input,
    the others ``atan2`` of their rotations: :func:`_shape`'s angles), compiled: see
    :func:`mechsyn.kinematics._kernel_numba.link_poses`. ``folds``: the sweep may not
    be assembled throughout (each tracked sweep made continuous on its own, rows not
    assembled and rates not defined blanked, in the poses and in ``C``; ``parts``: the
    fold scan's singular rows per tracked sweep,
    :func:`mechsyn.kinematics.folds.pass_fold_events`' first items, blanked too).
    Returns ``q, qd, qdd``, the rows assembled and, through folds, the rows whose rates
    are defined and the number of assembled rows whose rates are not (else None, 0)."""
    C, W, AL, *Z = pass_
    N, nl = U.shape[0], C.shape[1]
    dcol, dsgn, runs = layout(S, plan)[4]
    q, qd, qdd = np.empty((3, S.n, N))  # one block, three contiguous views
    if S.n > 3 * nl:  # unknowns other than the links' poses (none in a regular pass)
        q[3 * nl:] = qd[3 * nl:] = qdd[3 * nl:] = np.nan
    zr, zi = (Z[0][0], Z[0][1]) if Z else (C[0].real, C[0].imag)  # the planes of run() (N rows), else strided parts
    A = np.empty((nl, N))
    ok = np.empty((2, N), np.bool_)  # the rows assembled, the rows with rates
    for a, b in runs:  # the links no frame driver turns (NumPy's vector loops: a third of libm's time per angle)
        np.arctan2(zi[a:b, :N], zr[a:b, :N], out=A[a:b])
    sb = parts[1][0][::-1] if parts and len(parts) > 1 else _NO_ROWS  # the sweeps' singular rows in the sweep's
    sf = parts[0][0] if parts else np.zeros(N if folds else 0, np.bool_)  # order (backward, then forward)
    singular = _nb().link_poses(C, W, AL, N, U if U.flags.c_contiguous and U.dtype == _F64 else
                                np.ascontiguousarray(U, float), dcol, dsgn, S.q0[2:3 * nl:3].copy(),
                                -1 if split is None else split, folds, A, q, qd, qdd, ok[0], sb, sf, ok[1])
    return q, qd, qdd, ok[0], ok[1] if folds else None, singular


_NO_ROWS = np.zeros(0, np.bool_)
_NO_SIGNS = np.zeros((0, 0))
_F64 = np.dtype(float)


def fold_scan(program: tuple, D: np.ndarray, perm: np.ndarray, b: int, X: np.ndarray, paths: list, ks: np.ndarray,
              specs: np.ndarray, zero: float, singular_disc: float) -> tuple:
    """:func:`mechsyn.kinematics.folds.pass_fold_events` compiled in one call
    (:func:`mechsyn.kinematics._kernel_numba.fold_scan`): the masks of :func:`fold_rows`
    and the tracked sweeps' folds (refined on the discriminant of the regular pass's
    ``program``) and reassemblies. ``D`` (groups, rows): the groups' discriminants;
    ``X``: the pass's input rows; ``paths``: the sweeps'
    ``(path, shift)``; ``ks``: the groups' steps; ``specs``: their closed-form fold
    numbers. Returns whether a change point may be near, the singular rows in the layout
    ``perm`` and the events as rows (sweep, row, kind, group, input...)."""
    (ip, anc_j, _, nj, _), fp, anc_s = program
    (pa, sa), (pb, sb) = paths[0], paths[-1]
    if sa.flags.writeable or sb.flags.writeable:  # one array type for both (tracking_path's are read-only)
        sa, sb = np.array(sa, float), np.array(sb, float)
    return _nb().fold_scan(D, perm, b, zero, singular_disc, X, len(paths), pa.shape[0], sa, pb.shape[0], sb, ks, specs,
                           ip, fp, anc_j, anc_s, nj)


def scan_sweep(D: np.ndarray, X: np.ndarray, n0: int, zero: float, specs: np.ndarray, line) -> np.ndarray:
    """The kernel's fold scan of one tracked sweep
    (:func:`mechsyn.kinematics._kernel_numba.scan_sweep`, the source :func:`fold_scan`
    compiles) run as plain Python, each fold refined by the kernel's refinement on a
    Python discriminant: ``line(g, i, xa, xb)`` gives group ``g``'s discriminant ``f(t)``
    on the segment of inputs from ``xa`` (row ``i - 1``) to ``xb`` (the tracked groups',
    :func:`mechsyn.kinematics.folds.fold_events`, whose discriminants come from the
    generic group steps); ``specs``: the groups' closed-form fold numbers. ``D`` (groups,
    n): the groups' normalised discriminants on the input rows ``X`` (n, inputs), the
    first ``n0`` a connecting path. Returns the events as rows (sweep 0, row, kind,
    group, input)."""
    cap = int(np.count_nonzero((D[:, 1:] > -zero) != (D[:, :-1] > -zero)))
    ev = np.empty((2 * cap, 4 + X.shape[1]))
    ne = _plain()["scan_sweep"](D, X, n0, np.zeros(X.shape[1]), zero, (specs, zero, line), ev, 0, 0)
    return ev[:ne]


def _plain() -> dict:
    """The compiled functions' plain Python source, calling each other plain (a
    namespace of :mod:`mechsyn.kinematics._kernel_numba` whose functions are their
    ``py_func``; the same functions under ``NUMBA_DISABLE_JIT=1``), with the two leaves
    that read the program replaced by a Python context's own: ``_segment(c, g, i, xa,
    xb)`` calls ``c[2](g, i, xa, xb)`` (a discriminant ``f(t)``) and ``_disc_along(f,
    t)`` calls ``f(t)``. Kept in the one cache."""
    ns = CACHE.get(("plain kernel",))
    if ns is None:
        nb = _nb()
        ns = dict(vars(nb))
        for name, fn in vars(nb).items():
            py = getattr(fn, "py_func", fn)
            if isinstance(py, types.FunctionType) and py.__module__ == nb.__name__:
                ns[name] = types.FunctionType(py.__code__, ns, py.__name__, py.__defaults__, py.__closure__)
        ns["_segment"] = lambda c, g, i, xa, xb: c[2](g, i, xa, xb)
        ns["_disc_along"] = lambda f, t: f(t)
        CACHE.put(("plain kernel",), ns)
    return ns


def point_states(C: np.ndarray, w: np.ndarray, al: np.ndarray, idx: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Position, velocity, acceleration (3, m, N) complex of the local points ``s`` (m,
    complex) of the links ``idx`` from the links' states (``C`` (4, links, N), rates ``w``,
    ``al`` (links, N))."""
    out = np.empty((3, idx.shape[0], C.shape[2]), complex)
    _nb().point_states(C, w, al, idx, s, out)
    return out


def scalar_disc(program: tuple, k: int, sg: np.ndarray, u: np.ndarray) -> float:
    """The normalised discriminant of RRR step ``k`` of the regular pass's ``program`` at
    one input ``u`` (floats, one per driver), every upstream group in its mode ``sg``
    (floats +1 / -1 by step): the function the fold search refines a fold on, placed by
    the kernel's one circle intersection (:func:`mechsyn.kinematics._kernel_numba.circle`).
    """
    (ip, anc_j, _, nj, _), fp, anc_s = program
    return _nb().scalar_disc(ip, fp, anc_j, anc_s, u, nj, k, sg)
