"""Build hook: ship the repository's ``examples/`` inside the wheel as ``mechsyn/examples/data``.

Everything else is declared in pyproject.toml. The files stay in ``examples/`` (where the
docs, the tests and the CLI help name them); ``mechsyn.examples`` reads them from
``data/`` in an installed wheel and from ``examples/`` in a source checkout.
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py


class BuildWithExamples(build_py):
    def run(self):
        super().run()
        source = Path(__file__).resolve().parent / "examples"
        target = Path(self.build_lib) / "mechsyn" / "examples" / "data"
        if source.is_dir() and not self.editable_mode:
            shutil.rmtree(target, ignore_errors=True)
            shutil.copytree(source, target, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))


setup(cmdclass={"build_py": BuildWithExamples})
