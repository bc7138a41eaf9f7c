"""The one JSON dialect the toolkit writes: strict RFC 8259 JSON, a number that is not finite
written as null, which every JSON parser reads.

NaN is a number that does not exist (the beta of a fit without a slope, a time that never
came), infinity one beyond the data (the median of a wall that no run collapsed: the fit's
``status`` says which). Python's ``json`` would write ``NaN`` and ``Infinity``, which strict
parsers (JavaScript's ``JSON.parse``, ``jq``) refuse. Every JSON file and every JSON print of
the toolkit goes through :func:`json_text` (:func:`rockyade.io.atomic.write_json` writes it);
a reader maps null back to NaN where it expects a float (:func:`null_to_nan`).
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any


def finite_or_null(data: object) -> Any:
    """``data`` made JSON-ready: every float that is not finite (nested in mappings, lists,
    tuples and numpy arrays) replaced by None, numpy scalars and arrays by Python's, paths by
    strings.

    Parameters
    ----------
    data
        Mappings, lists, tuples, numpy arrays, numbers, strings, paths, None.

    Returns
    -------
    Any
        The same structure (mappings as dicts, tuples and arrays as lists), NaN and +/-inf as
        None; other values unchanged.
    """
    if isinstance(data, Mapping):
        return {k: finite_or_null(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [finite_or_null(v) for v in data]
    np = sys.modules.get("numpy")  # numpy values exist only once numpy is imported: never import it here
    if np is not None:
        if isinstance(data, np.ndarray):
            return finite_or_null(data.tolist())
        if isinstance(data, np.bool_):
            return bool(data)
        if isinstance(data, np.integer):
            return int(data)
        if isinstance(data, np.floating):
            data = float(data)
    if isinstance(data, bool):
        return data
    if isinstance(data, float):
        return data if math.isfinite(data) else None
    if isinstance(data, Path):
        return str(data)
    return data


def json_text(data: object, indent: int | None = 2) -> str:
    """Sorted strict JSON of ``data`` (:func:`finite_or_null`), indented as the CLI prints it.

    Parameters
    ----------
    data
        What :func:`finite_or_null` takes.
    indent
        Spaces per level (None: compact, one line).

    Raises
    ------
    TypeError
        A value JSON has no form for.
    """
    return json.dumps(finite_or_null(data), indent=indent, sort_keys=True, allow_nan=False)


def null_to_nan(value: float | None) -> float:
    """A float read from strict JSON: null (a number that was not finite) as NaN.

    Parameters
    ----------
    value
        The value read (a number or None).
    """
    return math.nan if value is None else float(value)
