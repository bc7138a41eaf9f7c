"""A wall's section out of its plane, named as wall engineers name it.

A wall of height ``height_m`` and thickness ``thickness_m`` (through the section: the
scene's ``width_m``) and length ``length_m`` along its plane (the blocks' ``thickness_m``,
out of the section), standing on the base centred on x = 0, in ``courses`` equal courses
(1: one block). The top is:

* ``"free"``: nothing above it (static threshold t / H for the whole wall);
* ``"restrained"``: a fixed block on each side of its top, ``restraint_height_m`` deep, each
  ``gap_m`` from the wall (a gap > 0 is required: restraints flush on both faces clamp the
  wall);
* ``"restrained-far"`` (``"restrained-near"``): one fixed block, on the far face (x > 0; the near
  face, x < 0) only, ``gap_m`` from it; a zero gap is allowed and gives the three-hinge
  mechanism of the paper's Fig. 2 towards the restraint.

The restraints are frictionless by default (``restraint_friction_deg``: a wall that slides up a
restraint is what lets hinges form), with the same friction for every course that can touch them
(the top courses beside them and the course whose corner meets their bottom corner). A gap of the
wall's thickness or more is refused: a wall turning about its toe overturns (its centroid passes
the toe) when its top has moved by its thickness, before such a gap closes.

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
(W b + N d) / (W h_c) for one block).

Block names: ``w01`` ... (bottom to top), ``restraint_near`` (x < 0), ``restraint_far``.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generators.common import (
    DEFAULT_DENSITY_KG_M3,
    DEFAULT_SAMPLE_DT_S,
    check_choice,
    check_count,
    check_density,
    check_length,
    check_number,
    exact,
    paper_contact,
    rect_block,
    scene_table,
)
from rockyade.scene.generators.overburden import add_overburden

TOPS = ("free", "restrained", "restrained-far", "restrained-near")


def wall_section(
    height_m: float = 3.0,
    thickness_m: float = 0.3,
    length_m: float = 1.0,
    courses: int = 1,
    top: str = "free",
    gap_m: float = 0.0,
    restraint_height_m: float = 0.3,
    restraint_width_m: float = 0.3,
    restraint_friction_deg: float = 0.0,
    overburden_n_per_m: float = 0.0,
    overburden_eccentricity_m: float = 0.0,
    density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = None,
    sample_dt_s: float = DEFAULT_SAMPLE_DT_S,
) -> dict[str, Any]:
    """A wall section as a scene dictionary (module docstring).

    Parameters
    ----------
    height_m, thickness_m, length_m
        The wall's height, thickness (through the section) and length (along its plane), m.
    courses
        Equal courses, 1 to 200.
    top
        "free", "restrained" (both faces), "restrained-far" or "restrained-near" (one face).
    gap_m, restraint_height_m, restraint_width_m
        The restraints' gap to the wall's face (> 0 with both faces restrained, less than the
        wall's thickness), depth and width, m.
    restraint_friction_deg
        Friction angle of the wall-restraint joints, degrees in [0, 90).
    overburden_n_per_m, overburden_eccentricity_m
        Vertical load per metre of wall on the top block, N/m, and its distance from the
        wall's axis, m (> 0 towards +x).
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for the other generators; the default contact is the paper's calibration.
    """
    H = exact(check_length("height_m", height_m))
    T = exact(check_length("thickness_m", thickness_m))
    length = check_length("length_m", length_m)
    n = check_count("courses", courses, 1, 200)
    kind = check_choice("top", top, TOPS)
    gap = exact(check_length("gap_m", gap_m, zero_ok=True))
    rh = exact(check_length("restraint_height_m", restraint_height_m))
    rw = exact(check_length("restraint_width_m", restraint_width_m))
    check_number("restraint_friction_deg", restraint_friction_deg, 0.0, 90.0, hi_open=True)
    density = check_density("density_kg_m3", density_kg_m3)
    zero = Fraction(0)
    h = H / n
    blocks = [rect_block(f"w{i + 1:02d}", T, h, zero, h * i, length, density) for i in range(n)]
    joints = None
    if kind != "free":
        if kind == "restrained" and gap <= 0:
            raise InputError(
                "gap_m",
                "must be > 0 with top = 'restrained': restraints flush on both faces clamp the wall (it cannot turn); "
                "restrain one face (top = 'restrained-far') for the three-hinge mechanism",
            )
        if gap >= T:
            raise InputError(
                "gap_m",
                f"must be < thickness_m ({float(T):g} m): the wall overturns when its top has moved by its "
                f"thickness, before a gap of {float(gap):g} m closes",
            )
        if rh > H:
            raise InputError("restraint_height_m", f"must be <= height_m ({float(H):g} m)")
        sides = {"restrained": ("near", "far"), "restrained-far": ("far",), "restrained-near": ("near",)}[kind]
        sign = {"near": -1, "far": 1}
        for side in sides:
            x = sign[side] * (T / 2 + gap + rw / 2)
            blocks.append(rect_block(f"restraint_{side}", rw, rh, x, H - rh, length, density, fixed=True))
        # every course beside a restraint, and the one whose top corner meets its bottom corner
        touching = [blocks[i]["name"] for i in range(n) if h * (i + 1) >= H - rh]
        joints = [
            {"blocks": [name, f"restraint_{side}"], "friction_angle_deg": float(restraint_friction_deg)}
            for side in sides
            for name in touching
        ]
    data = scene_table(
        blocks,
        contact=contact if contact is not None else paper_contact(),
        motion=motion,
        duration_s=duration_s,
        sample_dt_s=sample_dt_s,
        joints=joints,
    )
    return add_overburden(data, "section", force_N_per_m=overburden_n_per_m, eccentricity_m=overburden_eccentricity_m)
