"""mechsyn.io."""
