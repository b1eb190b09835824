"""The docstring examples' collection (``pytest --doctest-modules src/mechsyn``, CI's
.ci/steps/20-doctest.sh): the compiled kernel's module imports Numba, an optional
extra (``mechsyn[fast]``), so it is collected only where Numba is installed. Outside the
package: not shipped in the wheel."""

import importlib.util

collect_ignore = [] if importlib.util.find_spec("numba") else ["mechsyn/kinematics/_kernel_numba.py"]
