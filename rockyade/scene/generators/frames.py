"""The rocking frame of Makris & Vassiliou (2013): two equal free-standing columns and a free
cap beam resting on them.

The columns (width 2b, height 2h) stand on the base with their axes ``span_m`` apart,
centred on x = 0; the beam rests on both column tops and reaches ``beam_overhang_m`` past
the columns' outer faces. Makris & Vassiliou show that the frame rocks like one column of
the same slenderness with frequency p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)), gamma =
beam mass / mass of both columns (Makris, N. and Vassiliou, M. F., 2013, "Planar rocking
response and stability analysis of an array of free-standing columns capped with a freely
supported rigid beam", Earthquake Engineering & Structural Dynamics 42(3), 431-449).

Block names: ``column_left``, ``column_right``, ``beam``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

from rockyade.blocks.classical import p_rectangle
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.scene.generator_options import check, defaults
from rockyade.scene.generators.scene_tables import (
    check_density,
    exact,
    num,
    rect_block,
    scene_table,
)

#: The defaults (the generators' table).
FRAME = defaults("frame")


def frame_gamma(scene: Mapping[str, Any]) -> float:
    """gamma = beam mass / mass of both columns of a frame scene made by :func:`frame`."""
    mass = {}
    for b in scene["blocks"]:
        mass[b["name"]] = b["density_kg_m3"] * b["width_m"] * b["height_m"] * b["thickness_m"]
    return mass["beam"] / (mass["column_left"] + mass["column_right"])


def frame_frequency(column_width_m: float, column_height_m: float, gamma: float, g: float = G) -> float:
    """p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)) of the frame, rad/s (Makris & Vassiliou
    2013), with p = sqrt(3 g / (4 R)) of a rectangular column (paper Eq 3), R = sqrt(b^2 + h^2)."""
    p = p_rectangle(0.5 * math.hypot(column_width_m, column_height_m), g)
    return p * math.sqrt((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma))


def frame(
    column_width_m: float = FRAME.column_width_m,
    column_height_m: float = FRAME.column_height_m,
    span_m: float = FRAME.span_m,
    beam_height_m: float = FRAME.beam_height_m,
    beam_overhang_m: float = FRAME.beam_overhang_m,
    thickness_m: float = FRAME.thickness_m,
    density_kg_m3: float = FRAME.density_kg_m3,
    beam_density_kg_m3: float | None = FRAME.beam_density_kg_m3,
    gamma: float | None = FRAME.gamma,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = FRAME.duration_s,
    sample_dt_s: float = FRAME.sample_dt_s,
) -> dict[str, Any]:
    """The Makris & Vassiliou (2013) rocking frame as a scene dictionary (module docstring).

    Parameters
    ----------
    column_width_m, column_height_m
        Column width 2b and height 2h, m.
    span_m
        Distance between the column axes, m (> column width: the columns do not touch).
    beam_height_m, beam_overhang_m
        Beam depth and how far it reaches past each column's outer face, m.
    thickness_m
        Out-of-plane thickness of every block, m.
    density_kg_m3
        Density of the columns, kg/m^3.
    beam_density_kg_m3
        Density of the beam (default: the columns'), kg/m^3.
    gamma
        Instead of a beam density: the mass ratio gamma = beam mass / both columns' mass.
    motion, contact, duration_s, sample_dt_s
        As for the other generators; the default contact is the paper's calibration.

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    bw = exact(check("frame", "column_width_m", column_width_m))
    bh = exact(check("frame", "column_height_m", column_height_m))
    span = exact(check("frame", "span_m", span_m))
    if span <= bw:
        raise InputError("span_m", f"must be > column_width_m ({num(bw):g} m): the columns would overlap")
    beam_h = exact(check("frame", "beam_height_m", beam_height_m))
    overhang = exact(check("frame", "beam_overhang_m", beam_overhang_m))
    t = check("frame", "thickness_m", thickness_m)
    density = check("frame", "density_kg_m3", density_kg_m3)
    ratio = check("frame", "gamma", gamma)
    beam_density_kg_m3 = check("frame", "beam_density_kg_m3", beam_density_kg_m3)
    beam_length = span + bw + 2 * overhang
    if ratio is not None:
        if beam_density_kg_m3 is not None:
            raise InputError("gamma", "give gamma or beam_density_kg_m3, not both")
        beam_density = check_density("gamma", ratio * 2 * density * num(bw * bh) / num(beam_length * beam_h))
    else:
        beam_density = density if beam_density_kg_m3 is None else beam_density_kg_m3
    half = span / 2
    blocks = [
        rect_block("column_left", bw, bh, -half, Fraction(0), t, density),
        rect_block("column_right", bw, bh, half, Fraction(0), t, density),
        rect_block("beam", beam_length, beam_h, Fraction(0), bh, t, beam_density),
    ]
    return scene_table(blocks, contact=contact, motion=motion, duration_s=duration_s, sample_dt_s=sample_dt_s)


#: The former name of :func:`frame` (kept: scripts call it).
rocking_frame = frame
