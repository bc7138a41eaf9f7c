"""``restrained_wall``: a thin alias of :func:`~rockyade.scene.generators.wall_section`.

The wall restrained at its top of the paper's Fig. 2, under its former parameter names, mapped
onto the one generator of a wall's out-of-plane section:

=============================  ==========================================================
``restrained_wall``            ``wall_section``
=============================  ==========================================================
``wall_height_m``              ``height_m``
``wall_thickness_m``           ``thickness_m``
``wall_length_m``              ``length_m``
``blocks`` (1 or 2)            ``courses`` (1 to 200)
``split``                      ``split`` (2 courses)
``restraint = "side"``         ``top = "restrained-far"``
``restraint = "floor"``        ``top = "floor"``
=============================  ==========================================================

The other parameters (``restraint_width_m``, ``restraint_height_m``, ``gap_m``,
``restraint_friction_deg``, default 0) and their defaults are the same. The blocks carry
``wall_section``'s names: ``w01`` (and ``w02``), ``restraint_far`` or ``floor``.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generator_options import check, defaults, param
from rockyade.scene.generators.wall_sections import wall_section

RESTRAINTS = param("restrained-wall", "restraint").choices
#: The defaults (the generators' table).
RESTRAINED = defaults("restrained-wall")
#: restrained_wall's restraint -> wall_section's top.
TOP_OF_RESTRAINT = {"side": "restrained-far", "floor": "floor"}
#: wall_section's parameter names -> restrained_wall's (for error messages).
FORMER_NAMES = {
    "height_m": "wall_height_m",
    "thickness_m": "wall_thickness_m",
    "length_m": "wall_length_m",
    "courses": "blocks",
    "top": "restraint",
}


def restrained_wall(
    wall_height_m: float = RESTRAINED.wall_height_m,
    wall_thickness_m: float = RESTRAINED.wall_thickness_m,
    wall_length_m: float = RESTRAINED.wall_length_m,
    blocks: int = RESTRAINED.blocks,
    split: float = RESTRAINED.split,
    restraint: str = RESTRAINED.restraint,
    restraint_width_m: float = RESTRAINED.restraint_width_m,
    restraint_height_m: float = RESTRAINED.restraint_height_m,
    gap_m: float = RESTRAINED.gap_m,
    restraint_friction_deg: float | None = RESTRAINED.restraint_friction_deg,
    density_kg_m3: float = RESTRAINED.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = RESTRAINED.duration_s,
    sample_dt_s: float = RESTRAINED.sample_dt_s,
) -> dict[str, Any]:
    """``wall_section`` under restrained-wall's names (module docstring).

    Parameters
    ----------
    wall_height_m, wall_thickness_m, wall_length_m
        ``height_m``, ``thickness_m``, ``length_m``, m.
    blocks
        1 or 2 wall blocks (``courses``).
    split
        Two blocks: height of the lower one as a fraction of the wall's height, in (0, 1).
    restraint
        "side" (``top = "restrained-far"``) or "floor" (``top = "floor"``).
    restraint_width_m, restraint_height_m, gap_m, restraint_friction_deg
        As for :func:`~rockyade.scene.generators.wall_section`.
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for :func:`~rockyade.scene.generators.wall_section`.
    """
    n = check("restrained-wall", "blocks", blocks)
    kind = check("restrained-wall", "restraint", restraint)
    split = check("restrained-wall", "split", split) if n == 2 else split
    try:
        return wall_section(
            height_m=wall_height_m,
            thickness_m=wall_thickness_m,
            length_m=wall_length_m,
            courses=n,
            split=split if n == 2 else None,
            top=TOP_OF_RESTRAINT[kind],
            gap_m=gap_m,
            restraint_height_m=restraint_height_m,
            restraint_width_m=restraint_width_m,
            restraint_friction_deg=restraint_friction_deg,
            density_kg_m3=density_kg_m3,
            motion=motion,
            contact=contact,
            duration_s=duration_s,
            sample_dt_s=sample_dt_s,
        )
    except InputError as exc:
        words = re.sub(r"\b(height_m|thickness_m|length_m)\b", lambda m: FORMER_NAMES[m.group(0)], exc.message)
        raise InputError(FORMER_NAMES.get(exc.field, exc.field), words) from None
