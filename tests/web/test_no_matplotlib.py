"""The studio's JSON routes (simulate, analyze, export as text) load no Matplotlib: only
the GIF export draws, through ``mechsyn.plot``.

Not checked: ``/api/atlas``. The chain enumeration imports python-igraph (bliss canonical
forms, ``synthesis/canonical.py``), and igraph's own ``igraph.drawing`` package imports
Matplotlib whenever it is installed."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / "src"


def test_json_routes_load_no_matplotlib(tmp_path):
    code = textwrap.dedent(f"""
        import sys
        from starlette.testclient import TestClient
        from mechsyn.io import load_mechanism, mechanism_to_dict
        from mechsyn.web._app import create_app
        from mechsyn.web._service import example_path

        mech = mechanism_to_dict(load_mechanism(example_path("crank_rocker")))
        app = create_app({str(tmp_path)!r}, token="t")
        with TestClient(app, base_url="http://127.0.0.1", headers={{"X-Mechsyn-Token": "t"}}) as c:
            for path, body in (("/api/simulate", {{"mechanism": mech, "steps": 36}}),
                               ("/api/analyze", {{"mechanism": mech}}),
                               ("/api/export", {{"mechanism": mech, "format": "csv"}})):
                r = c.post(path, json=body)
                assert r.status_code == 200, (path, r.text)
        assert "matplotlib" not in sys.modules, "a JSON route imported matplotlib"
        print("ok")
    """)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    run = subprocess.run([sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, timeout=120,
                         env=env)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr[-2000:]
