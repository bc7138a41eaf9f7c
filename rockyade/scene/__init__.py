"""Scenes: the one description of a simulation that every solver reads (TOML or JSON).

``description`` (the validated dataclasses and cross-field checks) and ``loading`` (files and
dictionaries read field by field). May import ``blocks``, ``motion`` and ``io``.
"""

from typing import Any

from rockyade.scene.description import BlockSpec, ContactSpec, LoadSpec, OutputSpec, Scene

__all__ = ["BlockSpec", "ContactSpec", "LoadSpec", "OutputSpec", "Scene", "load_scene", "scene_from_dict"]


def __getattr__(name: str) -> Any:
    """``load_scene`` and ``scene_from_dict``, imported when first used: reading a scene loads
    every motion type (scipy, numba), which the scene's dataclasses alone do not need
    (``rockyade calibrate`` builds a ``ContactSpec`` and stays quick)."""
    if name in ("load_scene", "scene_from_dict"):
        from rockyade.scene import loading

        return getattr(loading, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
