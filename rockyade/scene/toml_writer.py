"""Writing scene dictionaries as TOML a user can read and edit.

A small emitter for the subset of TOML that scene files use: top-level keys, tables
(``[contact]``, ``[motion]``), arrays of tables (``[[blocks]]``, ``[[joints]]``), and values
that are strings, booleans, integers, finite floats and (nested) arrays of those. Floats
are written with Python's shortest round-trip representation, so a value read back is the
same double: flush joints stay flush to the last bit.

Every text produced is parsed back with :mod:`tomllib` and compared with the input before
anything is written, so an unsupported value fails here rather than in a later run.
"""

from __future__ import annotations

import math
import numbers
import re
import tomllib
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rockyade.errors import InputError

_BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")
_ESCAPES = {'"': '\\"', "\\": "\\\\", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\f": "\\f", "\r": "\\r"}


def _key(key: str) -> str:
    if not isinstance(key, str) or not key:
        raise InputError("scene", f"TOML keys must be non-empty strings, got {key!r}")
    return key if _BARE_KEY.match(key) else _string(key)


def _string(text: str) -> str:
    out = []
    for ch in text:
        if ch in _ESCAPES:
            out.append(_ESCAPES[ch])
        elif ord(ch) < 0x20 or ord(ch) == 0x7F:
            out.append(f"\\u{ord(ch):04x}")
        else:
            out.append(ch)
    return '"' + "".join(out) + '"'


def _float(number: float) -> str:
    """Shortest text that reads back as ``number``; exponent form from 1e6 up and below 1e-4."""
    text = repr(number)
    if "e" in text or number == 0.0 or 1e-4 <= abs(number) < 1e6:
        return text
    for places in range(17):
        candidate = f"{number:.{places}e}"
        if float(candidate) == number:
            return candidate
    return text


def _is_table(value: Any) -> bool:
    return isinstance(value, Mapping)


def _is_table_array(value: Any) -> bool:
    return isinstance(value, list | tuple) and bool(value) and all(map(_is_table, value))


def toml_value(value: Any, where: str = "scene") -> str:
    """One TOML value (string, bool, int, finite float or array of those), inline.

    Raises
    ------
    InputError
        For None, non-finite floats, tables nested inside arrays of values, or other types.
    """
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return _string(value)
    if hasattr(value, "tolist") and not isinstance(value, numbers.Number):
        value = value.tolist()  # numpy arrays
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        number = float(value)
        if not math.isfinite(number):
            raise InputError(where, f"must be a finite number to be written as TOML, got {number!r}")
        return _float(number)
    if isinstance(value, Sequence):
        if any(_is_table(v) for v in value):
            raise InputError(where, "an array mixing tables and values cannot be written as TOML")
        return "[" + ", ".join(toml_value(v, f"{where}[{i}]") for i, v in enumerate(value)) + "]"
    raise InputError(where, f"cannot be written as TOML: {type(value).__name__} {value!r}")


def _emit_table(lines: list[str], table: Mapping[str, Any], path: tuple[str, ...]) -> None:
    """Key/value lines of ``table``, then its sub-tables and arrays of tables."""
    subtables = []
    for key, value in table.items():
        if value is None:
            continue
        if _is_table(value) or _is_table_array(value):
            subtables.append((key, value))
            continue
        lines.append(f"{_key(key)} = {toml_value(value, '.'.join((*path, key)))}")
    for key, value in subtables:
        sub = (*path, key)
        header = ".".join(_key(k) for k in sub)
        if _is_table(value):
            lines.append("")
            lines.append(f"[{header}]")
            _emit_table(lines, value, sub)
        else:
            for item in value:
                lines.append("")
                lines.append(f"[[{header}]]")
                _emit_table(lines, item, sub)


def _plain(value: Any) -> Any:
    """``value`` as tomllib would read it back: None left out, numbers as int or float."""
    if _is_table(value):
        return {k: _plain(v) for k, v in value.items() if v is not None}
    if hasattr(value, "tolist") and not isinstance(value, numbers.Number):
        value = value.tolist()
    if isinstance(value, Sequence) and not isinstance(value, str):
        return [_plain(v) for v in value]
    if isinstance(value, bool | str):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    return float(value)


def toml_text(data: Mapping[str, Any], header: str = "") -> str:
    """The TOML text of ``data`` (None values left out), with ``header`` as leading comments.

    Raises
    ------
    InputError
        If a value cannot be written, or if the text does not read back as ``data``.
    """
    lines = [f"# {line}".rstrip() for line in header.splitlines()]
    body: list[str] = []
    _emit_table(body, data, ())
    # top-level tables come after the top-level keys; drop the blank line a leading table adds
    while body and body[0] == "":
        body.pop(0)
    if lines and body:
        lines.append("")
    text = "\n".join(lines + body) + "\n"
    if tomllib.loads(text) != _plain(data):
        raise InputError("scene", "the TOML written does not read back as the scene (unsupported value types)")
    return text


def write_toml(path: str | Path, data: Mapping[str, Any], header: str = "") -> None:
    """Write ``data`` as TOML to ``path`` atomically (see :func:`toml_text`)."""
    from rockyade.io.atomic import write_text

    write_text(path, toml_text(data, header))
