"""mechsyn.capability."""
