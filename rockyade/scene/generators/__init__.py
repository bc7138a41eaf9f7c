"""Generators of masonry assemblies: plain scene dictionaries a user can write and edit.

Each generator returns the dictionary of a positioned scene (every block placed by
``position_m``; see docs/assemblies.md), which :func:`rockyade.scene.scene_from_dict`
validates and :func:`write_scene` writes as TOML (or JSON)::

    from rockyade.scene.generators import wall, write_scene
    scene = wall(courses=5, units_per_course=6, openings=[(1.0, 0.0, 0.6, 0.6)])
    write_scene("wall.toml", scene)

Modules: ``wall`` (dry walls, running or stack bond, openings), ``column`` (drum columns,
stacks), ``arch`` (semicircular and pointed arches on piers), ``frame`` (the rocking frame
of Makris & Vassiliou 2013), ``restrained_wall`` (a wall restrained at its top, the
paper's Fig. 2), ``common`` (exact numbers, block tables, motions and contacts).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generators.arch import arch
from rockyade.scene.generators.column import drum_column, stack, tapered_widths
from rockyade.scene.generators.common import (
    free_motion,
    paper_contact,
    pulse_motion,
    record_motion,
    rest_motion,
    udec_contact,
)
from rockyade.scene.generators.frame import frame_frequency, frame_gamma, rocking_frame
from rockyade.scene.generators.restrained_wall import restrained_wall
from rockyade.scene.generators.wall import Opening, wall

#: CLI kind -> generator.
GENERATORS: dict[str, Callable[..., dict[str, Any]]] = {
    "wall": wall,
    "column": drum_column,
    "arch": arch,
    "frame": rocking_frame,
    "stack": stack,
    "restrained-wall": restrained_wall,
}


def write_scene(path: str | Path, scene: Mapping[str, Any], header: str = "") -> None:
    """Write a generated scene as ``.toml`` (with ``header`` as comments) or ``.json``, atomically."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".toml":
        from rockyade.scene.toml_writer import write_toml

        write_toml(path, scene, header)
    elif suffix == ".json":
        from rockyade.io.atomic import write_json

        write_json(path, dict(scene))
    else:
        raise InputError("out", f"must end in .toml or .json, got {suffix or 'no suffix'!r}")


__all__ = [
    "GENERATORS",
    "Opening",
    "arch",
    "drum_column",
    "frame_frequency",
    "frame_gamma",
    "free_motion",
    "paper_contact",
    "pulse_motion",
    "record_motion",
    "rest_motion",
    "restrained_wall",
    "rocking_frame",
    "stack",
    "tapered_widths",
    "udec_contact",
    "wall",
    "write_scene",
]
