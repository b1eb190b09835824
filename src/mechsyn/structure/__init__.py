"""mechsyn.structure."""
