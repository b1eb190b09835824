"""mechsyn.model."""
