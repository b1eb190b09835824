"""``mechsyn serve``: argument checks, and the app it builds (the server itself is mocked)."""

from __future__ import annotations

import pytest


@pytest.fixture
def served(monkeypatch):
    """Replace uvicorn and the browser: record what serve would start."""
    calls = {}

    def fake_run(app, host, port):
        calls.update(app=app, host=host, port=port)

    monkeypatch.setattr("mechsyn.web.run_server", fake_run)
    monkeypatch.setattr("webbrowser.open", lambda url: calls.setdefault("opened", url))
    return calls


def test_serve_example_binds_loopback(run_cli, served):
    code, out, err = run_cli("serve", "fourbar", "--no-browser", "--port", "8799")
    assert code == 0, err
    assert served["host"] == "127.0.0.1" and served["port"] == 8799 and "opened" not in served
    token = served["app"].state.token
    assert f"http://127.0.0.1:8799/?token={token}" in out.replace("\n", "")
    from starlette.testclient import TestClient

    c = TestClient(served["app"], base_url="http://127.0.0.1:8799", headers={"X-Mechsyn-Token": token})
    start = c.get("/api/start").json()
    assert start["name"] == "fourbar.yaml" and [j["id"] for j in start["mechanism"]["joints"]] == list("ABCD")


def test_serve_opens_the_browser(run_cli, served, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli("serve", "--port", "0")
    assert code == 0, err
    assert served["opened"].startswith("http://127.0.0.1:") and served["port"] > 0
    assert served["app"].state.root == tmp_path.resolve()


def test_serve_other_host_warns(run_cli, served):
    code, out, err = run_cli("serve", "--host", "0.0.0.0", "--no-browser", "--port", "8799")
    assert code == 0 and "warning" in err and served["host"] == "0.0.0.0"


def test_serve_unknown_target_is_one_line_exit_2(run_cli, served):
    code, out, err = run_cli("serve", "no_such_mechanism", "--no-browser")
    assert code == 2 and "no example named 'no_such_mechanism'" in err and "fourbar" in err
    code, out, err = run_cli("serve", "missing/file.yaml", "--no-browser")
    assert code == 2 and "no such file or example" in err
    assert "app" not in served
