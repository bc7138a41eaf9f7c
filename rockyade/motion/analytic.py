"""Analytic base motions: shake-table harmonics and pulses.

Harmonic (the paper's shake-table tests, given as displacement amplitude and frequency):

    d(t) = A w(t) sin(2 pi f tau),  tau = t - start,

with a smooth envelope w: a half-cosine ramp up over ``ramp_cycles`` cycles, the stationary
part of ``cycles`` cycles, and a half-cosine ramp down. Velocity and acceleration are the
exact derivatives, so the three are consistent; w and w' vanish at both ends and the motion
lasts a whole number of cycles, so the table starts and ends at rest with zero
displacement, velocity and acceleration. In the stationary part the acceleration amplitude
is A (2 pi f)^2. After the motion the block rocks freely (the paper's "transient,
stationary and free rocking" states, Section 7.1).

Pulses (overturning studies), acceleration a(t) for tau in [0, n T]:

* ``sine``: a_p sin(2 pi tau / T) (one-sine; a symmetric cycloidal velocity pulse, Makris);
* ``cosine``: a_p cos(2 pi tau / T) (an antisymmetric cycloidal velocity pulse);
* ``ricker``: a_p (1 - 2 u^2) exp(-u^2), u = pi (tau - 1.5 T) / T (lasts 3 T);
* ``symmetric`` and ``antisymmetric`` are the names of the cycloidal family for sine and cosine.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion

PULSE_SHAPES = ("sine", "cosine", "ricker", "symmetric", "antisymmetric")
_ALIASES = {"symmetric": "sine", "antisymmetric": "cosine"}


@dataclass(frozen=True)
class Harmonic:
    """A shake-table sine with smooth ramps (see module docstring).

    Attributes
    ----------
    amplitude_mm
        Table displacement amplitude A, mm.
    frequency_hz
        Frequency f, Hz.
    cycles
        Cycles of the stationary part (an integer).
    ramp_cycles
        Cycles of each ramp (up and down).
    start_s
        Time the table starts, s.
    """

    amplitude_mm: float
    frequency_hz: float
    cycles: int
    ramp_cycles: int = 2
    start_s: float = 0.0

    @property
    def omega(self) -> float:
        """Angular frequency, rad/s."""
        return 2.0 * math.pi * self.frequency_hz

    @property
    def ramp_s(self) -> float:
        """Duration of each ramp, s."""
        return self.ramp_cycles / self.frequency_hz

    @property
    def phases_s(self) -> dict[str, float]:
        """Times at which the ramp up ends, the stationary part ends and the motion ends."""
        up = self.start_s + self.ramp_s
        stationary = up + self.cycles / self.frequency_hz
        return {"ramp_up_end_s": up, "stationary_end_s": stationary, "end_s": stationary + self.ramp_s}

    @property
    def accel_amplitude_m_s2(self) -> float:
        """A (2 pi f)^2 in the stationary part, m/s^2."""
        return 1e-3 * self.amplitude_mm * self.omega**2

    def _envelope(
        self, tau: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        R = self.ramp_s
        S = self.cycles / self.frequency_hz
        w = np.zeros_like(tau)
        w1 = np.zeros_like(tau)
        w2 = np.zeros_like(tau)
        up = (tau >= 0) & (tau < R)
        mid = (tau >= R) & (tau <= R + S)
        down = (tau > R + S) & (tau <= 2 * R + S)
        k = math.pi / R
        w[up] = 0.5 * (1 - np.cos(k * tau[up]))
        w1[up] = 0.5 * k * np.sin(k * tau[up])
        w2[up] = 0.5 * k * k * np.cos(k * tau[up])
        w[mid] = 1.0
        s = tau[down] - R - S
        w[down] = 0.5 * (1 + np.cos(k * s))
        w1[down] = -0.5 * k * np.sin(k * s)
        w2[down] = -0.5 * k * k * np.cos(k * s)
        return w, w1, w2

    def kinematics(self, t: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Table displacement (m), velocity (m/s) and acceleration (m/s^2) at ``t``."""
        tau = np.asarray(t, dtype=float) - self.start_s
        A = 1e-3 * self.amplitude_mm
        wt = self.omega * tau
        w, w1, w2 = self._envelope(tau)
        s, c = np.sin(wt), np.cos(wt)
        d = A * w * s
        v = A * (w1 * s + w * self.omega * c)
        a = A * (w2 * s + 2.0 * w1 * self.omega * c - w * self.omega**2 * s)
        return d, v, a

    @property
    def sample_count(self) -> int:
        """Samples of :meth:`ground_motion`: 400 points per cycle from t = 0 to the end."""
        return math.ceil(self.phases_s["end_s"] * self.frequency_hz * 400) + 1

    def ground_motion(self, load_factor: float = 1.0) -> GroundMotion:
        """Acceleration sampled at 400 points per cycle from t = 0 to the end."""
        t = np.linspace(0.0, self.phases_s["end_s"], self.sample_count)
        label = f"harmonic {self.frequency_hz:g} Hz, {self.amplitude_mm:g} mm, {self.cycles} cycles"
        return _scaled(t, self.kinematics(t)[2], label, load_factor)


@dataclass(frozen=True)
class Pulse:
    """An acceleration pulse (see module docstring).

    Attributes
    ----------
    shape
        sine, cosine, ricker, symmetric (= sine) or antisymmetric (= cosine).
    amplitude_m_s2
        Peak acceleration a_p, m/s^2.
    period_s
        Period T, s.
    cycles
        Number of cycles n (sine and cosine).
    start_s
        Time the pulse starts, s.
    """

    shape: str
    amplitude_m_s2: float
    period_s: float
    cycles: int = 1
    start_s: float = 0.0

    def __post_init__(self) -> None:
        if self.shape not in PULSE_SHAPES:
            raise InputError("motion.shape", f"must be one of {', '.join(PULSE_SHAPES)}, got {self.shape!r}")

    @property
    def kind(self) -> str:
        """sine, cosine or ricker."""
        return _ALIASES.get(self.shape, self.shape)

    @property
    def duration_s(self) -> float:
        """Length of the pulse, s."""
        return 3.0 * self.period_s if self.kind == "ricker" else self.cycles * self.period_s

    def acceleration(self, t: ArrayLike) -> NDArray[np.float64]:
        """Base acceleration at ``t``, m/s^2."""
        tau = np.asarray(t, dtype=float) - self.start_s
        inside = (tau >= 0) & (tau <= self.duration_s)
        T = self.period_s
        if self.kind == "sine":
            a = np.sin(2 * math.pi * tau / T)
        elif self.kind == "cosine":
            a = np.cos(2 * math.pi * tau / T)
        else:
            u = math.pi * (tau - 1.5 * T) / T
            a = (1 - 2 * u * u) * np.exp(-u * u)
        return np.where(inside, self.amplitude_m_s2 * a, 0.0)

    @property
    def _jumps(self) -> bool:
        """The pulse starts with a jump (a cosine after t = 0): a sample pair puts it at the start
        time exactly in the piecewise-linear history."""
        return self.kind == "cosine" and self.start_s > 0

    @property
    def sample_count(self) -> int:
        """Samples of :meth:`ground_motion`: T / 400 (at most 1 ms) from t = 0 to the end, and
        the second of the jump's pair."""
        end = self.start_s + self.duration_s
        return math.ceil(end / min(self.period_s / 400.0, 1e-3)) + 1 + int(self._jumps)

    def ground_motion(self, load_factor: float = 1.0) -> GroundMotion:
        """Acceleration sampled at T / 400 (at most 1 ms) from t = 0 to the end."""
        t = np.linspace(0.0, self.start_s + self.duration_s, self.sample_count - int(self._jumps))
        if self._jumps:
            t = np.sort(np.concatenate([t, [np.nextafter(self.start_s, -np.inf)]]))
        label = f"{self.shape} pulse a_p = {self.amplitude_m_s2:g} m/s^2, T = {self.period_s:g} s"
        return _scaled(t, self.acceleration(t), label, load_factor)


def _scaled(t: NDArray[np.float64], accel: NDArray[np.float64], label: str, load_factor: float) -> GroundMotion:
    """An analytic motion's samples times ``load_factor`` (named in the label when not 1)."""
    return GroundMotion(t, load_factor * accel, None, label + (f", x{load_factor:g}" if load_factor != 1 else ""))
