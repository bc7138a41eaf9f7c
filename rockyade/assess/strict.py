"""Strict JSON: a number that is not finite becomes null, which every JSON parser reads.
NaN is a number that does not exist (the beta of a fit without a slope), infinity one
beyond the data (the median of a wall that no run collapsed: the fit's ``status`` says
which). Python's ``json`` would write ``NaN`` and ``Infinity``, which strict parsers
(JavaScript's ``JSON.parse``, ``jq``) refuse."""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def finite_or_null(data: Any) -> Any:
    """``data`` with every float that is not finite (nested in dicts, lists and tuples)
    replaced by None.

    Parameters
    ----------
    data
        JSON-ready values (dicts, lists, tuples, numbers, strings, numpy scalars).

    Returns
    -------
    Any
        The same structure (tuples as lists), NaN and +/-inf as None; other values unchanged.
    """
    if isinstance(data, dict):
        return {k: finite_or_null(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [finite_or_null(v) for v in data]
    if isinstance(data, float | np.floating) and not math.isfinite(data):
        return None
    return data
