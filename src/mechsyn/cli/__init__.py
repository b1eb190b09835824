"""The ``mechsyn`` command line: a thin layer over the library.

Each command lives in its own module of this package and registers itself on
:data:`mechsyn.cli.app.app` (or on one of its sub-apps, e.g. ``synth_app``);
:mod:`mechsyn.cli.main` imports the modules and runs the app.
"""
