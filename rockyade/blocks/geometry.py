"""Rigid blocks: convex polygon cross-sections with a thickness, and their mass properties.

Conventions (SI): the cross-section lies in the x (horizontal) - y (vertical) plane; a
block's vertices are given in its own frame with the base on y = 0; they are stored
counter-clockwise. Rotational inertia is about the z axis.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rockyade.errors import InputError

#: Relative tolerance used to decide that vertices lie on the base (or top) line.
LEVEL_TOL = 1e-9
#: Most vertices a block's polygon may have (a half-circle of 10,000 vertices is within
#: 1e-8 of the true circle's area; the DEM's contact search grows with the vertex count).
MAX_POLYGON_VERTICES = 10_000
#: Simplification tolerance, relative to the block's size (the larger of its width and
#: height): a vertex is dropped only if it lies within this distance of the outline without
#: it, and only if the area changes by less than this fraction of itself and the centroid
#: moves by less than this times the size.
SIMPLIFY_TOL = 1e-9


@dataclass(frozen=True)
class PolygonSection:
    """Area properties of a polygon (per unit thickness and density).

    Attributes
    ----------
    area_m2
        Area, m^2.
    centroid_m
        Centroid (x, y), m.
    polar_second_moment_m4
        Polar second moment of area about the centroid, integral of r^2 dA, m^4.
    """

    area_m2: float
    centroid_m: tuple[float, float]
    polar_second_moment_m4: float


def _next(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.roll(a, -1, axis=0)`` (each row's successor, cyclically) without its overhead."""
    return np.concatenate((a[1:], a[:1]))


def _previous(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.roll(a, 1, axis=0)`` (each row's predecessor, cyclically) without its overhead."""
    return np.concatenate((a[-1:], a[:-1]))


def polygon_section(vertices: NDArray[np.float64]) -> PolygonSection:
    """Area, centroid and polar second moment of a simple polygon (Green's theorem).

    Parameters
    ----------
    vertices
        (n, 2) array of vertices, m, counter-clockwise.

    Returns
    -------
    PolygonSection
    """
    x = vertices[:, 0]
    y = vertices[:, 1]
    xn = _next(x)
    yn = _next(y)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    cx = ((x + xn) * cross).sum() / (6.0 * area)
    cy = ((y + yn) * cross).sum() / (6.0 * area)
    ixx_origin = ((y * y + y * yn + yn * yn) * cross).sum() / 12.0
    iyy_origin = ((x * x + x * xn + xn * xn) * cross).sum() / 12.0
    polar_centroid = ixx_origin + iyy_origin - area * (cx * cx + cy * cy)
    return PolygonSection(float(area), (float(cx), float(cy)), float(polar_centroid))


def _as_vertices(vertices: ArrayLike, field_name: str) -> NDArray[np.float64]:
    """Validate a vertex list and return it as a counter-clockwise (n, 2) float array.

    At most :data:`MAX_POLYGON_VERTICES` vertices. Vertices in the middle of an edge are
    dropped (:func:`simplify_polygon`): relative to the block's size, and never changing its
    area or centroid beyond :data:`SIMPLIFY_TOL`.
    """
    try:
        arr = np.asarray(vertices, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(field_name, f"must be a list of [x, y] pairs in metres ({exc})") from None
    if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] < 3:
        raise InputError(field_name, "must be a list of at least 3 [x, y] pairs in metres")
    if arr.shape[0] > MAX_POLYGON_VERTICES:
        raise InputError(
            field_name,
            f"has {arr.shape[0]} vertices, more than the {MAX_POLYGON_VERTICES} a block may have: "
            "sample its curved parts more coarsely",
        )
    if not np.all(np.isfinite(arr)):
        raise InputError(field_name, "contains NaN or infinite coordinates")
    scale = float(np.max(np.ptp(arr, axis=0)))
    if not scale > 0:
        raise InputError(field_name, "all vertices are the same point")
    area = polygon_section_area(arr / scale)  # the checks on a polygon of unit size: no underflow
    if abs(area) <= LEVEL_TOL:
        raise InputError(
            field_name,
            "the vertices enclose no area: they lie on one line, or the outline crosses itself so that "
            "its parts cancel (a bow tie): give the vertices in order around a convex polygon",
        )
    if area < 0:
        arr = arr[::-1].copy()
    unit = arr / scale
    edges = _next(unit) - unit
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    if np.any(lengths <= LEVEL_TOL):
        raise InputError(field_name, "has repeated (coincident) vertices")
    offset = _offsets(unit)
    prev = _previous(edges)
    turn = prev[:, 0] * edges[:, 1] - prev[:, 1] * edges[:, 0]  # at each vertex
    if np.any((turn < 0) & (offset > SIMPLIFY_TOL)):
        raise InputError(field_name, "polygon must be convex (vertices in order around it)")
    dot = prev[:, 0] * edges[:, 0] + prev[:, 1] * edges[:, 1]
    winding = float(np.arctan2(turn, dot).sum()) / (2.0 * np.pi)
    if winding > 1.5:
        raise InputError(
            field_name,
            f"the outline crosses itself (it winds {winding:.0f} times, e.g. a star): "
            "give the vertices in order around a convex polygon",
        )
    return arr[simplify_polygon(unit, offset)].copy()


def _offsets(unit: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance of each vertex from the chord joining its two neighbours (same units)."""
    before = _previous(unit)
    after = _next(unit)
    return _distance_to_line(unit, before, after)


def _distance_to_line(p: NDArray[np.float64], a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Distance of points ``p`` from the lines through ``a`` and ``b`` (row by row)."""
    ab = b - a
    ap = p - a
    cross = ab[:, 0] * ap[:, 1] - ab[:, 1] * ap[:, 0]
    return np.abs(cross) / np.maximum(np.hypot(ab[:, 0], ab[:, 1]), 1e-300)


def simplify_polygon(unit: NDArray[np.float64], offset: NDArray[np.float64] | None = None) -> NDArray[np.bool_]:
    """Which vertices of a counter-clockwise polygon to keep: those in the middle of an edge go.

    Parameters
    ----------
    unit
        (n, 2) vertices scaled to a unit size (divided by the larger of width and height).
    offset
        Distance of each vertex from its neighbours' chord (computed when not given).

    Returns
    -------
    Boolean mask of the vertices kept.

    Notes
    -----
    A vertex is dropped only if it lies within :data:`SIMPLIFY_TOL` (relative to the block's
    size) of the outline *without* it: a finely sampled curve, each of whose vertices is
    nearly on its neighbours' chord, keeps its vertices, because the chords of a run of
    dropped vertices would cut the curve. If the simplified polygon's area differs from the
    given one by more than :data:`SIMPLIFY_TOL` of itself, or its centroid moves by more
    than :data:`SIMPLIFY_TOL` times the size, every vertex is kept.
    """
    n = unit.shape[0]
    if offset is None:
        offset = _offsets(unit)
    keep = offset > SIMPLIFY_TOL
    if np.count_nonzero(keep) < 3:  # a degenerate outline: start from its three farthest corners
        keep[np.argsort(offset)[-3:]] = True
    for _ in range(n):
        kept = np.flatnonzero(keep)
        dropped = np.flatnonzero(~keep)
        if dropped.size == 0:
            break
        pos = np.searchsorted(kept, dropped)
        after = kept[pos % kept.size]
        before = kept[pos - 1]  # pos 0 wraps to the last kept vertex
        far = _distance_to_line(unit[dropped], unit[before], unit[after]) > SIMPLIFY_TOL
        if not np.any(far):
            break
        keep[dropped[far]] = True
    if not keep.all():
        given, simplified = polygon_section(unit), polygon_section(unit[keep])
        moved = float(np.hypot(*np.subtract(given.centroid_m, simplified.centroid_m)))
        if abs(simplified.area_m2 - given.area_m2) > SIMPLIFY_TOL * abs(given.area_m2) or moved > SIMPLIFY_TOL:
            keep[:] = True
    return keep


def polygon_section_area(vertices: NDArray[np.float64]) -> float:
    """Signed area of a polygon (> 0 counter-clockwise), m^2 (shoelace formula)."""
    x = vertices[:, 0]
    y = vertices[:, 1]
    return 0.5 * float((x * _next(y) - _next(x) * y).sum())


def rectangle_vertices(width: float, height: float) -> NDArray[np.float64]:
    """Vertices of a rectangle centred on x = 0 with its base on y = 0 (counter-clockwise)."""
    b = 0.5 * width
    return np.array([[-b, 0.0], [b, 0.0], [b, height], [-b, height]])


def chamfered_rectangle_vertices(width: float, height: float, chamfer: float) -> NDArray[np.float64]:
    """Rectangle with 45-degree chamfers of leg ``chamfer`` at both base corners.

    Specimen 4 of the paper has "a large 45 degree cut (40 mm) at the base" (Section 3.1).
    """
    if not 0.0 < chamfer < min(0.5 * width, height):
        raise InputError("chamfer_m", f"must be in (0, {min(0.5 * width, height):g}) m")
    b = 0.5 * width
    return np.array(
        [
            [-b + chamfer, 0.0],
            [b - chamfer, 0.0],
            [b, chamfer],
            [b, height],
            [-b, height],
            [-b, chamfer],
        ]
    )


@dataclass(frozen=True)
class Block:
    """A rigid block: a convex polygon cross-section extruded over a thickness.

    Create blocks with :meth:`Block.rectangle` or :meth:`Block.polygon`; both validate
    their inputs and name the offending field in any error.

    Attributes
    ----------
    name
        Identifier used in result column names.
    vertices_m
        (n, 2) counter-clockwise vertices in the block frame, base on y = 0, m.
    thickness_m
        Out-of-plane thickness, m.
    mass_kg
        Mass, kg.
    inertia_c_kgm2
        Rotational inertia about the centroid (z axis), kg m^2.
    inertia_given
        True when the inertia was given explicitly rather than from uniform density.
    """

    name: str
    vertices_m: NDArray[np.float64] = field(repr=False)
    thickness_m: float
    mass_kg: float
    inertia_c_kgm2: float
    inertia_given: bool = False

    # ----------------------------------------------------------------- constructors
    @classmethod
    def rectangle(
        cls,
        width_m: float,
        height_m: float,
        thickness_m: float,
        *,
        mass_kg: float | None = None,
        density_kg_m3: float | None = None,
        inertia_kgm2: float | None = None,
        name: str = "block",
        field_prefix: str = "",
    ) -> Block:
        """A rectangular block of base ``width_m`` (2b) and height ``height_m`` (2h)."""
        _positive(width_m, f"{field_prefix}width_m")
        _positive(height_m, f"{field_prefix}height_m")
        verts, section = _rectangle_outline(float(width_m), float(height_m), f"{field_prefix}vertices_m")
        return cls._from_outline(
            verts,
            section,
            thickness_m,
            mass_kg=mass_kg,
            density_kg_m3=density_kg_m3,
            inertia_kgm2=inertia_kgm2,
            name=name,
            field_prefix=field_prefix,
        )

    @classmethod
    def polygon(
        cls,
        vertices_m: ArrayLike,
        thickness_m: float,
        *,
        mass_kg: float | None = None,
        density_kg_m3: float | None = None,
        inertia_kgm2: float | None = None,
        name: str = "block",
        field_prefix: str = "",
    ) -> Block:
        """A block of any convex polygon cross-section standing on a flat base.

        Parameters
        ----------
        vertices_m
            Vertices [[x, y], ...] in metres, in order around the polygon. The polygon is
            shifted vertically so that its lowest vertices are on y = 0.
        thickness_m
            Out-of-plane thickness, m.
        mass_kg, density_kg_m3
            Exactly one of the two.
        inertia_kgm2
            Optional rotational inertia about the centroid, kg m^2; by default that of a
            uniform density.
        """
        verts, section = _outline(vertices_m, f"{field_prefix}vertices_m")
        return cls._from_outline(
            verts,
            section,
            thickness_m,
            mass_kg=mass_kg,
            density_kg_m3=density_kg_m3,
            inertia_kgm2=inertia_kgm2,
            name=name,
            field_prefix=field_prefix,
        )

    @classmethod
    def _from_outline(
        cls,
        verts: NDArray[np.float64],
        section: PolygonSection,
        thickness_m: float,
        *,
        mass_kg: float | None,
        density_kg_m3: float | None,
        inertia_kgm2: float | None,
        name: str,
        field_prefix: str,
    ) -> Block:
        """:meth:`polygon` of validated vertices (:func:`_outline`) and their section."""
        _positive(thickness_m, f"{field_prefix}thickness_m")
        if (mass_kg is None) == (density_kg_m3 is None):
            raise InputError(f"{field_prefix}mass_kg", "give exactly one of mass_kg and density_kg_m3")
        if mass_kg is not None:
            _positive(mass_kg, f"{field_prefix}mass_kg")
            mass = float(mass_kg)
        else:
            density = _positive(density_kg_m3, f"{field_prefix}density_kg_m3")
            mass = density * section.area_m2 * float(thickness_m)
        if inertia_kgm2 is not None:
            _positive(inertia_kgm2, f"{field_prefix}inertia_kgm2")
            inertia = float(inertia_kgm2)
        else:
            inertia = mass / section.area_m2 * section.polar_second_moment_m4
        block = cls(name, verts, float(thickness_m), mass, inertia, inertia_kgm2 is not None)
        block.__dict__["section"] = section  # the cached property's value: computed above
        block._check_base(f"{field_prefix}vertices_m")
        return block

    def __post_init__(self) -> None:
        # a frozen block: its vertices may be shared (the cached outline) and its section is cached
        self.vertices_m.setflags(write=False)

    # ------------------------------------------------------------------- properties
    @cached_property
    def section(self) -> PolygonSection:
        """Area properties of the cross-section (computed once: a block is frozen)."""
        return polygon_section(self.vertices_m)

    @property
    def centroid_m(self) -> tuple[float, float]:
        """Centroid (x, y) in the block frame, m (the centre of mass)."""
        return self.section.centroid_m

    @property
    def height_m(self) -> float:
        """Overall height, m."""
        return float(np.ptp(self.vertices_m[:, 1]))

    @property
    def width_m(self) -> float:
        """Overall width, m."""
        return float(np.ptp(self.vertices_m[:, 0]))

    @property
    def density_kg_m3(self) -> float:
        """Mean density implied by mass, area and thickness, kg/m^3."""
        return self.mass_kg / (self.section.area_m2 * self.thickness_m)

    def level_vertices(self, level: str) -> tuple[float, float]:
        """x of the leftmost and rightmost vertex on the base (``"base"``) or top (``"top"``).

        Returns
        -------
        (x_left, x_right)
            In the block frame, m.
        """
        y = self.vertices_m[:, 1]
        target = y.min() if level == "base" else y.max()
        on_level = np.abs(y - target) <= LEVEL_TOL * max(self.height_m, 1.0)
        xs = self.vertices_m[on_level, 0]
        return float(xs.min()), float(xs.max())

    @property
    def pivots_m(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Left and right base corners (the rocking pivots), block frame, m."""
        x_left, x_right = self.level_vertices("base")
        return np.array([x_left, 0.0]), np.array([x_right, 0.0])

    def inertia_about(self, point_m: ArrayLike) -> float:
        """Rotational inertia about a point of the plane (parallel-axis theorem), kg m^2."""
        d = np.asarray(point_m, dtype=float) - np.asarray(self.centroid_m)
        return self.inertia_c_kgm2 + self.mass_kg * float(d @ d)

    def _check_base(self, field_name: str) -> None:
        x_left, x_right = self.level_vertices("base")
        if x_right - x_left <= LEVEL_TOL * max(self.width_m, 1.0):
            raise InputError(field_name, "block must stand on a flat base: two vertices at its lowest level")
        cx = self.centroid_m[0]
        if not x_left < cx < x_right:
            raise InputError(
                field_name,
                f"centroid x = {cx:g} m lies outside the base [{x_left:g}, {x_right:g}] m: the block cannot stand",
            )


def _outline(vertices_m: ArrayLike, field_name: str) -> tuple[NDArray[np.float64], PolygonSection]:
    """Validated vertices (counter-clockwise, lowest on y = 0, read-only) and their section."""
    verts = _as_vertices(vertices_m, field_name)
    verts = verts - np.array([0.0, verts[:, 1].min()])
    verts.setflags(write=False)
    return verts, polygon_section(verts)


@lru_cache(maxsize=256)
def _rectangle_outline(width_m: float, height_m: float, field_name: str) -> tuple[NDArray[np.float64], PolygonSection]:
    """:func:`_outline` of a rectangle (m), remembered per size (a wall has a few): its
    vertices are read-only."""
    return _outline(rectangle_vertices(width_m, height_m), field_name)


def _positive(value: object, field_name: str) -> float:
    """``value`` as a float; InputError unless it is a finite number > 0."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating, np.integer)):
        raise InputError(field_name, f"must be a number > 0, got {value!r}")
    if not np.isfinite(value) or value <= 0:
        raise InputError(field_name, f"must be a finite number > 0, got {value!r}")
    return float(value)
