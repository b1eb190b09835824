"""Branches (issue 12 §2-4): the closed form and Newton continuation agree through folds,
change points and gaps; the drawn configuration decides the branch wherever the sweep
starts; singular positions give null rates with an event, never a blow-up."""

from dataclasses import replace

import numpy as np
import pytest

from mechsyn.io import mechanism_from_dict
from mechsyn.kinematics.analysis import input_grid, simulate
from mechsyn.kinematics.dyads import decompose
from mechsyn.kinematics.system import build_system

from kinematics_helpers import EX, ex  # noqa: F401

KINDS = ("dead point", "reassembled", "singular")


def parallelogram(theta=60.0, crank=1.0, frame=4.0):
    """A parallelogram four-bar drawn at crank angle ``theta`` (change points at 0 and 180)."""
    t = np.radians(theta)
    B = [crank * np.cos(t), crank * np.sin(t)]
    C = [frame + B[0], B[1]]
    return mechanism_from_dict({
        "name": "parallelogram", "ground": "frame", "links": ["frame", "crank", "coupler", "rocker"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": B},
            {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": C},
            {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [frame, 0]}]}, "parallelogram")


def triad(theta=None):
    """A six-bar whose driven crank carries a class-III Assur group (a Stephenson triad:
    a ternary link held by three binary links), which does not split into dyads."""
    return mechanism_from_dict({
        "name": "triad", "ground": "frame", "links": ["frame", "crank", "b1", "b2", "b3", "tri"],
        "joints": [
            {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0], "actuated": True},
            {"id": "B", "type": "R", "links": ["crank", "b1"], "point": [0.5, 0.866]},
            {"id": "P1", "type": "R", "links": ["b1", "tri"], "point": [2.0, 2.5]},
            {"id": "P2", "type": "R", "links": ["b2", "tri"], "point": [4.0, 3.0]},
            {"id": "P3", "type": "R", "links": ["b3", "tri"], "point": [3.2, 1.4]},
            {"id": "G2", "type": "R", "links": ["b2", "frame"], "point": [5.0, 0.5]},
            {"id": "G3", "type": "R", "links": ["b3", "frame"], "point": [3.0, -0.6]}]}, "triad")


def redrawn(mech, theta, method):
    """The same mechanism drawn at input ``theta`` (its joint points moved there along the
    file's branch), without its named points."""
    ids = [j.id for j in mech.joints]
    sim = simulate(mech, {"A": np.array([theta])}, points=ids, method=method)
    assert sim.assembled[0]
    joints = tuple(replace(j, point=np.array(sim.points[j.id].position[0])) for j in mech.joints)
    return replace(mech.with_joints(joints), points={}), {j: sim.points[j].position[0] for j in ids}


def key_events(sim):
    return sorted((e["index"], e["kind"]) for e in sim.events if e["kind"] in KINDS
                  and not e.get("before_sweep"))


def compare(a, b, singular_tol=1e-5):
    """Same assembled rows, same positions (1e-9; 1e-5 at singular rows, where Newton's
    positions are only as accurate as the square root of its tolerance), same events."""
    assert np.array_equal(a.assembled, b.assembled)
    inp = next(iter(a.inputs))
    regular = a.assembled & np.isfinite(a.links[next(iter(a.links))].angular_velocity)
    for p in a.points:
        d = np.abs(a.points[p].position - b.points[p].position).max(axis=1)
        assert d[regular].max(initial=0) < 1e-9, (p, a.inputs[inp][regular][np.argmax(d[regular])])
        assert d[a.assembled].max(initial=0) < singular_tol
    assert key_events(a) == key_events(b)
    da = [e["input"][inp] for e in a.events if e["kind"] == "dead point"]
    db = [e["input"][inp] for e in b.events if e["kind"] == "dead point"]
    assert np.allclose(da, db, atol=1e-6, rtol=0)


@pytest.mark.parametrize("name,grid", [
    ("textbook/fourbar.yaml", (0, 360, 4)),
    pytest.param("textbook/fourbar.yaml", (200, 560, 6), marks=pytest.mark.slow),
    pytest.param("textbook/watt_sixbar.yaml", (-90, 270, 6), marks=pytest.mark.slow),
    pytest.param("textbook/stephenson_sixbar.yaml", (0, 360, 5), marks=pytest.mark.slow),
    pytest.param("kinematics/triple_rocker.yaml", (-90, 270, 6), marks=pytest.mark.slow),
])
def test_closed_form_equals_newton_through_dead_points_and_gaps(ex, name, grid):
    m = ex(name)
    a = simulate(m, {"A": input_grid(*grid)}, method="assur")
    n = simulate(m, {"A": input_grid(*grid)}, method="newton")
    assert a.method == "assur" and n.method == "newton"
    assert (~a.assembled).any()  # the sweep crosses a gap: dead points and reassembly
    compare(a, n)


@pytest.mark.parametrize("grid", [(-30, 390, 10), (-25, 385, 10), (170, 550, 7.5)])
def test_parallelogram_stays_a_parallelogram(grid):
    """Change points at 0 and 180 degrees: both methods stay on the drawn (parallelogram)
    branch, report each crossing as singular, and give null rates at a change point that
    is a sample, never a number of 1e16."""
    m = parallelogram(60.0)
    x = input_grid(*grid)
    th = np.radians(x)
    exact = np.stack([4 + np.cos(th), np.sin(th)], axis=1)
    sims = {meth: simulate(m, {"A": x}, points=["C"], method=meth) for meth in ("assur", "newton")}
    a = sims["assur"]
    assert np.abs(a.points["C"].position - exact).max() < 1e-12
    at_change = np.isclose(np.mod(x, 180.0), 0.0) | np.isclose(np.mod(x, 180.0), 180.0)
    for sim in sims.values():
        assert sim.assembled.all()
        v = sim.points["C"].velocity
        assert np.isnan(v[at_change]).all() and np.isfinite(v[~at_change]).all()
        assert np.nanmax(np.abs(sim.points["C"].acceleration)) < 10
        # the velocity of the parallelogram's C equals the crank tip's: (-sin, cos)
        assert np.allclose(v[~at_change], np.stack([-np.sin(th), np.cos(th)], 1)[~at_change], atol=1e-9)
    compare(a, sims["newton"])
    crossings = np.arange(180 * np.ceil(x[0] / 180), x[-1] + 1e-9, 180.0)
    sing = sorted(e["input"]["A"] for e in a.events if e["kind"] == "singular" and not e.get("before_sweep"))
    assert len(sing) == len(crossings) and np.allclose(sing, crossings, atol=1e-9, rtol=0)


def test_drawn_branch_decides_where_the_sweep_starts():
    """Drawn at 60 degrees, a sweep over -30..50 (not containing 60, behind a change point)
    starts on the parallelogram branch continued backwards from the drawn configuration,
    and says that a change point lies between."""
    m = parallelogram(60.0)
    x = input_grid(-30, 50, 5)
    th = np.radians(x)
    for meth in ("assur", "newton"):
        sim = simulate(m, {"A": x}, points=["C"], method=meth)
        assert np.abs(sim.points["C"].position - np.stack([4 + np.cos(th), np.sin(th)], 1)).max() < 1e-5
        if meth == "assur":
            assert np.abs(sim.points["C"].position - np.stack([4 + np.cos(th), np.sin(th)], 1)).max() < 1e-12
            before = [e for e in sim.events if e.get("before_sweep")]
            assert [e["kind"] for e in before] == ["singular"] and abs(before[0]["input"]["A"]) < 1e-9


@pytest.mark.parametrize("name", ["textbook/watt_sixbar.yaml", "textbook/stephenson_sixbar.yaml", "triad"])
@pytest.mark.parametrize("theta", [20.0, pytest.param(75.0, marks=pytest.mark.slow),
                                   pytest.param(100.0, marks=pytest.mark.slow)])
def test_sweeps_pass_through_the_drawn_configuration(ex, name, theta):
    base = triad() if name == "triad" else ex(name)
    S = build_system(base)
    methods = ["newton"] if decompose(S) is None else ["assur", "newton"]
    if name == "triad":
        assert decompose(S) is None  # a class-III group: Newton continuation
    drawn, points = redrawn(base, theta, methods[0])
    for lo, hi, step in [(theta - 80, theta + 20, 5), (theta - 20, theta + 40, 2.5), (theta, theta + 30, 10),
                         (theta - 30, theta, 6)]:
        x = input_grid(lo, hi, step)
        k = int(np.argmin(np.abs(x - theta)))
        assert abs(x[k] - theta) < 1e-9
        for meth in methods:
            sim = simulate(drawn, {"A": x}, points=list(points), method=meth)
            assert sim.assembled[k]
            for j, P in points.items():
                assert np.abs(sim.points[j].position[k] - P).max() < 1e-9, (meth, lo, hi, j)


def test_option_switches_to_the_other_branch_at_change_points():
    """change_points='switch': the parallelogram turns anti-parallelogram at its change
    points (the other assembly mode of the dyad B-C-D)."""
    m = parallelogram(60.0)
    x = input_grid(0, 360, 10)
    keep = simulate(m, {"A": x}, points=["C"])
    other = simulate(m, {"A": x}, points=["C"], change_points="switch")
    th = np.radians(x)
    first = x <= 180  # the drawn part, up to the first change point after the drawn input
    assert np.allclose(other.points["C"].position[first], keep.points["C"].position[first], atol=1e-12)
    later = (x > 180) & (x < 360)  # between the change points, where the two modes differ
    off = np.linalg.norm(other.points["C"].position - np.stack([4 + np.cos(th), np.sin(th)], 1), axis=1)
    assert off[later].min() > 1e-3
    # the anti-parallelogram: |BC| = 4, |CD| = 1 still
    B = np.stack([np.cos(th), np.sin(th)], 1)
    C = other.points["C"].position
    assert np.allclose(np.linalg.norm(C - B, axis=1), 4) and np.allclose(np.linalg.norm(C - [4, 0], axis=1), 1)
    assert any("other branch" in e["message"] for e in other.events if e["kind"] == "singular")
    with pytest.raises(Exception):
        simulate(m, {"A": x}, method="newton", change_points="switch")


def fold_input(mech, crank=("A", "B"), rocker=("C", "D"), coupler=("B", "C")):
    """The crank angle (degrees) at which the coupler and the rocker of a four-bar lie
    stretched along one line (a dead point of the crank), by the law of cosines."""
    P = {j.id: np.asarray(j.point, float) for j in mech.joints}
    a = np.linalg.norm(P[crank[1]] - P[crank[0]])
    b = np.linalg.norm(P[coupler[1]] - P[coupler[0]])
    c = np.linalg.norm(P[rocker[1]] - P[rocker[0]])
    g = np.linalg.norm(P[rocker[1]] - P[crank[0]])
    return float(np.degrees(np.arccos((a * a + g * g - (b + c) ** 2) / (2 * a * g))))


@pytest.mark.parametrize("method", ["assur", "newton"])
@pytest.mark.parametrize("side", ["starts", "ends"])
def test_sweep_at_its_dead_point(ex, method, side):
    """A sweep that starts (or ends) exactly at the dead point: the sample there is singular,
    an event says so, and its rates are undefined (NaN), never 1e5 from a nearly singular
    Jacobian; the closed form and Newton agree."""
    m = ex("textbook/fourbar.yaml")
    th = fold_input(m)
    x = input_grid(th, th + 40, 5) if side == "starts" else input_grid(th - 40, th, 5)
    k = 0 if side == "starts" else len(x) - 1
    assert x[k] == th
    sim = simulate(m, {"A": x}, points=["B", "C", "M"], method=method)
    assert sim.assembled[k]
    sing = [e for e in sim.events if e["kind"] == "singular" and e["index"] == k]
    assert sing and abs(sing[0]["input"]["A"] - th) < 1e-9
    for lk in sim.links.values():
        assert np.isnan(lk.angular_velocity[k]) and np.isnan(lk.angular_acceleration[k])
    for p in sim.points.values():
        assert np.isnan(p.velocity[k]).all() and np.isnan(p.acceleration[k]).all()
        regular = sim.assembled.copy()
        regular[k] = False
        assert np.isfinite(p.velocity[regular]).all() and np.abs(p.velocity[regular]).max(initial=0) < 1e3
    if side == "starts":
        dead = [e for e in sim.events if e["kind"] == "dead point"]
        assert len(dead) == 1 and abs(dead[0]["input"]["A"] - th) < 1e-9
    other = simulate(m, {"A": x}, points=["B", "C", "M"], method="assur" if method == "newton" else "newton")
    compare(sim, other)


def test_cli_sweep_at_its_dead_point_gives_null_rates(ex, cli_json):
    """The same through ``simulate --json``: the flagged row's rates are null, and no value
    of a numerical blow-up (above 1e6) is presented as a number anywhere."""
    th = fold_input(ex("textbook/fourbar.yaml"))
    for method in ("assur", "newton"):
        d = cli_json("simulate", EX / "textbook/fourbar.yaml", "--input", f"A={th!r}:{th + 40!r}:5",
                     "--points", "M,C", "--method", method)
        assert d["input"]["values"][0] == pytest.approx(th, abs=1e-12)
        flagged = {e["index"] for e in d["events"] if e["kind"] == "singular"}
        assert 0 in flagged, method
        for series in list(d["points"].values()) + list(d["links"].values()):
            for key, rows in series.items():
                if key in ("velocity", "acceleration", "angular_velocity", "angular_acceleration"):
                    assert rows[0] is None or all(v is None for v in rows[0]), (method, key)
                flat = np.array([v for r in rows if r is not None
                                 for v in (r if isinstance(r, list) else [r]) if v is not None], float)
                assert np.abs(flat).max(initial=0) < 1e6, (method, key)


@pytest.mark.parametrize("grid", ["between", "on"])
def test_peaucellier_cell_through_its_flat_rhombus(ex, grid):
    """The Peaucellier-Lipkin cell passes its flat rhombus (Q coincides with P, the dyad
    A-Q-B's two modes meet: a bifurcation) at crank angles +-2 acos(sqrt(21)/6): both
    methods report it as singular (refined input), agree on every position (1e-9 away from
    a singular sample), keep Q on its straight line x = 3.5 (the smooth branch, not the
    branch Q = P) and give null rates only at a sample that is the singular position."""
    m = ex("kinematics/peaucellier.yaml")
    P = {j.id: np.asarray(j.point, float) for j in m.joints}
    ell, s = np.linalg.norm(P["A1"] - P["O1"]), np.linalg.norm(P["A1"] - P["P1"])
    r = np.linalg.norm(P["P1"] - P["E"])
    k2 = ell ** 2 - s ** 2  # the inversion: OP * OQ = l^2 - s^2
    flat = float(np.degrees(2 * np.arccos(np.sqrt(k2) / (2 * r))))  # where OP = sqrt(l^2 - s^2)
    x = input_grid(-100, 100, 5) if grid == "between" else input_grid(-flat, flat, flat / 5)
    sims = {meth: simulate(m, {"E": x}, points=["P1", "A1", "B1", "Q"], method=meth)
            for meth in ("assur", "newton")}
    for meth, sim in sims.items():
        assert sim.method == meth and sim.assembled.all()
        sing = sorted(e["input"]["E"] for e in sim.events if e["kind"] == "singular")
        assert np.allclose(sing, [-flat, flat], atol=1e-9 if meth == "assur" else 1e-6, rtol=0), (meth, sing)
        assert not [e for e in sim.events if e["kind"] in ("dead point", "reassembled")]
        on = np.isin(np.arange(len(x)), [e["index"] for e in sim.events if e["kind"] == "singular"]) & (
            np.isclose(np.abs(x), flat, atol=1e-12))
        assert on.any() == (grid == "on")
        Q, Pp = sim.points["Q"].position, sim.points["P1"].position
        line = np.abs(Q[:, 0] - k2 / (2 * r))
        assert line[~on].max() < 1e-9 and line[on].max(initial=0) < 1e-6
        assert np.allclose(np.linalg.norm(Q, axis=1) * np.linalg.norm(Pp, axis=1), k2, atol=1e-6)
        v = sim.points["Q"].velocity
        assert np.isnan(v[on]).all() and np.isfinite(v[~on]).all() and np.abs(v[~on]).max() < 10
        assert np.allclose(v[~on, 0], 0, atol=1e-8)  # Q moves along its line
    compare(sims["assur"], sims["newton"])
