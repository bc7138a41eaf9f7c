"""Scenes: the one description of a simulation that every solver reads (TOML or JSON).

``description`` (the validated dataclasses and cross-field checks) and ``loading`` (files and
dictionaries read field by field). May import ``blocks``, ``motion`` and ``io``.
"""

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rockyade.scene.description import BlockSpec, ContactSpec, LoadSpec, OutputSpec, Scene
    from rockyade.scene.loading import load_scene, scene_from_dict

__all__ = ["BlockSpec", "ContactSpec", "LoadSpec", "OutputSpec", "Scene", "load_scene", "scene_from_dict"]

#: Where each name of the package lives.
_HOMES = {
    "BlockSpec": "description",
    "ContactSpec": "description",
    "LoadSpec": "description",
    "OutputSpec": "description",
    "Scene": "description",
    "load_scene": "loading",
    "scene_from_dict": "loading",
}


def __getattr__(name: str) -> Any:
    """The package's names, imported when first used: the dataclasses load numpy (the blocks'
    geometry), and reading a scene loads every motion type (scipy, numba); the generators'
    option table (:mod:`rockyade.scene.generator_options`, read by ``rockyade build --help``)
    needs neither, and ``rockyade calibrate`` builds a ``ContactSpec`` without the loader."""
    if name in _HOMES:
        import importlib

        return getattr(importlib.import_module(f"rockyade.scene.{_HOMES[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
