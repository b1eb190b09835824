"""Paper 000's parametric steps 8-13 (issue 8 item 5): ``synthesis.finger``.

Small optimiser budgets keep these fast; the bundled case's targets come from a
reference finger, so an exact solution exists and the tolerance below is meaningful.
"""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError
from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.kinematics.analysis import simulate
from mechsyn.kinematics.system import build_system
from mechsyn.synthesis.finger.cases import case_from_dict, load_case
from mechsyn.synthesis.finger.design import design_finger, stage1_objective
from mechsyn.synthesis.finger.evaluation import INFEASIBLE, evaluate_locked
from mechsyn.synthesis.finger.modes import force_objective
from mechsyn.synthesis.finger.vll import points_in_region

EX = Path(__file__).resolve().parents[2] / "examples" / "fingers"
CASE = EX / "finger_design_case.yaml"
TOL_DEG = 1.5   # max target error reached with the small test budget (the bundled run: < 0.01 deg)


def small(case):
    case.maxiter, case.popsize, case.force_maxiter, case.vll_steps = 25, 8, 4, 6
    return case


@pytest.fixture(scope="module")
def result():
    case = small(load_case(CASE))
    states: list = []
    res = design_finger(case, seed=3, time_limit=60, progress=states.append)
    res.states = states
    return case, res


def _drawn(mech, jid):
    S = build_system(mech)
    return float(np.degrees(next(d.assembled for d in S.drivers if d.joint == jid)))


def test_design_assembles_on_one_branch_and_meets_targets(result):
    case, res = result
    v = res.best_variant
    assert v.error_max <= TOL_DEG
    # independent check: the full file (cylinder + piston, VLL locked) by Newton continuation,
    # on a dense crank grid from the open to the closed extreme
    mech = mechanism_from_dict(v.mechanism)
    th0 = _drawn(mech, "E")
    grid = np.arange(0.0, 60.0 + 1e-9, 0.5)
    sim = simulate(mech, {"E": th0 + grid}, points=["tip"], vll={"S": "locked"}, method="newton")
    assert sim.assembled.all()
    assert not [e for e in sim.events if e["kind"] in ("dead point", "branch point", "singular")]
    S = sim.system
    idx = np.searchsorted(grid, case.target_inputs)
    for link, target in case.target_angles.items():
        i = S.index(link)
        rot = sim.links[link].angle[idx] - np.degrees(S.q0[3 * i + 2])
        np.testing.assert_allclose(rot, v.achieved[link], atol=1e-6)   # closed form == Newton
        assert np.max(np.abs(rot - target)) <= TOL_DEG


@pytest.mark.slow
def test_vll_range_keeps_paths_in_region_dense_resimulation(result):
    case, res = result
    v = res.best_variant
    lo, hi = v.vll_ranges["S"]
    assert lo == 24.0 and hi > lo          # the minimum constructible length, a real range
    mech = mechanism_from_dict(v.mechanism)
    th0 = _drawn(mech, "E")
    crank = np.arange(0.0, 60.0 + 1e-9, 1.0)
    for length in np.linspace(lo, hi, 7):
        sim = simulate(mech, {"E": th0 + crank, "S": np.full(len(crank), length)}, points=["tip"],
                       vll={"S": "free"}, method="newton")
        assert sim.assembled.all()
        assert points_in_region(sim.points["tip"].position, case.region).all(), length
    # and just beyond l_max some path leaves the region or the finger no longer assembles
    if hi < case.vll_limits("S")[1] - 1e-6:
        beyond = min(hi + 0.05 * (hi - lo) + 0.05, case.vll_limits("S")[1])
        d = copy.deepcopy(v.mechanism)
        for j in d["joints"]:
            if j["id"] == "S":
                j["limits"] = [lo, case.vll_limits("S")[1]]
        sim = simulate(mechanism_from_dict(d), {"E": th0 + crank, "S": np.full(len(crank), beyond)},
                       points=["tip"], vll={"S": "free"}, method="newton")
        assert not (sim.assembled.all() and points_in_region(sim.points["tip"].position, case.region).all())


def test_progress_reports_best_error_so_far(result):
    _case, res = result
    import re

    first = next(p.stage for p in res.states if p.stage.endswith(": stage 1"))  # "VLL S: stage 1"
    stage1 = [p for p in res.states if p.stage == first]  # its generations, counted within it
    assert [p.done for p in stage1] == list(range(1, len(stage1) + 1))
    best = [float(m.group(1)) for m in (re.search(r"generation \d+/\d+, best RMS error (\S+) deg", p.message)
                                        for p in stage1) if m]
    assert len(best) >= 2 and all(b <= a for a, b in zip(best, best[1:]))
    assert best[-1] == pytest.approx(res.best_variant.stage1_error_rms, rel=1e-3)   # printed to 4 digits
    generations = [p for p in stage1 if p.best is not None]
    assert generations[-1].best == pytest.approx(best[-1], rel=1e-3) and generations[-1].total


def test_force_stage_never_increases_peak_reaction(result):
    _case, res = result
    v = res.best_variant
    assert v.forces["peak_reaction"] <= v.stage1_forces["peak_reaction"] + 1e-12
    assert v.forces["criterion"] <= v.stage1_forces["criterion"] + 1e-12
    fa = v.forces["fully_actuated"]
    assert fa["assembled"] and all(u["assembled"] for u in v.forces["underactuated"])


def test_mode_forces_match_engine_newton_on_full_file(result):
    """Both modes' peaks from the fast merged model equal the kinematics engine's Newton
    solution of the full file (cylinder + piston; VLL locked, then free and held)."""
    case, res = result
    from mechsyn.kinetostatics import forces

    v = res.best_variant
    mech = mechanism_from_dict(v.mechanism)
    grid = _drawn(mech, "E") + case.sweep_inputs
    fa = forces(mech, {"E": grid}, gravity=(0, -case.gravity), static=True, vll={"S": "locked"},
                method="newton")
    assert v.forces["fully_actuated"]["peak_input_moment"] == pytest.approx(
        float(np.max(np.abs(fa.reactions.effort["E"]))), rel=1e-6)
    for s in v.forces["underactuated"]:
        fu = forces(mech, {"E": grid, "S": np.full(len(grid), s["vll_length"])}, gravity=(0, -case.gravity),
                    static=True, vll={"S": "free"}, method="newton")
        assert fu.simulation.assembled.all()
        assert s["peak_input_moment"] == pytest.approx(float(np.max(np.abs(fu.reactions.effort["E"]))), rel=1e-5)
        peak_engine = max(float(np.max(np.linalg.norm(fu.reactions.force[j], axis=1))) for j in "ABCDEKL")
        assert s["peak_reaction"] == pytest.approx(peak_engine, rel=1e-5)
        # the force a spring / stop holding the free VLL must supply (engine: the P pair's effort) equals
        # the merged link's axial force at the piston's pivot L up to the piston's own weight
        piston_weight = 0.002 * case.gravity
        assert abs(s["vll_force_peak"] - float(np.max(np.abs(fu.reactions.effort["S"])))) <= piston_weight


def test_infeasible_designs_get_no_reward():
    case = load_case(CASE)
    f = stage1_objective(case, ("S",))
    ref = np.array([14, 6, 8, 48, 123.69006753])        # the reference finger: feasible
    assert f(ref) < 0.01
    far = np.array([8, 0, 14, 56, 100.0])                # rod too short/long: no assembly
    ev = evaluate_locked(case, far, ("S",))
    if ev.feasible:                                     # (pick a surely unassemblable one)
        far = np.array([20, 12, 3, 42, 150.0])
        ev = evaluate_locked(case, far, ("S",))
    assert not ev.feasible and f(far) >= INFEASIBLE
    # a region that the reference's path leaves: infeasible though the targets are met exactly
    tight = copy.deepcopy(case)
    tight.region = np.array([[-6, 50], [10, 50], [10, 76], [-6, 76]], float)
    ev = evaluate_locked(tight, ref, ("S",))
    assert not ev.feasible and ev.error_rms < 0.01
    assert stage1_objective(tight, ("S",))(ref) >= INFEASIBLE > f(ref)
    assert force_objective(tight, ("S",), 1.0)(ref) >= INFEASIBLE


def test_cli_json_out_and_plot(tmp_path, capsys):
    data = yaml.safe_load(CASE.read_text())
    data["mechanism"] = str(EX / data["mechanism"])
    data["optimizer"] = {"maxiter": 10, "popsize": 6, "force_maxiter": 2, "vll_steps": 4}
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(data))
    out, png = tmp_path / "best.yaml", tmp_path / "fd.png"
    code = main(["synth", "finger-design", str(case), "--seed", "2", "--json", "--out", str(out),
                 "--plot", str(png)])
    assert code == 0
    js = json.loads(capsys.readouterr().out)
    b = js["best"]
    assert b["assembled_at_all_targets"] is True and b["combination"] == ["S"]
    assert set(b["design"]) == {"D.x", "D.y", "C.x", "C.y", "S.angle"}
    assert b["vll_ranges"]["S"][1] >= b["vll_ranges"]["S"][0] == 24.0
    assert png.stat().st_size > 10_000
    mech = load_mechanism(out)                            # loadable by analyze / simulate
    S = mech.joint("S")
    assert list(S.limits) == pytest.approx(b["vll_ranges"]["S"])
    assert main(["simulate", str(out), "--input", "E=100:110:5", "--json"]) == 0


@pytest.mark.parametrize("mutate, args", [
    (None, ["--time-limit", "0"]),
    (None, ["--plot", "x.jpg"]),
    (lambda d: d.pop("targets"), []),
    (lambda d: d.update(input="A"), []),
    (lambda d: d["variables"].append({"joint": "Z", "bounds": [0, 1]}), []),
    (lambda d: d["variables"].append({"joint": "L", "bounds": [0, 1]}), []),
    (lambda d: d["variables"].__setitem__(0, {"joint": "D", "bounds": [5, 1]}), []),
    (lambda d: d.update(region=[[0, 0], [1, 1]]), []),
    (lambda d: d.update(targets=[{"input": 0, "proximal": 0}]), []),
    (lambda d: d.update(combinations=[["K"]]), []),
    (lambda d: d.update(mechanism="nope.yaml"), []),
    (lambda d: d.update(masses={"nolink": {"mass": 1}}), []),
    (lambda d: d.update(masses={"distal": {"mass": "heavy"}}), []),
    (lambda d: d.update(loads=[{"link": "distal", "force": [1]}]), []),
])
def test_cli_bad_inputs_exit_2(tmp_path, capsys, mutate, args):
    data = yaml.safe_load(CASE.read_text())
    data["mechanism"] = str(EX / data["mechanism"])
    if mutate is not None:
        mutate(data)
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(data))
    assert main(["synth", "finger-design", str(case), *args]) == 2
    assert "error" in capsys.readouterr().err


def test_missing_case_file_exit_2(tmp_path):
    assert main(["synth", "finger-design", str(tmp_path / "none.yaml")]) == 2


def test_case_from_dict_rejects_non_mapping():
    with pytest.raises(MechsynInputError):
        case_from_dict([1, 2, 3])


def _tiny_case():
    case = load_case(CASE)
    case.maxiter, case.popsize, case.force_maxiter, case.vll_steps, case.candidates = 4, 5, 1, 3, 1
    return case


def test_same_seed_same_design():
    a = design_finger(_tiny_case(), seed=7)
    b = design_finger(_tiny_case(), seed=7)
    assert a.best_variant.design == b.best_variant.design
    assert a.best_variant.vll_ranges == b.best_variant.vll_ranges


def test_no_feasible_design_is_an_input_error(tmp_path, capsys):
    data = yaml.safe_load(CASE.read_text())
    data["mechanism"] = str(EX / data["mechanism"])
    data["region"] = [[100, 100], [110, 100], [110, 110]]     # no finger reaches it
    data["optimizer"] = {"maxiter": 2, "popsize": 5}
    case = tmp_path / "case.yaml"
    case.write_text(yaml.safe_dump(data))
    assert main(["synth", "finger-design", str(case)]) == 2
    assert "no feasible design" in capsys.readouterr().err


@pytest.mark.slow
def test_three_phalanx_every_vll_combination(tmp_path):
    """Two VLLs: the combinations S1, S2 and S1+S2 are each designed; the best has the
    smallest force criterion; a VLL outside the combination is rigid at its drawn length."""
    case = load_case(EX / "finger_design_three_phalanx.yaml")
    case.maxiter, case.popsize, case.force_maxiter, case.vll_steps, case.candidates = 12, 6, 2, 4, 1
    res = design_finger(case, seed=0)
    assert [v.combination for v in res.variants] == [("S1",), ("S2",), ("S1", "S2")]
    crit = [v.forces["criterion"] for v in res.variants]
    assert res.best == int(np.argmin(crit)) and min(crit) > 0      # masses and loads from the case
    for v in res.variants:
        assert v.assembled_at_all_targets and v.error_max <= 2.0
        assert set(v.vll_ranges) == set(v.combination)
        for jid, (lo, hi) in v.vll_ranges.items():
            assert lo == case.vll_limits(jid)[0] and hi >= lo
        lengths = {j["id"]: float(np.linalg.norm(np.subtract(j["point"], next(
            k["point"] for k in v.mechanism["joints"] if k["id"] == ("K1" if j["id"] == "S1" else "K2")))))
            for j in v.mechanism["joints"] if j["id"] in ("S1", "S2")}
        for jid, length in lengths.items():
            if jid in v.combination:
                assert length == pytest.approx(case.vll_limits(jid)[0])
            else:
                assert length > case.vll_limits(jid)[0] + 1.0           # drawn length, not the minimum


def test_cli_json_is_the_result_to_dict(tmp_path, capsys):
    """``synth finger-design --json`` prints the library result's ``to_dict()`` (the
    run's seconds aside), with the common fields of a synthesis result."""
    from mechsyn.results import to_jsonable

    data = yaml.safe_load(CASE.read_text())
    data["mechanism"] = str(EX / data["mechanism"])
    data["optimizer"] = {"maxiter": 4, "popsize": 5, "force_maxiter": 1, "vll_steps": 3, "candidates": 1}
    path = tmp_path / "case.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["synth", "finger-design", str(path), "--seed", "4", "--json"]) == 0
    js = json.loads(capsys.readouterr().out)
    res = design_finger(load_case(path), seed=4)
    expected = json.loads(json.dumps(to_jsonable(res.to_dict())))
    js.pop("seconds"), expected.pop("seconds")
    assert js == expected
    assert js["design"] == js["best"]["design"] and js["x"] == list(js["design"].values())
    assert js["error"] == js["best"]["error_rms_deg"] and js["seed"] == 4 and js["nfev"] > 0
    assert js["feasible"] == (js["reason"] == "")


@pytest.mark.parametrize("name", ["finger_design_case.yaml", "finger_design_three_phalanx.yaml"])
def test_population_evaluation_equals_one_design_evaluation(name):
    """The compiled locked model (kinematics.batch, K designs at once) gives
    evaluate_locked's answers: assembly, violation, target errors, paths (issue 14 §3)."""
    from mechsyn.synthesis.finger.design import force_population, stage1_population
    from mechsyn.synthesis.finger.population import locked_population

    case = load_case(EX / name)
    rng = np.random.default_rng(5)
    lo, hi = np.array([v.bounds for v in case.variables]).T
    X = lo + rng.random((40, len(lo))) * (hi - lo)
    for combo in case.combinations:
        pop = locked_population(case, combo)
        assert pop is not None
        ev = pop.evaluate(X)
        kinds = set()
        for k, x in enumerate(X):
            one = evaluate_locked(case, x, combo)
            kinds.add((one.q is not None, one.feasible))
            assert bool(ev.feasible[k]) == one.feasible
            assert ev.violation[k] == pytest.approx(one.violation, rel=1e-9, abs=1e-9)
            if one.q is not None:
                assert ev.error_rms[k] == pytest.approx(one.error_rms, rel=1e-9, abs=1e-9)
                assert ev.error_max[k] == pytest.approx(one.error_max, rel=1e-9, abs=1e-9)
                for p, P in one.paths.items():
                    np.testing.assert_allclose(ev.paths[p][k], P, atol=1e-9)
        assert len(kinds) >= 2          # the sample holds feasible and infeasible designs
    combo = case.combinations[0]
    f1, g1 = stage1_objective(case, combo), stage1_population(case, combo)
    np.testing.assert_allclose(g1(X[:8]), [f1(x) for x in X[:8]], rtol=1e-9)
    f2, g2 = force_objective(case, combo, 5.0), force_population(case, combo, 5.0)
    np.testing.assert_allclose(g2(X[:8]), [f2(x) for x in X[:8]], rtol=1e-9)
