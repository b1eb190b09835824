"""The hostile-input suite of the studio's routes (issue 27), beside the command line's
(:mod:`test_fuzz`): request bodies broken at random by the same strategies (values
replaced by booleans, NaN, infinities, 1e308, nested lists, control characters, rich
markup; keys deleted or added), plus what only a raw request can hold (NaN and
Infinity literals, numbers of thousands of digits, lone surrogates, nesting thousands
deep, a key twice), sent to every route that takes a body or a parameter.

Each answer: 200, or a 4xx JSON ``{"error", "field"}``; never a 5xx, never a trace, and
the server keeps answering. Derandomised like :mod:`test_fuzz`; ``MECHSYN_FUZZ_SCALE=20``
multiplies the counts for a local hunt.
"""

from __future__ import annotations

import copy
import json
import warnings

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("starlette")

from mechsyn.io import load_mechanism, mechanism_to_dict  # noqa: E402
from mechsyn.web._service import example_path  # noqa: E402

from test_fuzz import FIXED, SCALE, _paths, broken, hang_guard  # noqa: E402

TOKEN = "fuzz-token"
FOURBAR = mechanism_to_dict(load_mechanism(example_path("fourbar")))
WEB = settings(max_examples=10 * SCALE, deadline=None, derandomize=FIXED,
               suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    from starlette.testclient import TestClient

    from mechsyn.web import create_app

    warnings.simplefilter("ignore", DeprecationWarning)
    root = tmp_path_factory.mktemp("studio")
    with TestClient(create_app(root, token=TOKEN), base_url="http://127.0.0.1",
                    headers={"X-Mechsyn-Token": TOKEN}, raise_server_exceptions=False) as c:
        yield c


@pytest.fixture(scope="module")
def chain():
    from mechsyn.web import _service

    return _service.atlas(6, 1)[1]["chain"]


def _seeds(chain: dict) -> dict[str, dict]:
    """A valid body of every POST route (route -> body)."""
    return {
        "/api/validate": {"mechanism": FOURBAR},
        "/api/simulate": {"mechanism": FOURBAR, "steps": 24, "rates": True},
        "/api/analyze": {"mechanism": FOURBAR},
        "/api/export": {"mechanism": FOURBAR, "format": "json"},
        "/api/import": {"text": json.dumps(FOURBAR), "filename": "up.json"},
        "/api/file": {"path": "fuzz.yaml", "mechanism": FOURBAR, "overwrite": True},
        "/api/atlas/mechanism": {"chain": chain, "frame": 0, "input": 1},
    }


def _check(r, what: str) -> None:
    assert r.status_code < 500, f"{what}: {r.status_code} {r.text[:300]}"
    assert "Traceback" not in r.text, what
    if r.status_code >= 400:
        body = r.json()
        assert isinstance(body.get("error"), str) and body["error"], (what, body)


ROUTES = sorted(_seeds({}))

# what only raw JSON can hold, spliced in place of one value
RAW = ["NaN", "-Infinity", "1e999", "9" * 5000, '"\\ud800"', '"A\\u202e"', "[" * 5000 + "]" * 5000,
       '{"a": 1, "a": 2}', '"' + "x" * 100_000 + '"', "-0", "1e-400", "true", "null", '""']


@WEB
@given(data=st.data())
@pytest.mark.parametrize("route", ROUTES)
def test_broken_bodies(client, chain, route, data):
    body = data.draw(broken(_seeds(chain)[route]))
    with hang_guard():
        _check(client.post(route, content=json.dumps(body).encode("utf-8", "surrogatepass"),
                           headers={"content-type": "application/json"}), f"{route} {json.dumps(body)[:300]}")


@WEB
@given(data=st.data())
@pytest.mark.parametrize("route", ROUTES)
def test_raw_values_spliced_in(client, chain, route, data):
    seed = copy.deepcopy(_seeds(chain)[route])
    paths = [p for p, _ in _paths(seed) if p]
    path = data.draw(st.sampled_from(paths))
    raw = data.draw(st.sampled_from(RAW))
    marker = "\u2603MARK\u2603"
    node = seed
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = marker
    text = json.dumps(seed).replace(json.dumps(marker), raw)
    with hang_guard():
        _check(client.post(route, content=text.encode(), headers={"content-type": "application/json"}),
               f"{route} {path} = {raw[:40]}")


@WEB
@given(name=st.text(st.characters(blacklist_categories=()), max_size=300), links=st.text(max_size=8),
       mobility=st.text(max_size=8))
def test_parameters_in_urls(client, name, links, mobility):
    from urllib.parse import quote

    segment = quote(name.encode("utf-8", "surrogatepass"), safe="")  # any bytes, surrogates too
    with hang_guard():
        for r in (client.get(f"/api/file?path={segment}"),
                  client.get(f"/api/examples/{segment}"),
                  client.get("/api/atlas", params={"links": links, "mobility": mobility}),
                  client.get(f"/api/jobs/{segment}")):
            _check(r, f"{r.request.url}")


def test_the_server_still_answers(client):
    assert client.get("/api/examples").status_code == 200
    assert client.post("/api/validate", json={"mechanism": FOURBAR}).json()["ok"]
