"""Scenes: the one description of a simulation that every solver reads (TOML or JSON).

``model`` (the validated dataclasses and cross-field checks) and ``loading`` (files and
dictionaries read field by field). May import ``blocks``, ``motion`` and ``io``.
"""

from rockyade.scene.loading import load_scene, scene_from_dict
from rockyade.scene.model import BlockSpec, ContactSpec, OutputSpec, Scene

__all__ = ["BlockSpec", "ContactSpec", "OutputSpec", "Scene", "load_scene", "scene_from_dict"]
