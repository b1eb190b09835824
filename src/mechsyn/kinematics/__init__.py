"""mechsyn.kinematics."""
