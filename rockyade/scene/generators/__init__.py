"""Generators of masonry assemblies: plain scene dictionaries a user can write and edit.

Each generator returns the dictionary of a scene (every block placed by ``position_m``, or
a column scene; see docs/assemblies.md), which :func:`rockyade.scene.scene_from_dict`
validates and :func:`write_scene` writes as TOML (or JSON)::

    from rockyade.scene.generators import wall, write_scene
    scene = wall(courses=5, units_per_course=6, openings=[(1.0, 0.0, 0.6, 0.6)])
    write_scene("wall.toml", scene)

The generators carry the names of ``rockyade build KIND``: :func:`wall`, :func:`column`,
:func:`stack`, :func:`arch`, :func:`frame`, :func:`wall_section` (``wall-section``, a wall's section out of
its plane, free or restrained at its top; :func:`restrained_wall`, ``restrained-wall``, is its alias);
:data:`GENERATORS` maps each kind to its function. Their modules are named in the plural so
that no module hides a function of the same name: ``walls`` (dry walls, running or stack
bond, openings), ``columns`` (drum columns, stacks), ``arches`` (semicircular and pointed
arches on piers), ``frames`` (the rocking frame of Makris & Vassiliou 2013),
``wall_sections`` (a wall's out-of-plane section, the paper's Fig. 2), ``restrained_walls``
(the alias), ``scene_tables`` (exact
numbers, block tables, motions and contacts). ``drum_column`` and ``rocking_frame`` are the
former names of :func:`column` and :func:`frame`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generators.arches import arch
from rockyade.scene.generators.columns import column, drum_column, round_drum_mass_inertia, stack, tapered_widths
from rockyade.scene.generators.frames import frame, frame_frequency, frame_gamma, rocking_frame
from rockyade.scene.generators.restrained_walls import restrained_wall
from rockyade.scene.generators.scene_tables import (
    free_motion,
    paper_contact,
    pulse_motion,
    record_motion,
    rest_motion,
    udec_contact,
)
from rockyade.scene.generators.wall_sections import wall_section
from rockyade.scene.generators.walls import Opening, wall

#: CLI kind -> generator.
GENERATORS: dict[str, Callable[..., dict[str, Any]]] = {
    "wall": wall,
    "column": column,
    "arch": arch,
    "frame": frame,
    "stack": stack,
    "restrained-wall": restrained_wall,
    "wall-section": wall_section,
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
    "column",
    "drum_column",
    "frame",
    "frame_frequency",
    "frame_gamma",
    "free_motion",
    "paper_contact",
    "pulse_motion",
    "record_motion",
    "rest_motion",
    "restrained_wall",
    "rocking_frame",
    "round_drum_mass_inertia",
    "stack",
    "tapered_widths",
    "udec_contact",
    "wall",
    "wall_section",
    "write_scene",
]
