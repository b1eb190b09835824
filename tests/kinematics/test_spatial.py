"""Spatial kinematics (issue 25 item 4) against checks that do not use the engine's equations:
closure recomputed from the reported link poses, velocities and accelerations against finite
differences of the reported positions, Bennett's input-output relation, the spherical
Freudenstein equation, the Delta robot's closed-form inverse kinematics, the RSSR's
assembly condition, scale invariance, idle motions at rest, errors that name the fix."""

import json
from dataclasses import replace

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.cli.main import main
from mechsyn.errors import MechsynInputError
from mechsyn.errors import EngineDeclined
from mechsyn.kinematics.spatial import SpatialEngine


def sim(name, joint, grid, **kw):
    return ms.simulate(ms.examples.load(name), {joint: grid}, **kw)


def pose(s, link, k):
    if link not in s.links:
        return np.eye(3), np.zeros(3)
    return s.links[link].rotation[k], s.links[link].translation[k]


def joint_lines(s, j, k):
    """The joint's point and axis as carried by each of its two links at row ``k``."""
    out = []
    for link in j.links:
        R, t = pose(s, link, k)
        out.append((R @ np.asarray(j.point, float) + t, None if j.axis is None else R @ np.asarray(j.axis, float)))
    return out


def closure_error(s, mech, k):
    """Largest mismatch (in units of the length scale) of the pairs at row ``k``, from the
    reported poses alone: R, U, S points coincide, R axes stay parallel."""
    err = 0.0
    for j in mech.joints:
        (pa, aa), (pb, ab) = joint_lines(s, j, k)
        if j.type in ("R", "U", "S"):
            err = max(err, np.linalg.norm(pa - pb) / s.length_scale)
        if j.type == "R":
            err = max(err, np.linalg.norm(np.cross(aa, ab)) / np.linalg.norm(aa) ** 2)
        if j.type == "U":  # the cross keeps its right angle (or its drawn angle)
            Ra, _ = pose(s, j.links[0], k)
            Rb, _ = pose(s, j.links[1], k)
            a1, a2 = np.asarray(j.axis, float), np.asarray(j.axis2, float)
            a1, a2 = a1 / np.linalg.norm(a1), a2 / np.linalg.norm(a2)
            err = max(err, abs((Ra @ a1) @ (Rb @ a2) - a1 @ a2))
        if j.type == "P":  # no relative rotation; the slide along the first link's axis
            Ra, ta = pose(s, j.links[0], k)
            Rb, tb = pose(s, j.links[1], k)
            err = max(err, np.abs(Ra - Rb).max())
            x0 = np.zeros(3) if j.point is None else np.asarray(j.point, float)
            d = (Rb @ x0 + tb) - (Ra @ x0 + ta)
            err = max(err, np.linalg.norm(np.cross(d, Ra @ j.axis)) / np.linalg.norm(j.axis) / s.length_scale)
    return err


SWEEPS = [("bennett", "R1", (0, 360, 1)), ("spherical_fourbar", "A", (0, 360, 1)), ("rssr", "A", (0, 90, 1)),
          ("delta", "R1", (-30, 30, 1)), ("rps3", "P1", (-0.2, 0.2, 0.01)), ("stewart_6ups", "P1", (-0.1, 0.1, 0.01))]


@pytest.mark.parametrize("name,joint,rng", SWEEPS)
def test_closure_from_the_reported_poses(name, joint, rng):
    s = sim(name, joint, ms.input_grid(*rng))
    mech = ms.examples.load(name)
    assert s.engine == "spatial" and s.assembled.all() and s.events == []  # no false alarm
    assert np.nanmax(s.residual) < 1e-9
    assert max(closure_error(s, mech, k) for k in range(len(s.assembled))) < 1e-9


@pytest.mark.parametrize("name,joint,rng", SWEEPS[:4])
def test_velocities_and_accelerations_match_finite_differences(name, joint, rng):
    a, b, _ = rng
    x = np.linspace(a + 1, b - 1, 7)
    hv, ha = 1e-3, 0.05  # degrees: rounding (1e-12 / h, 1e-12 / h^2) and truncation (h^2) balanced
    grid = np.concatenate([x, x - hv, x + hv, x - ha, x + ha])
    s = sim(name, joint, grid, speeds={joint: 1.0})  # 1 rad/s: d/dt = d/d(input in rad)
    n = len(x)
    for pname, pm in s.points.items():
        P, V, A = pm.position, pm.velocity, pm.acceleration
        fd_v = (P[2 * n:3 * n] - P[n:2 * n]) / (2 * np.radians(hv))
        fd_a = (P[4 * n:] - 2 * P[:n] + P[3 * n:4 * n]) / np.radians(ha) ** 2
        assert np.abs(V[:n] - fd_v).max() < 1e-6 * s.length_scale, pname
        assert np.abs(A[:n] - fd_a).max() < 1e-4 * s.length_scale, pname


def dh_angles(s, mech, k, order):
    """Joint angles of a single 4R loop by the Denavit-Hartenberg convention: at each axis,
    from the common normal of the previous axis to that of the next, about the axis."""
    lines = []
    for jid in order:
        j = mech.joint(jid)
        R, t = pose(s, j.links[1], k)
        lines.append((R @ j.point + t, R @ (j.axis / np.linalg.norm(j.axis))))

    def normal(p1, z1, p2, z2):
        n = np.cross(z1, z2)
        n /= np.linalg.norm(n)
        return n if (p2 - p1) @ n > 0 else -n

    th = []
    for i in range(4):
        (pp, zp), (pc, zc), (pn, zn) = lines[i - 1], lines[i], lines[(i + 1) % 4]
        x0, x1 = normal(pp, zp, pc, zc), normal(pc, zc, pn, zn)
        th.append(np.arctan2(np.cross(x0, x1) @ zc, x0 @ x1))
    return np.array(th)


def test_bennett_input_output_relation():
    """Bennett (1914), Baker (1979): with twists α = 30°, β = 60° and a/sin α = b/sin β,
    tan(θ1/2) tan(θ2/2) = sin((β + α)/2) / sin((β - α)/2) all along the motion, and the
    opposite joint angles are equal and opposite (θ3 = -θ1, θ4 = -θ2)."""
    mech = ms.examples.load("bennett")
    s = sim("bennett", "R1", ms.input_grid(0, 360, 1))
    a, b = np.radians(30), np.radians(60)
    K = np.sin((b + a) / 2) / np.sin((b - a) / 2)
    drawn = dh_angles(s, mech, 0, ["R1", "R2", "R3", "R4"])[0]
    for k in range(0, 361, 7):
        th = dh_angles(s, mech, k, ["R1", "R2", "R3", "R4"])
        if abs(np.cos(th[0] / 2)) < 1e-3 or abs(np.cos(th[1] / 2)) < 1e-3:
            continue
        assert np.tan(th[0] / 2) * np.tan(th[1] / 2) == pytest.approx(K, rel=1e-9)
        assert np.sin(th[2] + th[0]) == pytest.approx(0, abs=1e-9)
        assert np.sin(th[3] + th[1]) == pytest.approx(0, abs=1e-9)
        # the drive: the input is the rotation from the drawn assembly
        assert np.sin(th[0] - drawn - np.radians(s.inputs["R1"][k])) == pytest.approx(0, abs=1e-9)


def test_spherical_four_bar_freudenstein():
    """The spherical Freudenstein equation (Chiang 1988) with arcs α1 = 60 (frame),
    α2 = 25 (crank), α3 = 55 (coupler), α4 = 45 (rocker) degrees: the rocker angle φ solves
    A cos φ + B sin φ = C; the branch is the drawn one, for every crank angle."""
    a1, a2, a3, a4 = np.radians([60, 25, 55, 45])
    s = sim("spherical_fourbar", "A", ms.input_grid(0, 360, 2), points=["B", "C", "P"])
    B_, C_ = s.point("B"), s.point("C")
    Ry = np.array([[np.cos(a1), 0, np.sin(a1)], [0, 1, 0], [-np.sin(a1), 0, np.cos(a1)]])
    theta = np.arctan2(B_[:, 1], B_[:, 0])
    v = C_ @ Ry  # rows: Ry^T c
    phi = np.arctan2(v[:, 1], v[:, 0])
    A = np.sin(a2) * np.cos(theta) * np.cos(a1) * np.sin(a4) - np.cos(a2) * np.sin(a1) * np.sin(a4)
    B = np.sin(a2) * np.sin(theta) * np.sin(a4)
    C = np.cos(a3) - np.sin(a2) * np.cos(theta) * np.sin(a1) * np.cos(a4) - np.cos(a2) * np.cos(a1) * np.cos(a4)
    expected = np.arctan2(B, A) + np.arccos(C / np.hypot(A, B))  # the drawn branch (+)
    assert np.abs(np.sin(phi - expected)).max() < 1e-9
    assert np.abs(np.sin(theta - np.radians(40 + s.inputs["A"]))).max() < 1e-9
    assert np.allclose(np.linalg.norm(C_, axis=1), 1.0, atol=1e-12)  # on the unit sphere
    # inputs in any order (long jumps between rows): the same branch at every row
    grid = np.random.default_rng(1).permutation(s.inputs["A"])
    t = sim("spherical_fourbar", "A", grid, points=["C"])
    k = np.searchsorted(s.inputs["A"], grid)
    assert np.abs(t.point("C") - C_[k]).max() < 1e-9


def delta_arm_angle(mech, i, platform_shift):
    """Clavel's Delta, arm ``i`` (1..3): the arm angles (rotation from the drawn assembly)
    that put the elbow at the bar length from the platform's attachment (closed form)."""
    R = mech.joint(f"R{i}")
    A, u = np.asarray(R.point, float), np.asarray(R.axis, float) / np.linalg.norm(R.axis)
    E0 = (np.asarray(mech.joint(f"S{i}a1").point) + np.asarray(mech.joint(f"S{i}b1").point)) / 2
    P0 = (np.asarray(mech.joint(f"S{i}a2").point) + np.asarray(mech.joint(f"S{i}b2").point)) / 2
    ell = np.linalg.norm(E0 - P0)
    r = E0 - A
    r_par = (r @ u) * u
    e1 = r - r_par
    e2 = np.cross(u, e1)
    d = P0 + platform_shift - A - r_par  # E(q) - A - r_par = cos q e1 + sin q e2
    # |cos q e1 + sin q e2 - d|^2 = ell^2  ->  a cos q + b sin q = c
    a, b = 2 * (e1 @ d), 2 * (e2 @ d)
    c = e1 @ e1 + d @ d - ell ** 2
    base = np.arctan2(b, a)
    off = np.arccos(np.clip(c / np.hypot(a, b), -1, 1))
    return np.array([base + off, base - off])


def test_delta_one_drive_against_closed_form_inverse_kinematics():
    mech = ms.examples.load("delta")
    s = sim("delta", "R1", ms.input_grid(-30, 30, 2))
    plat = s.link("platform")
    # the parallelograms keep the platform parallel to itself
    assert np.abs(plat.rotation - np.eye(3)).max() < 1e-9
    for k, q in enumerate(np.radians(s.inputs["R1"])):
        for i, want in ((1, q), (2, 0.0), (3, 0.0)):
            sols = delta_arm_angle(mech, i, plat.translation[k])
            assert np.abs(np.sin((sols - want) / 2)).min() < 1e-9


def test_delta_idle_spins_stay_at_rest():
    """The six idle motions (each S-S bar spinning about its own line) get no velocity: the
    bar's angular velocity has no component along the bar."""
    mech = ms.examples.load("delta")
    s = sim("delta", "R1", ms.input_grid(-20, 20, 5))
    assert s.idle == 6
    for i in (1, 2, 3):
        for side in "ab":
            bar = s.link(f"bar{i}{side}")
            p, q = s.point(f"S{i}{side}1"), s.point(f"S{i}{side}2")
            axis = (q - p) / np.linalg.norm(q - p, axis=1)[:, None]
            assert np.abs(np.einsum("ij,ij->i", bar.angular_velocity, axis)).max() < 1e-9


def scaled(mech, f):
    joints = tuple(replace(j, point=None if j.point is None else np.asarray(j.point, float) * f) for j in mech.joints)
    points = {k: replace(p, at=np.asarray(p.at, float) * f) for k, p in mech.points.items()}
    return replace(mech, joints=joints, points=points)


@pytest.mark.parametrize("f", [1e-3, 1e4])
@pytest.mark.parametrize("name,joint", [("bennett", "R1"), ("rssr", "A")])
def test_scale_invariance(name, joint, f):
    mech = ms.examples.load(name)
    grid = ms.input_grid(0, 360, 3)
    a = ms.simulate(mech, {joint: grid})
    b = ms.simulate(scaled(mech, f), {joint: grid})
    assert np.array_equal(a.assembled, b.assembled)
    assert [(e["kind"], e["index"]) for e in a.events] == [(e["kind"], e["index"]) for e in b.events]
    for name_ in a.points:
        ok = a.assembled
        assert np.allclose(b.point(name_)[ok] / f, a.point(name_)[ok], rtol=0, atol=1e-9 * a.length_scale)
        assert np.allclose(b.points[name_].velocity[ok] / f, a.points[name_].velocity[ok], rtol=0,
                           atol=1e-8 * a.length_scale)


def rssr_assembles(theta):
    """The RSSR of examples/textbook/rssr.yaml assembles at crank angle θ (rad, from the
    drawn assembly) iff the rod length lies between the nearest and farthest distances from
    the crank pin B to the circle that the rocker's ball C describes."""
    B = np.stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)], axis=1)
    centre, rho = np.array([3.0, 2.0, 1.0]), np.hypot(1.0, 1.2)  # circle in the plane x = 3
    rod = np.linalg.norm(np.array([3, 1, 2.2]) - np.array([1, 0, 0]))
    dx = 3.0 - B[:, 0]
    r = np.hypot(B[:, 1] - centre[1], B[:, 2] - centre[2])
    near, far = np.sqrt(dx ** 2 + (r - rho) ** 2), np.sqrt(dx ** 2 + (r + rho) ** 2)
    return (near <= rod) & (rod <= far), np.minimum(np.abs(near - rod), np.abs(far - rod))


def test_rssr_working_range_dead_points_and_gap():
    s = sim("rssr", "A", ms.input_grid(0, 360, 1))
    want, margin = rssr_assembles(np.radians(s.inputs["A"]))
    clear = margin > 1e-6
    assert np.array_equal(s.assembled[clear], want[clear])
    kinds = [e["kind"] for e in s.events]
    assert "dead point" in kinds and "other way round" in kinds  # the gap closed the other way round (modulo 360)
    assert np.isnan(s.point("C")[~s.assembled]).all()
    d = s.to_dict()
    gap = np.flatnonzero(~s.assembled)
    assert d["points"]["C"]["position"][gap[0]] is None


def test_gough_stewart_one_leg_moves_with_its_leg_spins_idle():
    s = sim("gough_stewart_6sps", next(j.id for j in ms.examples.load("gough_stewart_6sps").joints if j.actuated),
            np.linspace(0, 0.05, 11))
    assert s.assembled.all() and np.nanmax(s.residual) < 1e-9
    assert s.idle == 6


def test_helical_rocker_keeps_its_pitch():
    """An RSSH loop (the RSSR with its rocker on a screw of pitch 0.2 per radian): the screw's
    slide is the pitch times its rotation at every row, closure holds, and the rates match
    finite differences."""
    m = ms.examples.load("rssr")
    pitch = 0.2
    screw = replace(m, joints=tuple(replace(j, type="H", pitch=pitch) if j.id == "D" else j for j in m.joints))
    s = ms.simulate(screw, {"A": ms.input_grid(0, 80, 1)}, points=["C"])
    assert s.assembled.all() and np.nanmax(s.residual) < 1e-9
    assert np.allclose(s.joints["D/slide"], pitch * np.radians(s.joints["D"]), rtol=0, atol=1e-9)
    assert np.abs(s.joints["D/slide"]).max() > 0.01  # it does slide
    # the rocker (D's first link) moves along D's axis x by minus the slide (the slide is the
    # second link's, the frame's, relative to the first)
    P = s.point("C")
    assert np.allclose(P[:, 0] - P[0, 0], -(s.joints["D/slide"] - s.joints["D/slide"][0]), atol=1e-9)
    h = np.radians(1e-3)
    t = ms.simulate(screw, {"A": np.array([40 - 1e-3, 40, 40 + 1e-3])}, points=["C"])
    fd = (t.point("C")[2] - t.point("C")[0]) / (2 * h)
    assert np.abs(t.points["C"].velocity[1] - fd).max() < 1e-6


def parallelogram_3d(theta=60.0):
    """A parallelogram four-bar (crank 1, coupler 4) written as a spatial file, drawn at θ."""
    from mechsyn.io import mechanism_from_dict

    t = np.radians(theta)
    B = [np.cos(t), np.sin(t), 0.0]
    z = [0, 0, 1]
    return mechanism_from_dict({"name": "parallelogram 3-D", "kind": "spatial", "ground": "frame",
                                "links": ["frame", "crank", "coupler", "rocker"], "joints": [
        {"id": "A", "type": "R", "links": ["frame", "crank"], "point": [0, 0, 0], "axis": z, "actuated": True},
        {"id": "B", "type": "R", "links": ["crank", "coupler"], "point": B, "axis": z},
        {"id": "C", "type": "R", "links": ["coupler", "rocker"], "point": [4 + B[0], B[1], 0], "axis": z},
        {"id": "D", "type": "R", "links": ["rocker", "frame"], "point": [4, 0, 0], "axis": z}]}, "parallelogram")


def test_change_points_reported_and_passed_on_the_drawn_branch():
    """The parallelogram's change points (crank at 0, 180, 360 degrees, where it could turn
    into an anti-parallelogram) are singular: reported at the row that hits one (rates null)
    and, between rows, located by the search; the sweep stays a parallelogram throughout."""
    g = np.arange(-90, 330, 0.7)  # crank = 60 + input: 180 is a row, 0 and 360 fall between rows
    s = ms.simulate(parallelogram_3d(), {"A": g}, points=["B", "C"])
    assert s.assembled.all() and np.nanmax(s.residual) < 1e-9
    assert np.abs(s.point("C") - s.point("B") - [4, 0, 0]).max() < 1e-6
    sing = [e for e in s.events if e["kind"] == "singular"]
    crank = sorted(e["input"]["A"] + 60 for e in sing)
    assert np.allclose(crank, [0.0, 180.0, 360.0], rtol=0, atol=1e-6 * 0.7)  # refined to 1e-6 of the step
    at_row = [e for e in sing if not e.get("crossed")]
    assert len(at_row) == 1 and np.isnan(s.points["C"].velocity[at_row[0]["index"]]).all()


def test_spatial_engine_takes_planar_r_and_p_pairs_only():
    """A planar file of R and P pairs goes through as its 3-D equivalent (the same pose at
    the same input value, z = 0); a cam is declined in one line that names it."""
    eng = SpatialEngine()
    assert eng.name == "spatial"
    m = ms.examples.load("crank_rocker")
    s = eng.simulate(m, {"A": np.array([0.0, 75.0])})
    p = m.simulate({"A": np.array([0.0, 75.0])})
    assert s.inputs["A"].tolist() == [0.0, 75.0] and np.abs(s.point("M")[:, 2]).max() == 0.0
    assert np.abs(s.point("M")[:, :2] - p.point("M")).max() < 1e-9
    with pytest.raises(EngineDeclined, match="joint K is a cam pair"):
        eng.simulate(ms.examples.load("cam_roller"), {"O": np.array([0.0])})


def test_bad_inputs_name_the_fix():
    m = ms.examples.load("rssr")
    with pytest.raises(MechsynInputError, match="only R, P, H, C and U"):
        ms.simulate(m, {"B": np.array([0.0, 1.0])})
    cam = replace(m, joints=tuple(replace(j, type="E") if j.id == "C" else j for j in m.joints))
    with pytest.raises(MechsynInputError, match="R, P, C, U, S and H pairs"):
        ms.simulate(cam, {"A": np.array([0.0, 1.0])})
    with pytest.raises(MechsynInputError, match="no joint 'Q'"):
        ms.simulate(m, {"Q": np.array([0.0])})
    # a cylindrical rocker bearing frees a slide the drive does not determine
    with pytest.raises(MechsynInputError, match="force analysis needs a planar"):
        ms.forces(m, {"A": np.array([0.0, 1.0])})
    free = replace(m, joints=tuple(replace(j, type="C", pair_class=4) if j.id == "D" else j for j in m.joints))
    with pytest.raises(MechsynInputError, match="not determined"):
        ms.simulate(free, {"A": np.array([0.0, 1.0])})


def test_cli_json_is_to_dict_and_text_fits_80_columns(capsys, monkeypatch):
    assert main(["simulate", "bennett", "-i", "R1=0:360:30", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    s = sim("bennett", "R1", ms.input_grid(0, 360, 30))
    assert d["engine"] == "spatial" and set(d) == set(s.to_dict())
    assert np.allclose(np.array(d["points"]["R3"]["position"], float), s.point("R3"), atol=1e-12)
    monkeypatch.setenv("COLUMNS", "80")
    assert main(["simulate", "rssr", "-i", "A=0:360:5"]) == 0
    out = capsys.readouterr().out
    assert "dead point" in out and "other way round" in out
    assert max(len(line) for line in out.splitlines()) <= 80


def test_plot_and_animation_on_3d_axes():
    from matplotlib.figure import Figure

    s = sim("delta", "R1", ms.input_grid(-20, 20, 10))
    ax = s.plot(ax=Figure().add_subplot(projection="3d"))
    assert ax.name == "3d" and "length" in ax.get_xlabel()
    lo, hi = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()]).T
    assert np.allclose(hi - lo, (hi - lo)[0])  # equal scales
    anim = s.animate(fig=Figure())
    anim._init_draw()
    with pytest.raises(MechsynInputError, match="3-D axes"):
        s.plot(ax=Figure().add_subplot())
