"""Restraints that hold (issue 24 item 2): contacts with fixed blocks, corners included.

The case: a tuff wall 2.4 m high, 0.36 m thick, 1600 kg/m^3, in 8 courses of 0.3 m, joints at
35 degrees, a roof of 6 kN/m at e = 0.05 m from the axis (a force without mass), restrained by a
frictionless fixed block beside the far face (x > 0) of its top course, 1e-9 m from it. Loaded
towards the restraint (+x).

Before: the course below the restraint (w07) touches the restraint only at a corner (its top
corner on the restraint's bottom corner), which no joint held; the mechanism found (1.1885) moved
w06-w07 up and to the right, through the restraint.

Hand calculations (per metre of wall, W_c = 1600 g 0.36 0.3 = 1695.2 N a course):

* the three-hinge mechanism (paper's Fig. 2): the wall's lower 1.5 m turns clockwise about its
  toe (t/2, 0); the upper 0.9 m hinges on it at (-t/2, 1.5) and its face slides on the
  restraint's corner (t/2, 2.1) (v_x = 0 there). With the lower part's rate 1: v = (y, t/2 - x)
  on it, v_B = (1.5, t) at the hinge, the upper part's rate 0.6 omega_U = 1.5, omega_U = 2.5;
  its centroid (0, 1.95) moves (0.375, 2.25 t), the roof's point (0.05, 2.4) rises
  t + 2.5 (0.05 + t/2). Virtual work: lambda = (W_L t/2 + W_U 2.25 t + N (t + 2.5 (e + t/2)))
  / (0.75 W_L + 0.375 W_U) = 1.3619 (W_L = 5 W_c, W_U = 3 W_c);
* the mechanism found (lower): the seven lower courses turn as one about the toe (rate 1), the
  corner of w07 passes under the restraint's bottom face (moving along it, frictionless); the top
  course cannot move towards the restraint (u = 0) and is squeezed out upwards: it slides on w07
  by 2.1 per unit rate and, with associated friction, opens by tan(phi) 2.1 at the end of the joint
  that rises least (the toe's vertical, w07's top moving (2.1, t/2 - x)), so it rises
  t + 2.1 tan(phi). lambda = (W_L t/2 + (W_c + N)(t + 2.1 tan(phi))) / (W_L 2.1 / 2),
  W_L = 7 W_c: 1.3019.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.constants import G
from rockyade.limit import limit_analysis, rigid_block_model
from rockyade.limit.mechanism import point_velocity
from rockyade.limit.point_contacts import _ways
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import wall_section as _generated_section

H, T, RHO, N, E, PHI = 2.4, 0.36, 1600.0, 6000.0, 0.05, 35.0
BEFORE = 1.1885  # the multiplier of the inadmissible mechanism, before corners were contacts


def wall_section(**kwargs):
    """The generator's wall section with its roof as a force without mass (this module's case;
    the generator gives the roof its mass by default)."""
    data = _generated_section(**kwargs)
    if data.get("loads"):
        data = {**data, "loads": [{**q, "mass_kg": 0.0} for q in data["loads"]]}
    return data


def restrained_8_courses(gap_m: float = 1e-9, phi: float = PHI, **kwargs):
    contact = {"calibration": "paper", "friction_angle_deg": phi}
    data = wall_section(
        height_m=H,
        thickness_m=T,
        courses=8,
        top="restrained-far",
        gap_m=gap_m,
        overburden_n_per_m=N,
        overburden_eccentricity_m=E,
        density_kg_m3=RHO,
        contact=contact,
        motion={"type": "rest"},
        **kwargs,
    )
    return scene_from_dict(data)


def three_hinge() -> float:
    wc = RHO * G * T * 0.3
    wl, wu = 5 * wc, 3 * wc
    return (wl * T / 2 + wu * 2.25 * T + N * (T + 2.5 * (E + T / 2))) / (0.75 * wl + 0.375 * wu)


def squeezed_top() -> float:
    wc = RHO * G * T * 0.3
    wl = 7 * wc
    rise = T + 2.1 * math.tan(math.radians(PHI))
    return (wl * T / 2 + (wc + N) * rise) / (wl * 2.1 / 2)


def _depth(poly: np.ndarray, p: np.ndarray) -> float:
    """How deep p lies inside the convex counter-clockwise poly (< 0: outside), m."""
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
    return float(-np.max(np.einsum("ij,ij->i", p - poly, normals)))


def entering(result, step: float = 1e-7) -> float:
    """The deepest any vertex of one body goes into another (or below the base) along the
    mechanism, to first order: depth after a small step / step (0: admissible). Computed from the
    geometry and the velocities alone, not from the programme's contacts."""
    model = result.model
    vel = result.mechanism.velocities
    polys = model.polygons_m
    worst = 0.0
    for i, poly in enumerate(polys):
        for p in poly:
            vi = point_velocity(vel[i], model.centroids_m[i], p)
            if not model.fixed[i]:
                worst = max(worst, -(p[1] + step * vi[1]) / step)  # below the base
            for j, other in enumerate(polys):
                if j == i or (model.fixed[i] and model.fixed[j]) or _depth(other, p) < -1e-6:
                    continue  # the vertex does not touch body j at rest
                vj = point_velocity(vel[j], model.centroids_m[j], p)
                moved = p + step * (vi - vj)
                worst = max(worst, _depth(other, moved) / step)
    return worst


def test_the_hand_values():
    assert three_hinge() == pytest.approx(1.3619, abs=5e-5)
    assert squeezed_top() == pytest.approx(1.3019, abs=5e-5)


def test_no_mechanism_passes_through_the_restraint_and_the_multiplier_rises_to_the_hand_bound():
    scene = restrained_8_courses()
    res = limit_analysis(scene, direction="+x")
    assert res.status == "collapse"
    assert entering(res) <= 1e-6
    lam = res.load_multiplier
    assert BEFORE + 0.05 < lam <= three_hinge() * (1 + 1e-9)  # an upper bound for associated friction
    # the mechanism found, in closed form (module docstring): the lower seven courses turn about the toe,
    # the top course is squeezed out upwards
    assert lam == pytest.approx(squeezed_top(), rel=1e-9)
    assert [h.point_m for h in res.mechanism.hinges] == [(T / 2, 0.0)]
    assert any("w07's corner on restraint_far" in note for note in res.notes)


def test_a_zero_gap_gives_the_same_and_frictionless_joints_give_the_three_hinge_bound():
    """Gap 0: the same contacts (the restraint flush with the top course)."""
    res = limit_analysis(restrained_8_courses(gap_m=0.0), direction="+x")
    assert res.load_multiplier == pytest.approx(squeezed_top(), rel=1e-9)
    assert entering(res) <= 1e-6


def test_the_corner_of_the_course_below_is_a_contact_with_two_ways():
    model = rigid_block_model(restrained_8_courses())
    assert len(model.corners) == 1
    corner = model.corners[0]
    assert (model.names[corner.a], model.names[corner.b]) == ("w07", "restraint_far")
    assert corner.point_m == pytest.approx((T / 2, 2.1))
    normals = sorted(tuple(np.round(itf.normal, 12)) for way in corner.ways for itf in way)
    assert normals == [(-1.0, 0.0), (0.0, -1.0)]  # up the restraint's face, or under its bottom face
    assert all(itf.friction_angle_deg == 0.0 for way in corner.ways for itf in way)  # the restraint's


def test_the_ways_of_a_point_contact():
    q = math.pi / 2
    # a corner on the inside of an edge: one way, the edge's normal
    (way,) = _ways([(0.0, math.pi), (q / 2, q)])
    assert np.allclose(way, [(0.0, -1.0)])
    # two square corners meeting diagonally: pass on either side
    ways = _ways([(0.0, q), (0.0, q)])
    assert sorted(np.round(n, 12).tolist() for (n,) in ways) == [[-1.0, 0.0], [0.0, -1.0]]
    # a corner in a right-angled notch: excluded 270 degrees, one convex way of two faces
    (way,) = _ways([(0.0, 3 * q)])
    assert len(way) == 2


def test_without_the_restraint_the_wall_is_free():
    scene = restrained_8_courses()
    free = scene_from_dict(
        wall_section(
            height_m=H,
            thickness_m=T,
            courses=8,
            overburden_n_per_m=N,
            overburden_eccentricity_m=E,
            density_kg_m3=RHO,
            motion={"type": "rest"},
        )
    )
    assert (
        limit_analysis(free, direction="+x", nonlinear=False).load_multiplier
        < limit_analysis(scene, direction="+x", nonlinear=False).load_multiplier
    )


def test_the_capacity_curve_stops_where_the_gap_closes_and_says_so():
    """Gap 1 mm, restraints both sides: the free wall's mechanism (lambda = 0.1979, turning about
    its toe) until its top's far corner (t/2, H) meets the restraint, at sin(theta) = gap / H; the
    control point (w08's centroid, (0, 2.25)) has then moved t/2 (1 - cos theta) + 2.25 sin theta."""
    data = wall_section(
        height_m=H,
        thickness_m=T,
        courses=8,
        top="restrained",
        gap_m=0.001,
        overburden_n_per_m=N,
        overburden_eccentricity_m=E,
        density_kg_m3=RHO,
        motion={"type": "rest"},
    )
    res = limit_analysis(scene_from_dict(data), direction="+x")
    kin = res.kinematic
    assert kin.d0_star_m is None
    assert "w08 meets restraint_far" in kin.nonlinear_note and "gap closes" in kin.nonlinear_note
    theta = math.asin(0.001 / H)
    dk = T / 2 * (1 - math.cos(theta)) + 2.25 * math.sin(theta)
    assert kin.curve.dk_m[-1] == pytest.approx(dk, abs=5e-6)
    assert kin.curve.dk_m[-1] <= dk


def test_a_fixed_block_that_touches_nothing_is_named():
    data = wall_section(height_m=H, thickness_m=T, courses=2, motion={"type": "rest"})
    data["blocks"].append(
        {
            "name": "stray",
            "width_m": 0.2,
            "height_m": 0.2,
            "thickness_m": 1.0,
            "density_kg_m3": 2000.0,
            "position_m": [2.0, 0.5],
            "fixed": True,
        }
    )
    notes = rigid_block_model(scene_from_dict(data)).notes
    assert any("stray" in n and "touch no moving block" in n for n in notes)
    assert not any("touch no" in n for n in rigid_block_model(restrained_8_courses()).notes)


def test_the_three_hinge_mechanism_sliding_on_a_frictionless_restraint_is_followed_to_alpha_0():
    """restrained-wall's two blocks (t 0.3, H 3, split 1.5, restraint 0.3 deep, frictionless): the lower
    block turns by theta about (t/2, 0); the upper block hinges on it at the moved (-t/2, 1.5) and its
    face passes through the restraint's corner D = (t/2, 2.7) (the rotation phi of the upper block
    solves that). alpha(theta) = dV/dtheta / d(sum W x)/dtheta by finite differences of the positions,
    computed here without the package; it falls to 0 where V is highest."""
    from scipy.optimize import brentq

    from rockyade.scene.generators import restrained_wall

    t, h, h1, hr = 0.3, 3.0, 1.5, 0.3
    toe, corner, hinge0 = np.array([t / 2, 0.0]), np.array([t / 2, h - hr]), np.array([-t / 2, h1])

    def rot(a):
        return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])

    def centroids(theta):
        hinge = toe + rot(-theta) @ (hinge0 - toe)

        def off_face(phi):  # D's distance from the upper block's far face
            d = corner - (hinge + rot(phi) @ np.array([t, 0.0]))
            u = rot(phi) @ np.array([0.0, 1.0])
            return u[0] * d[1] - u[1] * d[0]

        phi = brentq(off_face, -1e-9, 1.0) if theta > 0 else 0.0
        lower = toe + rot(-theta) @ (np.array([0.0, h1 / 2]) - toe)
        upper = hinge + rot(phi) @ (np.array([0.0, (h + h1) / 2]) - hinge0)
        return lower, upper

    def alpha(theta, eps=1e-7):
        (l1, u1), (l0, u0) = centroids(theta + eps), centroids(theta - eps)
        return (h1 * (l1[1] - l0[1]) + (h - h1) * (u1[1] - u0[1])) / (h1 * (l1[0] - l0[0]) + (h - h1) * (u1[0] - u0[0]))

    theta0 = brentq(alpha, 1e-4, 0.5)
    d0 = centroids(theta0)[0][0]  # the control point: the lower block's centroid
    data = wall_section(courses=2, split=0.5, top="restrained-far", restraint_friction_deg=0.0, motion={"type": "rest"})
    assert data == restrained_wall(blocks=2, split=0.5, restraint="side", motion={"type": "rest"})  # the alias
    res = limit_analysis(scene_from_dict(data), direction="+x")
    assert res.mechanism.slides and res.load_multiplier == pytest.approx(17 / 35, rel=1e-9)
    kin = res.kinematic
    assert kin.control_block == "w01"
    assert kin.curve.d0_m == pytest.approx(d0, rel=1e-4)
    for theta in (0.01, 0.05, 0.1):
        dk = centroids(theta)[0][0]
        assert np.interp(dk, kin.curve.dk_m, kin.curve.alpha) == pytest.approx(alpha(theta), abs=2e-4)


def test_sliding_with_friction_says_why_it_is_not_followed():
    res = limit_analysis(restrained_8_courses(), direction="+x")
    assert res.mechanism.slides and res.kinematic.d0_star_m is None
    assert "slides with friction" in res.kinematic.nonlinear_note


@pytest.mark.slow
def test_the_pushover_of_a_wall_with_a_gap_sees_the_onset_before_the_restraint_holds_it():
    """The wall turns at alpha0 = 0.1979 but only until its top meets the restraint 1 mm away (its control
    point, w08's centroid, then moved 0.94 mm): the pushover's growth threshold of 1 mm would never be
    reached (the onset was NaN, 'stood at' every level); the onset is sought within the gap's travel."""
    from rockyade.assess.pushover import run_pushover

    data = wall_section(
        height_m=H,
        thickness_m=T,
        courses=8,
        top="restrained",
        gap_m=0.001,
        overburden_n_per_m=N,
        overburden_eccentricity_m=E,
        density_kg_m3=RHO,
        motion={"type": "rest"},
    )
    scene = scene_from_dict(data)
    res = limit_analysis(scene, direction="+x")
    check = run_pushover(scene, res.kinematic, "+x")
    assert math.isfinite(check.onset.multiplier)
    assert abs(check.difference) <= 0.011  # the first held level at or above alpha0 (levels 1 % apart)


def test_one_generator_its_names_defaults_and_gaps(tmp_path):
    from rockyade.cli import main
    from rockyade.errors import InputError
    from rockyade.scene import load_scene
    from rockyade.scene.generators import restrained_wall

    # one face, no gap: allowed; the restraint's friction (0 by default) on every course that can touch it
    scene = restrained_8_courses(gap_m=0.0)
    assert [b.name for b in scene.blocks if b.fixed] == ["restraint_far"]
    assert {j.blocks for j in scene.joints} == {("w07", "restraint_far"), ("w08", "restraint_far")}
    assert {j.get("friction_angle_deg") for j in scene.joints} == {0.0}
    # both faces need a gap; a gap the wall cannot close before it overturns is refused, with the numbers
    with pytest.raises(InputError, match="clamp"):
        wall_section(top="restrained")
    with pytest.raises(InputError, match=r"< thickness_m \(0.3 m\).*0.3 m closes") as info:
        wall_section(top="restrained-near", gap_m=0.3)
    assert info.value.field == "gap_m"
    with pytest.raises(InputError, match=r"must be < 0.01496 m with top = 'floor'") as info:
        wall_section(top="floor", gap_m=0.02)
    assert info.value.field == "gap_m"
    with pytest.raises(InputError, match=r"must be < wall_thickness_m \(0.3 m\)") as info:
        restrained_wall(gap_m=0.3)  # the alias names its own parameters
    assert info.value.field == "gap_m"
    # the same names and defaults: restrained-wall takes wall-section's names, its restraint frictionless
    assert (
        main(
            [
                "build",
                "restrained-wall",
                "--height-m",
                "2.4",
                "--thickness-m",
                "0.36",
                "--motion",
                "rest",
                "--out",
                str(tmp_path / "rw.toml"),
            ]
        )
        == 0
    )
    rw = load_scene(tmp_path / "rw.toml")
    assert rw.blocks[0].width_m == pytest.approx(0.36) and rw.blocks[-1].position_m[1] == pytest.approx(2.1)
    assert [j.get("friction_angle_deg") for j in rw.joints] == [0.0]


def test_with_joints_that_do_not_slide_at_45_degrees_it_is_the_hand_three_hinge_mechanism():
    """Joints at 45 degrees: the top course can no longer be squeezed out (tan 45 x 2.1 of rise), and the
    mechanism is the three hinges by hand, exactly, followed to alpha = 0 (the top slides on the
    frictionless restraint)."""
    res = limit_analysis(restrained_8_courses(phi=45.0), direction="+x")
    assert res.load_multiplier == pytest.approx(three_hinge(), rel=1e-9)
    assert [h.point_m for h in res.mechanism.hinges] == [(T / 2, 0.0), (-T / 2, 1.5)]
    assert entering(res) <= 1e-6
    assert res.kinematic.d0_star_m is not None and res.kinematic.d0_star_m > 0.1


def test_wall_section_in_two_courses_is_restrained_wall():
    """Two equal courses restrained on the far face with no gap: restrained-wall's 17/35."""
    res = limit_analysis(
        scene_from_dict(wall_section(courses=2, top="restrained-far", motion={"type": "rest"})), nonlinear=False
    )
    assert res.load_multiplier == pytest.approx(17 / 35, rel=1e-9)
