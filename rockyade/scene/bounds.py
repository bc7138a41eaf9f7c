"""The documented range of every physical input of a scene (docs/robustness.md lists them).

The ranges keep the inputs physical for rocking blocks from a brick to a monument, and keep
the arithmetic finite (no subnormal lengths or masses, no frequency that asks for 10^30
steps). A value outside its range is refused with an
:class:`~rockyade.errors.InputError` naming the field and the range. The cost of a whole
run (steps, samples, memory) is bounded separately (:mod:`rockyade.runner.cost_limits`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TypedDict

from rockyade.constants import G
from rockyade.errors import InputError, at_least, at_most


class NumberBounds(TypedDict):
    """The range keywords of :meth:`rockyade.io.fields.TableReader.number`."""

    lo: float
    hi: float
    lo_open: bool
    unit: str


@dataclass(frozen=True)
class Bound:
    """A closed range ``[lo, hi]`` (``lo_open``: ``(lo, hi]``) with its unit."""

    lo: float
    hi: float
    unit: str = ""
    lo_open: bool = False

    def kwargs(self) -> NumberBounds:
        """Keyword arguments of :meth:`rockyade.io.fields.TableReader.number`."""
        return {"lo": self.lo, "hi": self.hi, "lo_open": self.lo_open, "unit": self.unit}


#: Field -> range. Keys are the scene's field names (``contact.`` / ``output.`` prefixed).
BOUNDS: dict[str, Bound] = {
    "duration_s": Bound(0.0, 1.0e5, "s", lo_open=True),
    "sample_dt_s": Bound(1.0e-6, 10.0, "s"),
    "length_m": Bound(1.0e-3, 1000.0, "m"),  # width_m, height_m, thickness_m, polygon extent
    "mass_kg": Bound(1.0e-3, 1.0e9, "kg"),
    "loads.mass_kg": Bound(0.0, 1.0e9, "kg"),  # a load's mass moving with its block (0: without mass)
    "density_kg_m3": Bound(1.0, 1.0e5, "kg/m^3"),
    "alpha_rad": Bound(1.0e-3, math.pi / 2 - 1.0e-3, "rad"),
    "mu": Bound(0.05, 0.9999, ""),
    "contact.K_N_per_m": Bound(1.0, 1.0e13, "N/m"),
    "contact.Ks_N_per_m": Bound(1.0, 1.0e13, "N/m"),
    "contact.jkn_Pa_per_m": Bound(1.0, 1.0e15, "Pa/m"),
    "contact.jks_Pa_per_m": Bound(1.0, 1.0e15, "Pa/m"),
    "contact.stiffness_scale": Bound(1.0e-6, 1.0e9, "", lo_open=False),
    "contact.beta_s": Bound(0.0, 0.1, "s"),
    "contact.dt_s": Bound(1.0e-8, 1.0e-2, "s"),
    "contact.time_step_frac": Bound(1.0e-3, 1.0, ""),
    "contact.mass_damping_1_s": Bound(0.0, 1000.0, "1/s"),
    "output.accel_point": Bound(-1000.0, 1000.0, "m"),
    "output.accel_lowpass_hz": Bound(0.1, 1.0e4, "Hz"),  # and below the Nyquist frequency
    "motion.omega0_rad_s": Bound(-100.0, 100.0, "rad/s"),
    "motion.start_s": Bound(0.0, 1000.0, "s"),
    "motion.accel_m_s2": Bound(-1000.0, 1000.0, "m/s^2"),  # any sampled or recorded value
}

#: A given centroidal inertia must lie in [INERTIA_MIN_FRACTION, 1] x M r_max^2, r_max the
#: largest distance from the centroid to a vertex (no mass of the block lies farther out).
INERTIA_MIN_FRACTION = 1.0e-4

#: p_rad_s must lie in [P_MIN_FRACTION, P_MAX_FRACTION] x sqrt(g / R): p^2 = M g R / I_O
#: and I_O >= M R^2, so no rigid block rocks faster than sqrt(g / R).
P_MIN_FRACTION = 0.01
P_MAX_FRACTION = 0.99


def bound(name: str) -> Bound:
    """The range of field ``name`` (a key of :data:`BOUNDS`)."""
    return BOUNDS[name]


def p_range(block: object) -> tuple[float, float]:
    """The range of a block's ``p_rad_s`` override, rad/s: [P_MIN_FRACTION, P_MAX_FRACTION] x
    sqrt(g / R), R the distance from the centroid to the farthest base corner (p^2 = M g R / I_O
    and I_O >= M R^2: no rigid block rocks faster than sqrt(g / R)).

    Parameters
    ----------
    block
        A :class:`rockyade.blocks.geometry.Block`.
    """
    cx, cy = block.centroid_m  # type: ignore[attr-defined]
    r = max(math.hypot(cx - x, cy) for x in block.level_vertices("base"))  # type: ignore[attr-defined]
    p_limit = math.sqrt(G / r)
    return P_MIN_FRACTION * p_limit, P_MAX_FRACTION * p_limit


def check_block_ranges(block: object, spec: object, field_prefix: str, source: str | None) -> None:
    """Ranges that depend on the block's geometry: extent, mass from a density, given inertia, p override.

    Parameters
    ----------
    block
        The :class:`rockyade.blocks.geometry.Block` built from ``spec``.
    spec
        The :class:`rockyade.scene.description.BlockSpec`.
    field_prefix
        ``"blocks[i]."``, for the field names in errors.
    """
    import numpy as np

    length = BOUNDS["length_m"]
    verts = block.vertices_m  # type: ignore[attr-defined]
    for axis, name in ((0, "width"), (1, "height")):
        extent = float(np.ptp(verts[:, axis]))
        if extent < length.lo:
            raise InputError(
                f"{field_prefix}vertices_m",
                f"the polygon's {name} {extent:.3g} m is below {length.lo:g} m",
                source,
            )
    cx, cy = block.centroid_m  # type: ignore[attr-defined]
    mass = block.mass_kg  # type: ignore[attr-defined]
    bound = BOUNDS["mass_kg"]
    if getattr(spec, "density_kg_m3", None) is not None and not bound.lo <= mass <= bound.hi:
        raise InputError(  # the mass's range, however it is given
            f"{field_prefix}density_kg_m3",
            f"gives the block a mass of {mass:.4g} kg (density x area x thickness), outside mass_kg's range "
            f"[{bound.lo:g}, {bound.hi:g}] kg",
            source,
        )
    r_max2 = float(np.max((verts[:, 0] - cx) ** 2 + (verts[:, 1] - cy) ** 2))
    inertia = getattr(spec, "inertia_kgm2", None)
    if inertia is not None:
        hi = mass * r_max2
        lo = INERTIA_MIN_FRACTION * hi
        if not lo <= inertia <= hi:
            raise InputError(
                f"{field_prefix}inertia_kgm2",
                f"must be in [{at_least(lo, 4)}, {at_most(hi, 4)}] kg m^2 ({INERTIA_MIN_FRACTION:g} to 1 times "
                "M r^2, r = "
                f"{math.sqrt(r_max2):.4g} m the farthest vertex from the centroid), got {inertia:g}",
                source,
            )
    p = getattr(spec, "p_rad_s", None)
    if p is not None:
        lo, hi = p_range(block)
        p_limit = hi / P_MAX_FRACTION
        if not lo <= p <= hi:
            raise InputError(
                f"{field_prefix}p_rad_s",
                f"must be in [{at_least(lo, 4)}, {at_most(hi, 4)}] rad/s ({P_MIN_FRACTION:g} to "
                f"{P_MAX_FRACTION:g} times "
                f"sqrt(g / R) = {p_limit:.4g}: p^2 = M g R / I_O and I_O >= M R^2), got {p:g}",
                source,
            )
