"""MkDocs hook: the gallery's figures are made by running the examples during the build.

Each entry is a list of ``mechsyn`` commands run in-process in a temporary directory that
sees the repository's ``examples/``; the figure they write is added to the site as
``gallery/<name>.png`` (or ``.svg``) and ``gallery.md`` shows it under its commands. A
command that fails fails the build.
"""

from __future__ import annotations

import contextlib
import io
import os
import shlex
import tempfile
from pathlib import Path

from mkdocs.structure.files import File

ROOT = Path(__file__).resolve().parents[2]

GALLERY = [
    ("crank_rocker", "Crank-rocker: coupler path, speeds and accelerations",
     ["mechsyn simulate crank_rocker --input A=0:360:2 --points M "
      "--plot crank_rocker.png"], "crank_rocker.png"),
    ("jansen", "Jansen's leg, converted from a Pyslvs expression",
     ["mechsyn convert pyslvs/jansen.pyslvs -o jansen.yaml",
      "mechsyn simulate jansen.yaml --input P0=0:360:3 --points P7 --plot jansen.png"], "jansen.png"),
    ("jansen_plates", "Jansen's leg as plates to cut (DXF and SVG)",
     ["mechsyn export pyslvs/jansen.pyslvs --dxf jansen.dxf --svg jansen_plates.svg "
      "--width 6 --hole 2.5 --clearance 0.1"], "jansen_plates.svg"),
    ("forces", "Crank-rocker: joint reactions and the balancing moment",
     ["mechsyn forces crank_rocker --input A=0:360:5 --plot forces.png"], "forces.png"),
    ("belt", "Paper 001's belt manipulator: path of the hand, transfer functions",
     ["mechsyn belt analyze --file paper001 --plot belt.png"], "belt.png"),
    ("capability", "Paper 004's 3R arm: largest speed along +x over the working region",
     ["mechsyn capability paper004_3r --grid 1300:2100:100,100:900:100 "
      "--direction 1,0 --map capability.png"], "capability.png"),
    ("burmester", "Burmester motion generation through four poses: centre-point curve and best linkage",
     ["mechsyn synth motion poses_4 --plot burmester.png"], "burmester.png"),
    ("path", "Path generation: a four-bar through five targets (a published case)",
     ["mechsyn synth path path_cases_public --case P2_kk5_timing --time-limit 5 "
      "--restarts 2 --plot path.png"], "path.png"),
    ("fingers", "Paper 000: groups attached to a two-phalanx finger, with its VLL candidates",
     ["mechsyn synth finger two_phalanx_base_000 --max-links 3 --out fingers/"],
     "fingers/fingers.png"),
    ("atlas", "The atlas of six-link chains of mobility 1",
     ["mechsyn atlas --links 6 --mobility 1 --out atlas6.png"], "atlas6.png"),
]


def _run(commands: list[str], where: Path) -> None:
    from mechsyn.cli.main import main

    old = Path.cwd()
    os.chdir(where)
    try:
        for cmd in commands:
            words = shlex.split(cmd)
            with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
                code = main(words[1:])
            if code != 0:
                raise RuntimeError(f"gallery command failed ({code}): {cmd}\n{err.getvalue()}")
    finally:
        os.chdir(old)


def on_files(files, config):
    import sys

    sys.path.insert(0, str(ROOT / "src"))
    import matplotlib

    matplotlib.use("Agg")
    tmp = Path(tempfile.mkdtemp(prefix="mechsyn-gallery-"))
    (tmp / "examples").symlink_to(ROOT / "examples")
    lines = ["# Gallery", "",
             "Every figure on this page was drawn while this site was built, by running the commands "
             "shown under it from the repository's root.", ""]
    for name, title, commands, output in GALLERY:
        _run(commands, tmp)
        data = (tmp / output).read_bytes()
        uri = f"gallery/{output}"
        files.append(File.generated(config, uri, content=data))
        lines += [f"## {title}", "", "```bash", *commands, "```", "", f"![{title}]({uri})", ""]
    files.append(File.generated(config, "gallery.md", content="\n".join(lines)))
    return files
