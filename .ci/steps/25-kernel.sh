#!/usr/bin/env bash
# The compiled regular pass (mechsyn.kinematics.kernel, the fast extra): Numba is not in the
# test extra (the main run is a plain install's, the NumPy pass), so this step puts it in a
# folder of its own (.ci-fast, git-ignored) and runs the kinematics, synthesis, CLI and API
# tests with it importable: test_kernel.py compares both passes on every chain example,
# the rest must hold with the compiled pass. The first run compiles the kernel (seconds).
set -euo pipefail
rm -rf .ci-fast
python -m pip install --quiet --no-deps --target .ci-fast numba llvmlite
PYTHONPATH=.ci-fast python -c "import numba; print('numba', numba.__version__)"
PYTHONPATH=.ci-fast MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider tests/kinematics tests/synthesis tests/cli \
    tests/api
