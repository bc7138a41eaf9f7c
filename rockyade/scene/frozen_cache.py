"""What a frozen object (a scene, a block) works out once and keeps: in its own ``__dict__``,
under a name that starts with "_", left out when it pickles (a worker works it out again)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")


def computed_once(obj: object, key: str, compute: Callable[[], T]) -> T:
    """``compute()``, worked out once per frozen object and kept in its ``__dict__`` under
    ``key``, a name that starts with "_" (module docstring)."""
    value = obj.__dict__.get(key)
    if value is None:
        value = obj.__dict__[key] = compute()
    return value


def without_caches(obj: object) -> dict[str, object]:
    """A frozen object's fields for pickling, without what it computed and kept (keys with "_")."""
    return {k: v for k, v in obj.__dict__.items() if not k.startswith("_")}
