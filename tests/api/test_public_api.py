"""The Python API a notebook user meets: ``import mechsyn as ms`` (issue 13)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mechsyn as ms
from mechsyn.results import to_jsonable

# the session's animation is never rendered (it would be shown or saved by the user)
pytestmark = pytest.mark.filterwarnings("ignore:Animation was deleted")

SRC = Path(__file__).resolve().parents[2] / "src"


def _python(code: str, **env: str) -> str:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": str(SRC), **env})
    return out.stdout.strip()


def test_import_is_light_and_lazy():
    # importing, and touching the analysis entry points, loads no Matplotlib
    loaded = _python("import sys, mechsyn; mechsyn.simulate; mechsyn.analyze; "
                     "print(sorted(m for m in ('matplotlib', 'pandas', 'typer', 'rich') if m in sys.modules))")
    assert loaded == "[]"


def test_every_public_name_resolves():
    assert 25 <= len(ms.__all__) <= 45
    for name in ms.__all__:
        assert getattr(ms, name) is not None, name
    assert set(dir(ms)) == set(ms.__all__)
    with pytest.raises(AttributeError):
        ms.no_such_name  # noqa: B018


def test_notebook_session_writes_no_file(tmp_path, monkeypatch):
    import matplotlib
    from matplotlib.animation import Animation
    from matplotlib.axes import Axes

    monkeypatch.chdir(tmp_path)
    backend = matplotlib.get_backend()
    m = ms.load("crank_rocker")
    assert len(repr(m)) < 300 and "Crank-rocker" in repr(m)
    text = str(m)
    assert all(j.id in text for j in m.joints) and "drive" in text
    r = m.analyze()
    assert r.mobility == 1 and r.formulas["chebyshev"].value == 1
    assert "| formula |" in r._repr_markdown_()
    s = m.simulate(A=(0, 360, 1))
    M = s.point("M")
    assert M.shape == (361, 2) and np.isfinite(M).all()
    assert s.link("coupler").angle.shape == (361,)
    df = s.to_pandas()
    assert len(df) == 361 and np.allclose(df["M_x"], M[:, 0])
    ax = s.plot()
    assert isinstance(ax, Axes) and ax.lines
    anim = s.animate(max_frames=5)
    assert isinstance(anim, Animation)
    f = m.forces(A=(0, 360, 30))
    assert set(f.reactions.force) == {j.id for j in m.joints}
    assert matplotlib.get_backend() == backend  # the user's backend, not one chosen for them
    assert list(tmp_path.iterdir()) == []
    import matplotlib.pyplot as plt

    plt.close("all")


def test_simulate_inputs_are_checked():
    m = ms.examples.load("crank_rocker")
    with pytest.raises(ms.MechsynInputError, match="does not lead"):
        m.simulate(A=(0, 360, -1))
    with pytest.raises(ms.MechsynInputError, match="start, stop, step"):
        m.simulate(A=(0, 360))
    with pytest.raises(ms.MechsynInputError, match="no point"):
        m.simulate(A=[0.0, 10.0]).point("nowhere")
    # explicit values: a list is the values themselves
    assert m.simulate(A=[0, 90, 180]).inputs["A"].tolist() == [0, 90, 180]


def test_to_pandas_without_pandas(monkeypatch):
    s = ms.examples.load("crank_rocker").simulate(A=(0, 10, 5))
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"pip install \"mechsyn\[pandas\]\""):
        s.to_pandas()


def test_load_loads_save_round_trip(tmp_path):
    m = ms.load("fourbar")
    ms.save(m, tmp_path / "m.json")
    again = ms.load(tmp_path / "m.json")
    assert again.to_dict() == m.to_dict()
    assert ms.load(m.to_dict()).to_dict() == m.to_dict()
    assert ms.loads((tmp_path / "m.json").read_text(), format="json").name == m.name
    with pytest.raises(ms.MechsynInputError, match="no such file"):
        ms.load(tmp_path / "missing.yaml")


def test_examples_catalogue():
    table = ms.examples.list()
    assert len(table) == len({e.path for e in table}) >= 40
    assert all(len(line) <= 80 for line in str(table).splitlines())
    kinds = {e.name: e.kind for e in table}
    assert kinds["fourbar"] == "mechanism" and kinds["ur5_dh"] == "arm"
    assert ms.examples.load("ur5_dh").n == 6
    with pytest.raises(ms.MechsynInputError, match="belt case"):
        ms.examples.load("paper001")
    with pytest.raises(ms.MechsynInputError, match="no example"):
        ms.examples.path("no_such_example")


def test_cli_takes_an_example_name(cli_json):
    data = cli_json("analyze", "fourbar")
    assert data["mobility"] == 1


def test_analyze_json_is_the_report(cli_json):
    for name, extra in (("gripper_003", ["--remedies"]), ("double_parallelogram", []),
                        ("gripper_002_fig1_spatial", ["--method", "formulas"])):
        data = cli_json("analyze", name, *extra)
        report = ms.analyze(ms.load(name), remedies=bool(extra and extra[0] == "--remedies"),
                            method=extra[1] if extra[:1] == ["--method"] else None)
        assert data == json.loads(json.dumps(to_jsonable(report.to_dict())))


def test_library_errors_name_parameters_cli_names_options(run_cli):
    with pytest.raises(ms.MechsynInputError) as info:
        ms.analyze(ms.load("fourbar"), method="magic")
    assert info.value.field == "method" and info.value.source is None
    code, _, err = run_cli("analyze", "fourbar", "--method", "magic")
    assert code == 2 and "--method" in err and "unknown method" in err


def test_version_and_lazy_help(run_cli):
    code, out, _ = run_cli("--version")
    assert code == 0 and out.strip() == f"mechsyn {ms.__version__}"
    loaded = _python("import sys; from mechsyn.cli.main import main; main(['--help']); "
                     "print(sorted(m for m in ('numpy', 'scipy', 'matplotlib', 'mechsyn.cli.simulate') "
                     "if m in sys.modules))", COLUMNS="80")
    assert loaded.splitlines()[-1] == "[]"
    assert "simulate" in loaded and "synth" in loaded


def test_capability_point_json_is_the_report(cli_json):
    arm = ms.examples.path("paper004_3r")
    data = cli_json("capability", arm, "--point", "1000,1000", "--direction", "1,0", "--polytope")
    report = ms.capability_at(ms.load_arm(arm), [1000, 1000], [1, 0], polytope=True)
    assert data == json.loads(json.dumps(to_jsonable(report.to_dict())))
    assert data["best"]["exact"] == max(c["exact"] for c in data["configurations"])


def test_every_public_name_has_a_runnable_example():
    # pytest --doctest-modules src/mechsyn runs them (.ci/steps/20-doctest.sh)
    import inspect

    missing = [n for n in ms.__all__ if not n.startswith("__") and not inspect.ismodule(getattr(ms, n))
               and ">>>" not in (inspect.getdoc(getattr(ms, n)) or "")]
    assert missing == []
