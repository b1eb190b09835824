"""``mechsyn examples``: the example files shipped with mechsyn, by folder, or those a word finds.

One library call (:func:`mechsyn.examples.search`); a name it lists is accepted wherever a
command takes a file: ``mechsyn analyze fourbar``.
"""

from __future__ import annotations

from typing import Annotated, Optional

import typer

from mechsyn.cli.app import app


@app.command("examples")
def examples_cmd(
    word: Annotated[Optional[str], typer.Argument(help="Only the examples whose name, folder, kind or title "
                                                   "holds this word (any case).")] = None,
    folder: Annotated[Optional[str], typer.Option("--folder", help="Only this folder (kinematics, textbook, "
                                                  "spatial, structural, ...).")] = None,
    json_: Annotated[bool, typer.Option("--json", help="Print them as JSON (name, folder, kind, title, "
                                        "path).")] = False,
) -> None:
    """List the bundled example files (mechanisms, arms, belt, synthesis and finger-design cases)
    by folder; give a name where a command takes a file: mechsyn analyze fourbar."""
    from mechsyn.cli.common import emit_json
    from mechsyn.errors import MechsynInputError
    from mechsyn.examples import search

    found = search(word, folder)
    if not found:
        raise MechsynInputError(f"no example matches {word!r}" + (f" in {folder}" if folder else ""),
                                hint="`mechsyn examples` lists them all")
    if json_:
        emit_json([{"name": e.name, "folder": e.folder, "kind": e.kind, "title": e.title,
                    "path": str(e.path)} for e in found])
        return
    _render(found)


def _render(found) -> None:
    from rich.markup import escape

    from mechsyn.cli.common import console

    w = max(len(e.name) for e in found)
    k = max(len(e.kind) for e in found)
    room = max(12, console.width - w - k - 6)
    for folder in dict.fromkeys(e.folder for e in found):
        console.print(f"[bold]{escape(folder)}/[/]", highlight=False)
        for e in (e for e in found if e.folder == folder):
            title = e.title if len(e.title) <= room else e.title[:room - 1] + "…"
            console.print(escape(f"  {e.name:<{w}}  {e.kind:<{k}}  {title}"), highlight=False, soft_wrap=True)
    console.print(f"{len(found)} example{'s' if len(found) != 1 else ''}; use a name where a command takes a "
                  "file, e.g. mechsyn analyze fourbar", highlight=False)
