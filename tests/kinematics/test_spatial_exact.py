"""Spatial sweeps exact to the last row (issue 38), on mechanisms built here with their own
truth (:mod:`spatial_cases`): no false assembly (loop closure of the reported joint values by
the product of exponentials, the Bricard's symmetry), every change point (closed-form
spherical four-bar of arcs a + b = c + d at many steps and offsets), any place (1e-3, 1e4, 1e6
from the origin; points clustered at the centre), files drawn at a dead point and at a change
point, one rule after a gap."""

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.kinematics.spatial_model import compile_spatial, pair_error
from mechsyn.kinematics.spatial_track import NEWTON_TOL, Tracker
from spatial_cases import bricard, loop_error, rot, rssr_at_dead_point, sarrus, spherical_fourbar

SING_POS = 10 * np.sqrt(NEWTON_TOL)  # position accuracy on a singular row (Newton converges linearly there)


# --------------------------------------------------------------------------- 1. no false assembly
def test_pair_check_refuses_a_reversed_axis():
    """A crank turned half a turn about a line through its pivot perpendicular to the axis
    satisfies both dot equations and the coincidence of its R pair, but is not the pair."""
    m, _ = spherical_fourbar(25, 55, 45, 60, 40)
    M = compile_spatial(m, ("A",))
    R = np.tile(np.eye(3), (2, M.n + 1, 1, 1))
    j = m.joint("A")
    n1 = np.cross(j.axis, [1.0, 0, 0])
    R[1, M.index("crank")] = rot(n1, np.pi)
    err = pair_error(M, R)
    assert err[0].max() < 1e-15
    a = M.pairs.ids.index("A")
    assert err[1, a] > 1.9  # the axis reversed: Rot(a, θ) cannot match
    tr = Tracker(M)
    assert tr.true_pairs(R, np.array([True, True])).tolist() == [True, False]


@pytest.mark.parametrize("seed", range(12))
def test_bricard_rows_close_their_loop_and_keep_the_symmetry(seed):
    """Every row reported assembled is an assembly: the reported joint values close the loop
    (``exp(ξ1 θ1) ... exp(ξ6 θ6) = I``) and keep the line symmetry (``θ_i = θ_{i+3}``); every
    row not assembled carries no position."""
    m = bricard(seed)
    s = ms.simulate(m, {"J1": ms.input_grid(0, 360, 1)})
    ok = np.flatnonzero(s.assembled)
    assert len(ok) > 20
    assert max(loop_error(m, s.joints, k) for k in ok) < 1e-9
    for i in (1, 2, 3):
        d = s.joints[f"J{i}"][ok] - s.joints[f"J{i + 3}"][ok]
        assert np.abs((d + 180) % 360 - 180).max() < 1e-7
    assert np.isnan(s.point("J2")[~s.assembled]).all()
    if (s.reached == 3).any():  # rows no motion from the drawn assembly reaches: said so
        assert any("another assembly" in n for n in s.notes) and "reassembled" in {e["kind"] for e in s.events}
    if (s.reached == 2).any():
        assert any("other way round" in n for n in s.notes)


# --------------------------------------------------------------------------- 2. change points
def _on_either_branch(s, axes, phi0, g, centre=np.zeros(3), radius=1.0):
    """Largest distance (in radii) of joint C from the nearer closed-form assembly, per row."""
    C = (s.point("C") - centre) / radius
    out = np.full(len(g), np.nan)
    for k in np.flatnonzero(s.assembled):
        cands = [axes(phi0 + g[k], br) for br in (1, -1)]
        out[k] = min(np.abs(C[k] - c[2]).max() for c in cands if c is not None)
    return out


@pytest.mark.parametrize("step", [0.7, 1.0, 1.3, 2.9, 5.0])
@pytest.mark.parametrize("offset", [0.0, 0.1, 0.35, 0.5, 0.77])
def test_change_point_of_a_spherical_four_bar_found_at_every_step_and_offset(step, offset):
    """Arcs 30 + 70 = 50 + 50 (a Grashof limit): the four axes lie on one great circle at crank
    angle 0, a change point. Drawn at 40, every sweep through input -40 reports it there (to
    1e-6 of the step), assembles every row on a true assembly and prints no rate on the
    singular row."""
    m, axes = spherical_fourbar(30, 70, 50, 50, 40.0)
    g = np.arange(-100 + offset, 300, step)
    s = ms.simulate(m, {"A": g})
    assert s.assembled.all()
    err = _on_either_branch(s, axes, 40.0, g)
    sing = [e for e in s.events if e["kind"] == "singular"]
    assert len(sing) == 1 and abs(sing[0]["input"]["A"] + 40.0) < 1e-6 * step
    on_row = np.isclose(g, -40.0, rtol=0, atol=1e-6 * step)
    assert np.nanmax(err[~on_row]) < 1e-9 and np.nanmax(err, initial=0) < SING_POS
    if on_row.any():
        assert not sing[0].get("crossed") and np.isnan(s.points["C"].velocity[on_row]).all()
    regular = ~on_row
    assert np.isfinite(s.points["C"].velocity[regular]).all()


@pytest.mark.parametrize("alpha", [40.0, 23.7])
@pytest.mark.parametrize("step,offset", [(1.0, 0.0), (0.7, 0.31), (2.9, 0.5), (0.13, 0.05)])
def test_sarrus_change_and_fold_inputs_exact_to_a_millionth_of_the_step(alpha, step, offset):
    """A Sarrus linkage built here, driven at A1. With two equal legs of equal links both
    stretch at ``A1 = 90 - alpha`` (a change point: one singular event there); with leg B
    shorter (reach 1.8 against leg A's 2) the input stops where leg B is stretched, at
    ``A1 = asin(0.9) - alpha`` (a dead point, the working range's end). Both located to 1e-6
    of the step (the golden search alone gave 1e-5, the bisection alone 5e-7, both from one
    side), at steps and offsets that put the point anywhere between rows."""
    g = np.arange(-20 + offset, 110 - alpha, step)
    s = ms.simulate(sarrus(alpha, leg_b=(1.0, 1.0)), {"A1": g})
    assert s.assembled.all()
    z = 2 * np.sin(np.radians(alpha + g))  # the top's height, from leg A's isosceles triangle
    assert np.abs(s.point("A3")[:, 2] - z).max() < SING_POS
    sing = [e for e in s.events if e["kind"] == "singular"]
    assert len(sing) == 1 and abs(sing[0]["input"]["A1"] - (90 - alpha)) < 1e-6 * step
    s = ms.simulate(sarrus(alpha, leg_b=(0.8, 1.0)), {"A1": g})
    h = 2 * np.sin(np.radians(alpha + g))  # leg B reaches heights from 0.2 to 1.8
    clear = np.minimum(np.abs(h - 0.2), np.abs(h - 1.8)) > 1e-9
    assert np.array_equal(s.assembled[clear], ((h >= 0.2) & (h <= 1.8))[clear])
    fold = np.degrees(np.arcsin(0.9)) - alpha
    (lo, hi), = [r for r in s.working_ranges() if r[0] <= 0 <= r[1]]
    assert abs(hi - fold) < 1e-6 * step
    dead = [e for e in s.events if e["kind"] == "dead point" and e["index"] == np.argmax(g > fold)]
    assert len(dead) == 1 and abs(dead[0]["input"]["A1"] - fold) < 1e-6 * step


@pytest.mark.parametrize("step,offset", [(2.0, 0.0), (3.0, 0.0), (1.7, 0.3), (0.9, 0.1)])
def test_sarrus_rank_two_crossings_found_over_a_full_turn(step, offset):
    """The equal-legged Sarrus (both legs stretched or folded flat at once: two singular
    values vanish together, so the determinant keeps its sign and the ratio's V is bent)
    over nearly a full turn of A1: its four change points at ``A1 = -90 - alpha, -alpha,
    90 - alpha, 180 - alpha`` are each reported once, within 1e-6 of the step (at steps 2 and 3
    the two folds flat, at -40 and 140, were missed: neither a sign change nor a sharp V)."""
    alpha = 40.0
    g = np.arange(-185 + offset, 175, step)
    s = ms.simulate(sarrus(alpha, leg_b=(1.0, 1.0)), {"A1": g})
    assert s.assembled.all()
    got = sorted(e["input"]["A1"] for e in s.events if e["kind"] == "singular")
    want = [-90 - alpha, -alpha, 90 - alpha, 180 - alpha]
    assert len(got) == 4 and np.abs(np.array(got) - want).max() < 1e-6 * step


# --------------------------------------------------------------------------- 3. any size and place
@pytest.mark.parametrize("centre,radius", [((1e-3, 0, 0), 1.0), ((1e4, -2e3, 5e3), 1.0), ((1e6, -3e5, 5e5), 1.0),
                                           ((1.0, 0.5, -0.2), 1e-6), ((1.0, 0.5, -0.2), 1e-3)])
def test_spherical_four_bar_anywhere_assembles_every_row(centre, radius):
    """A crank-rocker (arcs 25, 55, 45, 60: the crank turns fully) placed far from the origin
    or with its points clustered about its centre: every row assembles, no event, the rocker
    where the closed form puts it (to the coordinates' own rounding)."""
    m, axes = spherical_fourbar(25, 55, 45, 60, 40.0, centre=centre, radius=radius)
    g = ms.input_grid(0, 360, 1)
    s = ms.simulate(m, {"A": g})
    assert s.assembled.all() and not s.events
    rounding = 1e3 * np.finfo(float).eps * np.abs(centre).max() / radius
    assert np.nanmax(_on_either_branch(s, axes, 40.0, g, np.asarray(centre), radius)) < max(1e-9, rounding)


# --------------------------------------------------------------------------- 4. drawn at a dead or change point
def test_rssr_drawn_at_a_dead_point_sweeps_every_row_that_assembles():
    """Drawn at the crank's limit: the rows on the feasible side assemble from the first one
    next to the drawn row (no false gap), the others do not, the rocker on a closed-form root,
    the range's far end refined to 1e-6 of the step."""
    m, phi_star, psi = rssr_at_dead_point()
    g = ms.input_grid(-60, 60, 1)
    s = ms.simulate(m, {"A": g})
    truth = np.array([psi(phi_star + u) for u in g])
    want = np.isfinite(truth[:, 0])
    assert np.array_equal(s.assembled, want)
    D = np.radians(s.joints["D"])
    err = np.nanmin(np.abs(np.angle(np.exp(1j * (D[:, None] - truth)))), axis=1)
    assert err[s.assembled].max() < SING_POS
    assert not [e for e in s.events if e["kind"] in ("reassembled", "refused")]
    (lo, hi), = s.working_ranges()
    assert hi == pytest.approx(0.0, abs=1e-6)

    def feasible(u):
        return np.isfinite(psi(phi_star + u)[0])

    a, b = g[np.argmax(want)] - 1.0, g[np.argmax(want)]  # the far end by bisection on the closed form
    for _ in range(60):
        c = 0.5 * (a + b)
        a, b = (a, c) if feasible(c) else (c, b)
    assert lo == pytest.approx(b, abs=1e-6)


@pytest.mark.parametrize("r", [1.7, 2.0, 2.9])
def test_rssr_full_turn_assembles_the_crank_range_no_motion_reaches(r):
    """Drawn at a dead point, the crank of these RSSRs works in two separate ranges (two
    circuits): a full turn of the input assembles every row of both, the one no motion from
    the drawn pose reaches re-assembled from the row after its gap (it lies before the first
    row reached) and said so (``reached`` 3, one ``reassembled`` event), the rocker on a
    closed-form root everywhere."""
    m, phi_star, psi = rssr_at_dead_point(r)
    g = np.arange(-179.5, 180, 0.7)
    s = ms.simulate(m, {"A": g})
    truth = np.array([psi(phi_star + u) for u in g])
    want = np.isfinite(truth[:, 0])
    edge = np.zeros(len(g), bool)  # rows next to a range's end: closer to it than the test can tell
    for e in np.flatnonzero(np.diff(want.astype(int))):
        edge[max(0, e - 1):e + 3] = True
    assert np.array_equal(s.assembled[~edge], want[~edge])
    assert (s.reached == 3).any() and (s.reached == 1).any()
    assert len([e for e in s.events if e["kind"] == "reassembled"]) == 1
    D = np.radians(s.joints["D"])
    err = np.nanmin(np.abs(np.angle(np.exp(1j * (D[s.assembled, None] - truth[s.assembled])))), axis=1)
    assert err.max() < SING_POS


def test_spherical_four_bar_drawn_at_its_change_point_sweeps_both_ways():
    m, axes = spherical_fourbar(30, 70, 50, 50, 0.0)
    g = ms.input_grid(-180, 180, 1)
    s = ms.simulate(m, {"A": g})
    assert s.assembled.all()
    assert np.nanmax(_on_either_branch(s, axes, 0.0, g)) < SING_POS
    sing = [e for e in s.events if e["kind"] == "singular"]
    assert [e["input"]["A"] for e in sing] == [0.0]
    C = s.point("C")  # one smooth branch through the drawn pose: second differences small
    d2 = np.linalg.norm(C[2:] - 2 * C[1:-1] + C[:-2], axis=1)
    assert d2.max() < 10 * np.median(d2)
    assert any("singular" in n for n in s.notes)


# --------------------------------------------------------------------------- 5. one rule after a gap
def test_rssr_full_turn_gap_closed_the_other_way_round():
    """The example RSSR's crank stops at two dead points; a 0..360 sweep reaches the rows past
    the gap by going backwards from the drawn pose (the input modulo 360): the same circuit,
    so the row at 360 is the drawn pose."""
    s = ms.simulate(ms.examples.load("rssr"), {"A": ms.input_grid(0, 360, 1)})
    kinds = [e["kind"] for e in s.events]
    assert "other way round" in kinds and "reassembled" not in kinds
    assert "reached going the other way round" in str(s) and set(np.unique(s.reached)) == {0, 1, 2}
    assert np.allclose(s.point("C")[-1], s.point("C")[0], atol=1e-12)
    (lo, hi), = s.working_ranges()  # one range through 360 (= 0): a whole turn's ends meet, as in the planar engines
    dead = sorted(e["input"]["A"] for e in s.events if e["kind"] == "dead point")
    assert lo == dead[1] and hi == pytest.approx(dead[0] + 360.0, abs=1e-12)


# --------------------------------------------------------------------------- one input convention (issue 37, 5)
def _fourbar_3d(zero):
    """examples/textbook/fourbar.yaml written as a spatial file (axes along z), with the
    crank's input zero ``zero`` (None: the drawn pose)."""
    from mechsyn.io import mechanism_from_dict

    m = ms.examples.load("fourbar")
    js = []
    for j in m.joints:
        d = {"id": j.id, "type": "R", "links": list(j.links), "point": [*map(float, j.point), 0.0],
             "axis": [0, 0, 1], "actuated": j.actuated}
        if j.actuated and zero is not None:
            d["zero"] = zero
        js.append(d)
    return mechanism_from_dict({"name": "four-bar 3-D", "kind": "spatial", "ground": "frame",
                                "links": [lk.name for lk in m.links], "joints": js}, "fourbar3d")


def test_a_zero_makes_an_input_the_same_pose_as_the_planar_engines():
    """With ``zero: [1, 0, 0]`` (the planar frame's x axis) ``A = 30`` is the crank line at 30
    degrees, as the planar engines read it; without it 0 is the drawn pose."""
    from mechsyn.kinematics.spatial_model import input_zero

    planar = ms.examples.load("fourbar")
    g = np.array([60.0, 70.0, 80.0])
    want = ms.simulate(planar, {"A": g}, points=["C"]).point("C")
    s = ms.simulate(_fourbar_3d([1, 0, 0]), {"A": g}, points=["C"])
    assert np.allclose(s.point("C")[:, :2], want, atol=1e-9) and s.zero["A"] == pytest.approx(np.degrees(np.arctan2(2, 1)))
    drawn = np.degrees(np.arctan2(2, 1))  # the crank line A -> B as drawn
    assert input_zero(planar, planar.joint("A")) == pytest.approx(np.radians(drawn))
    from mechsyn.kinematics.spatial import simulate_spatial

    handed = simulate_spatial(planar, {"A": g}, points=["C"])  # a planar file handed to the spatial engine
    assert np.allclose(handed.point("C")[:, :2], want, atol=1e-9) and np.allclose(handed.point("C")[:, 2], 0)
    s0 = ms.simulate(_fourbar_3d(None), {"A": g - drawn}, points=["C"])
    assert np.allclose(s0.point("C"), s.point("C"), atol=1e-9)
    assert np.allclose(s.joints["A"], g)


def test_zero_must_be_perpendicular_to_the_axis():
    with pytest.raises(ms.MechsynInputError, match="perpendicular") as exc:
        _fourbar_3d([1, 0, 1])
    assert "zero" in str(exc.value)


# --------------------------------------------------------------------------- 6. what a spatial designer reads
def test_text_and_csv_carry_joint_values_link_orientations_and_refined_events():
    m, phi_star, psi = rssr_at_dead_point()
    s = ms.simulate(m, {"A": ms.input_grid(-60, 60, 1)})
    text = str(s)
    lo = s.working_ranges()[0][0]
    assert f"{lo:.7g}" in text and "dead point at A=" in text
    assert "D" in s.table().splitlines()[0].split()  # the rocker's angle, a joint value
    rows = s.csv().splitlines()  # (Motion.columns: the CSV of every engine)
    head = rows[0].split(",")
    for col in ("joint_D", "rocker_rx_deg", "rocker_translation_z", "reached"):
        assert col in head
    k = int(np.flatnonzero(s.assembled)[3])
    vals = dict(zip(head, rows[k + 1].split(",")))
    R = s.links["rocker"].rotation[k]
    angle = np.degrees(np.arccos((np.trace(R) - 1) / 2))
    rv = np.array([float(vals[f"rocker_r{c}_deg"]) for c in "xyz"])
    assert np.linalg.norm(rv) == pytest.approx(angle, abs=1e-9)
    D = (float(vals["joint_D"]) + 180) % 360 - 180
    assert abs(D) == pytest.approx(angle, abs=1e-9)  # the rocker turns about D only


# --------------------------------------------------------------------------- 7. the verdict's first words
def test_analyze_headline_leads_with_what_the_mechanism_does():
    from spatial_cases import rssr_taut

    from mechsyn.structure.rank import motion_headline
    from mechsyn.structure.report import verdict

    taut = ms.analyze_rank(rssr_taut())  # stretched: only the rod's idle spin is finite
    assert motion_headline(taut) == "rigid (finite mobility 0; besides 1 idle motion), shaky: 2 instantaneous motions"
    assert taut.drives_needed == 0 and "locked" in taut.actuation_note and "redundant" not in taut.actuation_note
    four = ms.analyze_rank(ms.examples.load("fourbar_taut"))
    assert motion_headline(four) == "rigid (finite mobility 0), shaky: 2 instantaneous motions"
    v = verdict(ms.analyze(ms.examples.load("rssr")).analysis, ms.analyze_rank(ms.examples.load("rssr")))
    assert v["text"].startswith("moves with 1 degree of freedom (finite; besides 1 idle motion); drives needed: 1")


# --------------------------------------------------------------------------- 8. the ladder's finite check
def test_a_pose_without_redundant_constraints_is_regular_without_following_it(monkeypatch):
    """Rank = number of closure equations: the closure map is a submersion there, so its zero
    set is a manifold (implicit function theorem) and every instantaneous motion is finite;
    the motion is not followed. With redundant constraints it still is."""
    import mechsyn.structure.rank as rank_mod

    calls = []
    real = rank_mod.local_mobility
    monkeypatch.setattr(rank_mod, "local_mobility", lambda *a, **k: calls.append(1) or real(*a, **k))
    r = ms.analyze_rank(ms.examples.load("fourbar"))
    assert (r.redundant_constraints, r.finite_mobility, r.configuration, calls) == (0, 1, "regular", [])
    b = ms.analyze_rank(ms.examples.load("bennett"))
    assert (b.redundant_constraints, b.finite_mobility, b.configuration) == (3, 1, "regular") and calls
    t = ms.analyze_rank(ms.examples.load("fourbar_taut"))
    assert t.configuration == "shaky"  # q = 1: followed, and found rigid


def test_a_multi_drive_path_has_the_rates_of_its_derivative():
    """Two Delta arms along a curved path in input space: the platform's velocity and
    acceleration are those of the motion in time with R1 at 1 rad/s (central differences of
    the reported positions, which converge as h²: checked at two steps)."""
    m = ms.examples.load("delta")
    errs = []
    for n in (101, 201):
        t = np.linspace(0, 1, n)
        s = ms.simulate(m, {"R1": 20 * t - 10, "R2": 10 * np.sin(2 * t)})
        assert s.assembled.all() and any("one path" in x for x in s.notes)
        name = list(s.points)[-1]
        P, V, A = s.point(name), s.points[name].velocity, s.points[name].acceleration
        dt = np.radians(20 / (n - 1))
        fv = (P[2:] - P[:-2]) / (2 * dt)
        fa = (P[2:] - 2 * P[1:-1] + P[:-2]) / dt ** 2
        errs.append((np.abs(fv - V[1:-1]).max() / np.abs(V).max(), np.abs(fa - A[1:-1]).max() / np.abs(A).max()))
    (v1, a1), (v2, a2) = errs
    assert v2 < v1 / 3 and a2 < a1 / 3 and v2 < 1e-5 and a2 < 1e-4  # second order: a quarter when h halves


def test_c_and_u_pairs_can_be_driven():
    """A C pair driven by its slide and turn, a right-angled U pair by its two angles: the
    point on the driven link where the closed-form displacement puts it, velocities too."""
    from mechsyn.io import mechanism_from_dict

    c = mechanism_from_dict({"name": "C", "kind": "spatial", "ground": "frame", "links": ["frame", "s"], "joints": [
        {"id": "C1", "type": "C", "links": ["frame", "s"], "point": [0, 0, 0], "axis": [0, 0, 1], "actuated": True}],
        "points": {"Q": {"link": "s", "at": [1, 0, 0]}}}, "c.yaml")
    z, th = np.array([0.0, 0.5, 1.0]), np.array([0.0, 90.0, 180.0])
    s = ms.simulate(c, {"C1": z, "C1/turn": th}, points=["Q"])
    want = np.stack([np.cos(np.radians(th)), np.sin(np.radians(th)), z], axis=1)
    assert np.allclose(s.point("Q"), want, atol=1e-12)
    w = np.pi  # one path: the turn follows the slide, 180 degrees per unit of slide at the slide's speed 1
    assert np.allclose(s.points["Q"].velocity, np.stack([-w * want[:, 1], w * want[:, 0], np.ones(3)], axis=1),
                       atol=1e-12)
    assert np.allclose(s.joints["C1/slide"], z) and np.allclose(s.joints["C1"], th)
    u = mechanism_from_dict({"name": "U", "kind": "spatial", "ground": "frame", "links": ["frame", "u"], "joints": [
        {"id": "U1", "type": "U", "links": ["frame", "u"], "point": [0, 0, 0], "axis": [0, 0, 1], "axis2": [1, 0, 0],
         "actuated": True}], "points": {"Q": {"link": "u", "at": [0, 1, 0]}}}, "u.yaml")
    a, b = np.array([0.0, 90.0, 30.0]), np.array([0.0, 0.0, 50.0])
    s = ms.simulate(u, {"U1": a, "U1/2": b}, points=["Q"])
    want = [rot([0, 0, 1], np.radians(x)) @ rot([1, 0, 0], np.radians(y)) @ [0, 1, 0] for x, y in zip(a, b)]
    assert np.allclose(s.point("Q"), want, atol=1e-12)
    with pytest.raises(ms.MechsynInputError, match="takes"):
        ms.simulate(u, {"U1/turn": a})
