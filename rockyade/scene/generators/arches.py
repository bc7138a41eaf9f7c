"""Semicircular and pointed arches of n voussoirs on two piers.

The arch's intrados springs at x = -span/2 and x = +span/2 from the tops of two piers
(``pier_height_m`` tall, ``pier_width_m`` wide, inner faces flush with the intrados; with
``pier_height_m = 0`` the arch springs from the base). The left half of the ring is an arc
of radius R_i (intrados) to R_e = R_i + ``ring_depth_m`` (extrados) about a centre at
x = +e on the springing line, the right half its mirror image: e = 0 gives a semicircular
arch (R_i = span/2); a pointed arch has e = ``centre_offset_m`` > 0 (R_i = span/2 + e;
e = span/2 is the equilateral Gothic arch).

Each half's angle from the springing to the crown is divided equally among n/2 voussoirs;
the joints are radial (to the half's centre), and with an even n the crown joint is the
vertical line x = 0, with an odd n a keystone spans the crown. A voussoir is the convex
quadrilateral of its two joint faces: straight chords between the intrados points and
between the extrados points (a polygonal arch inscribed in the circular one).

Each voussoir is written as ``vertices_m`` in its own frame (the intrados chord on y = 0,
the frame origin at the chord's midpoint), placed by ``position_m`` and turned by
``rotation_rad`` (the chord's inclination): the scene format needs a flat base in the
block's frame. Neighbouring voussoirs are computed from the same joint points, so their
faces coincide to rounding (< 1e-15 m).

``piers = "fixed"`` makes the piers fixed abutments (they move with the base).

Block names: ``pier_left``, ``pier_right``, voussoirs ``v01`` ... from left to right.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from fractions import Fraction
from typing import Any

import numpy as np

from rockyade.errors import InputError
from rockyade.scene.generator_options import check, defaults, param
from rockyade.scene.generators.scene_tables import (
    BlockTable,
    digits,
    exact,
    num,
    polygon_block,
    rect_block,
    scene_table,
    udec_contact,
)

SHAPES = param("arch", "shape").choices
PIERS = param("arch", "piers").choices
#: The defaults (the generators' table).
ARCH = defaults("arch")

Point = tuple[float, float]


def _on_arc(centre_x: float, centre_y: float, radius: float, angle: float) -> Point:
    return (centre_x + radius * math.cos(angle), centre_y + radius * math.sin(angle))


def voussoir_quads(span: float, ring_depth: float, voussoirs: int, offset: float, spring_y: float) -> list[list[Point]]:
    """Counter-clockwise quadrilaterals (intrados start, intrados end, extrados end, extrados
    start) of the voussoirs from left to right, base frame, m (module docstring)."""
    r_i = span / 2 + offset
    r_e = r_i + ring_depth
    cx = offset  # centre of the left half's arcs
    apex_i = (0.0, spring_y + math.sqrt(r_i * r_i - offset * offset))
    apex_e = (0.0, spring_y + math.sqrt(r_e * r_e - offset * offset))
    crown_angle = math.pi - math.acos(offset / r_i)
    step = (math.pi - crown_angle) / (voussoirs / 2)
    joints_i: list[Point] = []
    joints_e: list[Point] = []
    for j in range(voussoirs // 2 + 1):
        if 2 * j == voussoirs:  # even count: the crown joint is vertical
            joints_i.append(apex_i)
            joints_e.append(apex_e)
        else:
            angle = math.pi - j * step
            joints_i.append(_on_arc(cx, spring_y, r_i, angle))
            joints_e.append(_on_arc(cx, spring_y, r_e, angle))
    joints_i[0] = (-span / 2, spring_y)
    joints_e[0] = (-span / 2 - ring_depth, spring_y)
    left = [[joints_i[j], joints_i[j + 1], joints_e[j + 1], joints_e[j]] for j in range(voussoirs // 2)]

    def mirror(quad: list[Point]) -> list[Point]:
        a, b, c, d = ((-x, y) for x, y in quad)
        return [b, a, d, c]  # mirrored order is clockwise: reverse along each chord

    middle = []
    if voussoirs % 2 == 1:
        k = voussoirs // 2
        (xi, yi), (xe, ye) = joints_i[k], joints_e[k]
        middle = [[(xi, yi), (-xi, yi), (-xe, ye), (xe, ye)]]
    return left + middle + [mirror(q) for q in reversed(left)]


def frame_of(quad: list[Point]) -> tuple[list[Point], Point, float]:
    """(vertices in the block frame, position, rotation) of a quadrilateral whose first edge
    becomes the block's base on y = 0, centred on the frame origin."""
    pts = np.array(quad, dtype=float)
    edge = pts[1] - pts[0]
    angle = math.atan2(edge[1], edge[0])
    origin = 0.5 * (pts[0] + pts[1])
    c, s = math.cos(angle), math.sin(angle)
    local = (pts - origin) @ np.array([[c, -s], [s, c]])  # rotate by -angle
    half = 0.5 * math.hypot(edge[0], edge[1])
    verts = [(-half, 0.0), (half, 0.0), *((float(x), float(y)) for x, y in local[2:])]
    return verts, (float(origin[0]), float(origin[1])), angle


def arch(
    span_m: float = ARCH.span_m,
    ring_depth_m: float = ARCH.ring_depth_m,
    thickness_m: float = ARCH.thickness_m,
    voussoirs: int = ARCH.voussoirs,
    shape: str = ARCH.shape,
    centre_offset_m: float | None = ARCH.centre_offset_m,
    pier_width_m: float = ARCH.pier_width_m,
    pier_height_m: float = ARCH.pier_height_m,
    piers: str = ARCH.piers,
    density_kg_m3: float = ARCH.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = ARCH.duration_s,
    sample_dt_s: float = ARCH.sample_dt_s,
) -> dict[str, Any]:
    """An arch of ``voussoirs`` voussoirs on two piers as a scene dictionary (module docstring).

    Parameters
    ----------
    span_m
        Clear span between the springings (intrados), m.
    ring_depth_m
        Depth of the ring, extrados radius minus intrados radius, m.
    thickness_m
        Out-of-plane thickness of every block, m.
    voussoirs
        Number of voussoirs (2 to 201).
    shape
        "semicircular" or "pointed".
    centre_offset_m
        Pointed arches: distance of each half's centre from the midspan, m (default
        span/2, the equilateral arch).
    pier_width_m, pier_height_m
        Pier size, m; ``pier_height_m = 0`` for no piers.
    piers
        "blocks" (free) or "fixed" (abutments that move with the base).
    density_kg_m3, motion, contact, duration_s, sample_dt_s
        As for the other generators; the default contact is UDEC-style
        (:func:`~rockyade.scene.generators.scene_tables.udec_contact` with the ring depth).

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    span = check("arch", "span_m", span_m)
    depth = check("arch", "ring_depth_m", ring_depth_m)
    t = check("arch", "thickness_m", thickness_m)
    n = check("arch", "voussoirs", voussoirs)
    shape = check("arch", "shape", shape)
    if shape == "semicircular":
        if centre_offset_m not in (None, 0, 0.0):
            raise InputError("centre_offset_m", 'applies to shape = "pointed" only')
        offset = 0.0
    else:
        offset = span / 2 if centre_offset_m is None else check("arch", "centre_offset_m", centre_offset_m)
    pw = exact(check("arch", "pier_width_m", pier_width_m))
    ph = exact(check("arch", "pier_height_m", pier_height_m))
    piers = check("arch", "piers", piers)
    density = check("arch", "density_kg_m3", density_kg_m3)
    if piers == "fixed" and ph == 0:
        raise InputError("piers", '"fixed" needs piers: give pier_height_m > 0')
    blocks: list[BlockTable] = []
    if ph > 0:
        half = exact(span) / 2
        fixed = piers == "fixed"
        blocks.append(rect_block("pier_left", pw, ph, -half - pw / 2, Fraction(0), t, density, fixed=fixed))
        blocks.append(rect_block("pier_right", pw, ph, half + pw / 2, Fraction(0), t, density, fixed=fixed))
    width_n = digits(n)
    for k, quad in enumerate(voussoir_quads(span, depth, n, offset, num(ph)), start=1):
        verts, position, rotation = frame_of(quad)
        blocks.append(polygon_block(f"v{k:0{width_n}d}", verts, position, rotation, t, density))
    contact_table = contact if contact is not None else udec_contact(depth, density)
    return scene_table(blocks, contact=contact_table, motion=motion, duration_s=duration_s, sample_dt_s=sample_dt_s)
