"""A wall restrained at its top, in its out-of-plane section (the paper's Fig. 2).

The section through the wall's thickness: a wall of ``wall_thickness_m`` x ``wall_height_m``
standing on the base, centred on x = 0, as one block or two (split at ``split`` of its
height: the two-block model of the paper's Fig. 2c, a hinge forming between them), and a
fixed block (it moves with the base) that restrains the top:

* ``restraint = "side"``: a block against the wall's far face (x > 0) at the top, e.g. a
  transverse wall or a floor's edge beam, ``restraint_width_m`` x ``restraint_height_m``,
  its top level with the wall's; the wall's top cannot move towards it;
* ``restraint = "floor"``: a floor slab resting on the wall's top, from the wall's near
  face (x < 0) to ``restraint_width_m`` past the far face, ``restraint_height_m`` deep. A
  fixed floor bearing on the wall stops it from rising, hence from rocking, unless a gap is
  left.

``gap_m`` leaves a gap between the wall and the restraint (horizontal for "side", vertical
for "floor"); a gap the wall cannot close before it overturns (the wall's thickness for "side",
sqrt(t^2 + H^2) - H for "floor") is refused. The wall's length along its plane is the blocks' ``thickness_m``
(``wall_length_m``).

``restraint_friction_deg`` sets the friction of the joints between the wall and the
restraint (a ``[[joints]]`` entry; default 0, as :func:`~rockyade.scene.generators.wall_section`'s;
None: the scene's). A restraint that holds the wall by friction locks the two-block wall: its
upper block must slide up the restraint for the three-hinge mechanism of Fig. 2 to form, which a
frictionless (or rolling) restraint allows (see docs/assemblies.md for the mechanism's
multiplier). :func:`~rockyade.scene.generators.wall_section` builds the same section in courses.

Block names: ``wall`` (or ``wall_lower``, ``wall_upper``) and ``restraint`` or ``floor``.
"""

from __future__ import annotations

import math
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

RESTRAINTS = ("side", "floor")


def restrained_wall(
    wall_height_m: float = 3.0,
    wall_thickness_m: float = 0.3,
    wall_length_m: float = 1.0,
    blocks: int = 2,
    split: float = 0.5,
    restraint: str = "side",
    restraint_width_m: float = 0.3,
    restraint_height_m: float = 0.3,
    gap_m: float = 0.0,
    restraint_friction_deg: float | None = 0.0,
    density_kg_m3: float = DEFAULT_DENSITY_KG_M3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = None,
    sample_dt_s: float = DEFAULT_SAMPLE_DT_S,
) -> dict[str, Any]:
    """A wall restrained at the top as a scene dictionary (module docstring).

    Parameters
    ----------
    wall_height_m, wall_thickness_m
        Height and thickness of the wall (the section's width), m.
    wall_length_m
        Length of the wall along its plane: the blocks' out-of-plane thickness, m.
    blocks
        1 or 2 wall blocks.
    split
        Height of the lower block as a fraction of the wall's height (two blocks), in (0, 1).
    restraint
        "side" or "floor" (module docstring).
    restraint_width_m, restraint_height_m
        Size of the restraining block, m ("floor": its reach past the far face and depth).
    gap_m
        Gap between the wall and the restraint, m.
    restraint_friction_deg
        Friction angle of the wall-restraint joints, degrees in [0, 90) (default 0; None: the scene's).
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for the other generators; the default contact is the paper's calibration
        (slender wall blocks).
    """
    H = exact(check_length("wall_height_m", wall_height_m))
    T = exact(check_length("wall_thickness_m", wall_thickness_m))
    length = check_length("wall_length_m", wall_length_m)
    n = check_count("blocks", blocks, 1, 2)
    ratio = exact(check_number("split", split, 0.0, 1.0, lo_open=True, hi_open=True))
    kind = check_choice("restraint", restraint, RESTRAINTS)
    rw = exact(check_length("restraint_width_m", restraint_width_m))
    rh = exact(check_length("restraint_height_m", restraint_height_m))
    gap = exact(check_length("gap_m", gap_m, zero_ok=True))
    density = check_density("density_kg_m3", density_kg_m3)
    if restraint_friction_deg is not None:
        check_number("restraint_friction_deg", restraint_friction_deg, 0.0, 90.0, hi_open=True)
    zero = Fraction(0)
    if n == 1:
        wall_blocks = [rect_block("wall", T, H, zero, zero, length, density)]
    else:
        lower = H * ratio
        wall_blocks = [
            rect_block("wall_lower", T, lower, zero, zero, length, density),
            rect_block("wall_upper", T, H - lower, zero, lower, length, density),
        ]
    # a gap the wall cannot close before it overturns (turning about its toe, its centroid over the toe
    # when its top has moved by its thickness and its top corner has risen by sqrt(t^2 + H^2) - H)
    reach = float(T) if kind == "side" else math.hypot(float(T), float(H)) - float(H)
    if float(gap) >= reach:
        raise InputError(
            "gap_m",
            f"must be < {reach:.4g} m with restraint = {kind!r}: the wall overturns (its top moved "
            f"{'by its thickness' if kind == 'side' else 'up by sqrt(t^2 + H^2) - H'}) before a gap of "
            f"{float(gap):g} m closes",
        )
    if kind == "side":
        if rh > H:
            raise InputError(
                "restraint_height_m", f"must be <= wall_height_m ({float(H):g} m): it stands beside the wall"
            )
        x = T / 2 + gap + rw / 2
        fixed = rect_block("restraint", rw, rh, x, H - rh, length, density, fixed=True)
    else:
        slab = T + rw
        fixed = rect_block("floor", slab, rh, -T / 2 + slab / 2, H + gap, length, density, fixed=True)
    joints = None
    if restraint_friction_deg is not None:
        # the top block touches the restraint at rest (side: its far face; floor: its top)
        pair = [wall_blocks[-1]["name"], fixed["name"]]
        joints = [{"blocks": pair, "friction_angle_deg": float(restraint_friction_deg)}]
    return scene_table(
        [*wall_blocks, fixed],
        contact=contact if contact is not None else paper_contact(),
        motion=motion,
        duration_s=duration_s,
        sample_dt_s=sample_dt_s,
        joints=joints,
    )
