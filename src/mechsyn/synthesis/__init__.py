"""mechsyn.synthesis."""
