"""Helpers shared by the command modules."""

from __future__ import annotations

from typing import Any


def json_out(data: Any) -> None:
    """Print ``data`` as indented, sorted JSON (numpy values converted)."""
    from rockyade.io.atomic import json_text

    print(json_text(data))
