"""Layout rules of the package (architecture.md, acceptance checks; issue 13).

* no library function is over 100 lines;
* no command function of the CLI (a module of ``mechsyn/cli/``) is over 40 lines.

Functions that still break a rule are listed by name in ``LIBRARY_EXCEPTIONS`` and
``CLI_EXCEPTIONS`` (with their length when listed): the branches that split them remove
their lines. A listed function that now keeps the rule, or no longer exists, fails the
test too, so the lists only shrink.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "mechsyn"
LIBRARY_MAX = 100
CLI_MAX = 40

# "module path relative to src/mechsyn: qualified function name" -> lines when listed
LIBRARY_EXCEPTIONS: dict[str, int] = {}
CLI_EXCEPTIONS: dict[str, int] = {}


def function_lengths(root: Path = PACKAGE) -> dict[str, int]:
    """Lines of every function and method under ``root`` (decorators excluded), keyed
    ``"relative/path.py:Qualified.name"``."""
    out: dict[str, int] = {}

    def visit(node: ast.AST, rel: str, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    out[f"{rel}:{name}"] = child.end_lineno - child.lineno + 1
                visit(child, rel, name + ".")
            else:
                visit(child, rel, prefix)

    for path in sorted(root.rglob("*.py")):
        rel = path.relative_to(root).as_posix()
        visit(ast.parse(path.read_text(encoding="utf-8")), rel, "")
    return out


def _unqualified(key: str) -> str:
    """``cli/x.py:f`` for ``cli/x.py:f`` and for a nested ``cli/x.py:g.f`` (as listed)."""
    rel, name = key.split(":")
    return f"{rel}:{name.rsplit('.', 1)[-1]}"


def _check(is_cli: bool, limit: int, exceptions: dict[str, int]) -> None:
    lengths = {k: v for k, v in function_lengths().items() if k.startswith("cli/") == is_cli}
    too_long = {_unqualified(k): v for k, v in lengths.items() if v > limit}
    new = {k: v for k, v in too_long.items() if k not in exceptions}
    assert not new, f"functions over {limit} lines (split them into small pure functions): {new}"
    stale = sorted(set(exceptions) - set(too_long))
    assert not stale, f"now within {limit} lines or gone: remove them from the exceptions: {stale}"


def test_no_library_function_over_100_lines():
    _check(False, LIBRARY_MAX, LIBRARY_EXCEPTIONS)


def test_no_cli_command_function_over_40_lines():
    _check(True, CLI_MAX, CLI_EXCEPTIONS)


def test_the_measure_counts_a_long_function(tmp_path):
    (tmp_path / "m.py").write_text("class A:\n    def f(self):\n" + "        x = 1\n" * 100 + "\n\n"
                                   "def g():\n    return 1\n")
    assert function_lengths(tmp_path) == {"m.py:A.f": 101, "m.py:g": 2}


@pytest.mark.parametrize("is_cli", [False, True])
def test_exceptions_are_of_their_kind(is_cli):
    listed = CLI_EXCEPTIONS if is_cli else LIBRARY_EXCEPTIONS
    assert all(k.startswith("cli/") == is_cli for k in listed)


# --------------------------------------------------------------------------- kinematics
KINEMATICS = PACKAGE / "kinematics"
KINEMATICS_FILE_MAX = 800
#: packages a computing module of kinematics/ never imports (reading, drawing, terminal)
KINEMATICS_FORBIDDEN = ("matplotlib", "pydantic", "yaml", "typer", "rich")


def mechsyn_imports(path: Path) -> set[str]:
    """The mechsyn modules ``path`` imports, at module level and inside functions
    (``from mechsyn.a import b`` counts ``mechsyn.a.b`` when that is a module)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("mechsyn"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("mechsyn"):
            out.add(node.module)
            for a in node.names:
                sub = PACKAGE.parent / (node.module + "." + a.name).replace(".", "/")
                if sub.with_suffix(".py").exists() or (sub / "__init__.py").exists():
                    out.add(f"{node.module}.{a.name}")
    return out


def third_party_imports(path: Path) -> set[str]:
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            out.add(node.module.split(".")[0])
    return out


def test_no_kinematics_file_over_800_lines():
    long = {p.name: n for p in KINEMATICS.rglob("*.py")
            if (n := len(p.read_text(encoding="utf-8").splitlines())) > KINEMATICS_FILE_MAX}
    assert not long, f"kinematics files over {KINEMATICS_FILE_MAX} lines (split them by concern): {long}"


def test_kinematics_imports_no_cycle():
    """The modules of kinematics/ import each other without a cycle, counting the imports
    inside functions (a cycle makes the import order decide what works)."""
    mods = {f"mechsyn.kinematics.{p.stem}": p for p in KINEMATICS.glob("*.py") if p.stem != "__init__"}
    graph = {m: {d for d in mechsyn_imports(p) if d in mods and d != m} for m, p in mods.items()}
    state: dict[str, int] = {}

    def visit(m: str, stack: list[str]) -> None:
        state[m] = 1
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                raise AssertionError("import cycle: " + " -> ".join(stack[stack.index(d):] + [d]))
            if d not in state:
                visit(d, stack + [d])
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])


def test_kinematics_computes_without_reading_drawing_or_terminal_packages():
    bad = {p.name: sorted(third_party_imports(p) & set(KINEMATICS_FORBIDDEN)) for p in KINEMATICS.rglob("*.py")}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, f"kinematics modules importing {KINEMATICS_FORBIDDEN}: {bad}"


def test_the_cycle_check_finds_a_cycle(tmp_path, monkeypatch):
    pkg = tmp_path / "mechsyn" / "kinematics"
    pkg.mkdir(parents=True)
    (pkg / "a.py").write_text("def f():\n    from mechsyn.kinematics import b\n")
    (pkg / "b.py").write_text("from mechsyn.kinematics.a import f\n")
    monkeypatch.setattr(sys.modules[__name__], "PACKAGE", tmp_path / "mechsyn")
    monkeypatch.setattr(sys.modules[__name__], "KINEMATICS", pkg)
    with pytest.raises(AssertionError, match="import cycle"):
        test_kinematics_imports_no_cycle()


#: function-level imports of mechsyn modules allowed in kinematics/ (by name): the lazy
#: package attribute and the Result's drawing delegation
KINEMATICS_DEFERRED = {"__init__.py": {"mechsyn.kinematics"}, "analysis.py": {"mechsyn.plot.kinematics"}}


def test_kinematics_imports_its_own_modules_at_module_level():
    """Own modules imported inside functions hide the import graph (issue 28): only the
    named delegations are deferred."""
    bad = {}
    for p in KINEMATICS.glob("*.py"):
        tree = ast.parse(p.read_text(encoding="utf-8"))
        inner = set()
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for node in ast.walk(fn):
                    if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("mechsyn"):
                        inner.add(node.module)
                    elif isinstance(node, ast.Import):
                        inner.update(a.name for a in node.names if a.name.startswith("mechsyn"))
        extra = inner - KINEMATICS_DEFERRED.get(p.name, set())
        if extra:
            bad[p.name] = sorted(extra)
    assert not bad, f"import these at module level: {bad}"
