"""The named parts of the reference DEM's kernel against closed forms: the contact law, the
shared ground-motion lookup, the placement of a body, and the leap-frog integration."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.dem.engine import polygon_arrays, tiny_problem
from rockyade.kernel import simulation as kernel
from rockyade.kernel.contact_law import (
    STATE_SLIP,
    STATE_STICK,
    JointLaw,
    add_released_energy,
    add_stored_energy,
    contact_law,
)
from rockyade.kernel.integration import Motion
from rockyade.kernel.state import pack
from rockyade.kernel.world import new_world, place_body
from rockyade.motion.ground import GroundMotion, ground_acceleration
from rockyade.scene.placement import rotation_matrix

KN, KS, CN, CS, TANPHI, DT = 2.0e8, 1.5e8, 3.0e3, 2.5e3, math.tan(math.radians(30.0)), 1e-5


def law(delta, ddot, vt, s_old):
    return contact_law(delta, ddot, vt, s_old, JointLaw(KN, KS, CN, CS, TANPHI), DT)


# ---------------------------------------------------------------------- contact law


@pytest.mark.parametrize("ddot", [0.0, 0.3, -0.4])
def test_normal_force_is_spring_plus_dashpot(ddot):
    delta = 2e-6
    fn, fn_spring, *_ = law(delta, ddot, 0.0, 0.0)
    assert fn_spring == KN * delta
    assert fn == pytest.approx(max(0.0, KN * delta + CN * ddot), rel=1e-15)


def test_no_tension_and_a_point_without_normal_force_cannot_hold_shear():
    """A point separating faster than its spring pushes: F_n = 0, not negative; its shear
    spring then slips to zero and dissipates what the trial force would have stored."""
    delta, ddot = 1e-7, -10.0  # K delta = 20 N, c_n delta_dot = -30 kN
    fn, fn_spring, s_new, visc, state, work = law(delta, ddot, 0.01, 5.0)
    assert fn == 0.0 and fn_spring == KN * delta
    assert s_new == 0.0 and visc == 0.0 and state == STATE_SLIP
    assert work == 0.0  # the slip works against F_n tan(phi) = 0


def test_sticking_point_adds_the_incremental_spring_and_the_shear_dashpot():
    delta, vt, s_old = 1e-5, 2e-3, 100.0
    fn, _, s_new, visc, state, work = law(delta, 0.0, vt, s_old)
    s_trial = s_old + KS * DT * vt
    assert abs(s_trial) <= fn * TANPHI
    assert s_new == s_trial and visc == CS * vt
    assert state == STATE_STICK and work == 0.0


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_coulomb_cap_slip_and_its_dissipation(sign):
    """|S_trial| > F_n tan(phi): S = sign(S_trial) F_n tan(phi), no shear dashpot, and the
    slip (|S_trial| - F_n tan(phi)) / K_s works against F_n tan(phi)."""
    delta, vt, s_old = 1e-6, sign * 0.5, sign * 150.0
    fn, _, s_new, visc, state, work = law(delta, 0.0, vt, s_old)
    s_trial = s_old + KS * DT * vt
    smax = fn * TANPHI
    assert abs(s_trial) > smax
    assert s_new == sign * smax and visc == 0.0 and state == STATE_SLIP
    assert work == pytest.approx(smax * (abs(s_trial) - smax) / KS, rel=1e-15) and work > 0.0


def test_slip_work_sums_to_coulomb_force_times_slip_distance():
    """A point held at constant F_n and dragged at constant v_t: after the spring saturates,
    the work per step is F_n tan(phi) v_t dt (Coulomb friction)."""
    delta, vt = 1e-6, 0.02
    fn = KN * delta
    s, works = 0.0, []
    for _ in range(200):
        _, _, s, _, _, work = law(delta, 0.0, vt, s)
        works.append(work)
    assert s == pytest.approx(fn * TANPHI, rel=1e-15)
    assert works[-1] == pytest.approx(fn * TANPHI * vt * DT, rel=1e-9)


def test_stored_and_released_energy():
    delta, s = 3e-6, 40.0
    e = add_stored_energy(1.0, KN * delta, delta, s, KS)
    assert e == pytest.approx(1.0 + 0.5 * KN * delta**2 + 0.5 * s * s / KS, rel=1e-15)
    assert add_stored_energy(0.0, KN * delta, delta, s, 0.0) == 0.5 * KN * delta * delta  # no shear spring
    assert add_released_energy(2.0, s * s, KS) == pytest.approx(2.0 + 0.5 * s * s / KS, rel=1e-15)
    assert add_released_energy(2.0, s * s, 0.0) == 2.0


# ---------------------------------------------------------------------- ground motion


@pytest.mark.slow
def test_ground_lookup_equals_linear_interpolation_for_any_time_order():
    rng = np.random.default_rng(3)
    t_s = np.cumsum(rng.uniform(0.001, 0.02, 400))
    motion = GroundMotion(t_s - t_s[0], rng.normal(0.0, 2.0, 400), rng.normal(0.0, 1.0, 400))
    times = np.concatenate(
        [
            rng.uniform(-0.5, motion.duration_s + 0.5, 3000),  # random order, some outside
            motion.t_s[::7],  # exactly on samples
            [motion.t_s[0], motion.t_s[-1], np.nextafter(motion.t_s[-1], 10.0), -1e-300],
            np.sort(rng.uniform(0.0, motion.duration_s, 500)),  # forward, as the kernel steps
        ]
    )
    hint = 0
    for t in times:
        for start in (hint, 0, -7, 10**6):  # the answer never depends on the hint
            ah, av, j = ground_acceleration(t, motion.t_s, motion.ah_m_s2, motion.av_m_s2, start)
            assert ah == pytest.approx(motion.horizontal(t), rel=1e-12, abs=1e-12)
            assert av == pytest.approx(motion.vertical(t), rel=1e-12, abs=1e-12)
            if motion.t_s[0] <= t <= motion.t_s[-1]:
                assert motion.t_s[j] <= t <= motion.t_s[j + 1]
        hint = j
    on = motion.t_s[5]
    assert ground_acceleration(on, motion.t_s, motion.ah_m_s2, motion.av_m_s2, 0)[0] == motion.ah_m_s2[5]
    last = ground_acceleration(motion.t_s[-1], motion.t_s, motion.ah_m_s2, motion.av_m_s2, 3)
    assert last[:2] == (motion.ah_m_s2[-1], motion.av_m_s2[-1])


def test_no_motion_is_zero_everywhere():
    empty = np.zeros(0)
    assert ground_acceleration(0.3, empty, empty, empty, 0)[:2] == (0.0, 0.0)
    one = np.ones(1)
    assert ground_acceleration(0.0, one * 0.0, one, one, 0)[:2] == (0.0, 0.0)


# ---------------------------------------------------------------------- placement


def test_placement_is_the_rigid_rotation_of_the_body_polygon():
    rng = np.random.default_rng(5)
    square = np.array([[-0.2, -0.5], [0.2, -0.5], [0.2, 0.5], [-0.2, 0.5]])
    angles = np.linspace(0.0, 2.0 * math.pi, 7, endpoint=False) + 0.05
    triangle = np.array([[-0.3, -0.1], [0.3, -0.1], [0.0, 0.2]])
    polys = [square, triangle]
    records = pack(
        {**tiny_problem(), **polygon_arrays(polys), "mass": np.ones(2), "moving": np.ones(2, dtype=bool)},
        stop_on_overturn=True,
        record_energy=False,
        record_corners=False,
        coherent=True,
    )
    bodies = records[0]
    for theta in angles:
        pos = rng.normal(0.0, 1.0, (2, 2))
        ang = np.array([theta, -2.0 * theta])
        still = (np.zeros((2, 2)), np.zeros(2))
        kin = Motion(pos, ang, *still, *still, *still)
        world = new_world(2, 4)
        for a, poly in enumerate(polys):
            place_body(a, kin, bodies, world)
            n = len(poly)
            rot = rotation_matrix(ang[a])
            expected = poly @ rot.T + pos[a]
            edges = np.roll(poly, -1, axis=0) - poly
            normals = np.column_stack([edges[:, 1], -edges[:, 0]]) / np.hypot(edges[:, 0], edges[:, 1])[:, None]
            np.testing.assert_allclose(world.wv[a, :n], expected, rtol=0, atol=1e-14)
            np.testing.assert_allclose(world.wn[a, :n], normals @ rot.T, rtol=0, atol=1e-14)
            np.testing.assert_allclose(world.wd[a, :n], np.sum(normals @ rot.T * expected, axis=1), atol=1e-14)
            np.testing.assert_allclose(world.lo[a], expected.min(axis=0), atol=1e-14)
            np.testing.assert_allclose(world.hi[a], expected.max(axis=0), atol=1e-14)


# ---------------------------------------------------------------------- integration


def test_free_flight_follows_the_leap_frog_closed_form():
    """A block far above the base under a constant base acceleration (a_h, a_v): in the base
    frame it feels (-a_h, -g - a_v); the leap-frog scheme gives exactly
    x_n = x_0 + n dt v_{-1/2} + dt^2 a n (n + 1) / 2 and a constant spin."""
    dt, n_steps, ah, av, g = 1e-3, 400, 1.5, -0.7, 9.81
    arrays = {
        **tiny_problem(),
        "pos0": np.array([[0.3, 5.0]]),
        "vel0": np.array([[0.2, 1.0]]),
        "angvel0": np.array([0.8]),
        "stop_angle": np.array([100.0]),
        "mt": np.array([0.0, 10.0]),
        "mah": np.array([ah, ah]),
        "mav": np.array([av, av]),
        "g": g,
        "dt": dt,
        "n_steps": n_steps,
        "steps_per_sample": 10,
    }
    out = kernel.simulate(*pack(arrays, stop_on_overturn=True, record_energy=True, record_corners=False, coherent=True))
    assert out.status == kernel.STATUS_COMPLETED and out.n_filled == n_steps // 10 + 1
    n = np.arange(0, n_steps + 1, 10)
    acc = np.array([-ah, -g - av])
    # positions x_n after n kicks of v_{k+1/2} = v_{-1/2} + (k + 1) dt a, k < n
    expected = arrays["pos0"][0] + np.outer(n * dt, arrays["vel0"][0]) + np.outer(dt * dt * n * (n + 1) / 2, acc)
    np.testing.assert_allclose(out.pos[:, 0], expected, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(out.ang[:, 0], 0.8 * dt * n, rtol=1e-12, atol=1e-15)
    assert np.all(out.n_contacts == 0)
    # mechanical energy in the moving base frame: kinetic + potential - base work stays constant
    e = out.energy
    total = e[:, kernel.E_KIN] + e[:, kernel.E_POT] - e[:, kernel.W_BASE]
    assert np.max(np.abs(total - total[0])) < 1e-9 * np.max(np.abs(e[:, kernel.E_POT]))
