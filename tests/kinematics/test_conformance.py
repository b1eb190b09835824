"""The conformance suite of the kinematics engines (issue 37), in the shape of
scikit-learn's ``parametrize_with_checks``: one parametrized test runs every engine of
:data:`mechsyn.kinematics.ENGINES` on every bundled example with a driven R joint, under
the one kernel of the regular pass, and compares it with the spatial engine on the drawn cycle.

The oracle is the spatial engine on the planar file's 3-D equivalent: another formulation
(each pair's constraint equations on the link poses, predictor-corrector continuation),
sharing no code with the planar engines but the file. On the drawn cycle (the driven
joint's drawn value +- 180 degrees, in steps of 5 that straddle the drawn value, so that
every engine also goes outwards from the drawn configuration) an engine that answers

* assembles the same rows,
* puts every named point within ``1e-9`` of the mechanism's size of the oracle's point
  on the working range through the drawn configuration (and at ``z = 0`` in the
  oracle; after a gap each engine reassembles by its own rule),
* gives the same velocities and accelerations where both define them (within
  ``1e-9`` of the size plus ``1e-6`` of the rate: rates grow without bound near a dead
  point),
* reports where a working range ends or starts (a dead point or a reassembly) within one
  row of where the oracle does, and nowhere else.

The spatial engine itself is checked against Newton's continuation of the planar
constraint equations the same way.

What an engine cannot treat it declines with :class:`~mechsyn.errors.EngineDeclined`:
the declines are declared in :data:`DECLINES` (a phrase of the one-line reason), not
written as tests of their own. A decline that is not declared fails, and so does a
declared one that no longer happens: the table can only shrink. A new engine gets every
check by being put in ``ENGINES``.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.errors import EngineDeclined, MechsynInputError
from mechsyn.kinematics import ENGINES
from mechsyn.kinematics.analysis import cached_plan
from mechsyn.model.mechanism import Mechanism

#: Why an engine declines an example, by engine and example: a phrase of its reason.
#: Examples the oracle cannot take (cams, belts, VLLs) are in ORACLE_DECLINES.
_GROUPS_ONLY = "does not split into drivers and dyads"
_RRR_ONLY = "chains of R drivers and RRR dyads only"
_NEAR_CHANGE = "minimum near zero"
DECLINES: dict[str, dict[str, str]] = {
    "regular pass": {"double_parallelogram": _GROUPS_ONLY, "inverted_slider_crank": _RRR_ONLY,
                     "shoe_pair_slide": _RRR_ONLY, "slider_block_two_pins": _RRR_ONLY,
                     "slider_crank": _RRR_ONLY, "slider_crank_coupler": _RRR_ONLY,
                     "peaucellier": _NEAR_CHANGE},
    "tracked chain": {"double_parallelogram": _GROUPS_ONLY, "inverted_slider_crank": _RRR_ONLY,
                      "shoe_pair_slide": _RRR_ONLY, "slider_block_two_pins": _RRR_ONLY,
                      "slider_crank": _RRR_ONLY, "slider_crank_coupler": _RRR_ONLY},
    "tracked groups": {"double_parallelogram": _GROUPS_ONLY},
    "newton": {},
    "spatial": {},
}

#: Examples the oracle declines (so no engine is compared on them), with the phrase: pairs
#: it does not take, and drawn configurations at a dead centre or a fold, which the planar
#: engines leave on a branch they choose and the spatial continuation cannot leave.
_SINGULAR = "the drawn assembly is singular"
#: Drawn at a change point: two branches cross at the drawn pose and each engine keeps one
#: of them (both are assemblies; the planar engines the drawn assembly modes, the spatial
#: continuation the branch its tangent picks); their assembled rows and limits are compared,
#: not their positions.
BRANCH_CHOICE = {"fourbar_folded": "two branches cross at the drawn pose"}
ORACLE_DECLINES = {"cam_follower": "cam pair", "cam_polar": "cam pair", "cam_roller": "cam pair",
                   "paper001_mechanism": "belt pair", "three_phalanx_vll_000": "is a VLL",
                   "two_phalanx_vll_000": "is a VLL"}


#: Rates are compared within this fraction of the size plus the largest rate of the point
#: on the sweep (both engines take them from the Jacobian at the pose, whose condition
#: grows near a dead point).
RATE_TOL = 1e-7


def _cycle(m: Mechanism, joint: str) -> np.ndarray:
    """The drawn cycle: the drawn value +- 180 degrees in steps of 5, straddling it."""
    d = next(d for d in cached_plan(m, inputs=(joint,)).system.drivers if d.joint == joint)
    return np.degrees(d.assembled) + np.arange(-177.5, 180.0, 5.0)


def _examples() -> list[tuple[str, Mechanism, str]]:
    """(name, mechanism, driven R joint) of every bundled planar example whose first driven
    joint is an R pair and that simulates with that one input."""
    out = []
    for name in ms.examples.names():
        try:
            m = ms.examples.load(name)
        except Exception:  # noqa: BLE001  (not a mechanism file: an arm, a case)
            continue
        if not isinstance(m, Mechanism) or m.kind != "planar":
            continue
        j = next((j for j in m.joints if j.actuated), None)
        if j is None or j.type != "R":
            continue
        try:
            ms.simulate(m, {j.id: _cycle(m, j.id)[:2]})
        except MechsynInputError:  # refused with one input (all its drives needed)
            continue
        out.append((name, m, j.id))
    return out


EXAMPLES = _examples()


@functools.lru_cache(maxsize=None)
def _oracle(name: str) -> ms.kinematics.Motion:
    _, m, joint = next(e for e in EXAMPLES if e[0] == name)
    return ms.simulate(m, {joint: _cycle(m, joint)}, method="spatial")


def _limit_rows(motion) -> list[int]:
    """The rows where a working range ends or starts (a dead point, a reassembly). A limit
    the spatial engine finds across the ends of a whole-turn sweep (its R input taken modulo
    360: ``last`` is the row at the other end, not a neighbour) is left out: the planar
    engines do not join the two ends of a sweep."""
    return sorted({e.index for e in motion.events if e.kind in ("dead point", "reassembled")
                   and (e.get("last") is None or abs(e["last"] - e.index) == 1)})


def _drawn_range(assembled: np.ndarray) -> np.ndarray:
    """The rows of the working range through the drawn configuration (between the middle
    rows): after a gap each engine reassembles by its own documented rule (the planar ones
    in the drawn assembly mode, the spatial one from the last pose it had), so positions
    are compared on the drawn branch only."""
    ok = np.zeros_like(assembled)
    k = len(assembled) // 2
    if not assembled[k]:
        return ok
    lo, hi = k, k
    while lo > 0 and assembled[lo - 1]:
        lo -= 1
    while hi < len(assembled) - 1 and assembled[hi + 1]:
        hi += 1
    ok[lo:hi + 1] = True
    return ok


@pytest.mark.parametrize("engine", [e.name for e in ENGINES])
@pytest.mark.parametrize("name", [e[0] for e in EXAMPLES])
def test_engine_agrees_with_the_spatial_engine(name, engine):
    _, m, joint = next(e for e in EXAMPLES if e[0] == name)
    if name in ORACLE_DECLINES:
        with pytest.raises(MechsynInputError, match=ORACLE_DECLINES[name]):
            _oracle(name)
        pytest.skip(f"the oracle declines {name}: {ORACLE_DECLINES[name]}")
    declared = DECLINES[engine].get(name)
    try:
        s = ms.simulate(m, {joint: _cycle(m, joint)}, method=engine)
    except EngineDeclined as exc:
        assert declared is not None, f"{engine} declines {name}, undeclared: {exc.why}"
        assert declared in exc.why and "\n" not in str(exc)
        return
    assert declared is None, f"{engine} declared to decline {name} ({declared}) but answers: remove it from DECLINES"
    assert s.engine == engine and isinstance(s, ms.kinematics.Motion)
    ref = _oracle(name) if engine != "spatial" else ms.simulate(m, {joint: _cycle(m, joint)}, method="newton")
    if engine == "spatial":  # the oracle itself is checked against Newton's continuation
        s, ref = ref, s
    size = cached_plan(m, inputs=(joint,)).system.scale
    np.testing.assert_array_equal(s.assembled, ref.assembled, err_msg="assembled rows")
    ok = _drawn_range(s.assembled)
    assert set(s.points) == set(ref.points)
    for p in (s.points if name not in BRANCH_CHOICE else ()):
        a, b = s.points[p], ref.points[p]
        dim = a.position.shape[1]
        if dim == 2:
            assert np.abs(b.position[ok, 2]).max(initial=0.0) <= 1e-9 * size
        assert np.abs(a.position[ok] - b.position[ok, :dim]).max(initial=0.0) <= 1e-9 * size, p
        for rate in ("velocity", "acceleration"):
            x, y = getattr(a, rate)[ok], getattr(b, rate)[ok, :dim]
            both = np.isfinite(x).all(axis=1) & np.isfinite(y).all(axis=1)
            top = np.abs(y[both]).max(initial=0.0)
            err = np.abs(x[both] - y[both]).max(initial=0.0)
            assert err <= RATE_TOL * (size + top), f"{p} {rate}: {err:.3g} of {size + top:.3g}"
    mine, theirs = _limit_rows(s), _limit_rows(ref)
    assert all(min(abs(i - k) for k in theirs) <= 1 for i in mine), (mine, theirs)
    assert all(min(abs(i - k) for k in mine) <= 1 for i in theirs), (mine, theirs)


def test_every_engine_is_compared_on_enough_examples():
    """The suite is not empty: at least 15 (example, engine) pairs are compared (the
    issue's floor), every engine by a unique name, the spatial one among them."""
    names = [e.name for e in ENGINES]
    assert len(set(names)) == len(names) and "spatial" in names
    compared = [(n, e) for n, _, _ in EXAMPLES if n not in ORACLE_DECLINES
                for e in names if e != "spatial" and n not in DECLINES[e]]
    assert len(compared) >= 15, compared
