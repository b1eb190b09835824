"""The ``mechsyn`` command line: a thin layer over the library.

Each command lives in its own module of this package and registers itself on
:data:`mechsyn.cli.app.app` (or on one of its sub-apps, e.g. ``synth_app``);
:mod:`mechsyn.cli.main` lists the modules in its ``COMMANDS`` table and imports one only
when its command runs.
"""
