"""One body's arithmetic of a time step, in scalars: written once, inlined by numba into the
three loops that step bodies (the general loop :mod:`.simulation` with :mod:`.placement`,
:mod:`.base_contacts` and :mod:`.integration`; the single-body path :mod:`.single`; the runs
stepped together :mod:`.runs`), so that a physics change is made here and every path takes it.

Each helper is ``inline="always"``: numba pastes its body into the caller, so the callers
compute the same operations on the same operands in the same order as when the arithmetic
was written out in each of them (the same doubles: ``tests/test_single_body.py`` and
``tests/test_runs_batched.py``), at the same speed.

The step (:mod:`.integration` for the scheme):

* the base acceleration between two motion samples, a_lo + u (a_hi - a_lo) with
  u = (t - t_lo) / (t_hi - t_lo) (:func:`rockyade.motion.ground.ground_acceleration`);
* a vertex in the base frame, p = x + R(theta) v (:func:`world_x`, :func:`world_y`);
* a vertex on the base (delta = -p_y >= 0) through the one contact law (:func:`base_point`);
* the kick with the optional mass-proportional damping (:func:`damping`, :func:`kicked`);
* the drift (:func:`drifted`) and the blow-up and overturn tests (:func:`blown_up`,
  :func:`beyond_stop_angle`).

numba's on-disk cache keys a compiled function by its own file: after editing this module (or
:mod:`.contact_law`), delete ``rockyade/kernel/__pycache__`` so that the loops are compiled
again with the change.
"""

from __future__ import annotations

import numba

from rockyade.kernel.contact_law import JointLaw, contact_law

#: Beyond these the state is a numerical blow-up, not rocking (a block overturning under
#: gravity turns at a few rad/s): the run fails instead of being called overturned.
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0


@numba.njit(cache=True, nogil=True, inline="always")
def fraction(t: float, t_lo: float, t_span: float) -> float:
    """Where ``t`` lies in a motion interval starting at ``t_lo`` (s) of length ``t_span`` (s):
    u = (t - t_lo) / t_span, between 0 and 1."""
    return (t - t_lo) / t_span


@numba.njit(cache=True, nogil=True, inline="always")
def lerp(u: float, a_lo: float, a_span: float) -> float:
    """a_lo + u a_span: the base acceleration at fraction ``u`` of an interval whose ends are
    ``a_lo`` and ``a_lo + a_span``, m/s^2."""
    return a_lo + u * a_span


@numba.njit(cache=True, nogil=True, inline="always")
def world_x(x: float, c: float, s: float, bx: float, by: float) -> float:
    """x of a body-frame point (bx, by) (m) of a body at centroid x (m) turned by theta
    (c = cos theta, s = sin theta): x + c bx - s by, m."""
    return x + c * bx - s * by


@numba.njit(cache=True, nogil=True, inline="always")
def world_y(y: float, c: float, s: float, bx: float, by: float) -> float:
    """y of a body-frame point (bx, by) (m) of a body at centroid y (m) turned by theta:
    y + s bx + c by, m."""
    return y + s * bx + c * by


@numba.njit(cache=True, nogil=True, inline="always")
def base_point(
    px: float,
    py: float,
    x: float,
    y: float,
    vx: float,
    vy: float,
    w: float,
    s_old: float,
    law: JointLaw,
    dt: float,
) -> tuple[float, float, float, float, float, float, float, int, float]:
    """The force of the base on a vertex p = (px, py) below it (delta = -p_y >= 0, m).

    The base normal is n = (0, 1) and the tangent t = (-1, 0); with r = p - x the relative
    velocity is v + w x r, so delta_dot = -v_y and v_t = -v_x (:mod:`.base_contacts`). The
    law (:mod:`.contact_law`) gives F_n, S and the shear dashpot; the force
    F_n n - (S + c_s v_t) t = (S + c_s v_t, F_n) acts at p.

    Parameters
    ----------
    px, py
        The vertex, base frame, m.
    x, y, vx, vy, w
        The body's centroid (m), velocity (m/s) and angular velocity (rad/s).
    s_old
        The vertex's shear spring of the last step, N.
    law, dt
        The base joint's law and the time step, s.

    Returns
    -------
    fx, fy, tz
        The force on the body (N) and its moment about the centroid, r x F (N m).
    fn, fn_spring, s_new, visc, state, slip_work
        As :func:`rockyade.kernel.contact_law.contact_law`.
    """
    delta = -py
    rax = px - x
    ray = py - y
    vrx = vx - w * ray
    vry = vy + w * rax
    fn, fn_spring, s_new, visc, state, slip_work = contact_law(delta, -vry, -vrx, s_old, law, dt)
    fx = s_new + visc
    return fx, fn, rax * fn - ray * fx, fn, fn_spring, s_new, visc, state, slip_work


@numba.njit(cache=True, nogil=True, inline="always")
def damping(mass: float, inertia: float, a: float, vx: float, vy: float, w: float) -> tuple[float, float, float]:
    """The mass-proportional damping -a (m v_x, m v_y, I w) (N, N, N m) of a body of mass
    ``mass`` (kg) and inertia ``inertia`` (kg m^2) at the velocities v_{n-1/2} (m/s, rad/s);
    ``a`` in 1/s."""
    return -a * mass * vx, -a * mass * vy, -a * inertia * w


@numba.njit(cache=True, nogil=True, inline="always")
def kicked(v: float, f: float, m: float, dt: float) -> float:
    """The leap-frog kick of one velocity component: v + dt f / m (m/s or rad/s; f in N or
    N m, m in kg or kg m^2)."""
    return v + dt * f / m


@numba.njit(cache=True, nogil=True, inline="always")
def drifted(x: float, v: float, dt: float) -> float:
    """The leap-frog drift of one coordinate: x + dt v (m or rad)."""
    return x + dt * v


@numba.njit(cache=True, nogil=True, inline="always")
def blown_up(vx: float, vy: float, w: float) -> bool:
    """Whether velocities v (m/s) and w (rad/s) are a numerical blow-up: beyond
    ``MAX_SPEED_M_S`` or ``MAX_SPIN_RAD_S``, or not finite (NaN fails both comparisons)."""
    return not (vx * vx + vy * vy <= MAX_SPEED_M_S * MAX_SPEED_M_S and abs(w) <= MAX_SPIN_RAD_S)


@numba.njit(cache=True, nogil=True, inline="always")
def beyond_stop_angle(ang: float, rest_ang: float, stop_angle: float) -> bool:
    """Whether a body at angle ``ang`` has turned from its rest angle ``rest_ang`` by at least
    ``stop_angle`` (all rad): it has overturned (:mod:`rockyade.dem.overturn`)."""
    return abs(ang - rest_ang) >= stop_angle
