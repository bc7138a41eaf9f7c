"""A wall's section out of its plane, named as wall engineers name it: the one generator of it.

A wall of height ``height_m`` and thickness ``thickness_m`` (through the section: the
scene's ``width_m``) and length ``length_m`` along its plane (the blocks' ``thickness_m``,
out of the section), standing on the base centred on x = 0, in ``courses`` equal courses
(1: one block; with 2, ``split`` puts the joint between them at ``split`` x ``height_m``: the
two-block model of the paper's Fig. 2c, a hinge forming between them). The top is:

* ``"free"``: nothing above it (static threshold t / H for the whole wall);
* ``"restrained"``: a fixed block on each side of its top, ``restraint_height_m`` deep, each
  ``gap_m`` from the wall (a gap > 0 is required: restraints flush on both faces clamp the
  wall);
* ``"restrained-far"`` (``"restrained-near"``): one fixed block, on the far face (x > 0; the near
  face, x < 0) only, ``gap_m`` from it (e.g. a transverse wall or a floor's edge beam); a zero gap
  is allowed and gives the three-hinge mechanism of the paper's Fig. 2 towards the restraint;
* ``"floor"``: a fixed floor slab over the top, from the near face to ``restraint_width_m`` past
  the far face, ``restraint_height_m`` deep, ``gap_m`` above the wall. A fixed floor bearing on the
  wall (no gap) stops it from rising, hence from rocking.

The restraints are frictionless by default (``restraint_friction_deg`` = 0: a wall that slides up
a restraint is what lets hinges form; None: no ``[[joints]]`` entry, the scene's friction), with the
same friction for every course that can touch them (the top courses beside them and the course
whose corner meets their bottom corner; the top course under a floor). A gap the wall cannot
close before it overturns is refused: turning about its toe, its centroid passes the toe when its
top has moved by its thickness (beside the top) and its top corner has risen by
sqrt(t^2 + H^2) - H (under a floor).

::

                gap_m |<->|          restraint_width_m
      restraint_near  +---+  wall  +---+  restraint_far
      (fixed)         |   |   top  |   |  (fixed)    ^ restraint_height_m
                      +---+ course +---+             v
                          |  w0n   |
                          |  ...   |   courses equal, height_m / courses each
                          |  w01   |
                  ========+========+======== base
                          |<------>| thickness_m (centred on x = 0)

and may carry an overburden ``overburden_n_per_m`` (per metre of wall, on the top block at
``overburden_eccentricity_m`` from the wall's axis, as ``[[loads]]``; static threshold
(W b + N d) / (W h_c) for one block, the load without mass).

Block names: ``w01`` ... (bottom to top), ``restraint_near`` (x < 0), ``restraint_far``, ``floor``.
:func:`~rockyade.scene.generators.restrained_wall` (``restrained-wall``) is a thin alias of this
generator under its former parameter names.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generator_options import check, defaults, param
from rockyade.scene.generators.overburden import add_overburden
from rockyade.scene.generators.scene_tables import (
    BlockTable,
    JointTable,
    exact,
    rect_block,
    scene_table,
)

TOPS = param("wall-section", "top").choices
#: The defaults (the generators' table).
SECTION = defaults("wall-section")
#: The fixed blocks of each top, by side.
SIDES = {"free": (), "restrained": ("near", "far"), "restrained-far": ("far",), "restrained-near": ("near",)}


def wall_section(
    height_m: float = SECTION.height_m,
    thickness_m: float = SECTION.thickness_m,
    length_m: float = SECTION.length_m,
    courses: int = SECTION.courses,
    split: float | None = SECTION.split,
    top: str = SECTION.top,
    gap_m: float = SECTION.gap_m,
    restraint_height_m: float = SECTION.restraint_height_m,
    restraint_width_m: float = SECTION.restraint_width_m,
    restraint_friction_deg: float | None = SECTION.restraint_friction_deg,
    overburden_n_per_m: float = SECTION.overburden_n_per_m,
    overburden_eccentricity_m: float = SECTION.overburden_eccentricity_m,
    density_kg_m3: float = SECTION.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = SECTION.duration_s,
    sample_dt_s: float = SECTION.sample_dt_s,
) -> dict[str, Any]:
    """A wall section as a scene dictionary (module docstring).

    Parameters
    ----------
    height_m, thickness_m, length_m
        The wall's height, thickness (through the section) and length (along its plane), m.
    courses
        Courses, 1 to 200, equal unless ``split`` is given.
    split
        With 2 courses: height of the joint between them as a fraction of ``height_m``, in (0, 1)
        (None: 0.5, equal courses).
    top
        "free", "restrained" (both faces), "restrained-far" or "restrained-near" (one face), or
        "floor" (a fixed slab over the top).
    gap_m, restraint_height_m, restraint_width_m
        The restraints' gap to the wall (horizontal beside it, > 0 with both faces restrained;
        vertical under a floor; one the wall cannot close before it overturns is refused), depth
        and width ("floor": the slab's depth and its reach past the far face), m.
    restraint_friction_deg
        Friction angle of the wall-restraint joints, degrees in [0, 90) (None: the scene's).
    overburden_n_per_m, overburden_eccentricity_m
        Vertical load per metre of wall on the top block, N/m, and its distance from the
        wall's axis, m (> 0 towards +x).
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for the other generators; the default contact is the paper's calibration.

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    H = exact(check("wall-section", "height_m", height_m))
    T = exact(check("wall-section", "thickness_m", thickness_m))
    length = check("wall-section", "length_m", length_m)
    n = check("wall-section", "courses", courses)
    kind = check("wall-section", "top", top)
    gap = exact(check("wall-section", "gap_m", gap_m))
    rh = exact(check("wall-section", "restraint_height_m", restraint_height_m))
    rw = exact(check("wall-section", "restraint_width_m", restraint_width_m))
    if restraint_friction_deg is not None:
        check("wall-section", "restraint_friction_deg", restraint_friction_deg)
    density = check("wall-section", "density_kg_m3", density_kg_m3)
    split = check("wall-section", "split", split)
    zero = Fraction(0)
    if split is None:
        levels = [H * i / n for i in range(n + 1)]
    else:
        if n != 2:
            raise InputError("split", f"applies to a wall in 2 courses, got {n}")
        levels = [zero, H * exact(split), H]
    blocks = [
        rect_block(f"w{i + 1:02d}", T, levels[i + 1] - levels[i], zero, levels[i], length, density) for i in range(n)
    ]
    fixed: list[BlockTable] = []
    touching: list[str] = []
    if kind == "restrained" and gap <= 0:
        raise InputError(
            "gap_m",
            "must be > 0 with top = 'restrained': restraints flush on both faces clamp the wall (it cannot turn); "
            "restrain one face (top = 'restrained-far') for the three-hinge mechanism",
        )
    if kind in ("restrained", "restrained-far", "restrained-near"):
        if gap >= T:
            raise InputError(
                "gap_m",
                f"must be < thickness_m ({float(T):g} m): the wall overturns when its top has moved by its "
                f"thickness, before a gap of {float(gap):g} m closes",
            )
        if rh > H:
            raise InputError("restraint_height_m", f"must be <= height_m ({float(H):g} m): it stands beside the wall")
        sign = {"near": -1, "far": 1}
        for side in SIDES[kind]:
            x = sign[side] * (T / 2 + gap + rw / 2)
            fixed.append(rect_block(f"restraint_{side}", rw, rh, x, H - rh, length, density, fixed=True))
        # every course beside a restraint, and the one whose top corner meets its bottom corner
        touching = [blocks[i]["name"] for i in range(n) if levels[i + 1] >= H - rh]
    elif kind == "floor":
        reach = math.hypot(float(T), float(H)) - float(H)
        if float(gap) >= reach:
            raise InputError(
                "gap_m",
                f"must be < {reach:.4g} m with top = 'floor': the wall overturns (its top corner risen by "
                f"sqrt(t^2 + H^2) - H) before a gap of {float(gap):g} m closes",
            )
        slab = T + rw
        fixed.append(rect_block("floor", slab, rh, -T / 2 + slab / 2, H + gap, length, density, fixed=True))
        touching = [blocks[-1]["name"]]
    joints: list[JointTable] | None = None
    if fixed and restraint_friction_deg is not None:
        joints = [
            {"blocks": [name, block["name"]], "friction_angle_deg": float(restraint_friction_deg)}
            for block in fixed
            for name in touching
        ]
    data = scene_table(
        [*blocks, *fixed],
        contact=contact,
        motion=motion,
        duration_s=duration_s,
        sample_dt_s=sample_dt_s,
        joints=joints,
    )
    load = check("wall-section", "overburden_n_per_m", overburden_n_per_m)
    eccentricity = check("wall-section", "overburden_eccentricity_m", overburden_eccentricity_m)
    return add_overburden(data, "section", force_N_per_m=load, eccentricity_m=eccentricity)
