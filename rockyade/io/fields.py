"""Reading validated fields from a table of a scene or study file.

A :class:`TableReader` wraps one TOML/JSON table, hands out typed values with range checks,
remembers which keys were read, and rejects unknown keys. Every error names the dotted
field path and the allowed range.
"""

from __future__ import annotations

import difflib
import math
from collections.abc import Iterable, Mapping
from typing import Any

from rockyade.errors import InputError

_MISSING = object()

#: Deepest nesting of tables and lists accepted in a scene or study (a scene needs 4).
MAX_NESTING = 32


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _as_float(value: Any) -> float | None:
    """``value`` as a float, or None when it is beyond the float range (a huge integer)."""
    try:
        return float(value)
    except OverflowError:
        return None


def plain_data(value: Any, path: str = "scene", source: str | None = None) -> Any:
    """``value`` with numpy arrays and scalars turned into lists and Python numbers.

    Tuples become lists. Nesting deeper than :data:`MAX_NESTING` is refused (InputError),
    so no reader recurses without bound.
    """
    return _plain(value, path, source, 0)


def _plain(value: Any, path: str, source: str | None, depth: int) -> Any:
    if depth > MAX_NESTING:
        raise InputError(path, f"nesting deeper than {MAX_NESTING} levels of tables or lists", source)
    if isinstance(value, Mapping):
        return {k: _plain(v, f"{path}.{k}", source, depth + 1) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{path}[{i}]", source, depth + 1) for i, v in enumerate(value)]
    module = type(value).__module__
    if (module == "numpy" or module.startswith("numpy.")) and hasattr(value, "tolist"):
        converted = value.tolist()
        if isinstance(converted, list):
            return _plain(converted, path, source, depth)
        return converted
    return value


class TableReader:
    """Typed, range-checked access to one table.

    Parameters
    ----------
    table
        The mapping read from TOML or JSON.
    path
        Dotted path of the table (``""`` for the top level, ``"contact"``, ``"blocks[1]"``).
    source
        File the table came from, quoted in errors.
    """

    def __init__(self, table: Any, path: str, source: str | None = None) -> None:
        if not isinstance(table, Mapping):
            raise InputError(path or "scene", f"must be a table, got {type(table).__name__}", source)
        self.table = table
        self.path = path
        self.source = source
        self.used: set[str] = set()

    def field(self, key: str) -> str:
        """Dotted path of ``key``."""
        return f"{self.path}.{key}" if self.path else key

    def error(self, key: str, message: str) -> InputError:
        """An InputError for ``key``."""
        return InputError(self.field(key), message, self.source)

    def has(self, key: str) -> bool:
        """True if ``key`` is present with a value (JSON null counts as absent)."""
        return self.table.get(key) is not None

    def raw(self, key: str, default: Any = _MISSING) -> Any:
        """The value as read, marking the key used; raise if missing and no default.

        A JSON ``null`` counts as absent.
        """
        self.used.add(key)
        if self.has(key):
            return self.table[key]
        if default is _MISSING:
            raise self._missing(key)
        return default

    def _missing(self, key: str) -> InputError:
        """A required key is absent: name a misspelt key the table has instead, if any."""
        others = [k for k in self.table if isinstance(k, str) and k not in self.used]
        close = difflib.get_close_matches(key, others, n=1, cutoff=0.8)
        if close:
            return self.error(close[0], f"unknown key; did you mean {key}? ({key} is required)")
        if others:  # a key under another name ('path' for 'file'): show what the table holds
            shown = ", ".join(sorted(others)[:8])
            return self.error(key, f"is required (also in this table: {shown})")
        return self.error(key, "is required")

    def number(
        self,
        key: str,
        default: Any = _MISSING,
        *,
        lo: float = -math.inf,
        hi: float = math.inf,
        lo_open: bool = False,
        hi_open: bool = False,
        unit: str = "",
    ) -> Any:
        """A finite number within [lo, hi] (open ends as asked), or ``default`` if absent."""
        value = self.raw(key, default)
        if value is None and default is None and not self.has(key):
            return None
        if not _is_number(value):
            raise self.error(key, f"must be a number{_unit(unit)}, got {_short(value)}")
        number = _as_float(value)
        if number is None or not math.isfinite(number):
            rng = _interval(lo, hi, lo_open, hi_open)
            raise self.error(key, f"must be a finite number in {rng}{_unit(unit)}, got {_short(value)}")
        value = number
        low_bad = value <= lo if lo_open else value < lo
        high_bad = value >= hi if hi_open else value > hi
        if low_bad or high_bad:
            raise self.error(key, f"must be in {_interval(lo, hi, lo_open, hi_open)}{_unit(unit)}, got {_short(value)}")
        return float(value)

    def positive(self, key: str, default: Any = _MISSING, unit: str = "") -> Any:
        """A finite number > 0."""
        return self.number(key, default, lo=0.0, lo_open=True, unit=unit)

    def integer(self, key: str, default: Any = _MISSING, *, lo: int = 0, hi: int | None = None) -> Any:
        """An integer in [lo, hi]."""
        value = self.raw(key, default)
        if value is None and default is None and not self.has(key):
            return None
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"must be an integer, got {_short(value)}")
        if value < lo or (hi is not None and value > hi):
            rng = f"[{lo}, {hi}]" if hi is not None else f">= {lo}"
            raise self.error(key, f"must be in {rng}, got {_short(value)}")
        return value

    def string(self, key: str, default: Any = _MISSING, *, choices: Iterable[str] | None = None) -> Any:
        """A string, optionally one of ``choices``."""
        value = self.raw(key, default)
        if value is None and default is None and not self.has(key):
            return None
        if not isinstance(value, str):
            raise self.error(key, f"must be a string, got {_short(value)}")
        if choices is not None:
            allowed = list(choices)
            if value not in allowed:
                raise self.error(key, f"must be one of {', '.join(repr(c) for c in allowed)}, got {_short(value)}")
        return value

    def boolean(self, key: str, default: Any = _MISSING) -> Any:
        """A boolean."""
        value = self.raw(key, default)
        if not isinstance(value, bool):
            raise self.error(key, f"must be true or false, got {_short(value)}")
        return value

    def number_list(self, key: str, default: Any = _MISSING, *, min_len: int = 1, unit: str = "") -> Any:
        """A list of finite numbers."""
        value = self.raw(key, default)
        if value is None and default is None and not self.has(key):
            return None
        if not isinstance(value, (list, tuple)) or len(value) < min_len:
            raise self.error(key, f"must be a list of at least {min_len} numbers{_unit(unit)}")
        out = []
        for i, v in enumerate(value):
            number = _as_float(v) if _is_number(v) else None
            if number is None or not math.isfinite(number):
                raise InputError(f"{self.field(key)}[{i}]", f"must be a finite number, got {_short(v)}", self.source)
            out.append(number)
        return out

    def sub(self, key: str, default: Any = _MISSING) -> TableReader:
        """A reader for a sub-table."""
        value = self.raw(key, default)
        return TableReader(value, self.field(key), self.source)

    def finish(self) -> None:
        """Reject keys that were never read (naming the allowed key a misspelt one resembles)."""
        unknown = sorted(set(self.table) - self.used)
        if unknown:
            allowed = ", ".join(sorted(self.used)) or "(none)"
            key = unknown[0]
            close = difflib.get_close_matches(key, sorted(self.used), n=1, cutoff=0.8) if isinstance(key, str) else []
            hint = f"did you mean {close[0]}? " if close else ""
            raise InputError(self.field(key), f"unknown key; {hint}allowed keys here: {allowed}", self.source)


def _short(value: Any, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters (a 400-digit integer stays readable)."""
    try:
        text = repr(value)
    except ValueError:  # an integer too long for repr
        return f"an integer of more than {limit} digits"
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""


def _interval(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    def fmt(v: float) -> str:
        if v == math.pi / 2:
            return "pi/2"
        if 0 < math.pi / 2 - v < 0.01:
            return f"pi/2 - {math.pi / 2 - v:.3g}"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return f"{v:g}"

    if math.isinf(hi) and not math.isinf(lo):
        return f"{'>' if lo_open else '>='} {fmt(lo)}"
    return f"{'(' if lo_open else '['}{fmt(lo)}, {fmt(hi)}{')' if hi_open else ']'}"
