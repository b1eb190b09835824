"""Safe evaluation of the small expressions of a file (a cam's polar profile r(t))."""

from __future__ import annotations

import ast

import numpy as np

from mechsyn.limits import limit

__all__ = ["ExpressionError", "evaluate", "polar_points"]

_FUNCS = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "exp": np.exp, "sqrt": np.sqrt, "abs": np.abs}
_OPS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide, ast.Pow: np.power,
        ast.USub: np.negative, ast.UAdd: np.positive}


class ExpressionError(ValueError):
    """An expression that is not a plain arithmetic function of t."""


def evaluate(text: str, t: np.ndarray) -> np.ndarray:
    """Evaluate ``text`` (a function of ``t``) on the array ``t``; only arithmetic,
    ``pi``, numbers and the functions sin, cos, tan, exp, sqrt, abs are allowed.

    Expressions longer than the limit ``expression_chars`` (:mod:`mechsyn.limits`) or
    nested too deeply for Python's parser raise :class:`ExpressionError`.
    """
    text = str(text)
    if len(text) > limit("expression_chars"):
        raise ExpressionError(f"the expression has {len(text):,} characters, more than the limit of "
                              f"{limit('expression_chars'):,} (MECHSYN_LIMIT_EXPRESSION_CHARS raises it)")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ExpressionError(f"cannot parse {text[:60]!r}: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ExpressionError(f"{text[:60]!r}... is nested too deeply") from None

    names = {"t": t, "pi": np.pi}

    def ev(node: ast.AST):
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(node.value, bool):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id in names:
                return names[node.id]
            raise ExpressionError(f"unknown name {node.id!r} in {text!r}")
        if isinstance(node, ast.BinOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.left), ev(node.right))
        if isinstance(node, ast.UnaryOp) and type(node.op) in _OPS:
            return _OPS[type(node.op)](ev(node.operand))
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in _FUNCS
                and len(node.args) == 1 and not node.keywords):
            return _FUNCS[node.func.id](ev(node.args[0]))
        raise ExpressionError(f"{ast.unparse(node)!r} is not allowed in {text!r}")

    with np.errstate(all="ignore"):
        try:
            value = ev(tree.body)
        except RecursionError:
            raise ExpressionError(f"{text[:60]!r}... is nested too deeply") from None
        out = np.broadcast_to(np.asarray(value, float), t.shape)
    return np.array(out)


def polar_points(text: str, center: np.ndarray, n: int = 720) -> np.ndarray:
    """Points ``center + r(t) (cos t, sin t)`` of a polar profile, t in [0, 2 pi)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = evaluate(text, t)
    if not np.all(np.isfinite(r)) or np.any(r <= 0):
        raise ExpressionError(f"r(t) = {text} must be finite and positive for every t")
    return np.asarray(center, float) + r[:, None] * np.stack([np.cos(t), np.sin(t)], axis=1)
