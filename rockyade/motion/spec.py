"""The ``[motion]`` table of a scene: one dataclass per motion type, parsed and validated.

Types: ``rest`` (the base at rest, every block released from rest: a drop test; the
static check is ``gravity-ramp``), ``free`` (free rocking from an initial tilt) and ``sampled`` (base acceleration
samples given inline); :mod:`rockyade.motion.types` registers the shake-table, pulse,
record and synthetic types.
"""

from __future__ import annotations

import itertools
import math
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from rockyade.io.fields import TableReader
from rockyade.motion.ground import GroundMotion

#: Largest |initial angular velocity| of free rocking, rad/s.
MAX_OMEGA0_RAD_S = 100.0
#: Largest |base acceleration| given in a scene (samples, pulses), m/s^2 (about 100 g).
MAX_ABS_ACCEL_M_S2 = 1000.0
#: Latest time a motion may reach (start times, sample times), s.
MAX_MOTION_TIME_S = 1.0e5
#: Latest start of a harmonic motion or a pulse, s.
MAX_START_S = 1000.0


class MotionSpec(ABC):
    """Base class of the motion specifications.

    Subclasses are frozen dataclasses with a ``type`` class attribute; they provide
    :meth:`ground_motion` (None for free rocking) and the initial tilt of the blocks.
    """

    type: ClassVar[str] = ""

    @abstractmethod
    def ground_motion(self, duration_s: float) -> GroundMotion | None:
        """The base acceleration over ``duration_s`` (None: the base does not move)."""

    @property
    def initial_theta_rad(self) -> float:
        """Initial tilt of the released block, rad (0 unless free rocking)."""
        return 0.0

    @property
    def initial_omega_rad_s(self) -> float:
        """Initial angular velocity of the released block, rad/s."""
        return 0.0

    @property
    def released_block(self) -> str | None:
        """Name of the block given the initial tilt (None: the top block)."""
        return None

    def to_dict(self) -> dict[str, Any]:
        """Canonical dictionary (all defaults filled in), as in a scene file."""
        d: dict[str, Any] = {"type": self.type}
        for f in fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            d[f.name] = list(value) if isinstance(value, tuple) else value
        return d

    def hash_material(self) -> dict[str, Any]:
        """What identifies the motion in a scene hash (content of files, not their paths)."""
        return self.to_dict()

    def sample_count(self, duration_s: float) -> int:
        """Samples of the base acceleration the motion builds (0 when the base does not move),
        computed without building them: the run's cost estimate (:mod:`rockyade.runner.cost_limits`)."""
        return 0


@dataclass(frozen=True)
class FreeRocking(MotionSpec):
    """Free rocking: a block released at ``theta0_rad`` on a base at rest.

    Attributes
    ----------
    theta0_rad
        Initial tilt, rad; > 0 pivots on the left corner. |theta0| < alpha for a block to
        come back.
    omega0_rad_s
        Initial angular velocity, rad/s.
    block
        Name of the block released (default: the top block); the others start at rest.
    """

    type: ClassVar[str] = "free"
    theta0_rad: float
    omega0_rad_s: float = 0.0
    block: str | None = None

    def ground_motion(self, duration_s: float) -> GroundMotion | None:
        """None: in free rocking the base does not move."""
        return None

    @property
    def initial_theta_rad(self) -> float:
        """The release tilt ``theta0_rad``, rad."""
        return self.theta0_rad

    @property
    def initial_omega_rad_s(self) -> float:
        """The release angular velocity ``omega0_rad_s``, rad/s."""
        return self.omega0_rad_s

    @property
    def released_block(self) -> str | None:
        """The block given the release tilt (``block``; None: the top block)."""
        return self.block

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> FreeRocking:
        """The motion from its ``[motion]`` table: ``theta0_rad``, ``omega0_rad_s``, ``block``."""
        theta0 = r.number("theta0_rad", lo=-math.pi / 2, hi=math.pi / 2, lo_open=True, hi_open=True, unit="rad")
        omega0 = r.number("omega0_rad_s", 0.0, lo=-MAX_OMEGA0_RAD_S, hi=MAX_OMEGA0_RAD_S, unit="rad/s")
        block = r.string("block", None)
        if theta0 == 0.0 and omega0 == 0.0:
            raise r.error("theta0_rad", "free rocking needs a non-zero theta0_rad or omega0_rad_s")
        return cls(theta0, omega0, block)


@dataclass(frozen=True)
class AtRest(MotionSpec):
    """The base at rest and every block released from rest: gravity alone.

    This is a drop test, not a static check: the whole of gravity acts at t = 0 on joints that
    carry nothing yet, and the blocks fall onto them (an arch slightly thicker than its
    static limit can fall). The static check is ``gravity-ramp``
    (:mod:`rockyade.motion.quasistatic`).
    """

    type: ClassVar[str] = "rest"

    def ground_motion(self, duration_s: float) -> GroundMotion | None:
        """None: the base does not move (gravity acts from t = 0: a drop test)."""
        return None

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> AtRest:
        """The motion from its ``[motion]`` table (no keys)."""
        return cls()


@dataclass(frozen=True)
class SampledMotion(MotionSpec):
    """Base acceleration samples given in the scene itself.

    Attributes
    ----------
    accel_m_s2
        Horizontal base acceleration samples, m/s^2.
    dt_s
        Constant sampling interval, s (or give ``t_s``).
    t_s
        Sample times, s, strictly increasing from 0 (instead of ``dt_s``).
    accel_v_m_s2
        Optional vertical samples, m/s^2 (> 0 upwards).
    load_factor
        Multiplies both components.
    """

    type: ClassVar[str] = "sampled"
    accel_m_s2: tuple[float, ...]
    dt_s: float | None = None
    t_s: tuple[float, ...] | None = None
    accel_v_m_s2: tuple[float, ...] | None = None
    load_factor: float = 1.0

    def sample_count(self, duration_s: float) -> int:
        """The samples given in the table."""
        return len(self.accel_m_s2)

    def ground_motion(self, duration_s: float) -> GroundMotion:
        """The given samples times ``load_factor``, at ``t_s`` or every ``dt_s``; m/s^2."""
        ah = np.array(self.accel_m_s2) * self.load_factor
        av = None if self.accel_v_m_s2 is None else np.array(self.accel_v_m_s2) * self.load_factor
        if self.t_s is not None:
            t = np.array(self.t_s, dtype=float)
        else:
            assert self.dt_s is not None  # parse() requires one of t_s and dt_s
            t = np.arange(ah.size, dtype=float) * self.dt_s
        return GroundMotion(t, ah, av, label=f"sampled ({ah.size} samples)")

    @classmethod
    def parse(cls, r: TableReader, base_dir: Path | None) -> SampledMotion:
        """The motion from its ``[motion]`` table: ``accel_m_s2`` with ``dt_s`` or ``t_s``, optional
        ``accel_v_m_s2``."""
        accel = r.number_list("accel_m_s2", min_len=2, unit="m/s^2")
        dt = r.number("dt_s", None, lo=1.0e-6, hi=1.0, unit="s")
        t = r.number_list("t_s", None, min_len=2, unit="s")
        av = r.number_list("accel_v_m_s2", None, min_len=2, unit="m/s^2")
        lf = r.number("load_factor", 1.0, lo=0.0, hi=100.0)
        for key, values in (("accel_m_s2", accel), ("accel_v_m_s2", av or [])):
            worst = max((abs(v) for v in values), default=0.0)
            if worst > MAX_ABS_ACCEL_M_S2:
                raise r.error(key, f"values must be within +/-{MAX_ABS_ACCEL_M_S2:g} m/s^2, got {worst:g}")
        if t is not None and not all(0.0 <= v <= MAX_MOTION_TIME_S for v in t):
            raise r.error("t_s", f"times must be in [0, {MAX_MOTION_TIME_S:g}] s")
        if (dt is None) == (t is None):
            raise r.error("dt_s", "give exactly one of dt_s and t_s")
        if t is not None:
            if len(t) != len(accel):
                raise r.error("t_s", f"must have as many values as accel_m_s2 ({len(accel)})")
            if t[0] != 0.0 or any(b <= a for a, b in itertools.pairwise(t)):
                raise r.error("t_s", "must start at 0 and increase strictly")
        if av is not None and len(av) != len(accel):
            raise r.error("accel_v_m_s2", f"must have as many values as accel_m_s2 ({len(accel)})")
        return cls(tuple(accel), dt, None if t is None else tuple(t), None if av is None else tuple(av), lf)


#: Parsers of the ``[motion]`` table by ``type``.
MOTION_TYPES: dict[str, Callable[[TableReader, Path | None], MotionSpec]] = {
    AtRest.type: AtRest.parse,
    FreeRocking.type: FreeRocking.parse,
    SampledMotion.type: SampledMotion.parse,
}


def parse_motion(table: Any, source: str | None = None, base_dir: Path | None = None) -> MotionSpec:
    """Parse and validate a ``[motion]`` table.

    Parameters
    ----------
    table
        The table as read from TOML or JSON.
    source
        File name for error messages.
    base_dir
        Directory that relative file paths in the table are relative to.
    """
    r = TableReader(table, "motion", source)
    kind = r.string("type", choices=sorted(MOTION_TYPES))
    spec = MOTION_TYPES[kind](r, base_dir)
    r.finish()
    return spec
