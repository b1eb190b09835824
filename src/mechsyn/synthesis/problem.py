"""What every synthesis in mechsyn shares: one result base, one seed convention, one
progress convention.

**Result.** :class:`SynthesisResult` is the base of every synthesis result (path,
mechanism, curve, belt; the finger-design result extends it too). Its fields, all
keyword-only with defaults so that a subclass may add positional fields of its own:

| field | meaning |
|---|---|
| `error` | the objective of the returned design (its unit is the problem's); `inf` or NaN when nothing feasible was found |
| `feasible` | whether the returned design meets every constraint |
| `reason` | why it does not; when it does, a bound the design sits on that decides it, and how to lift it (`""`: none) |
| `design` | the design as named values (`{"r1": 2.0, ...}`) |
| `x` | the same design as the optimiser's vector |
| `nfev` | objective evaluations (0 for a closed-form construction) |
| `seconds` | wall-clock time of the run |
| `seed` | the integer seed that reproduces the run (`None`: not random) |
| `interrupted` | Ctrl-C ended the search: the design is the best found so far |

Like every result of mechsyn it is a :class:`mechsyn._result.Result`: a short `str`, a
table in Jupyter, `to_dict()` (with the keys :data:`COMMON_KEYS`) and `plot(ax=None)`
where the result has a picture. Its summary puts `error`, `feasible` and `reason` first,
as SciPy's `OptimizeResult` does.

**Seeds.** A search takes `seed: int | None | numpy.random.Generator`.
:func:`resolve_seed` turns it into the one integer that is recorded in the result (give it
back to repeat the run); :func:`as_generator` gives the random generator of a seed.

**Progress.** A search that reports progress calls `progress(state)` with a
:class:`mechsyn.progress.Progress` (`done` of `total` steps, the stage, the best error so
far, a message: the one progress protocol of mechsyn); raising `KeyboardInterrupt` in
`progress` stops the search like Ctrl-C (the best so far is returned, `interrupted=True`).

Examples
--------
>>> import numpy as np
>>> from mechsyn.synthesis.problem import SynthesisResult, Progress, as_generator, resolve_seed
>>> res = SynthesisResult(error=0.5, feasible=True, design={"a": 1.0}, x=np.array([1.0]), seed=3)
>>> res.to_dict()["design"], res.to_dict()["seed"]
({'a': 1.0}, 3)
>>> resolve_seed(7), resolve_seed(np.random.default_rng(0)) == resolve_seed(np.random.default_rng(0))
(7, True)
>>> float(as_generator(1).random()) == float(np.random.default_rng(1).random())
True
>>> Progress(done=2, total=10, best=0.25).fraction
0.2
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mechsyn._result import Result
from mechsyn.errors import MechsynInputError
from mechsyn.progress import Progress, ProgressCallback  # noqa: F401  (re-exported: a search's progress)

__all__ = ["COMMON_KEYS", "Progress", "ProgressCallback", "SeedLike", "SynthesisResult",
           "as_generator", "resolve_seed"]

#: A seed as the searches accept it.
SeedLike = int | np.integer | np.random.Generator | None

#: Keys every synthesis result's ``to_dict()`` has.
COMMON_KEYS = ("error", "feasible", "reason", "design", "x", "nfev", "seconds", "seed", "interrupted")


def _empty() -> np.ndarray:
    return np.zeros(0)


@dataclass(kw_only=True, repr=False)
class SynthesisResult(Result):
    """Base of every synthesis result (see the module doc for the fields).

    Subclass it with ``@dataclass(repr=False)``: the common fields are keyword-only, so a
    subclass's own fields may be positional. A subclass keeps its own ``to_dict`` keys and
    adds the common ones with :meth:`common` (``{**own, **self.common()}``). Subclasses:
    :class:`mechsyn.synthesis.optimize.PathSynthesisResult`,
    :class:`mechsyn.synthesis.general.MechanismSynthesisResult`,
    :class:`mechsyn.synthesis.curves.synthesis.CurveSynthesisResult`,
    :class:`mechsyn.belt.BeltSynthesis`,
    :class:`mechsyn.synthesis.finger.design.FingerDesign`.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> from mechsyn.synthesis.problem import SynthesisResult
    >>> @dataclass(repr=False)
    ... class FitResult(SynthesisResult):
    ...     case: str = ""
    >>> r = FitResult(case="demo", error=0.01, feasible=True, design={"k": 2.0})
    >>> print(r)
    FitResult
      error        0.01
      feasible     True
      reason       ''
      design       dict of 1
      x            array(0,)
      nfev         0
      seconds      0
      seed         None
      interrupted  False
      case         'demo'
    """

    error: float = math.nan
    feasible: bool = False
    reason: str = ""
    design: Any = field(default_factory=dict)
    x: np.ndarray = field(default_factory=_empty)
    nfev: int = 0
    seconds: float = 0.0
    seed: int | None = None
    interrupted: bool = False

    def common(self) -> dict[str, Any]:
        """The common fields (:data:`COMMON_KEYS`) as a dict; ``design`` as named values."""
        out = {k: getattr(self, k) for k in COMMON_KEYS}
        if hasattr(out["design"], "to_dict"):
            out["design"] = out["design"].to_dict()
        return out


def resolve_seed(seed: SeedLike) -> int:
    """The integer that reproduces a run started with ``seed``.

    An int is itself; ``None`` draws a fresh 32-bit seed (recorded, so the run can be
    repeated, and exact in JSON for JavaScript too); a :class:`numpy.random.Generator`
    gives its next 32-bit integer (the same generator state gives the same run).

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.synthesis.problem import resolve_seed
    >>> resolve_seed(42)
    42
    >>> resolve_seed(np.random.default_rng(1)) == resolve_seed(np.random.default_rng(1))
    True
    """
    if isinstance(seed, np.random.Generator):
        return int(seed.integers(2**32))
    if seed is None:
        return int(np.random.default_rng().integers(2**32))
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise MechsynInputError(f"a seed is a non-negative integer, None or a numpy Generator, got {seed!r}",
                                field="seed")
    return int(seed)


def as_generator(seed: SeedLike) -> np.random.Generator:
    """The random generator of ``seed`` (a Generator is returned as it is).

    Examples
    --------
    >>> import numpy as np
    >>> from mechsyn.synthesis.problem import as_generator
    >>> g = np.random.default_rng(0)
    >>> as_generator(g) is g, int(as_generator(3).integers(10)) == int(np.random.default_rng(3).integers(10))
    (True, True)
    """
    if isinstance(seed, np.random.Generator):
        return seed
    return np.random.default_rng(resolve_seed(seed))
