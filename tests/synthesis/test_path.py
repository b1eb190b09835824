"""Path-generation problem: objective, constraints, feasibility-first scoring, parsing."""

import copy

import numpy as np
import pytest
from dimsynth_data import public_cases, public_data  # noqa: F401  (fixtures)

from mechsyn.errors import MechsynInputError
from mechsyn.synthesis.path import PathCase, PathProblem, evaluate_design


def test_published_designs_recompute_and_are_feasible(public_cases):
    for case in public_cases.values():
        for sol in case.published:
            if "branch" in sol:  # recorded on the other branch: infeasible for this case
                continue
            out = evaluate_design(case, sol["x"])
            assert out["error"] == pytest.approx(sol["recomputed_error"], rel=1e-9)
            assert out["feasible"] and out["assembled_at_all_targets"], sol["label"]


def test_other_branch_vector_is_not_accepted_on_the_case_branch(public_cases):
    case = public_cases["P5_ellipse10_notiming"]
    sol = next(s for s in case.published if s.get("branch") == 1)
    out = evaluate_design(case, sol["x"])
    assert out["error"] > 100 * sol["recomputed_error"]
    plus = PathCase.from_dict({**case.raw, "kinematics": {"branch": 1}})
    assert evaluate_design(plus, sol["x"])["error"] == pytest.approx(sol["recomputed_error"], rel=1e-9)


def test_infeasible_designs_are_never_rewarded(public_cases):
    for case in public_cases.values():
        prob = PathProblem(case)
        rng = np.random.default_rng(1)
        Z = rng.uniform(prob.lower, prob.upper, (20000, prob.dim))
        if case.timing == "free":  # random increments almost never keep the order: project
            Z = prob.expand(Z[:, :prob.reduced_dim])
        ev = prob.evaluate(Z)
        f = prob.fitness(Z)
        feas = ev.feasible
        assert feas.any() and (~feas).any()
        assert f[~feas].min() > f[feas].max()
        assert np.all(f[feas] == ev.error[feas])
        # and worse than any design within the bounds could ever score
        assert f[~feas].min() > prob.penalty_base


def test_non_assembling_design_with_small_clipped_error_loses():
    """A 'design' whose clipped / real-part coupler point would hit the targets exactly
    but that cannot be assembled must score worse than a poor feasible design."""
    T = [[1.0, 1.0], [1.2, 1.1], [1.3, 1.3]]
    case = PathCase.from_dict({
        "targets": T, "timing": {"type": "prescribed", "theta2": [0.3, 0.5, 0.7]},
        "fixed": {"x0": 0, "y0": 0, "theta0": 0},
        "variables": [{"name": n, "lower": -10 if n.startswith("rc") else 0, "upper": 10}
                      for n in ("r1", "r2", "r3", "r4", "rcx", "rcy")]})
    prob = PathProblem(case)
    bad = np.array([[9.0, 1.0, 1.0, 1.0, 0.0, 0.0]])  # r3 + r4 = 2 < |A O4| ~ 8: never assembles
    ev = prob.evaluate(bad)
    assert not ev.feasible[0] and not ev.assembled_at_all_targets[0]
    good = np.array([[3.0, 1.0, 3.0, 2.0, 5.0, 5.0]])
    assert prob.evaluate(good).feasible[0]
    assert prob.fitness(bad)[0] > prob.fitness(good)[0]


def test_grashof_and_order_constraints(public_cases):
    case = public_cases["P5_ellipse10_notiming"]
    prob = PathProblem(case)
    sol = next(s for s in case.published if s["label"] == "W.-Y. Lin")["x"]
    z = prob.internal(sol)
    assert prob.evaluate(z[None]).feasible[0]
    # reversed visiting order: increments sum to far more than one turn -> infeasible
    rev = dict(sol, theta2=list(reversed(sol["theta2"])))
    assert not prob.evaluate(prob.internal(rev)[None]).feasible[0]
    # non-Grashof lengths (triple rocker) are infeasible when the case asks for Grashof
    z2 = z.copy()
    z2[prob.names.index("r2")] = 60.0
    assert not prob.evaluate(z2[None]).feasible[0]


def test_sweep_between_targets_must_stay_assembled():
    """Prescribed angles on both sides of a dead position: assembled AT the targets but not
    between them, so the crank cannot move from one to the next (order defect)."""
    # crank r2 = 2 with r1 = 3, r3 = 2, r4 = 2: assembles for |A O4| <= 4, i.e. cos t >= -0.25
    base = {"timing": {"type": "prescribed", "theta2": [1.6, 4.6]}, "fixed": {"x0": 0, "y0": 0, "theta0": 0},
            "targets": [[0, 0], [0, 0]],
            "variables": [{"name": n, "lower": -10, "upper": 10} for n in ("r1", "r2", "r3", "r4", "rcx", "rcy")]}
    case = PathCase.from_dict(base)
    prob = PathProblem(case)
    z = np.array([[3.0, 2.0, 2.0, 2.0, 0.0, 0.0]])
    ev = prob.evaluate(z)
    assert ev.assembled_at_all_targets[0] is np.True_ or ev.assembled_at_all_targets[0]
    assert not ev.feasible[0]
    # going the short way round through theta = 0 is fine
    case2 = PathCase.from_dict({**base, "timing": {"type": "prescribed", "theta2": [1.6, -1.683]}})
    assert PathProblem(case2).evaluate(z).feasible[0]


def test_transmission_angle_and_link_ratio_options(public_cases):
    raw = copy.deepcopy(public_cases["P2_kk5_timing"].raw)
    sol = raw["published_solutions"][2]["x"]
    raw["options"] = {"transmission_angle_min_deg": 89.0}
    assert not evaluate_design(PathCase.from_dict(raw), sol)["feasible"]
    raw["options"] = {"transmission_angle_min_deg": 10.0, "link_ratio_max": 1.5}
    assert not evaluate_design(PathCase.from_dict(raw), sol)["feasible"]
    raw["options"] = {"transmission_angle_min_deg": 10.0, "link_ratio_max": 3.0}
    assert evaluate_design(PathCase.from_dict(raw), sol)["feasible"]


def test_free_timing_projection_gives_real_designs(public_cases):
    case = public_cases["P5_ellipse10_notiming"]
    prob = PathProblem(case)
    sol = next(s for s in case.published if s["label"] == "W.-Y. Lin")["x"]
    z = prob.internal(sol)
    m = prob.reduced_dim
    zp = prob.expand(z[None, :m])[0]
    # the projected angles are at least as good as the published ones (nearest points)
    assert prob.fitness(zp[None])[0] <= prob.fitness(z[None])[0] * (1 + 1e-6)
    assert np.allclose(np.angle(np.exp(1j * (zp[m:] - z[m:]))), 0, atol=1e-3)
    d = prob.design(zp)
    assert set(d) == {v.name for v in case.variables}
    assert all(0 <= d[f"theta2_{i}"] < 2 * np.pi for i in range(1, 11))


@pytest.mark.parametrize("mutate, field", [
    (lambda c: c.pop("targets"), "targets"),
    (lambda c: c.update(targets=[[1, 2, 3]]), "targets"),
    (lambda c: c.update(timing={"type": "sometimes"}), "timing.type"),
    (lambda c: c["timing"].update(theta2=[0.1, 0.2]), "timing.theta2"),
    (lambda c: c["variables"].append({"name": "r9", "lower": 0, "upper": 1}), "variables[6].name"),
    (lambda c: c["variables"][0].update(lower=5, upper=1), "variables[0]"),
    (lambda c: c["variables"].pop(0), "variables"),
    (lambda c: c.update(kinematics={"branch": 0}), "kinematics.branch"),
    (lambda c: c["fixed"].update(x0="abc"), "fixed.x0"),
])
def test_bad_cases_name_the_field(public_data, mutate, field):
    raw = copy.deepcopy(public_data["cases"][0])
    mutate(raw)
    with pytest.raises(MechsynInputError) as exc:
        PathCase.from_dict(raw, source="case.json")
    assert exc.value.field == field


def test_prescribed_increment_timing():
    case = PathCase.from_dict({
        "targets": [[0, 1], [1, 1], [2, 1]], "timing": {"type": "prescribed_increment", "step": 0.2},
        "variables": [{"name": n, "lower": 0, "upper": 5} for n in ("r1", "r2", "r3", "r4", "rcx", "rcy", "theta2_1")]})
    prob = PathProblem(case)
    vals, th, sweeps = prob.unpack(np.array([[3, 1, 3, 2, 1, 1, 0.5]]))
    assert np.allclose(th, [[0.5, 0.7, 0.9]])


def _change_point_case(**options):
    return PathCase.from_dict({
        "targets": [[0.0, 1.0], [0.0, 2.0]], "timing": {"type": "prescribed", "theta2": [1.0, 2.0]},
        "constraints": ["Grashof"], "options": options,
        "variables": [{"name": k, "lower": 0, "upper": 5} for k in ("r1", "r2", "r3", "r4", "rcx", "rcy")]})


def test_grashof_equality_folds_flat_and_is_refused_by_default():
    # s + l = p + q (1 + 3 = 2 + 2): the crank reaches theta2 = 0, where all four pivots
    # line up, so the linkage folds flat once per turn (a change point)
    flat = {"r1": 3.0, "r2": 1.0, "r3": 2.0, "r4": 2.0, "rcx": 0.5, "rcy": 0.2}
    out = evaluate_design(_change_point_case(), flat)
    assert out["fold_distance_deg"] == pytest.approx(0.0, abs=1e-6)
    assert not out["feasible"]
    assert evaluate_design(_change_point_case(fold_margin_deg=0), flat)["feasible"]
    # a little inside Grashof: feasible; its fold distance is the worst transmission angle
    # at theta2 = 0 and pi (cos mu = (r3^2 + r4^2 - (r1 -/+ r2)^2) / (2 r3 r4)), by hand
    inside = {**flat, "r1": 2.8}
    out = evaluate_design(_change_point_case(), inside)
    mu = np.degrees(np.arccos([(8 - 1.8 ** 2) / 8, (8 - 3.8 ** 2) / 8]))
    assert out["feasible"] and out["fold_distance_deg"] == pytest.approx(np.min(np.minimum(mu, 180 - mu)))


def test_minimum_transmission_angle_over_the_motion_is_the_default():
    case = _change_point_case(fold_margin_deg=0)
    assert case.transmission_angle_min_deg == 20.0
    # r3 = r4 = 2, r1 = 3, r2 = 1: mu(theta2) from cos mu = (8 - 10 + 6 cos t) / 8
    design = {"r1": 3.0, "r2": 1.0, "r3": 2.0, "r4": 2.0, "rcx": 0.5, "rcy": 0.2}
    t = np.linspace(1.0, 2.0, 2001)
    mu = np.degrees(np.arccos((8 - 10 + 6 * np.cos(t)) / 8))
    worst = np.min(np.minimum(mu, 180 - mu))
    out = evaluate_design(case, design)
    assert out["worst_transmission_angle_deg"] == pytest.approx(worst, abs=1e-6)
    tight = _change_point_case(fold_margin_deg=0, transmission_angle_min_deg=worst + 0.5)
    assert out["feasible"] and not evaluate_design(tight, design)["feasible"]


def test_residual_jacobian_is_one_batch_of_forward_differences(public_cases):
    from scipy.optimize._numdiff import approx_derivative

    prob = PathProblem(public_cases["P2_kk5_timing"])
    z = prob.internal(public_cases["P2_kk5_timing"].published[0]["x"])
    np.testing.assert_allclose(prob.residuals_batch(z[None])[0], prob.residuals(z))
    J = prob.residual_jacobian(z)
    ref = approx_derivative(prob.residuals, z, method="2-point", bounds=(prob.lower, prob.upper))
    np.testing.assert_allclose(J, ref, rtol=1e-6, atol=1e-6)
