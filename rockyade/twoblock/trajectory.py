"""A run of the two-block stack from Python: the start (a released block, or rest), the
compiled integration (:mod:`rockyade.twoblock.event_driven`), and what it found."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from rockyade.motion.ground import GroundMotion
from rockyade.twoblock import event_driven as integ
from rockyade.twoblock.dynamics import ADMISSIBLE_TOL, choose_mode, ground
from rockyade.twoblock.stack import TwoBlockModel

_STATUS_NAMES = ("completed", "overturned", "failed")
#: Why a run failed, by the integrator's failure code.
FAILURE_REASONS = {
    integ.FAIL_FLIGHT_BASE: "the lower block's pivot would pull on the base (N < 0): the stack leaves the "
    "ground, outside pure rocking",
    integ.FAIL_FLIGHT_SEAT: "the upper block's pivot would pull on its seat (N < 0): the upper block leaves "
    "the lower one, outside pure rocking",
    integ.FAIL_NO_MODE: "no rocking mode satisfies the contact conditions here (the stack would leave its "
    "supports, outside pure rocking)",
    integ.FAIL_STUCK: f"more than {integ.MAX_EVENTS_AT_ONE_TIME} events at one instant without a mode to go on in",
}


@dataclass
class TwoBlockTrajectory:
    """What the integration found.

    Attributes
    ----------
    t_s
        Sample times, s (up to the overturn or the failure).
    theta_rad, omega_rad_s, theta_dd_rad_s2
        (n, 2) absolute rotations (rad), angular velocities (rad/s) and accelerations
        (rad/s^2) of the lower and upper block.
    modes
        (n, 2) the base and seat joints' state: +1 rocking on the left corner, -1 on the
        right one, 0 closed.
    impacts
        (k, 8): time, joint (0 base, 1 seat), omega_1 and omega_2 before, after, and the
        joints' states after.
    peaks
        (k, 3): time, block (0 lower, 1 upper), theta at an extreme of the rotation.
    uplift_times_s
        When the stack left rest.
    mode_changes
        (k, 3): time and the joints' states from then on.
    counts
        All impacts, peaks, uplifts and mode changes (the arrays keep the first
        ``MAX_RECORDED_EVENTS``), and impacts with no admissible outcome (the least violated
        was taken).
    friction_max
        Largest |T| / N of the base and seat joints between events.
    friction_exceeded_s
        When |T| / N first exceeded each joint's friction coefficient (None: never).
    impulse_ratio_max
        Largest tangential over normal impulse at a landing corner, per joint.
    pivot_tension_s
        When each joint's pivot first pulled (N < 0) while the joint was past its alpha
        (held, as in Housner's model: the block falls either way), s; None: never. Within
        alpha a pulling pivot ends the run as failed.
    status
        "completed", "overturned" or "failed".
    end_time_s
        When the run stopped early (overturn or failure), s; None otherwise.
    overturned_block
        0 (lower) or 1 (upper) when overturned, else None.
    failure_reason
        Why it failed (None otherwise).
    step_s
        Largest Runge-Kutta step, s.
    """

    t_s: np.ndarray
    theta_rad: np.ndarray
    omega_rad_s: np.ndarray
    theta_dd_rad_s2: np.ndarray
    modes: np.ndarray
    impacts: np.ndarray
    peaks: np.ndarray
    uplift_times_s: np.ndarray
    mode_changes: np.ndarray
    counts: dict[str, int]
    friction_max: tuple[float, float]
    friction_exceeded_s: tuple[float | None, float | None]
    impulse_ratio_max: tuple[float, float]
    pivot_tension_s: tuple[float | None, float | None]
    status: str
    end_time_s: float | None
    overturned_block: int | None
    failure_reason: str | None
    step_s: float


def initial_state(
    model: TwoBlockModel, released: int, theta0: float, omega0: float, motion: GroundMotion | None
) -> tuple[float, float, float, float, int, int]:
    """(theta_1, phi, omega_1, omega_phi, base mode, seat mode) at t = 0.

    The released block turns by ``theta0`` (rad) at ``omega0`` (rad/s) with what rests on it,
    as the DEMs release it: the lower block (index 0) takes the upper one along (the stack
    about a base corner), the upper block (1) turns about a corner of its seat. A closed joint
    then takes the mode the contact conditions give (:func:`rockyade.twoblock.dynamics.choose_mode`).
    """
    if theta0 == 0.0 and omega0 == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0, 0
    side = 1 if theta0 > 0 or (theta0 == 0 and omega0 > 0) else -1
    th1, phi, w1, wp, sb, ss = 0.0, 0.0, 0.0, 0.0, 0, 0
    if released == 0:
        th1, w1, sb = theta0, omega0, side
    else:
        phi, wp, ss = theta0, omega0, side
    ah, av = ground(0.0, *_motion_arrays(motion, 0.0))
    nsb, nss, viol = choose_mode(th1, phi, w1, wp, sb, ss, ah, av, model.params(), sb == 0, ss == 0, False, False)
    if viol <= ADMISSIBLE_TOL:
        sb, ss = nsb, nss
    return th1, phi, w1, wp, sb, ss


def _motion_arrays(motion: GroundMotion | None, duration_s: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The base motion's samples (empty arrays: the base at rest)."""
    if motion is None:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    return motion.t_s, motion.ah_m_s2, motion.av_m_s2


def max_step(model: TwoBlockModel, dt_factor: float = 1.0) -> float:
    """The largest Runge-Kutta step, s: ``dt_factor`` / (``STEPS_PER_RADIAN`` p), p the larger of
    the stack's (rocking as one body) and the upper block's (on its seat)."""
    (p2_base, _), (p2_seat, _) = model.joint_rocking()
    return dt_factor / (integ.STEPS_PER_RADIAN * math.sqrt(max(p2_base, p2_seat)))


def solve(
    model: TwoBlockModel,
    motion: GroundMotion | None,
    duration_s: float,
    released: int = 1,
    theta0: float = 0.0,
    omega0: float = 0.0,
    sample_dt_s: float = 0.001,
    step_s: float | None = None,
) -> TwoBlockTrajectory:
    """Integrate the stack from t = 0 to ``duration_s``.

    Parameters
    ----------
    model
        The stack.
    motion
        Base acceleration (None: the base is at rest).
    duration_s
        End time, s.
    released, theta0, omega0
        The block given the initial tilt (0 lower, 1 upper), the tilt (rad) and its rate (rad/s).
    sample_dt_s
        Output sampling interval, s.
    step_s
        Largest Runge-Kutta step, s (default :func:`max_step`).
    """
    prm = model.params()
    step = max_step(model) if step_s is None else float(step_s)
    mt, mah, mav = _motion_arrays(motion, duration_s)
    th1, phi, w1, wp, sb, ss = initial_state(model, released, float(theta0), float(omega0), motion)
    n_samples = math.floor(duration_s / sample_dt_s + 1e-9) + 1
    out = integ.integrate(
        prm,
        mt,
        mah,
        mav,
        float(duration_s),
        th1,
        phi,
        w1,
        wp,
        sb,
        ss,
        float(sample_dt_s),
        n_samples,
        step,
        integ.REST_FRACTION,
        integ.MAX_RECORDED_EVENTS,
    )
    samples, modes, impacts, peaks, uplifts, changes, counts, fmax, fexceed, imp_ratio, tension = out[:11]
    status, fail_code, t_end, over_block, n_filled = out[11:]
    status = int(status)
    n_keep = int(n_filled) if status != 0 else n_samples
    cap = integ.MAX_RECORDED_EVENTS
    n_imp, n_peak, n_up, n_change, n_bad = (int(c) for c in counts)
    return TwoBlockTrajectory(
        t_s=np.arange(n_keep) * sample_dt_s,
        theta_rad=samples[:n_keep, 0:2].copy(),
        omega_rad_s=samples[:n_keep, 2:4].copy(),
        theta_dd_rad_s2=samples[:n_keep, 4:6].copy(),
        modes=modes[:n_keep].astype(int),
        impacts=impacts[: min(n_imp, cap)],
        peaks=peaks[: min(n_peak, cap)],
        uplift_times_s=uplifts[: min(n_up, cap)],
        mode_changes=changes[: min(n_change, cap)],
        counts={"impacts": n_imp, "peaks": n_peak, "uplifts": n_up, "mode_changes": n_change, "inadmissible": n_bad},
        friction_max=(float(fmax[0]), float(fmax[1])),
        friction_exceeded_s=tuple(float(x) if x >= 0 else None for x in fexceed),  # type: ignore[arg-type]
        impulse_ratio_max=(float(imp_ratio[0]), float(imp_ratio[1])),
        pivot_tension_s=tuple(float(x) if x >= 0 else None for x in tension),  # type: ignore[arg-type]
        status=_STATUS_NAMES[status],
        end_time_s=float(t_end) if status != 0 else None,
        overturned_block=int(over_block) if status == 1 else None,
        failure_reason=FAILURE_REASONS.get(int(fail_code)) if status == 2 else None,
        step_s=step,
    )


@functools.cache
def warm_up() -> None:
    """Load the compiled kernel once per process, so that wall times measure the solve (the
    first run after an installation compiles it: the solver says so,
    :func:`rockyade.solvers.base.say_if_compiling`)."""
    from rockyade.twoblock.stack import TwoBlockModel

    model = TwoBlockModel(
        names=("lower", "upper"),
        mass_kg=(2.0, 1.0),
        inertia_c_kgm2=(0.1, 0.05),
        centroid_m=((0.0, 0.5), (0.0, 1.5)),
        base_corners_x_m=(-0.2, 0.2),
        seat_corners_x_m=(-0.15, 0.15),
        seat_y_m=1.0,
        heights_m=(1.0, 1.0),
        widths_m=(0.4, 0.3),
        friction=(0.7, 0.7),
    )
    motion = GroundMotion(np.array([0.0, 0.05, 0.1]), np.array([0.0, 5.0, 0.0]))
    solve(model, motion, 0.02, 1, 0.01)
