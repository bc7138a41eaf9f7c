"""The intensity measure of a fragility curve: what a stripe's level is.

* ``pga``: peak ground acceleration max |a|, m/s^2 (shown in g);
* ``pgv``: peak ground velocity max |v|, v = int a dt from rest (exact for the
  piecewise-linear a, :meth:`rockyade.motion.ground.GroundMotion.velocity_displacement`), m/s;
* ``sa(T)``: the 5 % damped pseudo-spectral acceleration at period T
  (:func:`rockyade.motion.spectra.response_spectrum`), m/s^2 (shown in g);
* ``ag``: the design ground acceleration of the site a suite or a set of records is scaled
  to (``rockyade assess``): a suite's ag for every record of it, PGA / S for a record scaled
  so that its PGA is ag S (shown in g).

Each is proportional to a load factor on the record's accelerations (EN 1998-1's spectrum
too), so a record of intensity x at load factor 1 has x lambda at lambda. A value in g is
in standard gravity, 9.80665 m/s^2 (:data:`rockyade.constants.CODE_GRAVITY`), as records in g.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from rockyade.constants import CODE_GRAVITY as G
from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion
from rockyade.motion.records import Record
from rockyade.motion.spectra import response_spectrum

KINDS = ("pga", "pgv", "sa", "ag")
#: Range of the period of sa(T), s.
PERIOD_RANGE_S = (0.01, 10.0)
_SA = re.compile(r"^sa\(\s*([0-9]*\.?[0-9]+)\s*s?\s*\)$")


@dataclass(frozen=True)
class Measure:
    """An intensity measure (module docstring).

    Attributes
    ----------
    kind
        ``pga``, ``pgv``, ``sa`` or ``ag``.
    period_s
        T of ``sa``, s (None otherwise).
    """

    kind: str
    period_s: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise InputError("--intensity", f"must be pga, pgv or sa(T) with T in s, got {self.kind!r}")
        if (self.kind == "sa") != (self.period_s is not None):
            raise InputError("--intensity", "sa needs its period, e.g. sa(0.5); only sa takes one")
        if self.period_s is not None:
            lo, hi = PERIOD_RANGE_S
            if not (math.isfinite(self.period_s) and lo <= self.period_s <= hi):
                raise InputError(
                    "--intensity", f"the period of sa(T) must be in [{lo:g}, {hi:g}] s, got {self.period_s:g}"
                )

    @property
    def name(self) -> str:
        """``pga``, ``pgv``, ``sa(0.5 s)``, ``ag``."""
        return f"sa({self.period_s:g} s)" if self.kind == "sa" else self.kind

    @property
    def unit(self) -> str:
        """The unit shown: ``g`` or ``m/s``."""
        return "m/s" if self.kind == "pgv" else "g"

    @property
    def scale(self) -> float:
        """SI value / shown value (g or 1)."""
        return 1.0 if self.kind == "pgv" else G

    @property
    def si_unit(self) -> str:
        """``m/s^2`` or ``m/s``."""
        return "m/s" if self.kind == "pgv" else "m/s^2"

    @property
    def column(self) -> str:
        """The column of the level in the shown unit: ``pga_g``, ``pgv_m_s``, ``sa_g``, ``ag_g``."""
        return f"{self.kind}_{'m_s' if self.kind == 'pgv' else 'g'}"

    @property
    def si_column(self) -> str:
        """The column of the level in SI: ``pga_m_s2``, ``pgv_m_s``, ``sa_m_s2``, ``ag_m_s2``."""
        return f"{self.kind}_{'m_s' if self.kind == 'pgv' else 'm_s2'}"

    @property
    def label(self) -> str:
        """Axis label."""
        if self.kind == "sa":
            return f"Sa({self.period_s:g} s), 5 % damped (g)"
        return {
            "pga": "PGA (g)",
            "pgv": "PGV (m/s)",
            "ag": "design ground acceleration ag of the scaled records (g)",
        }[self.kind]

    def shown(self, value_si: float) -> float:
        """A value in the shown unit."""
        return value_si / self.scale

    def of_record(self, record: Record) -> float:
        """The measure of a record's accelerations as read (load factor 1), in SI.

        Raises
        ------
        InputError
            ``sa`` of a record that is not uniformly sampled; ``ag`` (not a measure of one record).
        """
        if self.kind == "pga":
            return record.pga_m_s2
        if self.kind == "pgv":
            v, _ = GroundMotion(record.t_s, record.accel_m_s2, None, record.source).velocity_displacement()
            return float(np.max(np.abs(v)))
        if self.kind == "sa":
            if not record.uniform:
                raise InputError("--intensity", f"sa(T) needs a uniformly sampled record; {record.source} is not")
            _, psa = response_spectrum(record.accel_m_s2, record.dt_s, np.array([self.period_s]), 0.05)
            return float(psa[0])
        raise InputError("--intensity", "ag is the site's, not a measure of one record")

    def to_dict(self) -> dict[str, object]:
        """JSON-ready."""
        return {"name": self.name, "kind": self.kind, "period_s": self.period_s, "unit": self.unit}


def parse_measure(text: str) -> Measure:
    """``pga``, ``pgv`` or ``sa(T)`` (T in s, e.g. ``sa(0.5)`` or ``sa(0.5s)``) as a :class:`Measure`.

    Raises
    ------
    InputError
        Anything else (field ``--intensity``).
    """
    t = str(text).strip().lower()
    if t in ("pga", "pgv"):
        return Measure(t)
    match = _SA.match(t)
    if match is None:
        raise InputError("--intensity", f"must be pga, pgv or sa(T) with T in s (e.g. sa(0.5)), got {text!r}")
    return Measure("sa", float(match.group(1)))
