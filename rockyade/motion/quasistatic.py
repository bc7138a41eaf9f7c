"""Quasi-static motions: gravity brought in smoothly (``gravity-ramp``) and the pushover.

``rest`` is a drop test: at t = 0 the whole of gravity acts on blocks whose contacts carry
nothing yet, and the blocks fall onto their joints (an arch between the static limit and a
slightly thicker one falls when dropped). ``gravity-ramp`` is the static check: in the
base frame, gravity enters as a vertical base acceleration

    a_v(t) = -g (1 - r(t)),   r(t) = (1 - cos(pi t / T)) / 2 for t < T, 1 after,

(a half-cosine ramp from 0 to 1 over ``ramp_s`` = T, with zero rate at both ends), so that
the apparent gravity g + a_v = g r(t) rises from 0 to g and is then held. Point loads ramp
in with it (:mod:`rockyade.kernel.point_loads`).

``pushover`` is the gravity ramp, a pause of ``settle_s``, then a horizontal base
acceleration whose multiplier lambda(t) = |a_h| / g rises at ``rate_g_per_s`` up to
``max_lambda`` and is then held. The equivalent static load lambda m g acts on every mass
towards ``direction`` (``"+x"``: the base accelerates towards -x, a_h = -lambda g), the
limit analysis's convention (:mod:`rockyade.limit`). With ``step_lambda`` the rise is a
staircase: levels start_lambda + k step_lambda, each reached at ``rate_g_per_s`` and held
``hold_s`` (a rising ramp has a dynamic lag; a held level shows whether the assembly stands
at it). Below ``start_lambda`` the rise is continuous. Scene tables::

    [motion]
    type = "gravity-ramp"
    ramp_s = 1.0

    [motion]
    type = "pushover"
    direction = "+x"
    ramp_s = 1.0            # gravity ramp
    settle_s = 0.5          # gravity held before the push
    rate_g_per_s = 0.05     # rise of lambda, 1/s
    max_lambda = 1.0
    start_lambda = 0.0      # optional: held levels from here,
    step_lambda = 0.0       # every step_lambda (0: a continuous rise),
    hold_s = 0.5            # each held this long
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np

from rockyade.constants import G
from rockyade.io.fields import TableReader
from rockyade.motion.ground import GroundMotion
from rockyade.motion.spec import MotionSpec

#: Samples of the half-cosine gravity ramp.
RAMP_SAMPLES = 401
#: Most held levels of a pushover staircase.
MAX_LEVELS = 10_000
#: Pushover directions and the sign of the base acceleration each gives.
DIRECTIONS = {"+x": -1.0, "-x": 1.0}


def gravity_ramp_samples(ramp_s: float, g: float = G) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and vertical base acceleration (m/s^2) of the half-cosine gravity ramp, from
    a_v = -g at t = 0 to 0 at t = ``ramp_s`` (module docstring)."""
    t = np.linspace(0.0, ramp_s, RAMP_SAMPLES)
    r = 0.5 * (1.0 - np.cos(np.pi * t / ramp_s))
    av = -g * (1.0 - r)
    av[-1] = 0.0
    return t, av


def _ramp_motion(ramp_s: float, duration_s: float, label: str) -> GroundMotion:
    t, av = gravity_ramp_samples(ramp_s)
    if duration_s > ramp_s:  # gravity held to the end (zero base acceleration is also the default)
        t = np.append(t, duration_s)
        av = np.append(av, 0.0)
    return GroundMotion(t, np.zeros_like(t), av, label)


@dataclass(frozen=True)
class GravityRamp(MotionSpec):
    """``type = "gravity-ramp"``: gravity brought in over ``ramp_s``, then held (module docstring).

    Attributes
    ----------
    ramp_s
        Duration of the half-cosine ramp, s.
    """

    type: ClassVar[str] = "gravity-ramp"
    ramp_s: float = 1.0

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """Vertical base acceleration av = -g (1 - r(t)), r a half-cosine ramp over ``ramp_s`` (module
        docstring), then held; m/s^2."""
        return _ramp_motion(self.ramp_s, duration_s, f"gravity ramp over {self.ramp_s:g} s")

    def sample_count(self, duration_s: float) -> int:
        """Samples of the ramp (the held tail needs none: the last sample is held)."""
        return RAMP_SAMPLES + 1

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> GravityRamp:
        """The motion from its ``[motion]`` table: ``ramp_s`` (s, 1e-3 to 1e3, default 1)."""
        return cls(r.number("ramp_s", 1.0, lo=1e-3, hi=1e3, unit="s"))


@dataclass(frozen=True)
class Pushover(MotionSpec):
    """``type = "pushover"``: the gravity ramp, then a rising horizontal multiplier (module docstring).

    Attributes
    ----------
    direction
        "+x" or "-x": where the equivalent load lambda m g pushes the masses.
    ramp_s, settle_s
        Gravity ramp and the pause after it, s.
    rate_g_per_s
        Rise of lambda = |a_h| / g, 1/s.
    max_lambda
        Last level, held to the end of the run.
    start_lambda, step_lambda, hold_s
        Held levels start_lambda + k step_lambda (step 0: a continuous rise), each held hold_s, s.
    """

    type: ClassVar[str] = "pushover"
    direction: str = "+x"
    ramp_s: float = 1.0
    settle_s: float = 0.5
    rate_g_per_s: float = 0.05
    max_lambda: float = 1.0
    start_lambda: float = 0.0
    step_lambda: float = 0.0
    hold_s: float = 0.5

    @property
    def push_start_s(self) -> float:
        """When lambda starts rising, s."""
        return self.ramp_s + self.settle_s

    def levels(self) -> np.ndarray:
        """The held levels of lambda (empty for a continuous rise)."""
        if self.step_lambda <= 0.0:
            return np.zeros(0)
        n = math.floor((self.max_lambda - self.start_lambda) / self.step_lambda + 1e-9) + 1
        return self.start_lambda + self.step_lambda * np.arange(n)

    def lambda_path(self, duration_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Times (s) and lambda of the push, from ``push_start_s`` (lambda = 0) to the end."""
        rate = self.rate_g_per_s
        t, lam = [self.push_start_s], [0.0]
        levels = self.levels()
        if levels.size == 0:
            levels = np.array([self.max_lambda])
            holds = [0.0]
        else:
            holds = [self.hold_s] * levels.size
        for level, hold in zip(levels, holds, strict=True):
            if level > lam[-1]:
                t.append(t[-1] + (level - lam[-1]) / rate)
                lam.append(float(level))
            if hold > 0.0:
                t.append(t[-1] + hold)
                lam.append(float(level))
        if duration_s > t[-1]:
            t.append(duration_s)
            lam.append(lam[-1])
        return np.array(t), np.array(lam)

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """The gravity ramp, then the horizontal base acceleration lambda(t) g in ``direction``
        (:meth:`lambda_path`); m/s^2."""
        t_g, av_g = gravity_ramp_samples(self.ramp_s)
        t_p, lam = self.lambda_path(duration_s)
        sign = DIRECTIONS[self.direction]
        t = np.concatenate([t_g, t_p])
        ah = np.concatenate([np.zeros_like(t_g), sign * lam * G])
        av = np.concatenate([av_g, np.zeros_like(t_p)])
        keep = np.concatenate([[True], np.diff(t) > 0.0])  # the settle pause starts where the ramp ends
        label = f"pushover {self.direction} at {self.rate_g_per_s:g} g/s to lambda {self.max_lambda:g}"
        if self.step_lambda > 0:
            label += f" (levels every {self.step_lambda:g} from {self.start_lambda:g}, held {self.hold_s:g} s)"
        return GroundMotion(t[keep], ah[keep], av[keep], label)

    def sample_count(self, duration_s: float) -> int:
        """Samples of the ramp and of the multiplier's path (two per held level)."""
        return RAMP_SAMPLES + 2 * max(1, self.levels().size) + 2

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> Pushover:
        """The motion from its ``[motion]`` table: direction, ramp_s, settle_s, rate_g_per_s,
        max_lambda, and held levels (start_lambda, step_lambda, hold_s); ranges in the module docstring."""
        direction = r.string("direction", "+x", choices=sorted(DIRECTIONS))
        ramp = r.number("ramp_s", 1.0, lo=1e-3, hi=1e3, unit="s")
        settle = r.number("settle_s", 0.5, lo=0.0, hi=1e3, unit="s")
        rate = r.number("rate_g_per_s", 0.05, lo=1e-5, hi=100.0, lo_open=False, unit="1/s")
        top = r.number("max_lambda", 1.0, lo=0.0, hi=10.0, lo_open=True)
        start = r.number("start_lambda", 0.0, lo=0.0, hi=10.0)
        step = r.number("step_lambda", 0.0, lo=0.0, hi=10.0)
        hold = r.number("hold_s", 0.5, lo=0.0, hi=1e3, unit="s")
        if start > top:
            raise r.error("start_lambda", f"must be <= max_lambda ({top:g}), got {start:g}")
        if step > 0 and (top - start) / step + 1 > MAX_LEVELS:
            raise r.error("step_lambda", f"gives more than {MAX_LEVELS} levels between start_lambda and max_lambda")
        if step > 0 and hold <= 0:
            raise r.error("hold_s", "must be > 0 with step_lambda (each level is held)")
        return cls(direction, ramp, settle, rate, top, start, step, hold)
