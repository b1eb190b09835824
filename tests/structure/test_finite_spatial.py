"""Issue 25 item 3: shaky spatial linkages, the nearest checkable stand-ins for Wohlhart's
three-loop linkage (whose joint geometry the sources at hand do not give).

``examples/spatial/octahedron_shaky.yaml``: the octahedral (3-3) platform with its six legs
locked, at Fichter's pose. The expected answers are computed here from the framework's
points and bars alone (no screws, nothing of mechsyn's rank method):

- Blaschke-Liebmann: the planes of four alternate faces meet in one point, so the
  octahedron is infinitesimally movable;
- the rigidity matrix of the bar framework (base fixed; three platform bars, six legs) has
  as many flexes as self-stresses (here one each);
- second-order rigidity (Connelly and Whiteley 1996): with the self-stress ``w`` and the flex
  ``v``, ``Σ w_ij |v_i - v_j|²`` is not zero, so the flex does not extend: the platform
  cannot move. What moves finitely is each leg spinning about its own ball-ball line.

So the instantaneous mobility is 6 spins + the flexes, the redundant constraints are the
self-stresses, the finite mobility is the 6 spins, and the configuration space (the spins'
torus, platform at rest) is smooth: a shaky configuration. Turned by a few degrees about
its normal, the platform is rigid to first order: 6 spins, nothing redundant, regular.

With R pairs only: a spherical four-bar stretched taut, its four axes through one centre
and in one plane, crank 20° + coupler 30° + rocker 40° = frame 90°. Four coplanar
rotation axes through a point span two rotations: instantaneous mobility 4 - 2 = 2 and
6 - 2 = 4 redundant constraints; by the spherical triangle inequality the angle between
the frame's two axes (90°) is at most crank + coupler + rocker (90°), with equality only
when all four axes lie on one great circle in order, so this is the only assembly:
finite mobility 0, an isolated (smooth, 0-dimensional) point: shaky.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from mechsyn.io import load_mechanism, mechanism_from_dict
from mechsyn.structure.analysis import analyze_structure
from mechsyn.structure.rank import analyze_rank

FILE = Path(__file__).resolve().parents[2] / "examples" / "spatial" / "octahedron_shaky.yaml"
SEEDS = (0, 1, 2)


def _file() -> dict:
    return yaml.safe_load(FILE.read_text())


def _points(d: dict) -> tuple[dict[str, np.ndarray], list[tuple[str, str]], set[str]]:
    """The octahedron in the file: its vertices (a joint point is a vertex; the frame's are
    fixed), its bars (each leg, and the platform's three sides) and the fixed vertices."""
    at = {j["id"]: tuple(float(x) for x in j["point"]) for j in d["joints"]}
    name = {p: f"V{i}" for i, p in enumerate(sorted(set(at.values())))}
    verts = {v: np.array(p) for p, v in name.items()}
    fixed = {name[at[j["id"]]] for j in d["joints"] if "frame" in j["links"]}
    legs = {}
    for j in d["joints"]:
        bar = next(link for link in j["links"] if link.startswith("bar"))
        legs.setdefault(bar, []).append(name[at[j["id"]]])
    top = sorted({name[at[j["id"]]] for j in d["joints"] if "platform" in j["links"]})
    bars = [tuple(v) for v in legs.values()] + [(top[0], top[1]), (top[1], top[2]), (top[2], top[0])]
    return verts, bars, fixed


def _rigidity(verts, bars, fixed):
    free = sorted(v for v in verts if v not in fixed)
    R = np.zeros((len(bars), 3 * len(free)))
    for k, (a, b) in enumerate(bars):
        d = verts[a] - verts[b]
        if a in free:
            R[k, 3 * free.index(a):3 * free.index(a) + 3] += d
        if b in free:
            R[k, 3 * free.index(b):3 * free.index(b) + 3] -= d
    return R, free


def framework_reading(d: dict) -> dict:
    """Flexes, self-stresses and the second-order test of the file's octahedron."""
    verts, bars, fixed = _points(d)
    R, free = _rigidity(verts, bars, fixed)
    u, s, vt = np.linalg.svd(R)
    rank = int(np.sum(s > 1e-9 * s[0]))
    flexes, stresses = R.shape[1] - rank, R.shape[0] - rank
    out = {"flexes": flexes, "stresses": stresses, "second_order": None}
    if flexes == 1 and stresses == 1:
        v, w = vt[-1], u[:, -1]
        vel = {name: v[3 * i:3 * i + 3] for i, name in enumerate(free)} | {name: np.zeros(3) for name in fixed}
        out["second_order"] = float(sum(w[k] * np.sum((vel[a] - vel[b]) ** 2) for k, (a, b) in enumerate(bars)))
    return out


def _turned(deg: float) -> dict:
    """The file with the platform turned by ``deg`` about its normal through its centre."""
    d = _file()
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    for j in d["joints"]:
        if "platform" in j["links"]:
            x, y, z = j["point"]
            j["point"] = [round(c * x - s * y, 12), round(s * x + c * y, 12), z]
    return d


def test_the_file_is_shaky_by_its_geometry():
    d = _file()
    verts, bars, fixed = _points(d)
    assert len(verts) == 6 and len(bars) == 9 and len(fixed) == 3  # an octahedron, base fixed
    # Blaschke-Liebmann: the platform's plane and the three faces (platform vertex, base edge)
    # of the other colour meet in one point
    top = [v for v in verts if v not in fixed]
    faces = [top] + [[a, *(b for bar in bars if a in bar for b in bar if b in fixed)] for a in top]
    planes = []
    for f in faces:
        p0, p1, p2 = (verts[x] for x in f)
        n = np.cross(p1 - p0, p2 - p0)
        planes.append(np.append(n / np.linalg.norm(n), -n @ p0 / np.linalg.norm(n)))
    P = np.array(planes)
    assert np.linalg.svd(P, compute_uv=False)[-1] < 1e-12  # four planes through one point
    r = framework_reading(d)
    assert (r["flexes"], r["stresses"]) == (1, 1)
    assert abs(r["second_order"]) > 0.1  # unit flex and stress: the flex does not extend


def test_the_turned_platform_is_rigid_to_first_order():
    r = framework_reading(_turned(5.0))
    assert (r["flexes"], r["stresses"]) == (0, 0)


@pytest.mark.parametrize("seed", SEEDS)
def test_rank_method_reads_the_octahedron_as_shaky(seed):
    geo = framework_reading(_file())
    spins = 6  # each bar about its own ball-ball line
    mech = load_mechanism(FILE)
    r = analyze_rank(mech, seed=seed)
    assert analyze_structure(mech).formulas["malyshev"].value == 6 * 7 - 3 * 12
    assert (r.mobility, len(r.idle_mobilities), r.redundant_constraints) == (spins + geo["flexes"], spins,
                                                                               geo["stresses"])
    assert all(i.family == "group" and len(i.links) == 1 for i in r.idle_mobilities)
    assert r.useful_mobility == geo["flexes"]
    assert (r.finite_mobility, r.configuration, r.shaky, r.singular) == (spins, "shaky", True, False)
    assert r.mobility_reading.startswith(f"shaky: instantaneous mobility {spins + 1} but finite mobility {spins}")


def test_turned_platform_reads_regular():
    r = analyze_rank(mechanism_from_dict(_turned(5.0), "turned.yaml"))
    assert (r.mobility, len(r.idle_mobilities), r.redundant_constraints) == (6, 6, 0)
    assert (r.finite_mobility, r.configuration, r.shaky, r.singular) == (6, "regular", False, False)


def test_the_verdict_says_shaky():
    from mechsyn.structure.report import verdict

    mech = load_mechanism(FILE)
    v = verdict(analyze_structure(mech), analyze_rank(mech))
    assert "not singular but SHAKY: finite mobility 6, 1 instantaneous motion(s) do not extend" in v["text"]
    assert (v["finite_mobility"], v["shaky"], v["singular"]) == (6, True, False)


@pytest.mark.slow
@pytest.mark.parametrize("rel, expected", [
    ("spatial/octahedron_shaky.yaml", (7, 6, "shaky")),
    ("textbook/fourbar_taut.yaml", (2, 0, "shaky")),
    ("textbook/fourbar_shaky_dyad.yaml", (2, 1, "shaky")),
    ("textbook/fourbar_folded.yaml", (2, 1, "singular")),
])
def test_thirty_seeds_read_alike(rel, expected):
    """The random samples never change the reading (a projection that jumps to a distant
    assembly, or a probe of a direction already found, once read the octahedron as singular)."""
    mech = load_mechanism(FILE.parents[1] / rel)
    runs = (analyze_rank(mech, seed=s) for s in range(30))
    readings = {(r.mobility, r.finite_mobility, r.configuration) for r in runs}
    assert readings == {expected}


def _spherical_taut(points: str) -> dict:
    """The taut spherical four-bar, its points at the centre or slid along the axes."""
    axes = [[round(np.cos(np.radians(a)), 12), 0.0, round(np.sin(np.radians(a)), 12)] for a in (0, 20, 50, 90)]
    slide = (0, 0, 0, 0) if points == "centre" else (1, 2, 1.5, 1)
    links = ["frame", "crank", "coupler", "rocker", "frame"]
    return {"name": "taut spherical four-bar", "kind": "spatial", "ground": "frame", "links": links[:4],
            "joints": [{"id": "ABCD"[i], "type": "R", "links": links[i:i + 2], "axis": a,
                        "point": [s * x for x in a]} for i, (a, s) in enumerate(zip(axes, slide))]}


@pytest.mark.parametrize("points, seed", [("centre", 0), ("centre", 1), ("centre", 2), ("along the axes", 0)])
def test_taut_spherical_fourbar_is_shaky_and_isolated(points, seed):
    d = _spherical_taut(points)
    rotations = np.linalg.matrix_rank(np.array([j["axis"] for j in d["joints"]]))  # 2: coplanar axes
    r = analyze_rank(mechanism_from_dict(d, "taut.yaml"), seed=seed)
    assert (r.mobility, r.redundant_constraints, len(r.idle_mobilities)) == (4 - rotations, 6 - rotations, 0)
    assert (r.finite_mobility, r.configuration, r.shaky, r.singular) == (0, "shaky", True, False)
