"""Benchmark: one full ``simulate`` (positions, velocities, accelerations, events) per
mechanism, as a ratio to a bare NumPy closed-form four-bar (positions only), and against
pylinkage in the same process (issue 30).

Run from the repository root::

    python benchmarks/kinematics_simulate.py [--repeats 30] [--big 1000000]

Cases (361 inputs, 0..360 degrees):

* ``crank-rocker``: examples/kinematics/crank_rocker.yaml, fully rotating (target <= 15x);
* ``four-bar, 2 dead points``: examples/textbook/fourbar.yaml (target <= 50x);
* ``Watt six-bar``, ``Stephenson six-bar``: examples/textbook/*_sixbar.yaml, with dead
  points (target <= 100x);
* ``Jansen leg``: examples/kinematics/jansen_leg.yaml with its knee double joint written
  three ways (target <= 100x);
* ``drag``: ``KinematicPlan.with_joint_points`` + ``simulate`` of the Watt six-bar (the
  editor's drag loop; no target in the issue, reported for the web app).

The bare NumPy reference computes the crank-rocker's joint positions B, C for the same
361 angles in five array expressions; mechsyn's answers are checked against it (1e-12),
and the dead points of the textbook four-bar against the law of cosines (1e-6 degree).
Times are minima (``3 x --repeats`` runs; the bare reference ``10 x``); ``x med`` is the
median of ``--repeats`` rounds' ratios, the case and the reference timed alternately.

Then the fixed costs of one call for the crank-rocker, the Watt six-bar and the Jansen leg
(issue 30), each stage looked up by name: a stage the code no longer has reads "n/a".

Then, when pylinkage is importable (``pip install pylinkage numba`` in a virtual
environment of its own, never a mechsyn dependency; without it one line says so), the
crank-rocker, the Watt six-bar (a full turn through its dead points, and a range without
them) and the Jansen leg are modelled in pylinkage from the same mechanisms
(benchmarks/pylinkage_models.py) and timed in this process, rounds interleaved:

* fresh, a joint moved each call: mechsyn ``Mechanism.with_joint_points`` (or, where it
  does not exist, the studio's path: ``mechanism_from_dict`` of the edited dict) and
  ``ms.simulate``; pylinkage build + ``compile`` + ``step_fast_with_kinematics``;
* cached: ``ms.simulate`` of the same mechanism again; ``step_fast_with_kinematics`` of a
  built, compiled linkage (numba compiled before any timing; the linkage put back to its
  start with ``set_coords`` between calls, untimed).

Positions, velocities and accelerations of every joint and named point are checked equal
to 1e-9 of the length scale on the rows both answer, and the rows each leaves unanswered
must be the same; the ratio mechsyn / pylinkage is the median of the rounds' ratios (and
the ratio of the minima), printed beside issue 30's targets. The crank-rocker is also
timed over ``--big`` inputs. Exit status 1 when an answer check fails.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import math
import sys
import textwrap
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "benchmarks"))

N = 361
TARGETS = {"crank-rocker": 15, "four-bar, 2 dead points": 50, "Watt six-bar": 100, "Stephenson six-bar": 100,
           "Jansen leg (double joint on foot)": 100, "Jansen leg (chain)": 100, "Jansen leg (star)": 100}
TOL = 1e-9  # answers equal to this fraction of the length scale


def bare_fourbar(theta: np.ndarray, A: np.ndarray, D: np.ndarray, a: float, b: float, c: float,
                 sigma: float) -> tuple[np.ndarray, np.ndarray]:
    """The reference: crank pin B and coupler-rocker joint C of a four-bar, closed form."""
    B = np.stack([A[0] + a * np.cos(theta), A[1] + a * np.sin(theta)], axis=1)
    d = D - B
    t = np.einsum("ij,ij->i", d, d)
    f = 0.5 + (b * b - c * c) / (2 * t)
    g = sigma * np.sqrt(b * b / t - f * f)
    C = B + f[:, None] * d + g[:, None] * np.stack([-d[:, 1], d[:, 0]], axis=1)
    return B, C


def read_all(sim):
    """Every array a simulation answers (each point's position, velocity and acceleration,
    each link's angle and rates), read: work a result defers until it is read is timed too,
    as pylinkage's step hands back all its arrays."""
    pts = [(p.position, p.velocity, p.acceleration) for p in sim.points.values()]
    links = [(lm.angle, lm.angular_velocity, lm.angular_acceleration) for lm in sim.links.values()]
    return sim, pts, links


def best_of(f, repeats: int) -> float:
    f()
    best = np.inf
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        best = min(best, time.perf_counter() - t)
    return best


def paired(f, ref, repeats: int, inner: int = 10) -> tuple[float, float, float]:
    """Median time of ``f``, median time of ``ref`` (each a median of ``inner`` calls) and
    the median of their ratios, the two timed alternately ``repeats`` times: on a shared
    machine both see the same load, so the ratio is steadier than either time."""
    f()
    ref()

    def med(g) -> float:
        ts = []
        for _ in range(inner):
            t = time.perf_counter()
            g()
            ts.append(time.perf_counter() - t)
        return float(np.median(ts))

    tf, tr = [], []
    for _ in range(repeats):
        tf.append(med(f))
        tr.append(med(ref))
    tf_, tr_ = np.array(tf), np.array(tr)
    return float(np.median(tf_)), float(np.median(tr_)), float(np.median(tf_ / tr_))


def both(f, ref, repeats: int, t_ref_min: float) -> tuple[float, float, float]:
    """(minimum time of ``f``, its ratio to the reference's minimum ``t_ref_min``, the
    median ratio of :func:`paired`)."""
    t = best_of(f, repeats * 3)
    return t, t / t_ref_min, paired(f, ref, repeats)[2]


def jansen(writing: str):
    import yaml

    from mechsyn.io import mechanism_from_dict

    d = yaml.safe_load((ROOT / "examples/kinematics/jansen_leg.yaml").read_text())
    J = {j["id"]: j for j in d["joints"]}
    if writing == "chain":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["c", "ghi"]
    elif writing == "star":
        J["P4"]["links"], J["P4_2"]["links"] = ["k", "c"], ["k", "ghi"]
    return mechanism_from_dict(d, f"jansen-{writing}")


def lookup(module: str, name: str):
    """``module.name``, or None where the code no longer has it (other branches rename
    the kinematics' internals: the table then says "n/a" instead of breaking)."""
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError):
        return None


def length_scale(mech) -> float:
    """The largest extent of the drawn joints (the scale of the answer checks)."""
    pts = np.array([np.asarray(j.point, float)[:2] for j in mech.joints])
    return float(np.ptp(pts, axis=0).max())


def fresh_maker(mech, joint: str):
    """``(make, path, where)``: ``make(k)`` is ``mech`` with ``joint`` moved to ``where(k)``
    (within 0.3 % of the length scale, seven positions in turn) by the public path a drag
    takes: ``Mechanism.with_joint_points`` where it exists, otherwise the studio's path of
    today (``mechanism_from_dict`` of the edited file dict, as ``mechsyn.web`` does on
    every drag step); ``path`` names it."""
    base = np.asarray(mech.joint(joint).point, float)[:2]
    step = 1e-3 * length_scale(mech)

    def where(k: int) -> np.ndarray:
        return base + step * np.array([(k % 7) - 3, (k % 5) - 2], float)

    wjp = getattr(mech, "with_joint_points", None)
    if wjp is not None:
        return (lambda k: wjp({joint: where(k)})), "Mechanism.with_joint_points", where
    from mechsyn.io import mechanism_from_dict, mechanism_to_dict

    d = mechanism_to_dict(mech)
    i = next(n for n, j in enumerate(d["joints"]) if j["id"] == joint)

    def rebuild(k: int):
        joints = list(d["joints"])
        joints[i] = {**joints[i], "point": where(k).tolist()}
        return mechanism_from_dict({**d, "joints": joints}, source="mechanism")

    return rebuild, "mechanism_from_dict (the studio's drag today)", where


def fixed_costs(mech, joint: str, moved: str, x: np.ndarray, repeats: int) -> tuple[dict, list]:
    """Where one ``simulate`` call of a freshly built geometry spends its time (minima in
    seconds): a new mechanism with ``moved`` displaced (the public path of
    :func:`fresh_maker`), its constraint system (``build_system``), the decomposition into
    Assur groups (``decompose``), the compiled plan (``compile_plan``), the checks of the
    drawn configuration, the engine's sweep (``first_sweep``), and the rest of ``simulate``
    (events in input units, named points, link motions, the result). A stage the code
    does not offer (renamed, or a changed signature) is NaN, with the reason in the list."""
    import mechsyn as ms

    build_system = lookup("mechsyn.kinematics.system", "build_system")
    decompose = lookup("mechsyn.kinematics.groups", "decompose")
    compile_plan = lookup("mechsyn.kinematics.analysis", "compile_plan")
    assemble = lookup("mechsyn.kinematics.solve", "assemble")
    singular = lookup("mechsyn.kinematics.solve", "singular_configuration")
    first_sweep = lookup("mechsyn.kinematics.engines", "first_sweep")
    engines = lookup("mechsyn.kinematics.engines", "PLANAR_ENGINES")
    make, _, _ = fresh_maker(mech, moved)
    k = [0]

    def fresh():
        k[0] += 1
        return make(k[0])

    m1, out, why = fresh(), {}, []
    S1 = build_system(m1) if build_system is not None else None

    def row(key: str, f, *needs) -> None:
        out[key] = math.nan
        if any(n is None for n in needs):
            why.append(f"{key}: not in this code")
            return
        try:
            out[key] = best_of(f, repeats)
        except (TypeError, AttributeError, ValueError, KeyError) as err:
            why.append(f"{key}: {type(err).__name__}: {err}")

    def sweep():
        kp = compile_plan(m1, inputs=(joint,))
        d = next(dd for dd in kp.system.drivers if dd.joint == joint)
        U = (np.radians(x) if d.type == "R" else x)[:, None]
        return lambda: first_sweep(engines, kp.system, kp.groups, U, np.ones(1))

    row("new geometry (public path)", fresh)
    row("build_system", lambda: build_system(m1), build_system)
    row("decompose", lambda: decompose(S1), S1, decompose)
    row("compile_plan", lambda: compile_plan(m1, inputs=(joint,)), compile_plan)
    row("assemble + mobility", lambda: assemble(build_system(m1)), build_system, assemble)
    row("singular drawn config?", lambda: singular(build_system(m1)), build_system, singular)
    try:
        f_sweep = sweep() if None not in (compile_plan, first_sweep, engines) else None
    except (TypeError, AttributeError, ValueError, KeyError, StopIteration) as err:
        f_sweep = None
        why.append(f"sweep (engine): {type(err).__name__}: {err}")
    row("sweep (engine)", f_sweep, f_sweep)
    row("simulate, plan cached", lambda: read_all(ms.simulate(mech, {joint: x})))
    row("simulate, fresh geometry", lambda: read_all(ms.simulate(fresh(), {joint: x})))
    out["events, points, result"] = out["simulate, plan cached"] - out["sweep (engine)"]
    for key in ("assemble + mobility", "singular drawn config?"):
        out[key] -= out["build_system"]
    return out, why


def print_fixed_costs(cases: list, x: np.ndarray, repeats: int) -> None:
    """The table of :func:`fixed_costs` for each case (milliseconds, 80 columns)."""
    rows, why = {}, []
    for name, m, j, moved in cases:
        rows[name], w = fixed_costs(m, j, moved, x, repeats)
        why += [f"{name}: {s}" for s in w]
    keys = list(next(iter(rows.values())))
    _, path, _ = fresh_maker(cases[0][1], cases[0][3])
    print()
    note(f"fixed costs per call, ms (minima of {repeats}; a new geometry by {path}; assemble and singular: "
         "less build_system; 'events, points, result' = cached simulate - sweep)")
    print(f"{'':26s}" + "".join(f"{n.split(' (')[0][:13]:>14s}" for n in rows))
    for key in keys:
        print(f"{key:26s}" + "".join(f"{rows[n][key] * 1e3:14.3f}" if math.isfinite(rows[n][key])
                                     else f"{'n/a':>14s}" for n in rows))
    for s in dict.fromkeys(why):
        print(f"  n/a: {s}")


# --------------------------------------------------------------------------- pylinkage
def interleaved(fns: dict, setups: dict, rounds: int, inner: int, warm: bool = True) -> tuple[dict, dict]:
    """Each callable timed ``inner`` times in turn, ``rounds`` times over (so all see the
    same load in a round): per-round medians and overall minima. ``setups[key]`` runs
    before each call of ``fns[key]``, untimed; ``warm``: one untimed call of each first."""
    def nothing():
        return None

    for key, f in fns.items():
        if warm:
            setups.get(key, nothing)()
            f()
    meds, mins = {k: [] for k in fns}, dict.fromkeys(fns, math.inf)
    for _ in range(rounds):
        for key, f in fns.items():
            s, ts = setups.get(key, nothing), []
            for _ in range(inner):
                s()
                t = time.perf_counter()
                f()
                ts.append(time.perf_counter() - t)
            meds[key].append(float(np.median(ts)))
            mins[key] = min(mins[key], min(ts))
    return {k: np.array(v) for k, v in meds.items()}, mins


def compare(sim, names: list, answer: tuple, scale: float) -> dict:
    """mechsyn's simulation against pylinkage's ``(positions, velocities, accelerations)``:
    the largest differences over the length scale on the rows both answer, and the rows
    one answers and the other does not (none, for equal answers). A row has positions
    (velocities, accelerations) when every point's are finite: mechsyn leaves a row it
    cannot assemble (a singular one) blank as a whole, frame and crank included, where
    pylinkage blanks only the joints it cannot place (whose rates it cannot give)."""
    out = {"differ": []}
    for key, q, attr in zip(("pos", "vel", "acc"), answer, ("position", "velocity", "acceleration")):
        a = np.stack([getattr(sim.points[n], attr) for n in names], axis=1)
        rows_m, rows_p = np.isfinite(a).all(axis=(1, 2)), np.isfinite(q).all(axis=(1, 2))
        if not np.array_equal(rows_m, rows_p):
            out["differ"].append(f"rows with {attr}s: mechsyn {int(rows_m.sum())}, pylinkage {int(rows_p.sum())}")
        both = rows_m & rows_p
        out[key] = float(np.abs(a[both] - q[both]).max()) / scale if both.any() else 0.0
        out.setdefault("answered", int(both.sum()))
    out["ok"] = not out["differ"] and max(out["pos"], out["vel"], out["acc"]) <= TOL
    return out


def runs(x: np.ndarray, rows: np.ndarray) -> str:
    """Consecutive ``rows`` as input ranges, '117.4..242.4 deg (126 rows)'."""
    k = np.flatnonzero(rows)
    cuts = np.flatnonzero(np.diff(k) > 1)
    parts = np.split(k, cuts + 1)
    return ", ".join(f"{x[p[0]]:.2f}..{x[p[-1]]:.2f} deg ({len(p)} rows)" if len(p) > 1
                     else f"{x[p[0]]:.2f} deg" for p in parts)


def what_pylinkage_did(case: str, x: np.ndarray, names: list, answer: tuple, sim, caught: list) -> list[str]:
    """What pylinkage answers on the rows it cannot assemble, beside mechsyn's report."""
    pos, vel, _ = answer
    bad = ~np.isfinite(pos).all(axis=2)
    lines = []
    if bad.any():
        rows = bad.any(axis=1)
        kept = [n for k, n in enumerate(names) if not bad[:, k].any()]
        lines.append(f"{case}: pylinkage returns NaN positions of {', '.join(n for k, n in enumerate(names) if bad[:, k].any())}"
                     f" on {runs(x, rows)} and numbers for {', '.join(kept) or 'none'}; "
                     f"{'warnings: ' + '; '.join(caught) if caught else 'no exception, no warning'}")
        lines.append(f"  mechsyn there: not assembled on {runs(x, ~sim.assembled)}; events: "
                     + ", ".join(f"{e['kind']} at {e['input'][next(iter(e['input']))]:.2f}" for e in sim.events))
    rates = np.isfinite(pos).all(axis=(1, 2)) & ~np.isfinite(vel).all(axis=(1, 2))
    if rates.any():
        rows_m = np.all([np.isfinite(sim.points[n].velocity).all(axis=1) for n in names], axis=0)
        same = not rows_m[rates].any()
        lines.append(f"  pylinkage: positions but NaN velocities and accelerations at {runs(x, rates)}; "
                     f"mechsyn: {'no velocities there either' if same else 'velocities there'}")
    return lines


def sweep_of(mech, drive: str, th0: float, kind: str, n: int) -> tuple[np.ndarray, float]:
    """The inputs (degrees) and pylinkage's step (radians): a full turn from the drawn crank
    angle ``th0`` (degrees), or (``clear``) 98 % of the longer run without dead points on
    either side of it, from mechsyn's working ranges of a full turn in 0.1 degree steps."""
    import mechsyn as ms

    ext = 360.0
    if kind == "clear":
        wr = ms.simulate(mech, {drive: th0 + np.linspace(0, 360, 3601)}).working_ranges()
        fwd = wr[0][1] - th0 if wr and abs(wr[0][0] - th0) < 1e-9 else 0.0
        back = th0 + 360 - wr[-1][0] if wr and abs(wr[-1][1] - th0 - 360) < 1e-9 else 0.0
        ext = 0.98 * (fwd if fwd >= back else -back)
    return th0 + np.linspace(0.0, ext, n), math.radians(ext) / (n - 1)


def pylinkage_case(mech, moved: str, kind: str, n: int, rounds: int, inner: int) -> dict:
    """One case against pylinkage: the answers checked (cached and fresh geometry) and the
    four calls timed interleaved."""
    import warnings

    import mechsyn as ms
    import pylinkage_models as pm

    model = pm.model_of(mech)
    if moved not in model.pins or moved in model.crank:
        raise ValueError(f"{moved} must name a pin off the crank: one of {', '.join(model.pins)}")
    P = pm.drawn_points(mech, model)
    x, step = sweep_of(mech, model.drive, math.degrees(pm.crank_angle(model, P)), kind, n)
    names = [p[6:] if p.startswith("point:") else model.pins[p][0] for p in model.names]
    scale, start, drive = length_scale(mech), math.radians(x[0]), model.drive
    make, path, where = fresh_maker(mech, moved)
    lk = pm.build(model, P, start, step)
    coords0 = lk.get_coords()
    lk.compile()

    def moved_points(k: int) -> dict:
        return {**P, moved: where(k)}

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lk.set_coords(coords0)
        cached = lk.step_fast_with_kinematics(iterations=n)
        fresh = pm.fresh(model, moved_points(0), start, step, n)
    sim = ms.simulate(mech, {drive: x}, points=names)
    checks = [compare(sim, names, cached, scale),
              compare(ms.simulate(make(0), {drive: x}, points=names), names, fresh, scale)]
    story = what_pylinkage_did("", x, names, cached, sim, sorted({str(w.message) for w in caught}))
    k = {"m": 0, "p": 0}

    def m_fresh():
        k["m"] += 1
        return read_all(ms.simulate(make(k["m"]), {drive: x}, points=names))

    def p_fresh():
        k["p"] += 1
        return pm.fresh(model, moved_points(k["p"]), start, step, n)

    fns = {"m fresh": m_fresh, "p fresh": p_fresh,
           "m cached": lambda: read_all(ms.simulate(mech, {drive: x}, points=names)),
           "p cached": lambda: lk.step_fast_with_kinematics(iterations=n)}
    # a long sweep was just run by the checks (numba compiled): no untimed call of each first
    meds, mins = interleaved(fns, {"p cached": lambda: lk.set_coords(coords0)}, rounds, inner, warm=inner > 1)
    return {"checks": checks, "story": story, "meds": meds, "mins": mins, "n": n, "path": path,
            "events": len(sim.events)}


PL_CASES = [  # (name, file, joint moved each fresh call, sweep, targets fresh and cached: (at most, goal))
    ("crank-rocker", "examples/kinematics/crank_rocker.yaml", "D", "turn", (1.0, None), (0.5, None)),
    ("Watt, full turn", "examples/textbook/watt_sixbar.yaml", "E", "turn", (1.0, 0.5), (1.0, 0.5)),
    ("Watt, no dead points", "examples/textbook/watt_sixbar.yaml", "E", "clear", (1.0, 0.5), (1.0, 0.5)),
    ("Jansen leg", "examples/kinematics/jansen_leg.yaml", "P5", "turn", (1.0, None), (1.0, None)),
]


def verdict(r: float, target: tuple) -> str:
    at_most, goal = target
    if at_most is None:
        return f"{'-':>11s}"
    state = "goal" if goal is not None and r <= goal else "ok" if r <= at_most else "MISS"
    return f"{'<=' + format(at_most, 'g'):>6s} {state:>4s}"


def note(text: str, indent: str = "# ") -> None:
    """A comment line of the report, wrapped at 80 columns."""
    print(textwrap.fill(text, 80, initial_indent=indent, subsequent_indent=indent))


def ms_cell(t: float, lo: float) -> str:
    """'median (minimum)' in milliseconds, three significant figures or more."""
    def f(v: float) -> str:
        return f"{v:.3f}" if v < 10 else f"{v:.1f}" if v < 1000 else f"{v:.0f}"

    return f"{f(t * 1e3)} ({f(lo * 1e3)})"


def print_pylinkage(results: list) -> bool:
    """The three tables of the comparison (80 columns); True when every answer check passed."""
    import numba
    import pylinkage

    print()
    note(f"against pylinkage {pylinkage.__version__} (numba {numba.__version__}) in this process. fresh = a "
         f"joint moved each call: mechsyn {results[0][1]['path']} + ms.simulate; pylinkage build + compile + "
         "step_fast_with_kinematics. cached = ms.simulate of the same mechanism again; "
         "step_fast_with_kinematics of a compiled linkage.")
    note(f"answers (cached and fresh geometry): largest difference / length scale on the rows both answer, "
         f"at most {TOL:g}; the rows answered must be the same. events: mechsyn's.")
    print(f"{'case':22s} {'inputs':>7s} {'answered':>8s} {'events':>6s} {'position':>8s} {'velocity':>8s} "
          f"{'accel.':>8s} {'check':>6s}")
    ok = True
    for name, r, _, _ in results:
        c = {key: max(ch[key] for ch in r["checks"]) for key in ("pos", "vel", "acc")}
        good = all(ch["ok"] for ch in r["checks"])
        ok &= good
        print(f"{name:22s} {r['n']:7d} {r['checks'][0]['answered']:8d} {r['events']:6d} {c['pos']:8.1e} "
              f"{c['vel']:8.1e} {c['acc']:8.1e} {'ok' if good else 'FAILED':>6s}")
        for ch in r["checks"]:
            for d in ch["differ"]:
                note(f"answers differ: {d}", "  ")
    print()
    note("ms per call, median of the rounds' medians (minimum)")
    print(f"{'case':20s} {'mechsyn fresh':>14s} {'pyl. fresh':>14s} {'mechsyn cached':>14s} {'pyl. cached':>14s}")
    for name, r, _, _ in results:
        cells = [ms_cell(float(np.median(r["meds"][k])), r["mins"][k]) for k in ("m fresh", "p fresh", "m cached",
                                                                               "p cached")]
        print(f"{name:20s}" + "".join(f"{c:>15s}" for c in cells))
    print()
    note(f"mechsyn / pylinkage: median of the interleaved rounds' ratios ({len(results[0][1]['meds']['m fresh'])}"
         f" rounds of 10 calls; 1e6 inputs: of 1 call), ratio of the minima in brackets; issue 30's targets, "
         "'goal' when at most 0.5")
    print(f"{'case':22s} {'fresh':>13s} {'target':>11s}  {'cached':>13s} {'target':>11s}")
    for name, r, tf, tc in results:
        m, lo = r["meds"], r["mins"]
        rf, rc = float(np.median(m["m fresh"] / m["p fresh"])), float(np.median(m["m cached"] / m["p cached"]))
        cf = f"{rf:.2f} ({lo['m fresh'] / lo['p fresh']:.2f})"
        cc = f"{rc:.2f} ({lo['m cached'] / lo['p cached']:.2f})"
        print(f"{name:22s} {cf:>13s} {verdict(rf, tf)}  {cc:>13s} {verdict(rc, tc)}")
    for name, r, _, _ in results:
        for line in r["story"]:
            note(f"{name}{line}" if line.startswith(":") else line.strip(), "  " if line.startswith(" ") else "")
    return ok


def run_pylinkage(repeats: int, big: int) -> bool:
    """The comparison with pylinkage, or one line on how to get it. False when an answer differs."""
    if importlib.util.find_spec("pylinkage") is None or importlib.util.find_spec("numba") is None:
        print("\npylinkage: not importable, skipped (get it: pip install pylinkage numba)")
        return True
    from mechsyn.io import load_mechanism

    results = []
    for name, file, moved, kind, tf, tc in PL_CASES:
        results.append((name, pylinkage_case(load_mechanism(ROOT / file), moved, kind, N, repeats, 10), tf, tc))
    if big:
        name, file, moved, kind, tf, tc = PL_CASES[0]
        r = pylinkage_case(load_mechanism(ROOT / file), moved, kind, big, min(3, repeats), 1)
        results.append((f"crank-rocker, {big:.0e}", r, (None, None), (None, None)))
    return print_pylinkage(results)


def mechsyn_tables(repeats: int) -> None:
    """The tables of mechsyn against the bare NumPy four-bar, then the fixed costs."""
    from mechsyn.io import load_mechanism
    from mechsyn import simulate

    x = np.linspace(0.0, 360.0, N)
    assert len(x) == N
    th = np.radians(x)
    cr = load_mechanism(ROOT / "examples/kinematics/crank_rocker.yaml")
    P = {j.id: np.asarray(j.point, float) for j in cr.joints}
    a, b, c = (float(np.linalg.norm(P[p] - P[q])) for p, q in (("A", "B"), ("B", "C"), ("C", "D")))
    B0 = P["B"] - P["A"]
    th0 = np.arctan2(B0[1], B0[0])
    dBD, dBC = P["D"] - P["B"], P["C"] - P["B"]
    sigma = 1.0 if dBD[0] * dBC[1] - dBD[1] * dBC[0] >= 0 else -1.0
    t_bare = best_of(lambda: bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma), repeats * 10)

    # answers checked: closed form equals the bare reference; dead points to 1e-6 degree
    sim = simulate(cr, {"A": np.degrees(th0 + th)}, points=["B", "C"])
    Bb, Cb = bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma)
    err = max(np.abs(sim.points["B"].position - Bb).max(), np.abs(sim.points["C"].position - Cb).max())
    assert err < 1e-12, err
    fb = simulate(load_mechanism(ROOT / "examples/textbook/fourbar.yaml"), {"A": x})
    dead = sorted(e["input"]["A"] for e in fb.events if e["kind"] == "dead point")
    # crank sqrt(5), coupler = rocker = sqrt(10), frame 5: stretched when |BD| = 2 sqrt(10)
    lim = np.degrees(np.arccos((5 + 25 - (2 * np.sqrt(10)) ** 2) / (2 * np.sqrt(5) * 5)))
    dead_err = max(abs(dead[0] - lim), abs(dead[1] - (360 - lim)))
    assert dead_err < 1e-6, (dead, lim)

    cases = [("crank-rocker", cr, "A"),
             ("four-bar, 2 dead points", load_mechanism(ROOT / "examples/textbook/fourbar.yaml"), "A"),
             ("Watt six-bar", load_mechanism(ROOT / "examples/textbook/watt_sixbar.yaml"), "A"),
             ("Stephenson six-bar", load_mechanism(ROOT / "examples/textbook/stephenson_sixbar.yaml"), "A"),
             ("Jansen leg (double joint on foot)", jansen("third"), "P0"),
             ("Jansen leg (chain)", jansen("chain"), "P0"),
             ("Jansen leg (star)", jansen("star"), "P0")]
    note(f"mechsyn simulate, {N} inputs; 'ms' and 'x bare': minimum of {repeats * 3} runs over the "
         f"minimum of the bare NumPy four-bar (positions only, {t_bare * 1e6:.0f} us); 'x med': median ratio of "
         f"{repeats} rounds of 10 calls each, the case and the bare reference alternately")
    note(f"checks: crank-rocker = bare NumPy to {err:.1e}; textbook four-bar dead points to {dead_err:.1e} deg")
    print(f"{'case':<34s} {'method':>6s} {'evts':>4s} {'ms':>7s} {'x bare':>7s} {'x med':>6s} {'target':>7s}")
    def bare() -> None:
        bare_fourbar(th0 + th, P["A"], P["D"], a, b, c, sigma)

    figures = {}
    for name, mech, joint in cases:
        t, ratio, med = figures[name] = both(lambda: read_all(simulate(mech, {joint: x})), bare, repeats, t_bare)
        s = simulate(mech, {joint: x})
        tgt = TARGETS[name]
        print(f"{name:<34s} {s.method:>6s} {len(s.events):>4d} {t * 1e3:7.2f} {ratio:7.1f} {med:6.1f} "
              f"{'<=' + str(tgt):>5s} {'ok' if ratio <= tgt else 'MISS'}")
    compile_plan = lookup("mechsyn.kinematics.analysis", "compile_plan")
    watt = compile_plan(cases[2][1], inputs=("A",)) if compile_plan is not None else None
    label = "Watt drag (plan.with_joint_points)"
    if watt is None or not hasattr(watt, "with_joint_points"):
        print(f"{label:<34s} n/a (no KinematicPlan.with_joint_points here)")
    else:
        k = [0]

        def drag():
            k[0] += 1
            read_all(watt.with_joint_points({"G": (5.0 + 0.001 * (k[0] % 7), 6.0)}).simulate({"A": x}))

        t, ratio, med = both(drag, bare, repeats, t_bare)
        print(f"{label:<34s} {'assur':>6s} {'':>4s} {t * 1e3:7.2f} {ratio:7.1f} {med:6.1f}")
    moved = {"crank-rocker": "D", "Watt six-bar": "E", "Jansen leg (chain)": "P5"}
    print_fixed_costs([(n, m, j, moved[n]) for n, m, j in cases if n in moved], x, repeats)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeats", type=int, default=30, help="rounds (and minima over 3x as many runs)")
    ap.add_argument("--big", type=int, default=10**6,
                    help="inputs of the crank-rocker's long sweep against pylinkage (0: none)")
    args = ap.parse_args()
    if args.repeats < 1 or args.big == 1 or args.big < 0:
        ap.error("--repeats must be at least 1, --big at least 2 (or 0: no long sweep)")
    try:
        mechsyn_tables(args.repeats)
        ok = run_pylinkage(args.repeats, args.big)
    except KeyboardInterrupt:
        print("\ninterrupted: the rows printed above were measured, the rest was not", file=sys.stderr)
        raise SystemExit(130) from None
    if not ok:
        print("answers differ from pylinkage's: see the lines above")
        raise SystemExit(1)


if __name__ == "__main__":
    main()
