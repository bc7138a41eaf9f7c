"""The modelled measurement of a free-rocking test: Housner's exact solution, shifted to the
release time, on the measurement grid, with the hold before the release and a sensor offset.

    theta_m(t) = s theta_H(t - t_r; alpha, p, mu, r alpha) + o        (t >= t_r)
    theta_m(t) = s r alpha + o                                        (t <  t_r, the hold)

theta_H is the free rocking of a symmetric block released at rest from theta_0 = r alpha
(paper Eq 1, base at rest, omega multiplied by mu at each impact), computed by
:func:`rockyade.housner.solve`; s is the side the block was tilted to, t_r the release
time and o the sensor offset. The solver is advanced from the release to the first sample
after it, then sampled on the measurement grid, so the model is exact at the measurement
times whatever the release time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import RockyadeError
from rockyade.housner import HousnerModel, Trajectory, solve
from rockyade.identification.measurement import MeasuredHistory, measured_history

#: The fitted unknowns, in the order of the parameter vector.
FIT_PARAMETERS = ("alpha_rad", "p_rad_s", "mu", "release_time_s", "offset_rad", "release_ratio")


class IdentificationError(RockyadeError):
    """The record shows no free rocking that Housner's model can be fitted to."""


@dataclass(frozen=True)
class FreeRockingFit:
    """Values of the six unknowns.

    Attributes
    ----------
    alpha_rad, p_rad_s, mu
        Classical parameters (rad, rad/s, -).
    release_time_s
        Time of the release, s (in the record's time base).
    offset_rad
        Sensor offset: the reading when the block stands upright, rad.
    release_ratio
        theta_0 / alpha, the release tilt as a fraction of alpha (0 < r < 1).
    side
        +1 when released tilted to theta > 0, -1 otherwise.
    """

    alpha_rad: float
    p_rad_s: float
    mu: float
    release_time_s: float
    offset_rad: float
    release_ratio: float
    side: int = 1

    @property
    def vector(self) -> NDArray[np.float64]:
        """The unknowns in :data:`FIT_PARAMETERS` order."""
        return np.array([getattr(self, k) for k in FIT_PARAMETERS])

    @classmethod
    def from_vector(cls, x: NDArray[np.float64], side: int) -> FreeRockingFit:
        """Unknowns from a parameter vector.

        Parameters
        ----------
        x
            Values in the order of :data:`FIT_PARAMETERS` (rad, 1/s, -, s, rad, -).
        side
            The side the block was tilted to: +1 or -1.
        """
        alpha_rad, p_rad_s, mu, release_time_s, offset_rad, release_ratio = (float(v) for v in x)
        return cls(alpha_rad, p_rad_s, mu, release_time_s, offset_rad, release_ratio, side=side)

    @property
    def theta0_rad(self) -> float:
        """Signed release tilt, rad."""
        return self.side * self.release_ratio * self.alpha_rad


def model_history(
    fit: FreeRockingFit, t0_s: float, dt_s: float, n: int, step_s: float | None = None
) -> tuple[NDArray[np.float64], Trajectory | None, float]:
    """The modelled measurement at t0 + k dt (k = 0..n-1), and Housner's trajectory.

    Parameters
    ----------
    fit
        Values of the six unknowns.
    t0_s, dt_s
        Time of the first sample and the sampling interval, s.
    n
        Number of samples.
    step_s
        Largest step of Housner's solver, s (None: its default).

    Returns
    -------
    theta
        Modelled reading, rad (hold, then free rocking, plus the offset).
    trajectory
        The solver's trajectory from the first sample after the release (or None when the
        release is after the record).
    delta_s
        Time from the release to that first sample, s.
    """
    theta = np.full(n, fit.theta0_rad + fit.offset_rad)
    i0 = max(0, math.ceil((fit.release_time_s - t0_s) / dt_s - 1e-9))
    if i0 >= n:
        return theta, None, 0.0
    model = HousnerModel.symmetric(fit.alpha_rad, fit.p_rad_s, fit.mu)
    start = abs(fit.theta0_rad)
    omega = 0.0
    delta = t0_s + i0 * dt_s - fit.release_time_s
    if delta > 1e-12:
        head = solve(model, None, delta, start, 0.0, sample_dt_s=delta, step_s=step_s)
        if head.status == "overturned":
            theta[i0:] = fit.side * 0.5 * math.pi + fit.offset_rad
            return theta, head, delta
        start, omega = float(head.theta_rad[-1]), float(head.omega_rad_s[-1])
    duration = (n - 1 - i0) * dt_s
    if duration <= 0.0:
        theta[i0:] = fit.side * start + fit.offset_rad
        return theta, None, delta
    traj = solve(model, None, duration, start, omega, sample_dt_s=dt_s, step_s=step_s)
    m = traj.theta_rad.size
    theta[i0 : i0 + m] = fit.side * traj.theta_rad + fit.offset_rad
    if m < n - i0:  # overturned: lying on its side
        theta[i0 + m :] = fit.side * math.copysign(0.5 * math.pi, traj.theta_rad[-1]) + fit.offset_rad
    return theta, traj, delta


def synthetic_measurement(
    alpha_rad: float,
    p_rad_s: float,
    mu: float,
    *,
    theta0_rad: float,
    rate_hz: float = 200.0,
    duration_s: float = 8.0,
    hold_s: float = 0.5,
    release_offset_s: float = 0.0,
    offset_rad: float = 0.0,
    noise_rad: float = 0.0,
    seed: int = 0,
    source: str = "synthetic",
) -> MeasuredHistory:
    """A free-rocking record made by Housner's solver, with a hold, an offset and white noise.

    The release happens at ``hold_s + release_offset_s`` (``release_offset_s`` lets the
    release fall between samples); the noise is Gaussian with standard deviation
    ``noise_rad`` from ``numpy.random.default_rng(seed)``.

    Parameters
    ----------
    alpha_rad, p_rad_s, mu
        The block's classical parameters (rad, 1/s, -).
    theta0_rad
        Release tilt, rad (its sign: the side tilted to).
    rate_hz, duration_s
        Sampling rate (Hz) and record length (s).
    hold_s, release_offset_s
        Hold before the release and the release's offset within a sample interval, s.
    offset_rad, noise_rad
        Sensor offset and noise standard deviation, rad.
    seed
        Seed of the noise.
    source
        Name of the record.
    """
    dt = 1.0 / rate_hz
    n = round(duration_s * rate_hz) + 1
    truth = FreeRockingFit(
        alpha_rad,
        p_rad_s,
        mu,
        hold_s + release_offset_s,
        offset_rad,
        abs(theta0_rad) / alpha_rad,
        1 if theta0_rad >= 0 else -1,
    )
    theta = model_history(truth, 0.0, dt, n)[0]
    rng = np.random.default_rng(seed)
    theta = theta + noise_rad * rng.standard_normal(n)
    return measured_history(np.arange(n, dtype=float) * dt, theta, source)
