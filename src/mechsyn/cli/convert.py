"""``mechsyn convert FILE -o OUT``: Pyslvs expressions to mechanism files and back."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Optional

import typer
from rich.markup import escape

from mechsyn.cli.app import app
from mechsyn.cli.common import ForceOpt, check_output_suffix, check_overwrite, err_console, is_stdout, write_output
from mechsyn.errors import MechsynInputError

_SUFFIXES = (".yaml", ".yml", ".json", ".pyslvs", ".txt")


def _pair(text: str) -> tuple[int, int]:
    try:
        a, b = (int(v) for v in text.strip("()[] ").split(","))
    except ValueError:
        raise MechsynInputError(f"expected BASE,DRIVE point indices, got {text!r}", source="--input",
                                hint="write e.g. --input 0,1") from None
    return a, b


@app.command("convert")
def convert_cmd(
    file: Annotated[Path, typer.Argument(help="A Pyslvs expression (.pyslvs) or a mechanism file (.yaml, .json).")],
    out: Annotated[str, typer.Option("--out", "-o", help="Output file: .yaml/.json from a Pyslvs expression, "
                                     ".pyslvs from a mechanism file; - for stdout (with --to).")],
    to: Annotated[Optional[str], typer.Option("--to", help="Output format when writing to stdout: "
                                              "yaml, json or pyslvs.")] = None,
    input: Annotated[Optional[list[str]], typer.Option(
        "--input", "-i", metavar="BASE,DRIVE", help="Pyslvs input pair BASE,DRIVE (point indices; the link through both turns "
                              "about BASE). Repeat for several; default: ground cranks.")] = None,
    name: Annotated[Optional[str], typer.Option("--name", help="Mechanism name (default: the file's stem).")] = None,
    force: ForceOpt = False,
) -> None:
    """Convert a Pyslvs mechanism expression into a mechanism file, or back."""
    from mechsyn.io.convert import convert_file

    if is_stdout(out):
        if to is None:
            raise MechsynInputError("writing to stdout needs the format", source="--to",
                                    hint="add --to yaml, --to json or --to pyslvs")
        suffix = "." + to.lower().lstrip(".")
    else:
        suffix = Path(out).suffix.lower()
    check_output_suffix(Path(f"x{suffix}"), _SUFFIXES, "--out", ".yaml, .json or .pyslvs")
    check_overwrite(out, "--out", force)
    result = convert_file(file, suffix, [_pair(t) for t in input or []] or None, name)
    write_output(out, result.text)
    for note in result.notes:
        err_console.print(f"note: {escape(note)}", highlight=False, soft_wrap=True)
