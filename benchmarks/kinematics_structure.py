"""The structure of ``mechsyn.kinematics``, measured and drawn from the code.

Prints the figures that the one-motion-contract work is judged by: code lines (no
blank lines, comments or docstrings), private names imported across the package's
modules, ``pragma: no cover`` marks, modules, import arrows and floors (the longest
chain of imports under a module, plus one), and draws the import graph floor by floor
(the higher a module, the more it stands on) with NetworkX and Matplotlib.

Run from the repository's root::

    python benchmarks/kinematics_structure.py                      # figures of the checkout
    python benchmarks/kinematics_structure.py --png imports.png    # and the drawing
    python benchmarks/kinematics_structure.py --rev e5e7b50 --png before.png   # an older commit

``--rev`` reads the package as it was at a git commit (``git show``), so before and after
come from one command.
"""

from __future__ import annotations

import argparse
import ast
import io
import subprocess
import tokenize
from pathlib import Path

import networkx as nx

PACKAGE = "src/mechsyn/kinematics"
ROOT = Path(__file__).resolve().parents[1]


def sources(rev: str | None) -> dict[str, str]:
    """The package's modules (stem -> text), from the working tree or from commit ``rev``."""
    if rev is None:
        return {p.stem: p.read_text() for p in sorted((ROOT / PACKAGE).glob("*.py"))}
    names = subprocess.run(["git", "ls-tree", "--name-only", f"{rev}:{PACKAGE}"], cwd=ROOT, check=True,
                           capture_output=True, text=True).stdout.split()
    return {n[:-3]: subprocess.run(["git", "show", f"{rev}:{PACKAGE}/{n}"], cwd=ROOT, check=True,
                                   capture_output=True, text=True).stdout
            for n in sorted(names) if n.endswith(".py")}


def _doc_lines(tree: ast.AST) -> set[int]:
    """Lines of docstrings (module, class, function) and of bare string statements."""
    out: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Expr) and isinstance(node.value, ast.Constant) and isinstance(node.value.value, str):
            out.update(range(node.lineno, node.end_lineno + 1))
    return out


def code_lines(text: str) -> int:
    """Lines that carry a code token (not a comment, not a docstring)."""
    docs = _doc_lines(ast.parse(text))
    skip = {tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT, tokenize.ENDMARKER}
    lines: set[int] = set()
    for tok in tokenize.generate_tokens(io.StringIO(text).readline):
        if tok.type not in skip:
            lines.update(n for n in range(tok.start[0], tok.end[0] + 1) if n not in docs)
    return len(lines)


def imports(stem: str, text: str, stems: set[str]) -> tuple[set[str], list[str]]:
    """The package's modules that ``stem`` imports, and the private names it takes from them."""
    targets, private = set(), []
    for node in ast.walk(ast.parse(text)):
        if not isinstance(node, ast.ImportFrom):
            continue
        module = node.module or ""
        if node.level:
            module = f"mechsyn.kinematics.{module}" if module else "mechsyn.kinematics"
        if not module.startswith("mechsyn.kinematics"):
            continue
        rest = module[len("mechsyn.kinematics"):].lstrip(".")
        names = [rest] if rest else [a.name for a in node.names]
        targets.update(n for n in names if n in stems and n != stem)
        private += [f"{stem} <- {rest or '.'}.{a.name}" for a in node.names
                    if a.name.startswith("_") and not a.name.startswith("__")]
    return targets, private


def structure(rev: str | None = None) -> tuple[nx.DiGraph, dict]:
    """The import graph (an arrow from importer to imported) and the figures."""
    src = sources(rev)
    graph, private = nx.DiGraph(), []
    graph.add_nodes_from(src)
    for stem, text in src.items():
        targets, priv = imports(stem, text, set(src))
        graph.add_edges_from((stem, t) for t in targets)
        private += priv
    dag = nx.condensation(graph)
    floor_of_scc = {}
    for scc in reversed(list(nx.topological_sort(dag))):
        floor_of_scc[scc] = 1 + max((floor_of_scc[s] for s in dag.successors(scc)), default=0)
    floors = {m: floor_of_scc[dag.graph["mapping"][m]] for m in graph}
    figures = {"modules": len(src), "arrows": graph.number_of_edges(),
               "code lines": sum(code_lines(t) for t in src.values()),
               "private names imported across modules": len(private),
               "pragma: no cover": sum(t.count("pragma: no cover") for t in src.values()),
               "floors": max(floors.values(), default=0),
               "cycles": sum(1 for c in nx.strongly_connected_components(graph) if len(c) > 1)}
    nx.set_node_attributes(graph, floors, "floor")
    return graph, {**figures, "private": private}


def draw(graph: nx.DiGraph, title: str, ax=None):
    """The graph floor by floor: floor 1 (imports nothing of the package) at the bottom."""
    import matplotlib.pyplot as plt

    if ax is None:
        ax = plt.gca()
    by_floor: dict[int, list[str]] = {}
    for m, f in graph.nodes(data="floor"):
        by_floor.setdefault(f, []).append(m)
    pos = {}
    for f, mods in by_floor.items():
        for i, m in enumerate(sorted(mods)):
            pos[m] = ((i + 0.5) / len(mods), f)
    nx.draw_networkx_edges(graph, pos, ax=ax, alpha=0.25, arrows=True, arrowsize=6, node_size=900,
                           connectionstyle="arc3,rad=0.05")
    drawn = nx.draw_networkx_labels(graph, pos, ax=ax, font_size=7,
                                    bbox={"boxstyle": "round", "fc": "#eef3fb", "ec": "#4a6fa5", "lw": 0.6})
    ax.tick_params(axis="y", left=True, labelleft=True)
    ax.set_yticks(sorted(by_floor))
    ax.set_ylabel("floor (longest import chain beneath, + 1)")
    ax.set_xticks([])
    ax.set_title(title)
    return drawn


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rev", help="a git commit to read the package from (default: the working tree)")
    ap.add_argument("--png", type=Path, help="draw the import graph into this PNG")
    ap.add_argument("-v", action="store_true", help="list the private names imported across modules")
    args = ap.parse_args()
    graph, fig = structure(args.rev)
    for k, v in fig.items():
        if k != "private":
            print(f"{k:40s} {v:,}")
    if args.v:
        print("\n".join(fig["private"]))
    if args.png:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        f, ax = plt.subplots(figsize=(13, 0.9 * fig["floors"] + 2), layout="constrained")
        draw(graph, f"mechsyn.kinematics at {args.rev or 'the working tree'}: {fig['modules']} modules, "
             f"{fig['arrows']} arrows, {fig['floors']} floors", ax=ax)
        f.savefig(args.png, dpi=110)
        print(f"wrote {args.png}")


if __name__ == "__main__":
    main()
