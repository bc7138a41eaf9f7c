"""Overburden: the floor and roof loads a wall or a column carries at its top, as ``[[loads]]``.

Three cases (``kind``):

* ``"section"`` (a wall's section out of its plane: ``wall-section``): the load per metre
  of wall ``force_N_per_m`` times the wall's length (the blocks' ``thickness_m``), vertical,
  on the top block at ``eccentricity_m`` from the wall's axis (the top face's centre;
  > 0 towards +x);
* ``"line"`` (a wall in its plane: ``wall``): ``force_N_per_m`` times the length of each top
  unit's top face, at its centre (an eccentricity would be out of the plane: refused);
* ``"point"`` (a column or a stack): the force ``force_N`` on the top block at
  ``eccentricity_m`` from its axis.

Each load carries the mass of its weight, ``mass_kg`` = force / g (the code counts the
vertical loads a wall carries among the masses the horizontal acceleration acts on,
Circolare 2019 C8.7.1; :mod:`rockyade.scene.carried`), unless ``with_mass`` is False (a
force without mass: its horizontal force goes elsewhere).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.scene.description import LoadTable
from rockyade.scene.generator_options import LINE_LOAD, OFFSET, POINT_LOAD

KINDS = ("section", "line", "point")


def _top_blocks(scene) -> list[Any]:
    """The moving blocks whose tops are the highest (within 1e-9 of the size)."""
    from rockyade.scene.placement import placed_blocks

    placed = [b for b in placed_blocks(scene) if not b.fixed]
    tops = np.array([float(b.vertices_m[:, 1].max()) for b in placed])
    size = max(b.size_m for b in placed)
    return [b for b, top in zip(placed, tops, strict=True) if top >= tops.max() - 1e-9 * size]


def _top_face(block) -> tuple[float, float, float]:
    """(x of its centre, y, length) of a block's top face, m."""
    v = block.vertices_m
    top = float(v[:, 1].max())
    xs = v[v[:, 1] >= top - 1e-9 * max(1.0, block.size_m), 0]
    return 0.5 * (float(xs.min()) + float(xs.max())), top, float(xs.max() - xs.min())


def _load(block: str, point: list[float], force: float, with_mass: bool) -> LoadTable:
    """A vertical [[loads]] entry of ``force`` N downwards, with the mass of its weight or none."""
    return {"block": block, "point_m": point, "force_N": [0.0, -force], "mass_kg": force / G if with_mass else 0.0}


def add_overburden(
    scene_dict: dict[str, Any],
    kind: str,
    force_N_per_m: float = 0.0,
    force_N: float = 0.0,
    eccentricity_m: float = 0.0,
    with_mass: bool = True,
) -> dict[str, Any]:
    """``scene_dict`` with its overburden as ``[[loads]]`` (module docstring).

    Parameters
    ----------
    scene_dict
        A generated scene.
    kind
        "section", "line" or "point".
    force_N_per_m
        Vertical load per metre of wall, N/m (downwards; "section" and "line").
    force_N
        Vertical load, N (downwards; "point").
    eccentricity_m
        Distance of the load from the axis of the top block, m (> 0 towards +x).
    with_mass
        Each load carries the mass of its weight (``mass_kg`` = force / g), else none.

    Returns
    -------
    dict
        A copy with ``loads`` appended to (nothing added for a zero load).

    Raises
    ------
    InputError
        A negative, absurd or non-finite load, or an eccentricity outside the top face.
    """
    from rockyade.scene import scene_from_dict

    if kind not in KINDS:
        raise InputError("overburden", f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    q = LINE_LOAD.check("overburden_N_per_m", force_N_per_m)  # the generators' table's ranges: downwards
    n = POINT_LOAD.check("overburden_N", force_N)
    eccentricity_m = OFFSET.check("overburden_eccentricity_m", eccentricity_m)
    if (q if kind != "point" else n) == 0.0:
        return dict(scene_dict)
    scene = scene_from_dict(scene_dict)
    tops = _top_blocks(scene)
    loads = list(scene_dict.get("loads", []))
    if kind == "line":
        if eccentricity_m != 0.0:
            raise InputError(
                "overburden_eccentricity_m",
                "an in-plane wall's overburden has no eccentricity in its plane (an eccentricity across the wall's "
                "thickness acts out of plane: build a wall section)",
            )
        for block in tops:
            x, y, length = _top_face(block)
            loads.append(_load(block.name, [x, y], q * length, with_mass))
        return {**scene_dict, "loads": loads}
    if len(tops) != 1:
        raise InputError("overburden", f"needs one top block, found {len(tops)}: {[b.name for b in tops][:5]}")
    block = tops[0]
    x, y, length = _top_face(block)
    if abs(eccentricity_m) > 0.5 * length + 1e-12:
        raise InputError(
            "overburden_eccentricity_m",
            f"must lie on the top face of {block.name}: |e| <= {0.5 * length:g} m, got {eccentricity_m:g}",
        )
    spec = scene.blocks[block.index]
    force = q * spec.thickness_m if kind == "section" else n
    loads.append(_load(block.name, [x + eccentricity_m, y], force, with_mass))
    return {**scene_dict, "loads": loads}
