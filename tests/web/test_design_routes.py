"""Issue 40's routes (POST /api/design/...), called in-process: one library call each."""

from __future__ import annotations

import pytest

from mechsyn.io import load_mechanism, mechanism_from_dict, mechanism_to_dict
from mechsyn.kinematics.dimensions import link_lengths
from mechsyn.web._service import example_path


def ex(name):
    return mechanism_to_dict(load_mechanism(example_path(name)))


def test_dimension_route_keeps_the_other_lengths_or_names_the_condition(client):
    d = ex("crank_rocker")
    r = client.post("/api/design/dimension", json={"mechanism": d, "change": {"link": "rocker", "kind": "length", "value": 3.2}})
    assert r.status_code == 200
    assert link_lengths(mechanism_from_dict(r.json()["mechanism"])) == pytest.approx(
        {"frame": 4, "crank": 1, "coupler": 3.5, "rocker": 3.2}, rel=1e-9)
    bad = client.post("/api/design/dimension", json={"mechanism": d, "change": {"link": "rocker", "kind": "length", "value": 0.05}})
    assert bad.status_code == 400 and "triangle inequality" in bad.json()["error"] and bad.json()["field"] == "length"
    worse = client.post("/api/design/dimension", json={"mechanism": d, "change": {"link": "rocker", "kind": "bend", "value": 1}})
    assert worse.status_code == 400 and worse.json()["field"] == "kind"
    lst = client.post("/api/design/dimensions", json={"mechanism": d}).json()["dimensions"]
    assert [x["link"] for x in lst] == ["frame", "crank", "coupler", "rocker"]


def test_grashof_change_is_noted(client):
    d = ex("crank_rocker")
    r = client.post("/api/design/dimension", json={"mechanism": d, "change": {"link": "crank", "kind": "length", "value": 2.5}})
    assert r.status_code == 200 and any("Grashof" in n or "was crank-rocker" in n for n in r.json()["notes"])


def test_burmester_route_three_poses(client):
    body = {"targets": [[0, 0], [1, 0.5], [2, 0.6]], "angles": [0, 20, 45], "pivots": [[-0.5, 0.2], [1.0, 1.5]]}
    r = client.post("/api/design/burmester", json=body).json()
    assert len(r["results"]) == 1 and r["results"][0]["mechanism"]["name"].startswith("Four-bar motion")
    assert r["results"][0]["pivots"]["moving"][0][0] == pytest.approx([-0.5, 0.2])
    bad = client.post("/api/design/burmester", json={**body, "pivots": [[0, 0]]})
    assert bad.status_code == 400 and bad.json()["field"] == "pivots"


def test_robot_routes(client):
    d = ex("five_bar_5r")
    info = client.post("/api/design/drives", json={"mechanism": d}).json()
    assert [x["id"] for x in info["drives"]] == ["A", "E"] and info["tools"][0]["id"] == "tool"
    r = client.post("/api/design/reach", json={"mechanism": d, "point": "tool", "target": [2.3, 3.2]}).json()
    assert r["reached"] and r["mechanism"]["points"]["tool"]["at"] == pytest.approx([2.3, 3.2], abs=1e-8)
    far = client.post("/api/design/reach", json={"mechanism": d, "point": "tool", "target": [2.3, 30]}).json()
    assert not far["reached"] and "workspace boundary" in far["message"]
    p = client.post("/api/design/pose", json={"mechanism": d, "values": {"E": info["drives"][1]["value"] + 10}})
    assert p.status_code == 200 and p.json()["mechanism"]["joints"][1]["point"] == pytest.approx(d["joints"][1]["point"])
    assert client.post("/api/design/pose", json={"mechanism": d, "values": {"Z": 1}}).status_code == 400


def test_centres_and_cams(client):
    c = client.post("/api/design/centres", json={"mechanism": ex("crank_rocker"), "inputs": {"A": 120}}).json()
    assert len(c["centres"]) == 6 and {x["kind"] for x in c["centres"]} == {"primary", "Kennedy"}
    cams = client.post("/api/design/cams", json={"mechanism": ex("cam_follower")}).json()["cams"]
    assert cams[0]["link"] == "cam" and cams[0]["pivot"] == "O" and len(cams[0]["points"]) == 120


def test_dxf_on_the_default_install_and_unitless_without_a_unit(client):
    r = client.post("/api/studio/dxf", json={"mechanism": ex("fourbar")})
    assert r.status_code == 200 and "$INSUNITS\n 70\n0\n" in r.text.replace("\r", "")


def test_atlas_names_watt_and_stephenson(client):
    chains = client.get("/api/atlas?links=6&mobility=1").json()["chains"]
    assert sorted(c["name"] for c in chains) == ["Stephenson chain", "Watt chain"]
    assert all(c["name"] in c["label"] for c in chains)
