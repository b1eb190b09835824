#!/usr/bin/env bash
# The kernels' coverage (mechsyn.kinematics.kernel and _kernel_numba, issue 37; the spatial
# kernel _spatial_numba, issue 38): their compiled functions run as plain Python under
# NUMBA_DISABLE_JIT=1, so coverage sees every line of the one implementation (the spatial
# kernel on six spatial tests: all of them take half an hour as plain Python). In an environment of its own (.venv-kernel: the test
# extra and pytest-cov, which the test extra does not carry); fails below the floor.
set -euo pipefail
FLOOR=90  # percent of the kernel module's lines (93 when this step was written)
. .ci/fresh-venv kernel "test"
python -m pip install --quiet "pytest-cov>=5"
NUMBA_DISABLE_JIT=1 MPLBACKEND=Agg python -m pytest -q -p no:cacheprovider -n 2 \
    tests/kinematics/test_kernel.py tests/kinematics/test_folds.py \
    tests/kinematics/test_spatial.py::test_bennett_input_output_relation \
    tests/kinematics/test_spatial.py::test_delta_one_drive_against_closed_form_inverse_kinematics \
    tests/kinematics/test_spatial.py::test_rssr_working_range_dead_points_and_gap \
    tests/kinematics/test_spatial.py::test_helical_rocker_keeps_its_pitch \
    tests/kinematics/test_spatial.py::test_change_points_reported_and_passed_on_the_drawn_branch \
    tests/kinematics/test_spatial_exact.py::test_pair_check_refuses_a_reversed_axis \
    --cov=mechsyn.kinematics._kernel_numba --cov=mechsyn.kinematics.kernel \
    --cov=mechsyn.kinematics._spatial_numba --cov-report=term-missing \
    --cov-report=json:.venv-kernel/coverage.json
python - "$FLOOR" <<'PY'
import json
import sys

floor = float(sys.argv[1])
files = json.load(open(".venv-kernel/coverage.json"))["files"]
ok = True
for module in ("_kernel_numba.py", "_spatial_numba.py"):
    name = next(f for f in files if f.endswith(module))
    got = files[name]["summary"]["percent_covered"]
    print(f"kernel line coverage (NUMBA_DISABLE_JIT=1): {got:.1f} % of {module} (floor {floor:.0f} %)")
    ok = ok and got >= floor
sys.exit(0 if ok else 1)
PY
