"""What ``simulate`` does around the engine on every call (issue 30, the per-call work): the
checks of the inputs kept per plan, the drawn row remembered per input bytes, radians and
degrees as products, the rows of a sweep through folds. Each answer is compared with the
computation it replaces."""

import math

import numpy as np
import pytest

from mechsyn.errors import MechsynInputError
from mechsyn.kinematics import engines
from mechsyn.kinematics.analysis import _DEG, _RAD, cached_plan, input_grid, simulate

from kinematics_helpers import ex  # noqa: F401


def test_radians_and_degrees_as_products_are_numpys_bit_for_bit(ex):
    """The factors simulate multiplies by give np.radians / np.degrees to the bit (sign of
    zero included), and a simulation's inputs and link angles are those of the ufuncs."""
    rng = np.random.default_rng(30)
    x = np.concatenate([rng.uniform(-1e3, 1e3, 200_000), rng.normal(0, 1e-3, 50_000),
                        np.arange(-720.0, 720.0, 0.01), [0.0, -0.0, 5e-324, 1e300, -1e300]])
    for got, want in ((x * _RAD, np.radians(x)), (x * _DEG, np.degrees(x))):
        assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))
    m = ex("textbook/watt_sixbar.yaml")
    vals = input_grid(-37.5, 322.5, 0.75)
    s = simulate(m, {"A": vals})
    assert np.array_equal(s.sweep.inputs[:, 0], np.radians(vals))
    for i, name in enumerate(s.system.links):
        assert np.array_equal(s.link(name).angle, np.degrees(s.sweep.q[:, 3 * i + 2]), equal_nan=True)
        assert s.link(name).angular_velocity is not None and s.link(name).angle.flags.c_contiguous


@pytest.mark.parametrize("start, stop, step", [(0, 360, 1), (-3.7, 11.0, 0.013), (1, 0, -0.25), (-0.0, -10, -2.5),
                                               (0.1, 1.0, 0.1), (1e10, 1e10 + 700, 7.3)])
def test_input_grid_numbers_are_start_plus_step_times_k(start, stop, step):
    """The grid built in place on a float arange holds the numbers ``start + step * k``
    of the integer arange (signs of zero included) and its count."""
    got = input_grid(start, stop, step)
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    want = start + step * np.arange(n)
    assert np.array_equal(got, want) and np.array_equal(np.signbit(got), np.signbit(want))


def test_input_grid_of_an_overflowing_count_is_refused_in_one_line():
    """A range whose count overflows to infinity is over the limit, not an OverflowError."""
    with pytest.raises(MechsynInputError, match="more than the limit"):
        input_grid(-1e308, 1e308, 1e-300)
    with pytest.raises(MechsynInputError, match="no sweep"):
        input_grid(0.0, math.inf, 1.0)


@pytest.mark.parametrize("f, j", [("kinematics/crank_rocker.yaml", "A"), ("textbook/watt_sixbar.yaml", "A"),
                                  ("textbook/fourbar.yaml", "A"), ("kinematics/jansen_leg.yaml", "P0")])
def test_drawn_row_remembered_equals_the_row_computed(ex, f, j):
    """drawn_row's answer for inputs it has seen (the same bytes, the same drawn values) is
    the one computed anew, for grids through, around and away from the drawn input; the
    same grid with another mechanism's drawn value is not mistaken for it."""
    S = cached_plan(ex(f), inputs=(j,)).system
    u0 = math.degrees(S.drivers[0].assembled)
    grids = [input_grid(0, 360, 1), input_grid(360, 0, -3), u0 + input_grid(-30, 30, 0.5), u0 + np.array([10.0]),
             u0 + input_grid(5, 90, 5), input_grid(-180, 540, 2.5), u0 + 720 + input_grid(-5, 5, 10)]
    for g in grids:
        U = np.radians(g)[:, None]
        want = None if len(U) < 2 else engines._segment_row(S.drivers, U.copy())
        engines.CACHE.clear()
        assert engines.drawn_row(S, U) == want  # computed
        assert engines.drawn_row(S, U.copy()) == want  # remembered
    big = np.radians(input_grid(-180, 540, 0.005))[:, None]  # over 64 KiB: computed, not kept
    engines.CACHE.clear()
    assert engines.drawn_row(S, big) == engines._segment_row(S.drivers, big.copy())
    assert engines.CACHE.get(("input grid", big.shape, big.dtype.str)) is None
    other = cached_plan(ex("textbook/stephenson_sixbar.yaml"), inputs=("A",)).system
    U = np.radians(u0 + input_grid(-30, 30, 0.5))[:, None]
    assert engines.drawn_row(S, U) is not None
    assert engines.drawn_row(other, U) == engines._segment_row(other.drivers, U.copy())


def test_drawn_row_of_several_inputs_is_the_first_segment_through_the_drawn_values():
    """Two inputs (R and P, or two R): the row of the first segment that holds the drawn
    values (an R value up to whole turns), checked against a plain loop over the rows
    (a point of the segment: on its line, between its ends)."""
    class Driver:
        def __init__(self, type_, assembled):
            self.type, self.assembled = type_, assembled

    def by_loop(drivers, U):
        for k in range(1, len(U)):
            a, d = U[k - 1], U[k] - U[k - 1]
            for turn in (-1, 0, 1, 2, 3):
                v = np.array([dr.assembled + (2 * np.pi * (np.rint((a[i] - dr.assembled) / (2 * np.pi)) + turn - 1)
                                               if dr.type == "R" else 0.0) for i, dr in enumerate(drivers)])
                t = float((v - a) @ d / (d @ d))
                if 0 < t <= 1 and np.abs(a + t * d - v).max() <= 1e-12 * (1 + np.abs(v).max()):
                    return k
        return None

    rng = np.random.default_rng(7)
    found = 0
    for trial in range(200):
        drivers = [Driver("R", rng.uniform(-7, 7)), Driver("P" if trial % 2 else "R", rng.uniform(-1, 1))]
        U = np.stack([np.linspace(rng.uniform(-10, 0), rng.uniform(0, 10), 40),
                      np.linspace(rng.uniform(-2, 0), rng.uniform(0, 2), 40)], axis=1)
        if trial % 3 == 0:  # the second input held at its drawn value: the first decides
            U[:, 1] = drivers[1].assembled
        want = engines._segment_row(drivers, U)
        assert want == by_loop(drivers, U), trial
        found += want is not None
    assert found >= 50  # (rows found, not only None)


def test_a_sweep_through_folds_is_nan_on_whole_rows(ex):
    """The regular pass through folds says its rows are NaN whole and which rows have
    rates: that must be so (simulate's named points and rates_ok rely on it)."""
    s = simulate(ex("textbook/watt_sixbar.yaml"), {"A": input_grid(0, 360, 1)})
    sw = s.sweep
    assert sw.nan_rows and (~s.assembled).sum() > 10
    if sw.links is not None:  # the compiled pass's link states: NaN where the poses are
        C = sw.links.C
        assert np.isnan(C[:, :, ~s.assembled]).all() and np.isfinite(C[0][:, s.assembled]).all()
    ok = np.isfinite(sw.q).all(axis=1)
    rates = np.isfinite(sw.qd).all(axis=1) & np.isfinite(sw.qdd).all(axis=1)
    assert np.array_equal(sw.rates_ok, rates) and np.array_equal(sw.assembled, ok)
    assert np.isnan(sw.q[~ok]).all() and np.isnan(sw.qd[~rates]).all() and np.isnan(sw.qdd[~rates]).all()
    P = s.points["P"]
    assert np.isnan(P.position[~ok]).all() and np.isfinite(P.position[ok]).all()
    assert np.isnan(P.velocity[~rates]).all() and np.isfinite(P.acceleration[rates]).all()
    for name, pm in s.points.items():  # every point, on the frame too: NaN exactly where the poses are
        assert np.isnan(pm.position[~ok]).all() and np.isfinite(pm.position[ok]).all(), name
        assert np.isnan(pm.velocity[~rates]).all() and np.isfinite(pm.velocity[rates]).all(), name


def test_input_errors_one_line_each_in_input_order(ex):
    """The checks kept per plan and input names give the errors they gave, the first
    input's first (not driven, then not finite, then outside its limits), and a plan
    asked first with good inputs still refuses bad ones."""
    m = ex("kinematics/crank_rocker.yaml")
    x = input_grid(0, 90, 10)
    simulate(m, {"A": x})  # the spec of ("A",) kept

    def refused(inputs, match, **kw):
        with pytest.raises(MechsynInputError, match=match):
            simulate(m, inputs, **kw)

    refused({"A": np.r_[x[:-1], np.nan]}, "input values of A must be finite")
    refused({"A": np.r_[x[:-1], np.inf]}, "input values of A must be finite")
    refused({"Q": x}, "no joint 'Q'")
    refused({"B": x}, r"joint B \(R\) is not driven")
    refused({"A": x, "B": x[:3]}, "same number of values")
    refused({"A": []}, "input range is empty")
    refused({"B": [np.nan], "A": [1.0]}, "joint B .* is not driven")  # the first input's error first
    refused({"A": [np.nan], "B": [1.0]}, "input values of A must be finite")
    refused({"A": x}, "a speed is given for C", speeds={"C": 2.0})
    refused({"A": x}, "speeds must be finite", speeds={"A": math.nan})
    s = simulate(m, {"A": x}, speeds={"A": 2.0})
    assert s.speeds == {"A": 2.0} and np.array_equal(s.sweep.speeds, [2.0])
    f = ex("fingers/two_phalanx_vll_000.yaml")
    with pytest.raises(MechsynInputError, match=r"input of S goes outside its limits \[24, 34\]"):
        simulate(f, {"E": [0.0, 1.0], "S": [25.0, 40.0]}, vll={"S": "active"})
