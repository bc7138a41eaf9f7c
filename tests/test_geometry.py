"""Blocks and mass properties: closed forms and a direct numerical integration."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad

from rockyade import paper
from rockyade.blocks.geometry import Block, chamfered_rectangle_vertices, polygon_section, rectangle_vertices
from rockyade.errors import InputError


def _integrate_convex(vertices: np.ndarray) -> tuple[float, float, float, float]:
    """Area, centroid (x, y) and polar moment about the origin by nested quadrature.

    For a convex polygon every horizontal line cuts an interval [xl(y), xr(y)]; the inner
    integrals over x are done by quad too, so nothing here shares code with Green's theorem.
    """
    ys = vertices[:, 1]
    edges = list(zip(vertices, np.roll(vertices, -1, axis=0), strict=True))

    def span(y: float) -> tuple[float, float]:
        xs = []
        for (x0, y0), (x1, y1) in edges:
            if (y0 - y) * (y1 - y) <= 0 and y0 != y1:
                xs.append(x0 + (y - y0) * (x1 - x0) / (y1 - y0))
            elif y0 == y1 == y:
                xs += [x0, x1]
        return min(xs), max(xs)

    def inner(y: float, f) -> float:
        xl, xr = span(y)
        return quad(lambda x: f(x, y), xl, xr, epsabs=1e-14)[0]

    breaks = sorted(set(ys.tolist()))

    def outer(f):
        return sum(quad(lambda y: inner(y, f), a, b, epsabs=1e-14)[0] for a, b in itertools.pairwise(breaks))

    area = outer(lambda x, y: 1.0)
    cx = outer(lambda x, y: x) / area
    cy = outer(lambda x, y: y) / area
    polar = outer(lambda x, y: x * x + y * y)
    return area, cx, cy, polar


@pytest.mark.parametrize(
    "vertices",
    [
        rectangle_vertices(0.25, 1.0),
        chamfered_rectangle_vertices(0.16, 0.457, 0.04),
        np.array([[0.0, 0.0], [0.5, 0.0], [0.45, 0.3], [0.1, 0.6], [-0.05, 0.2]]),
    ],
    ids=["rectangle", "specimen4", "irregular"],
)
def test_polygon_section_against_numerical_integration(vertices):
    area, cx, cy, polar_origin = _integrate_convex(vertices)
    section = polygon_section(vertices)
    assert section.area_m2 == pytest.approx(area, rel=1e-10)
    assert section.centroid_m[0] == pytest.approx(cx, rel=1e-9, abs=1e-12)
    assert section.centroid_m[1] == pytest.approx(cy, rel=1e-9)
    polar_centroid = polar_origin - area * (cx * cx + cy * cy)
    assert section.polar_second_moment_m4 == pytest.approx(polar_centroid, rel=1e-9)


def test_rectangle_mass_and_inertia_closed_form():
    b = Block.rectangle(0.25, 1.0, 0.754, mass_kg=503)
    assert b.mass_kg == 503
    assert b.centroid_m == pytest.approx((0.0, 0.5))
    assert b.inertia_c_kgm2 == pytest.approx(503 * (0.25**2 + 1.0**2) / 12, rel=1e-12)
    corner = b.pivots_m[0]
    # I_O = 4/3 M R^2 for a rectangle about a base corner (R^2 = b^2 + h^2)
    assert b.inertia_about(corner) == pytest.approx(4 / 3 * 503 * (0.125**2 + 0.5**2), rel=1e-12)


def test_density_gives_mass():
    b = Block.rectangle(0.2, 0.6, 0.55, density_kg_m3=2650)
    assert b.mass_kg == pytest.approx(2650 * 0.2 * 0.6 * 0.55)
    assert b.density_kg_m3 == pytest.approx(2650)


def test_explicit_inertia_is_kept():
    b = Block.rectangle(0.25, 1.0, 0.754, mass_kg=503, inertia_kgm2=50.0)
    assert b.inertia_c_kgm2 == 50.0 and b.inertia_given


def test_specimen4_is_a_chamfered_polygon():
    s = paper.specimen(4)
    b = s.block()
    assert len(b.vertices_m) == 6
    xl, xr = b.level_vertices("base")
    assert (xl, xr) == pytest.approx((-0.04, 0.04))
    assert b.section.area_m2 == pytest.approx(0.16 * 0.457 - 0.04**2)


def test_clockwise_vertices_are_reordered():
    cw = rectangle_vertices(0.2, 0.5)[::-1]
    b = Block.polygon(cw, 0.3, mass_kg=10)
    assert polygon_section(b.vertices_m).area_m2 > 0


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        (dict(width_m=0.0, height_m=1.0, thickness_m=0.5, mass_kg=1), "width_m"),
        (dict(width_m=0.2, height_m=-1.0, thickness_m=0.5, mass_kg=1), "height_m"),
        (dict(width_m=0.2, height_m=1.0, thickness_m=0.0, mass_kg=1), "thickness_m"),
        (dict(width_m=0.2, height_m=1.0, thickness_m=0.5), "mass_kg"),
        (dict(width_m=0.2, height_m=1.0, thickness_m=0.5, mass_kg=1, density_kg_m3=2), "mass_kg"),
        (dict(width_m=0.2, height_m=1.0, thickness_m=0.5, mass_kg=float("nan")), "mass_kg"),
        (dict(width_m=0.2, height_m=1.0, thickness_m=0.5, mass_kg=1, inertia_kgm2=-1), "inertia_kgm2"),
    ],
)
def test_bad_rectangle_inputs_name_the_field(kwargs, field):
    with pytest.raises(InputError) as info:
        Block.rectangle(**kwargs)
    assert info.value.field == field


def test_non_convex_polygon_rejected():
    with pytest.raises(InputError, match="convex"):
        Block.polygon([[0, 0], [1, 0], [1, 1], [0.5, 0.2], [0, 1]], 0.2, mass_kg=1)


def test_pointed_base_rejected():
    with pytest.raises(InputError, match="flat base"):
        Block.polygon([[0, 0], [0.5, 0.5], [0, 1], [-0.5, 0.5]], 0.2, mass_kg=1)


def test_block_that_cannot_stand_rejected():
    with pytest.raises(InputError, match="cannot stand"):
        Block.polygon([[0, 0], [0.1, 0], [1.5, 1.0], [1.2, 1.0]], 0.2, mass_kg=1)


def test_polygon_vertices_shifted_to_base():
    b = Block.polygon(rectangle_vertices(0.2, 0.5) + np.array([0.0, 3.0]), 0.3, mass_kg=5)
    assert b.vertices_m[:, 1].min() == 0.0
    assert math.isclose(b.height_m, 0.5)


# ---------------------------------------------------------------------- fine polygons


def _half_circle_top(n: int, radius: float = 0.5, rise: float = 0.125) -> np.ndarray:
    """A 1 m wide, 1 m tall rectangle whose top is a half-ellipse of rise ``rise`` sampled by
    ``n`` vertices, odd to hold the apex (exact height 1 + rise; exact area 1 + pi/2 r rise)."""
    angle = np.linspace(0.0, math.pi, n)
    top = np.c_[radius * np.cos(angle), 1.0 + rise * np.sin(angle)]
    return np.vstack([[[-radius, 0.0], [radius, 0.0]], top])


@pytest.mark.parametrize("n", [1_001, 5_001, 9_997])
def test_finely_sampled_curves_are_kept(n):
    """The collinearity test was absolute on each vertex: 1,000 to 20,000 vertices of a curved
    top made a plain rectangle (height 1.0 m, not 1.125 m)."""
    verts = _half_circle_top(n)
    block = Block.polygon(verts, 0.5, density_kg_m3=2000.0)
    assert len(block.vertices_m) == n + 2
    assert block.height_m == pytest.approx(1.125, rel=1e-12)
    given = polygon_section(verts)
    assert block.section.area_m2 == pytest.approx(given.area_m2, rel=1e-12)
    exact = 1.0 + math.pi / 2 * 0.5 * 0.125
    assert block.section.area_m2 == pytest.approx(exact, rel=1e-5)


def test_more_vertices_than_the_cap_are_refused_cleanly():
    from rockyade.blocks.geometry import MAX_POLYGON_VERTICES

    for n in (MAX_POLYGON_VERTICES - 1, 30_000, 50_000):  # 30,000 gave a ZeroDivisionError
        verts = _half_circle_top(n)
        if len(verts) <= MAX_POLYGON_VERTICES:
            assert len(Block.polygon(verts, 0.5, mass_kg=1.0).vertices_m) == len(verts)
            continue
        with pytest.raises(InputError) as info:
            Block.polygon(verts, 0.5, mass_kg=1.0)
        assert info.value.field == "vertices_m"
        assert f"has {len(verts)} vertices, more than the {MAX_POLYGON_VERTICES}" in info.value.message


def test_a_scene_polygon_beyond_the_cap_is_refused_naming_the_block():
    from rockyade.blocks.geometry import MAX_POLYGON_VERTICES
    from rockyade.scene import scene_from_dict

    from .conftest import free_scene_dict

    d = free_scene_dict()
    block = d["blocks"][0]
    for key in ("width_m", "height_m", "alpha_rad", "p_rad_s", "mu"):
        block.pop(key)
    block["vertices_m"] = _half_circle_top(MAX_POLYGON_VERTICES + 1).tolist()
    with pytest.raises(InputError) as info:
        scene_from_dict(d)
    assert info.value.field == "blocks[0].vertices_m" and "more than the" in info.value.message


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_vertices_in_the_middle_of_edges_are_dropped_at_any_size(scale):
    square = np.array([[0, 0], [0.5, 0], [1, 0], [1, 0.25], [1, 1], [0.3, 1], [0, 1], [0, 1 / 3]]) * scale
    block = Block.polygon(square, scale, mass_kg=1.0)
    assert len(block.vertices_m) == 4
    assert block.section.area_m2 == pytest.approx(scale**2, rel=1e-15)


def test_a_run_of_nearly_collinear_vertices_is_not_cut_by_one_chord():
    """Each vertex of a shallow arc is within 1e-9 of its neighbours' chord, but the arc as a
    whole rises 1e-5 above its end points: the arc is kept (dropping every vertex at once made
    a different block)."""
    x = np.linspace(1.0, -1.0, 4001)
    arc = np.c_[x, 1.0 + 1e-5 * (1.0 - x**2)]
    verts = np.vstack([[[-1.0, 0.0], [1.0, 0.0]], arc])
    block = Block.polygon(verts, 1.0, mass_kg=1.0)
    given = polygon_section(verts)
    assert block.section.area_m2 == pytest.approx(given.area_m2, rel=1e-9)
    assert block.height_m == pytest.approx(1.0 + 1e-5, rel=1e-12)


def test_simplification_never_moves_area_or_centroid_beyond_its_tolerance():
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from rockyade.blocks.geometry import SIMPLIFY_TOL

    @settings(max_examples=150, deadline=None, derandomize=True)
    @given(
        n=st.integers(3, 40),
        extra=st.lists(st.tuples(st.integers(0, 39), st.floats(0.01, 0.99)), max_size=30),
        aspect=st.floats(0.05, 20.0),
        size=st.floats(1e-3, 100.0),
    )
    def check(n, extra, aspect, size):
        angles = np.sort(np.random.default_rng(n).uniform(0, 2 * math.pi, n))
        if np.max(np.diff(np.r_[angles, angles[0] + 2 * math.pi])) >= math.pi:
            return  # not a polygon around its centre
        ring = np.c_[np.cos(angles) * aspect, np.sin(angles)] * size
        verts = list(ring)
        for edge, t in sorted(extra, reverse=True):  # points inserted on edges
            i = edge % n
            a, b = ring[i], ring[(i + 1) % n]
            verts.insert(i + 1, a + t * (b - a))
        verts = np.array(verts)
        verts = verts - [0.0, verts[:, 1].min()]
        try:
            kept = Block.polygon(verts, 1.0, mass_kg=1.0).vertices_m
        except InputError:
            return  # e.g. a pointed base: refused, not changed
        given_section, kept_section = polygon_section(verts), polygon_section(kept)
        scale = float(np.max(np.ptp(verts, axis=0)))
        assert abs(kept_section.area_m2 - given_section.area_m2) <= SIMPLIFY_TOL * given_section.area_m2
        moved = np.hypot(*np.subtract(kept_section.centroid_m, given_section.centroid_m))
        assert moved <= SIMPLIFY_TOL * scale
        assert len(kept) <= n

    check()
