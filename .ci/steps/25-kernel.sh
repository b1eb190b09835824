#!/usr/bin/env bash
# The compiled regular pass (mechsyn.kinematics.kernel, the fast extra), in an environment
# of its own (.venv-fast: the test and fast extras): test_kernel.py compares both passes on
# every chain example; the kinematics, synthesis, CLI and API tests must hold with the
# compiled pass. The first run compiles the kernel (seconds).
set -euo pipefail
. .ci/fresh-venv fast "test,fast"
python -c "import numba; print('numba', numba.__version__)"
MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider tests/kinematics tests/synthesis tests/cli tests/api
