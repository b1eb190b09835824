"""The docstring examples of the reliability modules run."""

import doctest
import importlib

import pytest


@pytest.mark.parametrize("module", ["mechsyn.interrupt", "mechsyn.limits", "mechsyn.io.files",
                                    "mechsyn.io.checks", "mechsyn.cli.common", "mechsyn.errors"])
def test_docstring_examples(module):
    result = doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted > 0
