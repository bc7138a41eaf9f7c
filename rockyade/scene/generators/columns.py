"""Columns: multi-drum columns (with an optional capital) and stacks of blocks of given sizes.

Both are centred on x = 0 and can be written as an assembly (every block placed by
``position_m``) or as a column scene (blocks listed bottom to top, no positions: the form
the Housner solver reads for one or two blocks). The blocks are the same either way.

Block names: drums ``d01`` ... from the bottom and ``capital``; stack blocks ``b01`` ....

Drums are round by default: the scene's blocks are plane sections, so a round drum is drawn
and rocks on the rectangle of its section through the axis (diameter D x height h), and
the generator writes the cylinder's own mass and centroidal inertia for rocking in that
plane (``mass_kg``, ``inertia_kgm2``: :func:`round_drum_mass_inertia`), which Housner's
solver (alpha, p and mu from them) and both DEMs (the bodies' mass and inertia, the joints
calibrated from them) read. A square prism of the same section is 4/pi = 1.27 times heavier.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generator_options import MAX_STACK_BLOCKS, STACK_WIDTHS_M, check, defaults, param
from rockyade.scene.generators.scene_tables import (
    BlockTable,
    Outline,
    block_table,
    check_count,
    digits,
    exact,
    num,
    rect_block,
    scene_table,
)

LAYOUTS = param("stack", "layout").choices
TAPERS = param("stack", "taper").choices
SECTIONS = param("column", "section").choices
#: The defaults (the generators' table).
STACK = defaults("stack")
COLUMN = defaults("column")


def _block(
    name: str,
    bottom_width: Fraction,
    top_width: Fraction,
    height: Fraction,
    y: Fraction,
    thickness: float,
    density: float,
    layout: str,
) -> BlockTable:
    """A rectangle (equal widths) or a symmetric trapezoid, base centre at (0, y)."""
    if bottom_width == top_width:
        table = rect_block(name, bottom_width, height, Fraction(0), y, thickness, density)
    else:
        b, t = bottom_width / 2, top_width / 2
        outline: Outline = {
            "vertices_m": [[num(-b), 0.0], [num(b), 0.0], [num(t), num(height)], [num(-t), num(height)]]
        }
        table = block_table(name, outline, (Fraction(0), y), thickness, density)
    if layout == "column":
        del table["position_m"]
    return table


def tapered_widths(
    blocks: int, bottom_width_m: float, top_width_m: float, taper: str = STACK.taper
) -> tuple[list[float], float | None]:
    """Widths for a linearly tapered :func:`stack` of ``blocks`` blocks, m.

    Returns
    -------
    (widths_m, top_width_m)
        "steps": the blocks' widths from ``bottom_width_m`` (bottom block) to ``top_width_m``
        (top block), and None. "continuous": the blocks' bottom widths and the top block's
        top width ``top_width_m``: straight sides from the bottom to the top of the stack.
    """
    n = check("stack", "blocks", blocks)
    lo = exact(check("stack", "bottom_width_m", bottom_width_m))
    hi = exact(check("stack", "top_width_m", top_width_m))
    taper = check("stack", "taper", taper)
    if taper == "continuous":
        return [num(lo + (hi - lo) * k / n) for k in range(n)], num(hi)
    if n == 1:
        return [num(lo)], None
    return [num(lo + (hi - lo) * k / (n - 1)) for k in range(n)], None


def stack(
    widths_m: Sequence[float] = STACK_WIDTHS_M,
    heights_m: Sequence[float] | float = STACK.heights_m[0],
    thickness_m: float = STACK.thickness_m,
    taper: str = STACK.taper,
    top_width_m: float | None = STACK.top_width_m,
    layout: str = STACK.layout,
    density_kg_m3: float = STACK.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = STACK.duration_s,
    sample_dt_s: float = STACK.sample_dt_s,
) -> dict[str, Any]:
    """A stack of blocks of given sizes, bottom to top, centred on x = 0.

    Parameters
    ----------
    widths_m
        Width of each block, bottom first, m (:func:`tapered_widths` makes a linear taper);
        with ``taper = "continuous"`` the width of each block's bottom.
    heights_m
        Height of each block, m, or one height for all.
    thickness_m
        Out-of-plane thickness, m.
    taper
        "steps": rectangles (each block as wide as given); "continuous": trapezoids whose
        bottom is the block's width and top the next block's width (``top_width_m`` for the
        top block, default its own width), so the sides are straight lines.
    layout
        "positioned" (an assembly) or "column" (a column scene).
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for :func:`~rockyade.scene.generators.walls.wall`; the default contact is the
        paper's calibration (slender blocks).

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    if isinstance(widths_m, str) or not isinstance(widths_m, Sequence) or not widths_m:
        raise InputError("widths_m", "must be a non-empty list of widths in metres")
    n = check_count("widths_m (number of blocks)", len(widths_m), 1, MAX_STACK_BLOCKS)
    widths = [exact(w) for w in check("stack", "widths_m", list(widths_m))]
    if isinstance(heights_m, (int, float)):
        heights = [exact(check("stack", "heights_m", heights_m))] * n
    else:
        if len(heights_m) != n:
            raise InputError("heights_m", f"needs one height per block ({n}) or a single height, got {len(heights_m)}")
        heights = [exact(h) for h in check("stack", "heights_m", list(heights_m))]
    thickness = check("stack", "thickness_m", thickness_m)
    taper = check("stack", "taper", taper)
    layout = check("stack", "layout", layout)
    density = check("stack", "density_kg_m3", density_kg_m3)
    if taper == "steps" and top_width_m is not None:
        raise InputError("top_width_m", 'applies to taper = "continuous" only')
    last = widths[-1] if top_width_m is None else exact(check("stack", "top_width_m", top_width_m))
    tops = widths if taper == "steps" else [*widths[1:], last]
    blocks = []
    y = Fraction(0)
    width_n = digits(n)
    for i in range(n):
        blocks.append(_block(f"b{i + 1:0{width_n}d}", widths[i], tops[i], heights[i], y, thickness, density, layout))
        y += heights[i]
    return scene_table(blocks, contact=contact, motion=motion, duration_s=duration_s, sample_dt_s=sample_dt_s)


def round_drum_mass_inertia(diameter_m: float, height_m: float, density_kg_m3: float) -> tuple[float, float]:
    """Mass (kg) and centroidal inertia (kg m^2) of a solid cylinder with a vertical axis,
    about a horizontal axis through its centroid (rocking in a plane through the axis).

    m = rho pi D^2 / 4 h and I = m (3 r^2 + h^2) / 12, r = D / 2 (a solid cylinder about a
    diameter of its mid-section: e.g. Gere & Goodno, Mechanics of Materials, Appendix E).

    Parameters
    ----------
    diameter_m
        Drum diameter D, m.
    height_m
        Drum height h, m.
    density_kg_m3
        Density rho, kg/m^3.
    """
    r = 0.5 * diameter_m
    mass = density_kg_m3 * math.pi * r * r * height_m
    return mass, mass * (3.0 * r * r + height_m * height_m) / 12.0


def column(
    drums: int = COLUMN.drums,
    diameter_m: float = COLUMN.diameter_m,
    drum_height_m: float = COLUMN.drum_height_m,
    thickness_m: float | None = COLUMN.thickness_m,
    capital_width_m: float | None = COLUMN.capital_width_m,
    capital_height_m: float | None = COLUMN.capital_height_m,
    section: str = COLUMN.section,
    layout: str = COLUMN.layout,
    density_kg_m3: float = COLUMN.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = COLUMN.duration_s,
    sample_dt_s: float = COLUMN.sample_dt_s,
) -> dict[str, Any]:
    """A column of ``drums`` equal drums, optionally under a capital (abacus) block.

    Parameters
    ----------
    drums
        Number of drums.
    diameter_m
        Drum width in the plane of rocking (the diameter of a round drum), m.
    drum_height_m
        Height of each drum, m.
    thickness_m
        Out-of-plane thickness, m (default: the diameter): the contact width the joints
        take (and a square drum's depth).
    capital_width_m, capital_height_m
        Give both for a capital block on top (an abacus: a slab wider than the drums).
    section
        "round" (default): cylinders, each drum with the mass and inertia of
        :func:`round_drum_mass_inertia`; "square": prisms ``diameter_m`` x ``thickness_m``
        of ``density_kg_m3``. The capital is a square slab either way.
    layout, density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for :func:`stack`.

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    n = check("column", "drums", drums)
    d = exact(check("column", "diameter_m", diameter_m))
    h = exact(check("column", "drum_height_m", drum_height_m))
    t = num(d) if thickness_m is None else check("column", "thickness_m", thickness_m)
    layout = check("column", "layout", layout)
    section = check("column", "section", section)
    density = check("column", "density_kg_m3", density_kg_m3)
    capital_width_m = check("column", "capital_width_m", capital_width_m)
    capital_height_m = check("column", "capital_height_m", capital_height_m)
    if (capital_width_m is None) != (capital_height_m is None):
        missing = "capital_height_m" if capital_height_m is None else "capital_width_m"
        raise InputError(missing, "give both capital_width_m and capital_height_m for a capital, or neither")
    width_n = digits(n)
    blocks = [_block(f"d{i + 1:0{width_n}d}", d, d, h, i * h, t, density, layout) for i in range(n)]
    if section == "round":
        mass, inertia = round_drum_mass_inertia(num(d), num(h), density)
        for table in blocks:
            del table["density_kg_m3"]
            table["mass_kg"] = mass
            table["inertia_kgm2"] = inertia
    if capital_width_m is not None and capital_height_m is not None:
        cw, ch = exact(capital_width_m), exact(capital_height_m)
        blocks.append(_block("capital", cw, cw, ch, n * h, t, density, layout))
    return scene_table(blocks, contact=contact, motion=motion, duration_s=duration_s, sample_dt_s=sample_dt_s)


#: The former name of :func:`column` (kept: scripts call it).
drum_column = column
