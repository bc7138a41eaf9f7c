"""The code's kinematic quantities (NTC 2018 / Circolare 2019 C8.7.1) of limit-analysis
mechanisms, against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.constants import CODE_GRAVITY, G
from rockyade.errors import InputError
from rockyade.limit import PointLoad, limit_analysis, rigid_block_model
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rocking_frame

from .limit_scenes import arch_scene, block_scene, course_wall_scene


def _theta_of(dk: np.ndarray, b: float, h_c: float) -> np.ndarray:
    """Rotation of a block about its corner when its centroid has moved dk horizontally:
    dk = R sin(a) - R sin(a - theta), R = sqrt(b^2 + h_c^2), a = atan(b / h_c)."""
    r = math.hypot(b, h_c)
    a = math.atan2(b, h_c)
    return a - np.arcsin(np.clip((r * math.sin(a) - dk) / r, -1.0, 1.0))


@pytest.mark.parametrize(("width", "height"), [(0.4, 2.0), (0.3, 0.6), (1.0, 0.5)])
@pytest.mark.parametrize("direction", ["+x", "-x"])
def test_a_block_has_e_star_1_and_d0_star_b_and_the_curve_of_statics(width, height, direction):
    b, h_c = width / 2, height / 2
    result = limit_analysis(block_scene(width, height), direction=direction, sliding=False)
    kin = result.kinematic
    mass = float(result.model.masses_kg[0])
    assert kin.e_star == pytest.approx(1.0, rel=1e-12)
    assert kin.M_star_kg == pytest.approx(mass, rel=1e-12)
    assert kin.a0_star_m_s2 == pytest.approx((width / height) * CODE_GRAVITY / 1.35, rel=1e-9)
    assert kin.d0_star_m == pytest.approx(b, rel=1e-6)  # the centroid reaches the pivot's vertical
    assert kin.du_star_m == pytest.approx(0.4 * b, rel=1e-6)
    # alpha(theta) = tan(a - theta) for a block turning about its corner, all along the curve
    curve = kin.curve
    theta = _theta_of(curve.dk_m, b, h_c)
    assert np.max(np.abs(curve.alpha - np.tan(math.atan2(b, h_c) - theta))) < 1e-9
    assert len(curve.dk_m) > 50 and curve.max_joint_gap_m < 1e-12
    # Ts at ds* = 0.16 b, from the closed form of a*(d*)
    ds = 0.16 * b
    a_s = math.tan(math.atan2(b, h_c) - _theta_of(np.array([ds]), b, h_c)[0]) * CODE_GRAVITY / 1.35
    assert kin.ds_star_m == pytest.approx(ds, rel=1e-6)
    assert kin.as_star_m_s2 == pytest.approx(a_s, rel=1e-5)
    assert kin.Ts_s == pytest.approx(2 * math.pi * math.sqrt(ds / a_s), rel=1e-5)


@pytest.mark.parametrize("courses", [1, 2, 3, 5, 8])
def test_a_wall_of_n_courses_turning_as_one_has_the_e_star_of_the_closed_form(courses):
    """dx_i proportional to the courses' centroid heights (i - 1/2) h:
    e* = (1/4) / (1/3 - 1/(12 n^2)), tending to 0.75."""
    unit_l, unit_h = 0.4, 0.5
    result = limit_analysis(course_wall_scene(courses, unit_l, unit_h), sliding=False)
    kin = result.kinematic
    assert result.load_multiplier == pytest.approx(unit_l / (courses * unit_h), rel=1e-9)
    assert kin.e_star == pytest.approx(0.25 / (1 / 3 - 1 / (12 * courses**2)), rel=1e-9)
    # d0*: the wall turns about its toe until its centre of mass is over it; the control point
    # is the top course's centroid; d* = dk sum(y_i^2) / (y_k sum(y_i))
    b, height = unit_l / 2, courses * unit_h
    theta0 = math.atan2(b, height / 2)
    ys = (np.arange(courses) + 0.5) * unit_h
    y_k = ys[-1]
    dk0 = -b * math.cos(theta0) + y_k * math.sin(theta0) + b
    assert kin.control_block == result.model.names[-1]
    assert kin.d0_star_m == pytest.approx(dk0 * np.sum(ys**2) / (y_k * np.sum(ys)), rel=1e-6)


def test_an_overburden_follows_the_block_in_the_nonlinear_curve():
    """Block with a vertical load N at (x_N, h) on its top, turning by theta about (b, 0):
    alpha = (W (b cos - h_c sin) + N ((b - x_N) cos - h sin)) / (W (b sin + h_c cos))."""
    width, height = 0.4, 2.0
    b, h_c = width / 2, height / 2
    scene = block_scene(width, height)
    W = float(rigid_block_model(scene).masses_kg[0] * G)
    N, x_n = 0.5 * W, -0.1
    result = limit_analysis(scene, loads=[PointLoad("b01", (x_n, height), (0.0, -N), mass_kg=0.0)], sliding=False)
    kin = result.kinematic
    theta = _theta_of(kin.curve.dk_m, b, h_c)
    c, s = np.cos(theta), np.sin(theta)
    expected = (W * (b * c - h_c * s) + N * ((b - x_n) * c - height * s)) / (W * (b * s + h_c * c))
    assert np.max(np.abs(kin.curve.alpha - expected)) < 1e-9
    theta0 = math.atan2(W * b + N * (b - x_n), W * h_c + N * height)  # alpha = 0
    d0 = b - math.hypot(b, h_c) * math.sin(math.atan2(b, h_c) - theta0)
    assert kin.d0_star_m == pytest.approx(d0, rel=1e-6)
    assert kin.e_star == pytest.approx(1.0)  # the load has no mass


@pytest.mark.parametrize("gamma", [0.5, 1.0, 2.0])
def test_the_rocking_frame_keeps_tan_alpha_minus_theta_for_any_beam(gamma):
    """Makris & Vassiliou (2013): the frame uplifts at g tan(alpha) of its columns, whatever the
    beam's mass; statics at finite rotation gives alpha(theta) = tan(alpha - theta) too (the beam
    moves with the columns' top corners). e* = 4 (m_c + m_b)^2 / ((2 m_c + m_b)(2 m_c + 4 m_b)),
    the beam's virtual displacement twice the columns' centroids'."""
    scene = scene_from_dict(rocking_frame(gamma=gamma))
    result = limit_analysis(scene, sliding=False)
    model = result.model
    cols = [model.names.index("column_left"), model.names.index("column_right")]
    m_c = float(model.masses_kg[cols[0]])
    m_b = float(model.masses_kg[model.names.index("beam")])
    poly = model.polygons_m[cols[0]]
    b, h = np.ptp(poly[:, 0]) / 2, np.ptp(poly[:, 1]) / 2
    alpha = math.atan2(b, h)
    assert result.load_multiplier == pytest.approx(b / h, rel=1e-9)
    kin = result.kinematic
    assert kin.e_star == pytest.approx(4 * (m_c + m_b) ** 2 / ((2 * m_c + m_b) * (2 * m_c + 4 * m_b)), rel=1e-9)
    assert kin.control_block == "beam"
    # the beam translates with a column's top corner: dk = 2R sin(alpha) - 2R sin(alpha - theta)
    r2 = 2 * math.hypot(b, h)
    theta = alpha - np.arcsin(np.clip((r2 * math.sin(alpha) - kin.curve.dk_m) / r2, -1, 1))
    assert np.max(np.abs(kin.curve.alpha - np.tan(alpha - theta))) < 1e-8


@pytest.mark.slow
def test_an_arch_mechanism_is_followed_from_its_multiplier_down_to_zero():
    result = limit_analysis(arch_scene(0.15, 20), sliding=False)
    kin = result.kinematic
    curve = kin.curve
    assert curve.alpha[0] == pytest.approx(result.load_multiplier, rel=1e-9)
    assert np.all(np.diff(curve.alpha) < 0) and curve.alpha[-1] <= 0 < curve.alpha[-2]
    assert curve.max_joint_gap_m < 1e-12
    assert 0.6 < kin.e_star < 1.0 and kin.d0_star_m > 0 and kin.Ts_s > 0
    assert kin.ds_star_m == pytest.approx(0.16 * kin.d0_star_m)


def test_a_sliding_mechanism_has_the_linear_quantities_only():
    result = limit_analysis(block_scene(2.0, 0.4, friction_deg=10.0))
    kin = result.kinematic
    assert kin.alpha0 == pytest.approx(math.tan(math.radians(10.0)))
    assert kin.e_star == pytest.approx(1.0)
    assert kin.curve is None and kin.d0_star_m is None and kin.Ts_s is None
    assert "slides" in kin.nonlinear_note
    data = result.to_dict()
    assert data["d0_star_m"] is None and data["e_star"] == pytest.approx(1.0)


def test_fc_scales_a0_star_and_is_checked():
    scene = block_scene(0.4, 2.0)
    a1 = limit_analysis(scene, fc=1.0, sliding=False).kinematic
    a2 = limit_analysis(scene, fc=1.35, sliding=False).kinematic
    assert a1.a0_star_m_s2 == pytest.approx(0.2 * CODE_GRAVITY)
    assert a2.a0_star_m_s2 == pytest.approx(0.2 * CODE_GRAVITY / 1.35)
    assert a1.d0_star_m == pytest.approx(a2.d0_star_m)  # FC scales accelerations only
    for bad in (0.5, 11.0, math.nan):
        with pytest.raises(InputError, match="FC"):
            limit_analysis(scene, fc=bad)


@pytest.mark.slow
def test_hinges_that_would_lock_a_wall_mechanism_open_on_the_way():
    """A wall with a door and a window, no sliding: the mechanism's ten hinges are compatible at
    rest to first order only; some open as it moves (hinges are unilateral) and alpha falls
    smoothly to 0."""
    from rockyade.scene import load_scene

    from .conftest import EXAMPLES

    result = limit_analysis(load_scene(EXAMPLES / "assemblies/wall_door_window.toml"), sliding=False)
    curve = result.kinematic.curve
    assert len(result.mechanism.hinges) == 10 and curve.opened
    assert curve.alpha[0] == pytest.approx(result.load_multiplier, rel=1e-9)
    assert np.all(np.diff(curve.alpha) < 0) and curve.alpha[-1] <= 0.0
    assert curve.max_joint_gap_m < 1e-12 and result.kinematic.d0_star_m > 0
    data = result.kinematic.to_dict()
    assert data["curve"]["opened_hinges"] and data["curve"]["max_overlap_m"] >= 0.0
