#!/usr/bin/env bash
# The kinematics tests again with the NumPy regular pass (MECHSYN_KERNEL=numpy): the main
# run has Numba installed (the test extra), so it takes the compiled pass
# (mechsyn.kinematics.kernel); a user without the fast extra takes this one.
set -euo pipefail
MECHSYN_KERNEL=numpy MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider tests/kinematics
