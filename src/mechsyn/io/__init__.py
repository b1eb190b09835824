"""The mechanism file format: reading, validation, writing, JSON Schema, converters.

* :mod:`~mechsyn.io.load`: mechanism files (YAML or JSON) to :class:`~mechsyn.model.Mechanism`
  and back (:func:`load`, :func:`save`, :func:`mechanism_from_dict`, :func:`mechanism_to_dict`);
* :mod:`~mechsyn.io.schema`: the format as pydantic models (:func:`json_schema`);
* :mod:`~mechsyn.io.plain`: a plain file read without building pydantic's validators;
* :mod:`~mechsyn.io.checks`: the geometry a file cannot mean, checked once on reading;
* :mod:`~mechsyn.io.files`: the one reader of every input file (mechanism, case, arm,
  belt, table files) with its size limits and error messages;
* :mod:`~mechsyn.io.pyslvs`, :mod:`~mechsyn.io.convert`: Pyslvs expressions in and out.

``io`` sits on :mod:`mechsyn.model` and :mod:`mechsyn.errors`; the analyses and the
synthesis read their files through it.
"""

from mechsyn.io.load import (
    load,
    load_mechanism,
    loads,
    save,
    mechanism_from_dict,
    mechanism_from_text,
    mechanism_to_dict,
    read_data,
    write_mechanism,
)
from mechsyn.io.schema import json_schema

__all__ = [
    "load", "loads", "save", "load_mechanism", "mechanism_from_dict", "mechanism_from_text", "mechanism_to_dict",
    "read_data", "write_mechanism", "json_schema",
]
