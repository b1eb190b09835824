"""The studio editor's server side (mechsyn.web._studio): invalid states in the studio's
words, the Examples menu with the spatial files, the drawing and DXF exports."""

from __future__ import annotations

import copy

import pytest

from mechsyn.io import load_mechanism, mechanism_to_dict
from mechsyn.structure.report import analyze
from mechsyn.web._service import example_path


@pytest.fixture
def fourbar():
    return mechanism_to_dict(load_mechanism(example_path("fourbar")))


def diagnostics(client, mech):
    r = client.post("/api/studio/check", json={"mechanism": mech})
    assert r.status_code == 200, r.json()
    return r.json()


def test_a_valid_mechanism_has_nothing_to_say(client, fourbar):
    d = diagnostics(client, fourbar)
    assert d["diagnostics"] == [] and d["drives"] == ["A"]
    assert d["mobility"] == analyze(load_mechanism(example_path("fourbar"))).mobility == 1


def test_structure_and_extra_drives(client, fourbar):
    tri = {"name": "t", "kind": "planar", "ground": "frame", "links": ["frame", "L1", "L2"],
           "joints": [{"id": "A", "type": "R", "links": ["frame", "L1"], "point": [0, 0], "actuated": True},
                      {"id": "B", "type": "R", "links": ["L1", "L2"], "point": [1, 1]},
                      {"id": "C", "type": "R", "links": ["L2", "frame"], "point": [2, 0]}]}
    (msg,) = diagnostics(client, tri)["diagnostics"]
    assert msg["blocks"] and "structure" in msg["message"] and msg["elements"] == [{"kind": "joint", "id": "A"}]
    two = copy.deepcopy(fourbar)
    two["joints"][3]["actuated"] = True
    (msg,) = diagnostics(client, two)["diagnostics"]
    assert msg["message"].startswith("2 drives (A, D) for mobility 1: ") and msg["elements"] == [{"kind": "joint", "id": "D"}]


def test_loose_parts_in_the_studio_words(client, fourbar):
    no_c = copy.deepcopy(fourbar)
    no_c["joints"] = [j for j in no_c["joints"] if j["id"] != "C"]
    msgs = diagnostics(client, no_c)["diagnostics"]
    assert [m["elements"] for m in msgs] == [[{"kind": "link", "id": "coupler"}], [{"kind": "link", "id": "rocker"}]]
    assert all("join it to another link with Link, or delete it" in m["message"] for m in msgs)
    assert not any("actuated" in m["message"] or "links: [" in m["message"] for m in msgs)
    no_pivots = copy.deepcopy(fourbar)
    no_pivots["joints"] = [j for j in no_pivots["joints"] if j["id"] not in ("A", "D")]
    msgs = diagnostics(client, no_pivots)["diagnostics"]
    assert "links crank, coupler and rocker are not connected to the frame" in msgs[-1]["message"]


def test_spatial_is_said_not_refused(client):
    d = diagnostics(client, mechanism_to_dict(load_mechanism(example_path("bennett"))))
    # issue 25: the engine moves the Bennett linkage, so the studio shows it in 3-D (test_studio_3d.py)
    assert d["spatial"] and d["diagnostics"][0]["message"].startswith("spatial mechanism: 3-D view")


def test_examples_menu_lists_the_spatial_files(client):
    ex = client.get("/api/studio/examples").json()["examples"]
    kinds = {e["name"]: e["kind"] for e in ex}
    assert {kinds[n] for n in ("bennett", "delta", "rps3", "gough_stewart_6sps")} == {"spatial"}
    assert kinds["fourbar"] == "planar" and kinds["cam_follower"] == "planar"
    planar = [e["name"] for e in client.get("/api/examples").json()["examples"]]
    assert [e["name"] for e in ex if e["kind"] == "planar"] == planar


def test_drawing_is_the_library_drawing(client, fourbar):
    from mechsyn.export.drawing import drawing_of

    r = client.post("/api/studio/drawing", json={"mechanism": fourbar})
    assert r.status_code == 200 and r.headers["content-type"].startswith("image/svg+xml")
    svg = r.text
    assert svg.startswith("<?xml") or svg.startswith("<svg")
    plain = drawing_of(load_mechanism(example_path("fourbar")), dimensions=True)
    assert svg.count("<line") >= plain.count("<line")  # the same bars, plus the paths


def test_dxf_needs_ezdxf_or_gives_plates(client, fourbar):
    r = client.post("/api/studio/dxf", json={"mechanism": fourbar})
    try:
        import ezdxf  # noqa: F401
    except ImportError:
        assert r.status_code == 400 and "ezdxf" in r.json()["error"] and r.json()["hint"]
    else:
        assert r.status_code == 200 and "SECTION" in r.text


def test_the_check_reads_the_finite_mobility_and_names_a_redundant_bar(client):
    """A four-bar drawn folded moves with one drive (instantaneous mobility 2, finite 1); one
    pulled taut cannot move (finite mobility 0); the double parallelogram moves and says which
    bar is redundant; a pivot just placed is a next step, not a file error."""
    def ex(name):
        return mechanism_to_dict(load_mechanism(example_path(name)))

    assert diagnostics(client, ex("fourbar_folded"))["diagnostics"] == []
    (taut,) = diagnostics(client, ex("fourbar_taut"))["diagnostics"]
    assert taut["blocks"] and taut["message"].startswith("cannot move") and "finite mobility 0" in taut["message"]
    (dup,) = diagnostics(client, ex("double_parallelogram"))["diagnostics"]
    assert not dup["blocks"] and "crank2 or crank3 is redundant" in dup["message"]
    assert dup["elements"] == [{"kind": "link", "id": "crank2"}, {"kind": "link", "id": "crank3"}]
    pivot = {"name": "n", "kind": "planar", "ground": "frame", "links": ["frame"],
             "joints": [{"id": "A", "type": "R", "links": ["frame"], "point": [0, 0]}]}
    (first,) = diagnostics(client, pivot)["diagnostics"]
    assert first["level"] == "note" and "not joined to a moving link yet" in first["message"]
    assert "links: [" not in first["message"]
