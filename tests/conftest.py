import json
from pathlib import Path

import pytest

from mechsyn.cli.main import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


@pytest.fixture
def run_cli(capsys):
    """Run the command line in-process; return (exit status, stdout, stderr)."""

    def run(*args: str) -> tuple[int, str, str]:
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return code, out.out, out.err

    return run


@pytest.fixture
def cli_json(run_cli):
    """Run a command with --json and parse its output (asserting exit status 0)."""

    def run(*args: str) -> dict:
        code, out, err = run_cli(*args, "--json")
        assert code == 0, err
        return json.loads(out)

    return run


def pytest_collection_modifyitems(config, items):
    """Browser and video tests are marked by what they use (the ``browser``/``page``
    fixtures of tests/web, an animation written as video): the default run leaves them out
    with the slow ones (``-m 'not slow and not browser and not video'`` in pyproject.toml),
    CI runs them with ``-m 'slow or browser or video'``."""
    for item in items:
        names = set(getattr(item, "fixturenames", ()))
        if names & {"browser", "page"}:
            item.add_marker(pytest.mark.browser)
        if item.get_closest_marker("video") is None and "movie" in item.nodeid and "mp4" in item.nodeid:
            item.add_marker(pytest.mark.video)


def pytest_configure(config):
    """Compile the regular pass's kernel (Numba) once, in the controlling process, before
    any worker or CLI subprocess needs it: on a fresh checkout each xdist worker and each
    subprocess test that starts while Numba's on-disk cache is still empty would compile
    it again (tens of seconds each); afterwards they load it (about a second)."""
    if hasattr(config, "workerinput"):  # an xdist worker: the controller warmed the cache
        return
    from mechsyn.kinematics import kernel

    kernel.warm()
