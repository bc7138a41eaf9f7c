"""Dry masonry walls (in-plane section): running or stack bond, with rectangular openings.

The wall stands on the base from x = 0 to x = units_per_course x unit_length; course c
(1 at the bottom) spans y = (c - 1) h to c h. In running bond every second course (2, 4,
...) starts and ends with a half unit, so its head joints sit half a unit from those of the
courses above and below; in stack bond every course is the same.

Openings (doors, windows) are rectangles x, y, width, height in metres (x from the wall's
left end, y from the base). Every unit is cut by every opening: what is left of a unit is
cut into rectangles (left and right of the opening over the unit's full height, and the
parts below and above the opening in between), so the opening is exactly empty. Pieces
narrower or lower than ``min_piece_m`` are left out (the void grows by that sliver).

Above an opening that does not reach the wall's top, ``lintel = "block"`` places one lintel
block of height ``lintel_height_m`` resting on the opening's top edge and bearing
``lintel_bearing_m`` on the masonry either side; the units it takes the place of are cut the
same way. With ``lintel = "none"`` the units above an opening rest on their neighbours
where the bond laps them over the jambs, and the others stand on nothing: they fall at the
start of a run (a dry wall without a lintel).

Block names: ``c03_u07`` (course 3, unit 7, counted from the left after the cuts),
``lintel1`` (above opening 1).
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from rockyade.errors import InputError
from rockyade.scene.generator_options import check, defaults, param
from rockyade.scene.generators.scene_tables import (
    BlockTable,
    check_length,
    digits,
    exact,
    rect_block,
    scene_table,
    udec_contact,
)

BONDS = param("wall", "bond").choices
LINTELS = param("wall", "lintel").choices
MAX_WALL_BLOCKS = 100_000
#: The defaults (the generators' table).
WALL = defaults("wall")

#: A rectangle (x0, x1, y0, y1), m, exact.
Rect = tuple[Fraction, Fraction, Fraction, Fraction]


@dataclass(frozen=True)
class Opening:
    """A rectangular opening: lower-left corner (x_m from the wall's left end, y_m from the
    base), width and height, m."""

    x_m: float
    y_m: float
    width_m: float
    height_m: float

    @classmethod
    def of(cls, value: Opening | Sequence[float] | Mapping[str, float], name: str) -> Opening:
        """An Opening from an Opening, an (x, y, width, height) sequence or a mapping."""
        if isinstance(value, Opening):
            return value
        if isinstance(value, Mapping):
            try:
                return cls(value["x_m"], value["y_m"], value["width_m"], value["height_m"])
            except KeyError as exc:
                raise InputError(name, f"needs x_m, y_m, width_m and height_m (missing {exc})") from None
        if isinstance(value, str) or len(value) != 4:
            raise InputError(name, f"must be x, y, width, height in metres, got {value!r}")
        return cls(*value)


def _overlap(a: Rect, b: Rect) -> bool:
    """True when two rectangles share a positive area."""
    return a[0] < b[1] and b[0] < a[1] and a[2] < b[3] and b[2] < a[3]


def subtract(r: Rect, o: Rect) -> list[Rect]:
    """``r`` minus ``o`` as at most four rectangles: left, right (full height), below, above."""
    if not _overlap(r, o):
        return [r]
    x0, x1, y0, y1 = r
    out: list[Rect] = []
    if o[0] > x0:
        out.append((x0, o[0], y0, y1))
    if o[1] < x1:
        out.append((o[1], x1, y0, y1))
    mx0, mx1 = max(x0, o[0]), min(x1, o[1])
    if o[2] > y0:
        out.append((mx0, mx1, y0, o[2]))
    if o[3] < y1:
        out.append((mx0, mx1, o[3], y1))
    return out


def course_units(course: int, units: int, length: Fraction, bond: str) -> list[tuple[Fraction, Fraction]]:
    """x intervals of the units of course ``course`` (0 at the bottom), m."""
    if bond == "running" and course % 2 == 1:
        half = length / 2
        edges = [Fraction(0), *(half + k * length for k in range(units)), units * length]
    else:
        edges = [k * length for k in range(units + 1)]
    return list(itertools.pairwise(edges))


def _exact_openings(openings: Sequence[Any], wall_length: Fraction, wall_height: Fraction) -> list[Rect]:
    rects: list[Rect] = []
    for k, raw in enumerate(openings):
        name = f"openings[{k}]"
        o = Opening.of(raw, name)
        x, y = (
            exact(check_length(f"{name}.x_m", o.x_m, zero_ok=True)),
            exact(check_length(f"{name}.y_m", o.y_m, zero_ok=True)),
        )
        w, h = exact(check_length(f"{name}.width_m", o.width_m)), exact(check_length(f"{name}.height_m", o.height_m))
        if x + w > wall_length:
            raise InputError(
                f"{name}.width_m",
                f"x + width = {float(x + w):g} m passes the wall's right end ({float(wall_length):g} m)",
            )
        if y + h > wall_height:
            raise InputError(
                f"{name}.height_m", f"y + height = {float(y + h):g} m passes the wall's top ({float(wall_height):g} m)"
            )
        rect = (x, x + w, y, y + h)
        for j, other in enumerate(rects):
            if _overlap(rect, other):
                raise InputError(name, f"overlaps opening #{j + 1} (openings[{j}])")
        rects.append(rect)
    return rects


def _lintels(
    openings: list[Rect],
    wall_length: Fraction,
    wall_height: Fraction,
    height: Fraction,
    bearing: Fraction,
    min_piece: Fraction,
) -> list[tuple[int, Rect]]:
    """(opening index, rectangle) of each lintel block."""
    out: list[tuple[int, Rect]] = []
    for k, (x0, x1, _, y1) in enumerate(openings):
        top = min(wall_height, y1 + height)
        if top - y1 < min_piece:
            continue  # the opening reaches (nearly) the wall's top: nothing to carry
        rect = (max(Fraction(0), x0 - bearing), min(wall_length, x1 + bearing), y1, top)
        for j, other in enumerate(openings):
            if _overlap(rect, other):
                raise InputError(
                    f"openings[{k}]",
                    f"its lintel ({float(rect[0]):g}-{float(rect[1]):g} m, y {float(y1):g}-{float(top):g} m) "
                    f"overlaps opening #{j + 1}: move the openings apart or reduce lintel_bearing_m / lintel_height_m",
                )
        for j, other in out:
            if _overlap(rect, other):
                raise InputError(f"openings[{k}]", f"its lintel overlaps the lintel of opening #{j + 1}")
        out.append((k, rect))
    return out


def wall_pieces(
    courses: int,
    units_per_course: int,
    unit_length: Fraction,
    unit_height: Fraction,
    bond: str,
    obstacles: Sequence[Rect],
    min_piece: Fraction,
) -> list[tuple[int, Rect]]:
    """(course index, rectangle) of every unit piece left after cutting out ``obstacles``."""
    pieces: list[tuple[int, Rect]] = []
    for c in range(courses):
        y0, y1 = c * unit_height, (c + 1) * unit_height
        for x0, x1 in course_units(c, units_per_course, unit_length, bond):
            parts: list[Rect] = [(x0, x1, y0, y1)]
            for o in obstacles:
                parts = [p for part in parts for p in subtract(part, o)]
            pieces.extend((c, p) for p in parts if p[1] - p[0] >= min_piece and p[3] - p[2] >= min_piece)
    return pieces


def wall(
    courses: int = WALL.courses,
    units_per_course: int = WALL.units_per_course,
    unit_length_m: float = WALL.unit_length_m,
    unit_height_m: float = WALL.unit_height_m,
    unit_thickness_m: float = WALL.unit_thickness_m,
    bond: str = WALL.bond,
    openings: Sequence[Opening | Sequence[float] | Mapping[str, float]] = (),
    lintel: str = WALL.lintel,
    lintel_height_m: float | None = WALL.lintel_height_m,
    lintel_bearing_m: float | None = WALL.lintel_bearing_m,
    min_piece_m: float | None = WALL.min_piece_m,
    density_kg_m3: float = WALL.density_kg_m3,
    motion: Mapping[str, Any] | None = None,
    contact: Mapping[str, Any] | None = None,
    duration_s: float | None = WALL.duration_s,
    sample_dt_s: float = WALL.sample_dt_s,
) -> dict[str, Any]:
    """A dry masonry wall in running or stack bond, as a scene dictionary (module docstring).

    Parameters
    ----------
    courses, units_per_course
        Number of courses and of whole units per course.
    unit_length_m, unit_height_m, unit_thickness_m
        Unit size: along the wall, vertical, and out of plane (the blocks' thickness), m.
    bond
        "running" (half units at both ends of courses 2, 4, ...) or "stack".
    openings
        Rectangles (x, y, width, height), m, or :class:`Opening` records.
    lintel
        "block" (a lintel block over each opening) or "none".
    lintel_height_m, lintel_bearing_m
        Lintel height (default one unit height) and bearing each side (default half a unit), m.
    min_piece_m
        Cut pieces smaller than this in width or height are left out (default a quarter of
        the smaller unit dimension), m.
    density_kg_m3
        Density of units and lintels, kg/m^3.
    motion, contact
        The ``[motion]`` and ``[contact]`` tables (default: a one-sine pulse; UDEC-style
        joints, :func:`~rockyade.scene.generators.scene_tables.udec_contact`).
    duration_s, sample_dt_s
        Simulated time and output interval, s. The default time is a record's length plus
        :data:`~rockyade.motion.coverage.RECORD_TAIL_S` of free rocking for a ``record`` or
        ``synthetic`` motion (:func:`~rockyade.scene.generators.scene_tables.default_duration_s`),
        else 3 s.

    Returns
    -------
    dict
        The scene, ready for :func:`rockyade.scene.scene_from_dict` or
        :func:`rockyade.scene.toml_writer.write_toml`.

    Every argument is checked against its range in the generators' table
    (:mod:`rockyade.scene.generator_options`).
    """
    courses = check("wall", "courses", courses)
    units_per_course = check("wall", "units_per_course", units_per_course)
    if courses * units_per_course > MAX_WALL_BLOCKS:
        raise InputError("units_per_course", f"courses x units_per_course must be at most {MAX_WALL_BLOCKS}")
    length = exact(check("wall", "unit_length_m", unit_length_m))
    height = exact(check("wall", "unit_height_m", unit_height_m))
    thickness = check("wall", "unit_thickness_m", unit_thickness_m)
    bond = check("wall", "bond", bond)
    lintel = check("wall", "lintel", lintel)
    density = check("wall", "density_kg_m3", density_kg_m3)
    wall_length, wall_height = units_per_course * length, courses * height
    piece = check("wall", "min_piece_m", min_piece_m)  # None for these three: the defaults below
    lintel_h = check("wall", "lintel_height_m", lintel_height_m)
    bearing = check("wall", "lintel_bearing_m", lintel_bearing_m)
    min_piece = min(length, height) / 4 if piece is None else exact(piece)
    holes = _exact_openings(openings, wall_length, wall_height)
    lintels: list[tuple[int, Rect]] = []
    if lintel == "block" and holes:
        lh = height if lintel_h is None else exact(lintel_h)
        lb = length / 2 if bearing is None else exact(bearing)
        lintels = _lintels(holes, wall_length, wall_height, lh, lb, min_piece)
    pieces = wall_pieces(courses, units_per_course, length, height, bond, holes + [r for _, r in lintels], min_piece)
    if not pieces and not lintels:
        raise InputError("openings", "leave no masonry: every unit is cut away")
    width_c = digits(courses)
    blocks: list[BlockTable] = []
    for c in range(courses):
        row = sorted((r for k, r in pieces if k == c), key=lambda r: (r[0], r[2]))
        width_u = digits(len(row))
        for u, (x0, x1, y0, y1) in enumerate(row, start=1):
            name = f"c{c + 1:0{width_c}d}_u{u:0{width_u}d}"
            blocks.append(rect_block(name, x1 - x0, y1 - y0, (x0 + x1) / 2, y0, thickness, density))
    for k, (x0, x1, y0, y1) in lintels:
        blocks.append(rect_block(f"lintel{k + 1}", x1 - x0, y1 - y0, (x0 + x1) / 2, y0, thickness, density))
    contact_table = contact if contact is not None else udec_contact(float(height), density)
    return scene_table(blocks, contact=contact_table, motion=motion, duration_s=duration_s, sample_dt_s=sample_dt_s)
