"""The reference DEM's time loop: rigid convex polygons with the paper's joint.

Each step t_n = n dt, in this order:

1. ground motion: the base acceleration a_h, a_v at t_n (:func:`rockyade.motion.ground.
   ground_acceleration`, linear between samples, zero outside them);
2. placement: the moving bodies' polygons in the base frame (:mod:`.placement`);
3. loads: gravity and the base frame's inertia, m (-a_h, -g - a_v) (:mod:`.integration`),
   and the point loads (:mod:`.point_loads`);
4. base contacts: every vertex below y = 0 (:mod:`.base_contacts`);
5. pair contacts: one manifold of at most two points per candidate pair (:mod:`.pair_contacts`,
   :mod:`.contacts`), each point with the pair's joint;
   both use the one contact law (:mod:`.contact_law`): F_n = K delta + c_n delta_dot >= 0
   (no tension), an incremental shear spring S += K_s dt v_t capped at F_n tan(phi)
   (Coulomb; slip), the shear dashpot c_s v_t only while sticking;
6. kick: v_{n+1/2} = v_{n-1/2} + dt F / m (the leap-frog scheme of YADE's NewtonIntegrator);
7. energy terms with the step-mean velocities (:mod:`.energy`), and every
   ``steps_per_sample`` steps a sample at t_n (:mod:`.recording`);
8. drift: x_{n+1} = x_n + dt v_{n+1/2}, then the overturn and blow-up checks;
9. broad phase: when a body has moved by more than its margin, the candidate pairs are
   rebuilt by sort and sweep over grown boxes (:mod:`.broadphase`, :mod:`.pairs`), so a
   step costs O(bodies + pairs).

The inputs are five records (:mod:`.state`); the output is an :class:`Output` record.
:func:`simulate` allocates the working state (:class:`Work`) and rebuilds the candidate
pairs; :func:`advance` runs the steps 1-8 (and the test of step 9) between two rebuilds.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.base_contacts import BaseState, base_contacts, new_base_state
from rockyade.kernel.broadphase import initial_order, moved_beyond_margin
from rockyade.kernel.contact_law import STATE_OPEN, STATE_SLIP, STATE_STICK
from rockyade.kernel.energy import (
    E_DASH,
    E_EL,
    E_FRIC,
    E_KIN,
    E_POT,
    N_ENERGY,
    T_BASE,
    T_DASH,
    T_EL,
    T_FRIC,
    W_BASE,
    Dashpots,
    add_base_work,
    add_dashpot_work,
    dashpot_room,
    mechanical_energy,
    new_dashpots,
    new_totals,
)
from rockyade.kernel.integration import (
    MAX_SPEED_M_S,
    MAX_SPIN_RAD_S,
    STATUS_COMPLETED,
    STATUS_FAILED,
    STATUS_OVERTURNED,
    Motion,
    apply_body_loads,
    drift,
    initial_motion,
    kick,
)
from rockyade.kernel.pair_contacts import pair_manifold, pair_opened, pair_points
from rockyade.kernel.pairs import PairState, build_pairs, no_pairs
from rockyade.kernel.point_loads import apply_point_loads
from rockyade.kernel.recording import (
    CORNER_TOL_REL,
    Output,
    Samples,
    Tally,
    new_samples,
    new_tally,
    output_of,
    record_energy_sample,
    record_sample,
    reset_tally,
)
from rockyade.kernel.world import World, new_world, place_bodies
from rockyade.motion.ground import ground_acceleration

__all__ = [
    "CORNER_TOL_REL",
    "E_DASH",
    "E_EL",
    "E_FRIC",
    "E_KIN",
    "E_POT",
    "MAX_SPEED_M_S",
    "MAX_SPIN_RAD_S",
    "N_ENERGY",
    "STATE_OPEN",
    "STATE_SLIP",
    "STATE_STICK",
    "STATUS_COMPLETED",
    "STATUS_FAILED",
    "STATUS_OVERTURNED",
    "W_BASE",
    "Output",
    "Work",
    "advance",
    "simulate",
]


class Work(NamedTuple):
    """The run's working state (arrays updated in place; ``pairs`` and ``dash`` are replaced
    at a rebuild)."""

    kin: Motion  #: the bodies' state and loads
    world: World  #: the placed polygons
    base: BaseState  #: shear springs of the base contacts
    pairs: PairState  #: candidate pairs and their state
    dash: Dashpots  #: this step's contact points for the dashpot power
    tally: Tally  #: this step's contact counts and vertex states
    samples: Samples  #: the sampled outputs
    totals: NDArray[np.float64]  #: (4,) running energy totals (``T_*`` of :mod:`.energy`)
    clip: NDArray[np.float64]  #: (2, 3) scratch for a manifold's points


@numba.njit(cache=True, nogil=True)
def simulate(bodies, joints, motion, settings, initial) -> Output:
    """Run the DEM (module docstring).

    Parameters
    ----------
    bodies, joints, motion, settings, initial
        :class:`rockyade.kernel.state.Bodies`, ``Joints``, ``BaseMotion``, ``Settings`` and
        ``Initial`` (:func:`rockyade.kernel.state.pack`).

    Returns
    -------
    Output
        The samples, how the run ended and the broad phase's counts.
    """
    nb, maxv = bodies.verts.shape[0], bodies.verts.shape[1]
    kin = initial_motion(bodies, initial)
    world = new_world(nb, maxv)
    place_bodies(kin, bodies, world, False)
    axis, order = initial_order(world.lo, world.hi)
    pairs = build_pairs(no_pairs(), bodies, joints, kin, world, axis, order)
    n_base = np.sum(bodies.nverts * bodies.moving)
    dash = dashpot_room(settings.record_energy, n_base, pairs.keys.size, new_dashpots(1))
    samples = new_samples(nb, maxv, settings.n_steps // settings.steps_per_sample + 1, settings.record_corners)
    work = Work(
        kin, world, new_base_state(nb, maxv), pairs, dash, new_tally(nb, maxv), samples, new_totals(), np.zeros((2, 3))
    )
    # int64, not the literal 0: advance would be compiled twice, for Literal[int](0) and for int64
    step, hint, n_filled = np.int64(0), np.int64(0), np.int64(0)
    n_tests, n_builds, max_pairs = 0, 1, pairs.keys.size
    while True:
        # one stretch of steps per candidate list
        step, rebuild, status, t_stop, stop_body, hint, n_filled, tests = advance(
            step, hint, n_filled, bodies, joints, motion, settings, work
        )
        n_tests += tests
        if not rebuild:
            break
        pairs = build_pairs(work.pairs, bodies, joints, kin, world, axis, order)
        dash = dashpot_room(settings.record_energy, n_base, pairs.keys.size, work.dash)
        work = Work(kin, world, work.base, pairs, dash, work.tally, samples, work.totals, work.clip)
        n_builds += 1
        max_pairs = max(max_pairs, pairs.keys.size)
    return output_of(samples, status, n_filled, t_stop, stop_body, n_builds, max_pairs, n_tests)


# Compiled without numba's reference counting (``_nrt=False``): it allocates nothing and
# returns scalars only, and every function it calls is inlined. With it, passing the records
# to the inlined parts costs nothing; with reference counting, every array of a record passed
# to a part inside a loop was counted up and down at each call (an atomic operation each, 15x
# slower in all).
@numba.njit(cache=True, nogil=True, _nrt=False)  # type: ignore[call-overload]  # numba's stubs omit _nrt
def advance(
    step0: int, hint: int, n_filled: int, bodies, joints, motion, settings, work
) -> tuple[int, bool, int, float, int, int, int, int]:
    """Run steps from ``step0`` until the end, an early stop, or a body leaving its margin.

    Parameters
    ----------
    hint
        The ground-motion lookup's cursor.
    n_filled
        Samples written so far.
    work
        :class:`Work`, updated.

    Returns
    -------
    step, rebuild, status, t_stop, stop_body, hint, n_filled, n_tests
        The next step to run; whether the candidate pairs must be rebuilt before it; the run's
        status, the time it stopped early (-1: it did not) and the body that stopped it (-1:
        none); the cursor; the samples written; the separating-axis tests run.
    """
    kin, world, base, pairs, dash, tally, samples, totals, clip = work
    dt, sps, n_steps, g = settings.dt, settings.steps_per_sample, settings.n_steps, settings.g
    record_energy, record_corners, coherent = settings.record_energy, settings.record_corners, settings.coherent
    mt, mah, mav = motion.t_s, motion.ah, motion.av
    nb = bodies.mass.size
    e_el, e_dash, e_fric, w_base = totals[T_EL], totals[T_DASH], totals[T_FRIC], totals[T_BASE]
    status, t_stop, stop_body, n_tests, rebuild = STATUS_COMPLETED, -1.0, -1, 0, False
    step = step0
    for step in range(step0, n_steps + 1):
        ah, av, hint = ground_acceleration(step * dt, mt, mah, mav, hint)
        sampling = step % sps == 0
        if step > 0:
            place_bodies(kin, bodies, world, True)
        apply_body_loads(bodies, kin, g, ah, av)
        apply_point_loads(bodies, kin, g, av)
        if sampling:
            reset_tally(tally, record_corners)
        e_el_now, n_dash, d_fric = base_contacts(
            bodies, joints, settings, kin, world, base, tally, dash, sampling, 0.0, 0, 0.0
        )
        # the pair contacts (.pair_contacts), each part inlined here rather than in one
        # function of the pass: numba copies an inlined function's whole tree into each
        # caller, and one copy of the pass's (manifold, points, contact law) cost a fifth of
        # this loop's compilation (the same code, the same bits, the same speed)
        for k in range(pairs.side.size):
            n_new, apart, side, face, ref, inc, edge, tested = pair_manifold(
                k, bodies, kin, world, pairs, coherent, clip
            )
            n_tests += tested
            if n_new == 0:
                d_fric = pair_opened(k, pairs, joints, apart, record_energy, d_fric)
                continue
            pairs.side[k] = side
            pairs.face[k] = face
            e_el_now, n_dash, d_fric = pair_points(
                k,
                n_new,
                ref,
                inc,
                face,
                edge,
                bodies,
                joints,
                settings,
                kin,
                world,
                pairs,
                tally,
                dash,
                clip,
                sampling,
                e_el_now,
                n_dash,
                d_fric,
            )
        e_dash_before, w_base_before = e_dash, w_base
        e_dash = kick(bodies, kin, dt, settings.mass_damping, record_energy, e_dash)
        if record_energy:
            e_dash = add_dashpot_work(e_dash, dash, n_dash, kin, dt)
            e_fric += d_fric
            w_base = add_base_work(w_base, bodies, kin, ah, av, dt)
            e_el = e_el_now
        if sampling:
            k = step // sps
            record_sample(k, samples, bodies, kin, tally, record_corners)
            if record_energy:
                e_kin, e_pot = mechanical_energy(bodies, kin, g)
                record_energy_sample(
                    k, samples, e_kin, e_pot, e_el, e_dash, e_dash_before, e_fric, w_base, w_base_before
                )
            n_filled = k + 1
        if step == n_steps:
            break
        status, stop_body = drift(bodies, kin, samples, step, dt, settings.stop_on_overturn, status)
        if status != STATUS_COMPLETED:
            t_stop = (step + 1) * dt
            break
        if nb > 1 and moved_beyond_margin(
            kin.pos, kin.ang, pairs.pos_at_build, pairs.ang_at_build, bodies.radius, bodies.margin, bodies.moving
        ):
            rebuild = True
            step += 1
            break
    totals[T_EL], totals[T_DASH], totals[T_FRIC], totals[T_BASE] = e_el, e_dash, e_fric, w_base
    return step, rebuild, status, t_stop, stop_body, hint, n_filled, n_tests
