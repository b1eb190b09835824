"""Optional features and the extra that installs each: one clear line, never a traceback.

mechsyn's base install (``pip install mechsyn``) computes, plots and serves the studio;
a few features need packages of an *extra* (``pip install "mechsyn[cad]"``...). A
feature whose package is missing raises :class:`MissingExtraError`, which the command
line shows as one line naming the extra (exit status 2), and which Python code can catch
as an :class:`ImportError` or a :class:`mechsyn.errors.MechsynInputError`.

Examples
--------
>>> from mechsyn._extras import EXTRAS, require
>>> EXTRAS["ezdxf"]
'cad'
>>> require("math", "a test").sqrt(4.0)
2.0
>>> try:
...     require("no_such_module_for_the_doctest", "a test", extra="cad")
... except ImportError as exc:
...     print(exc)
a test needs no_such_module_for_the_doctest (fix: pip install "mechsyn[cad]")
"""

from __future__ import annotations

import importlib
from types import ModuleType

from mechsyn.errors import MechsynInputError

__all__ = ["EXTRAS", "MissingExtraError", "extra_for", "require"]

#: top-level module -> the extra of pyproject.toml that installs it
EXTRAS: dict[str, str] = {
    "anywidget": "notebook",
    "traitlets": "notebook",
    "httpx": "notebook",
    "nbclient": "notebook",
    "pandas": "pandas",
    "dask": "dask",
    "distributed": "dask",
    "pynauty": "nauty",
    "ezdxf": "cad",
    "imageio_ffmpeg": "video",
    "numba": "fast",  # a base dependency since issue 37; an install older than that lacks it
    "mkdocs": "docs",
    "starlette": "web",  # base dependencies today; an install older than issue 26 lacks them
    "uvicorn": "web",
}


class MissingExtraError(MechsynInputError, ImportError):
    """An optional feature whose package is not installed; the hint names the extra."""


def extra_for(module: str) -> str | None:
    """The extra that installs top-level module ``module`` (``"dask.distributed"`` -> ``"dask"``)."""
    return EXTRAS.get(module.split(".")[0])


def missing(module: str, feature: str, extra: str | None = None) -> MissingExtraError:
    """The error for ``feature`` without ``module`` (``extra`` defaults to :data:`EXTRAS`'s)."""
    extra = extra or extra_for(module)
    hint = f'pip install "mechsyn[{extra}]"' if extra else f"pip install {module.split('.')[0]}"
    return MissingExtraError(f"{feature} needs {module}", hint=hint)


def require(module: str, feature: str, extra: str | None = None) -> ModuleType:
    """Import ``module`` for ``feature`` or raise :class:`MissingExtraError` naming its extra.

    Parameters
    ----------
    module:
        The module to import, e.g. ``"ezdxf"`` or ``"dask.distributed"``.
    feature:
        What needs it, as the user called it (``"mechsyn export --dxf"``).
    extra:
        The extra that installs it; by default looked up in :data:`EXTRAS`.

    Returns
    -------
    module
        The imported module.
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        root = (exc.name or module).split(".")[0]
        if root != module.split(".")[0] and root not in EXTRAS:
            raise  # the module is there, something it imports is not: not a missing extra
        raise missing(module, feature, extra) from None
