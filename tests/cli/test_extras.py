"""Every optional feature without its extra answers with one line naming
``pip install "mechsyn[extra]"`` and exit status 2, never a traceback (issue 26).

Each case runs in a fresh interpreter whose imports of the extra's packages are blocked
(a meta-path finder that refuses them, as a plain ``pip install mechsyn`` would leave
them missing), so the test does not depend on what this environment has installed.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[2] / "src")

BLOCK = textwrap.dedent("""
    import sys
    BLOCKED = {blocked!r}

    class _Block:
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
            return None

    sys.meta_path.insert(0, _Block())
    for _m in list(sys.modules):
        if _m.split(".")[0] in BLOCKED:
            del sys.modules[_m]
""")

CLI = "from mechsyn.cli.main import main\nsys.exit(main({argv!r}))\n"


def _run(blocked: list[str], code: str, tmp_path: Path, env: dict[str, str] | None = None):
    script = BLOCK.format(blocked=blocked) + code
    full_env = {**os.environ, "PYTHONPATH": SRC, "COLUMNS": "200", **(env or {})}
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=tmp_path,
                          env=full_env, timeout=300)


def _one_clean_line(proc, extra: str) -> str:
    err = proc.stderr.strip()
    assert "Traceback" not in proc.stderr, proc.stderr
    assert re.search(rf"pip install (['\"])mechsyn\[{extra}\]\1", err), err
    assert len(err.splitlines()) == 1, err
    return err


CLI_CASES = [
    ("cad", ["ezdxf"], ["export", "fourbar", "--dxf", "plates.dxf"], {}),
    ("video", ["imageio_ffmpeg"], ["simulate", "fourbar", "-i", "A=0:360:30", "--animate", "out.mp4"], {}),
    ("dask", ["dask", "distributed"], ["atlas", "-n", "4", "--scheduler", "tcp://127.0.0.1:1"], {}),
    ("nauty", ["pynauty"], ["atlas", "-n", "4"], {"MECHSYN_GRAPH_BACKEND": "pynauty"}),
    ("web", ["starlette", "uvicorn"], ["serve", "fourbar", "--no-browser", "--port", "0"], {}),
]


@pytest.mark.parametrize("extra, blocked, argv, env", CLI_CASES, ids=[c[0] for c in CLI_CASES])
def test_cli_feature_without_its_extra_says_which_extra(extra, blocked, argv, env, tmp_path):
    proc = _run(blocked, CLI.format(argv=argv), tmp_path, env)
    assert proc.returncode == 2, proc.stderr
    _one_clean_line(proc, extra)
    assert not any(tmp_path.iterdir()), "nothing written"


API_CASES = [
    ("notebook", ["anywidget"], "import mechsyn as ms\nms.load('fourbar').widget()\n"),
    ("notebook", ["httpx"], "import mechsyn as ms\nms.load('fourbar').widget()\n"),
    ("pandas", ["pandas"], "import mechsyn as ms\nms.load('fourbar').simulate(A=(0, 360, 30)).to_pandas()\n"),
]


@pytest.mark.parametrize("extra, blocked, code", API_CASES, ids=[f"{c[0]}-{c[1][0]}" for c in API_CASES])
def test_python_feature_without_its_extra_raises_import_error_naming_the_extra(extra, blocked, code, tmp_path):
    wrapped = ("from mechsyn._extras import MissingExtraError\n"
               "try:\n" + textwrap.indent(code, "    ") +
               "except MissingExtraError as exc:\n"
               "    assert isinstance(exc, ImportError)\n"
               "    print(exc, file=sys.stderr)\n"
               "    sys.exit(2)\n")
    proc = _run(blocked, wrapped, tmp_path)
    assert proc.returncode == 2, proc.stderr
    _one_clean_line(proc, extra)


def test_serve_needs_no_extra():
    """starlette and uvicorn are base dependencies: ``pip install mechsyn && mechsyn serve``."""
    import tomllib

    project = tomllib.loads((Path(SRC).parent / "pyproject.toml").read_text())["project"]
    base = {d.split(">")[0].split("=")[0].split("[")[0].strip() for d in project["dependencies"]}
    assert {"starlette", "uvicorn"} <= base
