"""Exceptions raised by mechsyn.

Every error caused by a user's input is a :class:`MechsynInputError`: it names the
file, the line or field, says what is wrong and how to fix it. The command line turns
it into one message and exit status 2, never a traceback.
"""

from __future__ import annotations


class MechsynError(Exception):
    """Base class of mechsyn's own errors.

    Examples
    --------
    >>> import mechsyn as ms
    >>> issubclass(ms.MechsynInputError, ms.MechsynError)
    True
    """


class MechsynInputError(MechsynError, ValueError):
    """Bad input: a file, a field or an argument that cannot be used.

    Parameters
    ----------
    message:
        What is wrong, in one sentence.
    source:
        The file (or ``"--option"``) the input came from.
    field:
        Dotted path of the offending field, e.g. ``joints[2].links``.
    line:
        1-based line number in ``source`` where known.
    hint:
        How to fix it.

    Examples
    --------
    >>> from mechsyn.errors import MechsynInputError
    >>> print(MechsynInputError("unknown joint 'Q'", source="arm.yaml", line=4, field="joints[1]",
    ...                         hint="use an id from joints"))
    arm.yaml:4: joints[1]: unknown joint 'Q' (fix: use an id from joints)
    """

    def __init__(
        self,
        message: str,
        *,
        source: str | None = None,
        field: str | None = None,
        line: int | None = None,
        hint: str | None = None,
    ) -> None:
        self.message = message
        self.source = source
        self.field = field
        self.line = line
        self.hint = hint
        super().__init__(self.format())

    def format(self) -> str:
        where = ""
        if self.source:
            where = self.source
            if self.line is not None:
                where += f":{self.line}"
            where += ": "
        field = f"{self.field}: " if self.field else ""
        text = f"{where}{field}{self.message}"
        if self.hint:
            text += f" (fix: {self.hint})"
        return text

    def with_source(self, source: str) -> "MechsynInputError":
        """Return a copy that names ``source`` when it had none."""
        if self.source:
            return self
        return MechsynInputError(
            self.message, source=source, field=self.field, line=self.line, hint=self.hint
        )


class OverActuatedError(MechsynInputError):
    """More independent drives than the mobility, one of them without an input: the
    simulation would hold it at its drawn value and find no configuration. ``check`` is the
    :class:`~mechsyn.structure.drives.DriveCheck` (``.drives``, ``.mobility``, ``.excess``,
    the drives without an input among ``.excess``)."""

    def __init__(self, message: str, *, check: object, **kw: object) -> None:
        self.check = check
        super().__init__(message, **kw)  # type: ignore[arg-type]

    def with_source(self, source: str) -> "MechsynInputError":
        if self.source:
            return self
        return OverActuatedError(self.message, check=self.check, source=source, field=self.field,
                                 line=self.line, hint=self.hint)


class EngineDeclined(MechsynInputError):
    """A kinematics engine asked for by name (``simulate(..., method=NAME)``) cannot treat
    this mechanism or these options; the message says why in one line and the hint names
    the way out (``method="auto"`` takes the first engine that can).

    Examples
    --------
    >>> import mechsyn as ms
    >>> from mechsyn.errors import EngineDeclined
    >>> try:
    ...     ms.examples.load("slider_crank").simulate(A=(0, 90, 45), method="regular pass")
    ... except EngineDeclined as e:
    ...     print(e.message)
    the regular pass engine cannot simulate Slider-crank mechanism: it takes chains of R drivers and RRR dyads only
    >>> issubclass(EngineDeclined, ms.MechsynError)
    True
    """

    def __init__(self, engine: str, mechanism: str, why: str) -> None:
        super().__init__(f"the {engine} engine cannot simulate {mechanism}: {why}", field="method",
                         hint='method="auto" takes the first engine that can')
        self.engine, self.mechanism, self.why = engine, mechanism, why


def input_boundary(what: str):
    """Decorate a function that validates user data (``fn(data, source, ...)``): a
    ``TypeError``, ``KeyError``, ``IndexError``, ``AttributeError``, ``ValueError``,
    ``OverflowError``, ``RecursionError`` or NumPy ``LinAlgError`` escaping its checks
    becomes one :class:`MechsynInputError` naming the source, never a traceback.

    Specific checks come first and name the field; this is the net under them, for shapes
    of data nobody anticipated (the fuzzing tests find them).

    Examples
    --------
    >>> @input_boundary("case")
    ... def load(data, source=None):
    ...     return data["a"] + 1
    >>> load({"a": [1]}, "c.yaml")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mechsyn.errors.MechsynInputError: c.yaml: malformed case: ...
    """
    import functools
    import inspect

    def decorate(fn):
        sig = inspect.signature(fn)

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            try:
                return fn(*args, **kwargs)
            except MechsynInputError:
                raise
            except (TypeError, KeyError, IndexError, AttributeError, ValueError, OverflowError,
                    RecursionError) as exc:
                try:
                    source = sig.bind(*args, **kwargs).arguments.get("source")
                except TypeError:
                    source = None
                detail = f"{type(exc).__name__}: {exc}" if str(exc) else type(exc).__name__
                raise MechsynInputError(
                    f"malformed {what}: {detail[:200]}", source=str(source) if source else None,
                    hint=f"check the {what} against the documentation and the examples") from None

        return wrapper

    return decorate
