"""One schema per request body of the studio (pydantic, strict): types, finiteness and
magnitudes checked before any work, so that a wrongly typed field is a 400 naming it.

Strict means JSON types as they are: ``"false"`` is not a boolean, ``"10"`` not a number,
``true`` not 1 (issue 42: ``"closed": "false"`` was read as true, ``"restarts": [1]``
ended as an internal error). Numbers are finite (the body parser refuses NaN and
Infinity) and within ±:data:`MAX_MAGNITUDE`, inside a mechanism too (an axis
(1e200, 1e200, 0) overflowed to a zero or infinite vector deep in the library: a 500).
A mechanism's own fields are the file format's (:mod:`mechsyn.io.schema`), checked where
it is built; :func:`mechanism_types` checks them alone, for the structure check that reads
a mechanism before building it.

Examples
--------
>>> body = parse(SimulateBody, {"mechanism": {"links": []}, "steps": 36})
>>> body.steps, body.rates
(36, True)
>>> parse(SimulateBody, {"mechanism": {}, "rates": "false"})
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: rates: must be true or false, not 'false' (fix: write true or false (JSON, no quotes))
>>> parse(MechanismBody, {"mechanism": {"joints": [{"axis": [1e200, 1e200, 0]}]}})
Traceback (most recent call last):
...
mechsyn.errors.MechsynInputError: joints[0].axis[0]: 1e+200 is too large: numbers are within ±1e+12 (fix: give a smaller number: another unit for lengths, a unit vector for a direction)
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, ValidationError
from pydantic_core import PydanticCustomError

from mechsyn.errors import MechsynInputError
from mechsyn.web import _files
from mechsyn.web._service import PATH_MAX_SIZE

#: The largest magnitude of a number in a request (a mechanism's coordinates, axes,
#: masses; a target point): products and squares of such numbers stay far from overflow.
MAX_MAGNITUDE = 1e12
#: The most target points of a synthesis run (a drawn curve is resampled to far fewer).
MAX_TARGETS = 10_000


def _magnitude(value: Any, path: list[Any]) -> tuple[list[Any], float] | None:
    """The path and value of the first number in ``value`` beyond ±:data:`MAX_MAGNITUDE`."""
    todo = [(value, path)]
    while todo:
        v, p = todo.pop()
        if isinstance(v, dict):
            todo.extend((x, p + [k]) for k, x in reversed(list(v.items())))
        elif isinstance(v, list):
            todo.extend((x, p + [k]) for k, x in reversed(list(enumerate(v))))
        elif isinstance(v, (int, float)) and not isinstance(v, bool) and abs(v) > MAX_MAGNITUDE:
            return p, v
    return None


def _bounded(value: Any) -> Any:
    hit = _magnitude(value, [])
    if hit is not None:
        raise PydanticCustomError("magnitude", f"{float(hit[1]):.4g} is too large: numbers are within "
                                  f"±{MAX_MAGNITUDE:.0e}", {"path": hit[0]})
    return value


def _file_name(value: str) -> str:
    problem = _files.name_problem(value)
    if problem is not None:
        raise PydanticCustomError("file_name", problem)
    return value


#: A finite JSON number within ±MAX_MAGNITUDE (an integer is a number; true is not).
Number = Annotated[float, AfterValidator(_bounded)]
#: A mechanism as the file format's dict (its own fields are checked where it is built).
Mechanism = Annotated[dict[str, Any], AfterValidator(_bounded)]
#: Target points [x, y] of a synthesis run (their count is the run's to check).
Points = Annotated[list[Annotated[list[Number], Field(min_length=2, max_length=2)]], Field(max_length=MAX_TARGETS)]
#: A file name for Save or an upload: printable text, no markup (:func:`mechsyn.web._files.name_problem`).
FileName = Annotated[str, Field(max_length=_files.MAX_NAME), AfterValidator(_file_name)]
#: Rows of a sweep (their range is the service's to check, ``mechsyn.web._service.MAX_STEPS``).
Steps = int


class Body(BaseModel):
    """A request body: strict JSON types; fields a route does not know are left alone."""

    model_config = ConfigDict(strict=True, extra="ignore")


class MechanismBody(Body):
    mechanism: Mechanism


class SimulateBody(MechanismBody):
    steps: Steps = 180
    rates: bool = True


class SweepBody(MechanismBody):
    """The spatial view and plots."""

    steps: Steps = 180


class ForcesBody(MechanismBody):
    gravity: Annotated[list[Number], Field(min_length=2, max_length=2)] = [0.0, 0.0]
    speed: Number = 1.0
    steps: Steps = 180


class ExportBody(MechanismBody):
    format: Literal["yaml", "json", "csv", "gif"] = "yaml"
    steps: Steps = 180
    frames: Annotated[int, Field(ge=2, le=360)] = 72


class SaveBody(MechanismBody):
    path: FileName
    overwrite: bool = False


class ImportBody(Body):
    text: str
    filename: FileName = "upload.yaml"


class ChainBody(Body):
    chain: dict[str, Any]
    frame: int | None = None
    input: int | None = None


class FourbarPathParams(Body):
    targets: Points
    time_limit: Number = 10.0
    restarts: int = 4
    #: the size bound in target diagonals, as ``synth path --max-size`` (0: none)
    max_size: Annotated[Number, Field(ge=0)] = PATH_MAX_SIZE


class CurveParams(Body):
    targets: Points
    time_limit: Number = 20.0
    max_links: int = 6
    closed: bool | None = None


class MotionParams(Body):
    targets: Points
    angles: list[Number] | None = None
    #: two moving pivots picked for 3 poses (drawing coordinates at pose 1)
    pivots: Annotated[list[Annotated[list[Number], Field(min_length=2, max_length=2)]],
                      Field(min_length=2, max_length=2)] | None = None
    #: the unbuildable linkages too (left out by default)
    all: bool = False


class BurmesterBody(Body):
    """The linkage of two moving pivots picked for 3 poses (the Synthesis tab's drag)."""

    targets: Points
    angles: list[Number]
    pivots: Annotated[list[Annotated[list[Number], Field(min_length=2, max_length=2)]],
                      Field(min_length=2, max_length=2)] | None = None


class DimensionBody(MechanismBody):
    """A typed dimension: ``change`` names the dimension and its new value."""

    change: dict[str, Any]


class PoseBody(MechanismBody):
    """Every drive's value (``{drive: value}``)."""

    values: dict[str, Number]


class ReachBody(MechanismBody):
    """A point of a link taken to a target (inverse kinematics)."""

    point: Annotated[str, Field(min_length=1, max_length=200)]
    target: Annotated[list[Number], Field(min_length=2, max_length=3)]


class CentresBody(MechanismBody):
    """Instant centres at the drive values ``inputs`` (the drawn pose when absent)."""

    inputs: dict[str, Number] | None = None


#: The parameters of each synthesis kind (a kind not listed: a JSON object of bounded numbers).
SYNTHESIS_PARAMS: dict[str, type[Body]] = {"fourbar_path": FourbarPathParams, "curve": CurveParams,
                                           "motion": MotionParams}


class AnyParams(Body):
    model_config = ConfigDict(strict=True, extra="allow")


_HINTS = {
    "bool_type": "write true or false (JSON, no quotes)", "int_type": "write a whole number", "float_type": "write a number",
    "string_type": "write a text in quotes", "list_type": "write a list [...]", "dict_type": "write an object {...}",
    "magnitude": "give a smaller number: another unit for lengths, a unit vector for a direction", "missing": None,
}
_MESSAGES = {"bool_type": "must be true or false", "int_type": "must be a whole number",
             "float_type": "must be a number", "string_type": "must be a text", "list_type": "must be a list",
             "dict_type": "must be an object", "missing": "missing"}


def _field(loc: list[Any], mechanism: bool) -> str:
    """``["mechanism", "joints", 0, "axis"]`` → ``joints[0].axis`` (a mechanism's fields are
    named as the file format's errors name them); ``["targets", 2, 0]`` → ``targets[2][0]``."""
    parts = loc[1:] if mechanism and loc and loc[0] == "mechanism" and len(loc) > 1 else loc
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _input_error(exc: ValidationError, data: dict[str, Any]) -> MechsynInputError:
    """The first problem of ``exc`` as one input error naming its field (and the element of
    the mechanism it is in, for the studio to outline)."""
    from mechsyn.web._service import _element_of

    err = exc.errors()[0]
    loc = [p for p in err["loc"] if not (isinstance(p, str) and p.startswith(("function-", "nullable")))]
    loc += list((err.get("ctx") or {}).get("path", []))
    in_mech = bool(loc) and loc[0] == "mechanism" and len(loc) > 1
    field = _field(loc, in_mech) or "body"
    kind = err["type"]
    message = _MESSAGES.get(kind, err["msg"])
    if kind in _MESSAGES and kind != "missing":
        message += f", not {str(err.get('input'))[:40]!r}" if isinstance(err.get("input"), str) else \
            f", not {type(err.get('input')).__name__}"
    out = MechsynInputError(message, field=field, hint=_HINTS.get(kind))
    out.element = _element_of(data.get("mechanism"), field) if in_mech else None  # type: ignore[attr-defined]
    return out


def parse(model: type[Body], data: dict[str, Any]) -> Any:
    """``data`` (a request's JSON object) validated by ``model``, or the input error naming
    the first wrong field."""
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise _input_error(exc, data) from None


def mechanism_types(data: Any) -> None:
    """The mechanism's fields typed as the file format says (:class:`mechsyn.io.schema.MechanismFile`,
    its errors named as :func:`mechsyn.io.mechanism_from_dict` names them), without building
    it: for the structure check, which reads a mechanism that may not build (a link joined to
    nothing) before building it. An input error names the field and the element."""
    from mechsyn.io.load import _validation_error
    from mechsyn.io.schema import MechanismFile
    from mechsyn.web._service import _element_of

    if not isinstance(data, dict):
        raise MechsynInputError("the mechanism must be a JSON object", field="mechanism")
    try:
        MechanismFile.model_validate(data)
    except ValidationError as exc:
        err = _validation_error(exc, data, "mechanism", None)
        err.element = _element_of(data, err.field)  # type: ignore[attr-defined]
        raise err from None
