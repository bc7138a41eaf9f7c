"""Recording: what the kernel keeps every ``steps_per_sample`` steps, at t_n.

Per body: centroid position and rotation (x_n), angular velocity and the velocity of the
output point (averaged over the step: (v_{n-1/2} + v_{n+1/2}) / 2), the number of contact
points on the body and whether one of them slips; optionally the state of each vertex
(0 open, 1 stick, 2 slip: the worst state of the points at that corner) and the energy
terms (:mod:`rockyade.kernel.energy`).

A contact point belongs to a vertex when it lies within ``CORNER_TOL_REL`` of the smaller
block's width from it (penetrations are far smaller, another block's corner is farther).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.contact_law import STATE_SLIP
from rockyade.kernel.energy import E_DASH, E_EL, E_FRIC, E_KIN, E_POT, N_ENERGY, W_BASE

#: A contact point counts for a vertex's state within this fraction of the smaller block's width.
CORNER_TOL_REL = 0.01


class Samples(NamedTuple):
    """The sampled outputs (see :class:`Output`)."""

    pos: NDArray[np.float64]  #: (n_samples, nb, 2) m
    ang: NDArray[np.float64]  #: (n_samples, nb) rad
    angvel: NDArray[np.float64]  #: (n_samples, nb) rad/s
    vpoint: NDArray[np.float64]  #: (n_samples, nb, 2) m/s
    corner_states: NDArray[np.int8]  #: (n_samples or 1, nb, maxv)
    energy: NDArray[np.float64]  #: (n_samples, N_ENERGY) J
    n_contacts: NDArray[np.int32]  #: (n_samples, nb)
    slipping: NDArray[np.bool_]  #: (n_samples, nb)
    overturn_time: NDArray[np.float64]  #: (nb,) s


class Output(NamedTuple):
    """What :func:`rockyade.kernel.simulation.simulate` returns (the fields of
    :class:`rockyade.dem.engine.KernelOutput`, in its order)."""

    pos: NDArray[np.float64]  #: (n_samples, nb, 2) centroids, m (NaN after the run ended)
    ang: NDArray[np.float64]  #: (n_samples, nb) angles, rad
    angvel: NDArray[np.float64]  #: (n_samples, nb) step-mean angular velocities, rad/s
    vpoint: NDArray[np.float64]  #: (n_samples, nb, 2) step-mean velocity of the output point, m/s
    corner_states: NDArray[np.int8]  #: (n_samples or 1, nb, maxv) vertex states (zeros unless recorded)
    energy: NDArray[np.float64]  #: (n_samples, 6) energy terms, J (NaN unless recorded)
    status: int  #: STATUS_COMPLETED, STATUS_OVERTURNED or STATUS_FAILED
    n_filled: int  #: samples written
    t_stop: float  #: time the run ended early, s (-1: it ran to the end)
    stop_body: int  #: body that ended it (-1: none)
    n_contacts: NDArray[np.int32]  #: (n_samples, nb) contact points on each body
    slipping: NDArray[np.bool_]  #: (n_samples, nb) a point of the body slips
    overturn_time: NDArray[np.float64]  #: (nb,) first time |theta| >= stop angle, s (NaN: never)
    n_builds: int  #: broad-phase builds
    max_pairs: int  #: largest candidate list
    n_tests: int  #: separating-axis tests run (pair-steps)


class Tally(NamedTuple):
    """Contact points of the current step, per body and per vertex (while sampling)."""

    ncont: NDArray[np.int32]  #: (nb,) points on each body
    slipping: NDArray[np.bool_]  #: (nb,) one of them slips
    vstate: NDArray[np.int8]  #: (nb, maxv) worst state of the points at each vertex


@numba.njit(cache=True, nogil=True, inline="always")
def new_samples(nb: int, maxv: int, n_samples: int, record_corners: bool) -> Samples:
    """NaN-filled samples (zero counts and states)."""
    return Samples(
        np.full((n_samples, nb, 2), np.nan),
        np.full((n_samples, nb), np.nan),
        np.full((n_samples, nb), np.nan),
        np.full((n_samples, nb, 2), np.nan),
        np.zeros((n_samples if record_corners else 1, nb, maxv), dtype=np.int8),
        np.full((n_samples, N_ENERGY), np.nan),
        np.zeros((n_samples, nb), dtype=np.int32),
        np.zeros((n_samples, nb), dtype=np.bool_),
        np.full(nb, np.nan),
    )


@numba.njit(cache=True, nogil=True, inline="always")
def output_of(
    s: Samples,
    status: int,
    n_filled: int,
    t_stop: float,
    stop_body: int,
    n_builds: int,
    max_pairs: int,
    n_tests: int,
) -> Output:
    """The run's :class:`Output`: its samples ``s`` and how it ended (the fields' meanings there)."""
    return Output(
        s.pos,
        s.ang,
        s.angvel,
        s.vpoint,
        s.corner_states,
        s.energy,
        status,
        n_filled,
        t_stop,
        stop_body,
        s.n_contacts,
        s.slipping,
        s.overturn_time,
        n_builds,
        max_pairs,
        n_tests,
    )


@numba.njit(cache=True, nogil=True, inline="always")
def new_tally(nb: int, maxv: int) -> Tally:
    """An empty tally."""
    return Tally(np.zeros(nb, dtype=np.int32), np.zeros(nb, dtype=np.bool_), np.zeros((nb, maxv), dtype=np.int8))


@numba.njit(cache=True, nogil=True, inline="always")
def reset_tally(tally, record_corners: bool) -> None:
    """Empty the tally at the start of a sampled step."""
    tally.ncont[:] = 0
    tally.slipping[:] = False
    if record_corners:
        tally.vstate[:, :] = 0


@numba.njit(cache=True, nogil=True, inline="always")
def count_point(tally, a: int, state: int) -> None:
    """One contact point on body ``a`` in ``state``."""
    tally.ncont[a] += 1
    if state == STATE_SLIP:
        tally.slipping[a] = True


@numba.njit(cache=True, nogil=True, inline="always")
def mark_corner(vstate, body: int, v: int, px: float, py: float, wv, tol2: float, state: int) -> None:
    """Raise vertex v's state to ``state`` when the point (px, py) lies within sqrt(tol2) of it."""
    dx = wv[body, v, 0] - px
    dy = wv[body, v, 1] - py
    if dx * dx + dy * dy <= tol2 and state > vstate[body, v]:
        vstate[body, v] = state


@numba.njit(cache=True, nogil=True, inline="always")
def mark_pair_corners(
    tally, world, bodies, a: int, b: int, ref: int, face: int, inc: int, edge: int, px: float, py: float, state: int
) -> None:
    """Raise the states of the vertices at a pair's contact point (px, py): the ends of the
    reference face and of the incident edge (within ``CORNER_TOL_REL`` of the smaller width)."""
    vstate, wv, scale, nverts = tally.vstate, world.wv, bodies.scale, bodies.nverts
    tol2 = (CORNER_TOL_REL * min(scale[a], scale[b])) ** 2
    nr = nverts[ref]
    ni = nverts[inc]
    mark_corner(vstate, ref, face, px, py, wv, tol2, state)
    mark_corner(vstate, ref, face + 1 if face + 1 < nr else 0, px, py, wv, tol2, state)
    mark_corner(vstate, inc, edge, px, py, wv, tol2, state)
    mark_corner(vstate, inc, edge + 1 if edge + 1 < ni else 0, px, py, wv, tol2, state)


@numba.njit(cache=True, nogil=True, inline="always")
def record_sample(k: int, samples, bodies, kin, tally, record_corners: bool) -> None:
    """Sample k of the bodies' state at t_n (velocities averaged over the step)."""
    pos, ang, vel, vel_prev, angvel, angvel_prev = kin.pos, kin.ang, kin.vel, kin.vel_prev, kin.angvel, kin.angvel_prev
    ap, nverts = bodies.accel_points, bodies.nverts
    ncont, slipping, vstate = tally.ncont, tally.slipping, tally.vstate
    s_pos, s_ang, s_angvel, s_vpoint = samples.pos, samples.ang, samples.angvel, samples.vpoint
    s_ncont, s_slip, s_state = samples.n_contacts, samples.slipping, samples.corner_states
    for a in range(nverts.size):
        vx = 0.5 * (vel[a, 0] + vel_prev[a, 0])
        vy = 0.5 * (vel[a, 1] + vel_prev[a, 1])
        w = 0.5 * (angvel[a] + angvel_prev[a])
        s_pos[k, a, 0] = pos[a, 0]
        s_pos[k, a, 1] = pos[a, 1]
        s_ang[k, a] = ang[a]
        s_angvel[k, a] = w
        c = math.cos(ang[a])
        s = math.sin(ang[a])
        qx = c * ap[a, 0] - s * ap[a, 1]
        qy = s * ap[a, 0] + c * ap[a, 1]
        s_vpoint[k, a, 0] = vx - w * qy
        s_vpoint[k, a, 1] = vy + w * qx
        s_ncont[k, a] = ncont[a]
        s_slip[k, a] = slipping[a]
        if record_corners:
            for v in range(nverts[a]):
                s_state[k, a, v] = vstate[a, v]


@numba.njit(cache=True, nogil=True, inline="always")
def record_energy_sample(
    k: int,
    samples,
    e_kin: float,
    e_pot: float,
    e_el: float,
    e_dash: float,
    e_dash_before: float,
    e_fric: float,
    w_base: float,
    w_base_before: float,
) -> None:
    """Sample k of the energy terms; the dashpot and base work are the mean of their values
    before and after the step (half of its work belongs before t_n and half after it)."""
    e = samples.energy
    e[k, E_KIN] = e_kin
    e[k, E_POT] = e_pot
    e[k, E_EL] = e_el
    e[k, E_DASH] = 0.5 * (e_dash + e_dash_before)
    e[k, E_FRIC] = e_fric
    e[k, W_BASE] = 0.5 * (w_base + w_base_before)
