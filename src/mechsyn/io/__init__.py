"""The mechanism file format: reading, validation, writing, JSON Schema."""

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
