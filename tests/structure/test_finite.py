"""Issue 25 item 3: finite (local) mobility, singular and shaky configurations.

Expected values from the mechanisms' geometry, not from the program:
- Bennett's linkage moves (Bennett 1903): finite mobility 1 although Malyshev gives -2;
  with one axis tilted by 1 degree the 4R loop is generic and rigid (finite 0);
- a change-point four-bar folded flat: instantaneous 2, two branches cross, finite 1,
  singular;
- a taut four-bar (crank + coupler + rocker = frame) stretched flat: its only assembly is
  this one, so finite 0; instantaneous 2: shaky;
- a four-bar with a straight dyad between two coupler points: finite 1 (Chebyshev),
  instantaneous 2 at every pose: shaky (Müller 2016's permanently shaky linkages);
- the Delta robot with its drives free: 3 translations + 6 bar spins, all finite: 9.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from mechsyn.io import load_mechanism
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.finite import local_mobility
from mechsyn.structure.rank import analyze_rank, as_spatial

EX = Path(__file__).resolve().parents[2] / "examples"
SEEDS = (0, 1, 2)


def load(rel: str):
    return load_mechanism(EX / rel)


@pytest.mark.parametrize("seed", SEEDS)
def test_bennett_moves_finitely(seed):
    mech = load("textbook/bennett.yaml")
    r = analyze_rank(mech, seed=seed)
    assert analyze_structure(mech).formulas["malyshev"].value == -2
    assert (r.mobility, r.finite_mobility, r.configuration) == (1, 1, "regular")
    assert not r.singular and not r.shaky


def test_bennett_with_one_axis_tilted_is_rigid():
    r = analyze_rank(load("spatial/bennett_tilted.yaml"))
    assert (r.mobility, r.finite_mobility, r.singular, r.shaky) == (0, 0, False, False)


@pytest.mark.parametrize("seed", SEEDS)
def test_change_point_fourbar_folded_flat_is_singular(seed):
    r = analyze_rank(load("textbook/fourbar_folded.yaml"), seed=seed)
    assert (r.mobility, r.finite_mobility, r.configuration) == (2, 1, "singular")
    assert r.singular and not r.shaky
    assert r.mobility_reading.startswith("singular: instantaneous mobility 2 but finite mobility 1")


@pytest.mark.parametrize("seed", SEEDS)
def test_taut_fourbar_is_shaky_and_finitely_rigid(seed):
    mech = load("textbook/fourbar_taut.yaml")
    r = analyze_rank(mech, seed=seed)
    assert analyze_structure(mech).formulas["chebyshev"].value == 1
    assert (r.mobility, r.finite_mobility, r.configuration) == (2, 0, "shaky")
    assert r.shaky and not r.singular


@pytest.mark.parametrize("seed", SEEDS)
def test_straight_dyad_on_a_coupler_is_shaky(seed):
    r = analyze_rank(load("textbook/fourbar_shaky_dyad.yaml"), seed=seed)
    assert (r.mobility, r.finite_mobility, r.configuration) == (2, 1, "shaky")
    assert "shaky: instantaneous mobility 2 but finite mobility 1" in r.mobility_reading


@pytest.mark.parametrize("name, finite, configuration", [("fourbar_taut", 0, "shaky"),
                                                         ("fourbar_folded", 1, "singular"),
                                                         ("fourbar_shaky_dyad", 1, "shaky")])
def test_the_same_readings_in_space(name, finite, configuration):
    # the planar files seen in 3-D (R axes along z): six closure equations per contour
    r = analyze_rank(as_spatial(load(f"textbook/{name}.yaml")))
    assert (r.motion, r.mobility, r.finite_mobility, r.configuration) == ("spatial", 2, finite, configuration)


def test_delta_finite_mobility_with_drives_free():
    r = analyze_rank(load("textbook/delta.yaml"))
    assert (r.mobility, r.useful_mobility, len(r.idle_mobilities)) == (9, 3, 6)
    assert (r.finite_mobility, r.configuration) == (9, "regular")


@pytest.mark.parametrize("rel", ["textbook/fourbar.yaml", "textbook/bennett_4dp.yaml", "textbook/sarrus.yaml",
                                 "spatial/spherical_3rrr.yaml", "spatial/hooke_coupling_ru.yaml",
                                 "structural/gough_stewart_6sps.yaml"])
def test_ordinary_mechanisms_are_regular(rel):
    r = analyze_rank(load(rel))
    assert r.finite_mobility == r.mobility and r.configuration == "regular"


def test_to_dict_says_which_reading_holds():
    d = analyze_rank(load("textbook/fourbar_taut.yaml")).to_dict()
    assert (d["finite_mobility"], d["singular"], d["shaky"], d["configuration"]) == (0, False, True, "shaky")
    assert d["mobility_reading"].startswith("shaky: instantaneous mobility 2 but finite mobility 0")
    d = analyze_rank(load("textbook/fourbar.yaml"), check_singular=False).to_dict()
    assert d["finite_mobility"] is None and d["configuration"] == "not checked"


def make(rows):
    """``step`` and ``null`` of :func:`local_mobility` for closure equations given as
    (function, gradient) pairs."""
    import numpy as np

    def closure(t):
        return np.array([f(t) for f, _ in rows]), np.array([g(t) for _, g in rows])

    def step(t):
        err, J = closure(t)
        return err, np.linalg.lstsq(J, err, rcond=1e-9)[0]

    def null(t):
        _, s, vt = np.linalg.svd(closure(t)[1])
        r = int(np.sum(s > 1e-6))
        return r, vt[r:].T
    return step, null


def test_local_mobility_on_a_toy_system():
    """Two constraints in the plane, ``y = x²`` and ``y = 0``, meet at the origin only; at
    the origin the Jacobian has rank 1. Doubling the line (``y = 0`` twice) keeps the
    whole line: finite 1, regular."""
    import numpy as np

    parabola = (lambda t: t[1] - t[0] ** 2, lambda t: [-2 * t[0], 1.0])
    line = (lambda t: t[1], lambda t: [0.0, 1.0])
    N = np.array([[1.0], [0.0]])
    lm = local_mobility(*make([parabola, line]), N, 1, 1e-6)
    assert (lm.finite, lm.configuration) == (0, "shaky")
    lm = local_mobility(*make([line, line]), N, 1, 1e-6)
    assert (lm.finite, lm.configuration) == (1, "regular")


@pytest.mark.parametrize("seed", range(40))
def test_two_branches_crossing_along_a_line(seed):
    """``x y = 0`` in space: the planes ``x = 0`` and ``y = 0`` cross along the z axis, and
    the origin lies on that crossing. Each branch is 2-dimensional, the Jacobian is zero at
    the origin (instantaneous 3): finite 2, singular. A landing point near the z axis sees
    both planes within its probing distance; a branch is never wider than the
    instantaneous motions at its point (2 off the axis), which keeps it from reading 3."""
    import numpy as np

    step, null = make([(lambda t: t[0] * t[1], lambda t: [t[1], t[0], 0.0])])
    lm = local_mobility(step, null, np.eye(3), 0, 1e-9, seed=seed)
    assert (lm.instantaneous, lm.finite, lm.configuration) == (3, 2, "singular")


@pytest.mark.parametrize("seed", range(20))
def test_a_cusp_is_never_read_smooth(seed):
    """``y² = x³``: one curve through the origin, but with a cusp there (its tangent cone is a
    half-line, not a line): never shaky or regular; singular, or said not followed where
    the steps towards ``x < 0``, which has no assembly near, fail."""
    import numpy as np

    step, null = make([(lambda t: t[1] ** 2 - t[0] ** 3, lambda t: [-3 * t[0] ** 2, 2 * t[1]])])
    lm = local_mobility(step, null, np.eye(2), 0, 1e-9, seed=seed)
    assert (lm.finite, lm.configuration) in ((1, "singular"), (None, "not followed"))
