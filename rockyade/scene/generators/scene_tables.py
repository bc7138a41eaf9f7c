"""What every generator shares: exact numbers, parameter checks, block tables, the scene table.

The checks take their ranges from the generators' table of parameters
(:mod:`rockyade.scene.generator_options`).

Geometry is computed with :class:`fractions.Fraction` from the decimal value of each input
(``0.1`` is read as 1/10), and converted to the nearest double only when a block table is
written: a joint's two faces are then the same number, or one rounding apart (< 1e-15 m),
and the file shows ``0.3`` rather than ``0.30000000000000004``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from fractions import Fraction
from pathlib import Path
from typing import Any, Required, TypedDict

from rockyade.errors import InputError
from rockyade.scene.generator_options import DENSITY, LENGTH, LENGTH_OR_ZERO, Range, count, defaults
from rockyade.scene.generator_options import check as check_param

_COMMON = defaults("common")
#: Defaults shared by the generators (the table's).
DEFAULT_DENSITY_KG_M3: float = _COMMON.density_kg_m3
#: Simulated time of a generated scene whose motion has no length of its own to go by, s
#: (a record's scene lasts the record plus a tail: :func:`default_duration_s`).
DEFAULT_DURATION_S = 3.0
DEFAULT_SAMPLE_DT_S: float = _COMMON.sample_dt_s
#: The placeholder base motion: a one-sine acceleration pulse (edit it in the scene file).
DEFAULT_PULSE = {
    "type": "pulse",
    "shape": _COMMON.pulse_shape,
    "amplitude_g": _COMMON.amplitude_g,
    "period_s": _COMMON.period_s,
    "cycles": _COMMON.cycles,
}
#: Header comment of written scenes: how to change the placeholder motion.
MOTION_NOTE = (
    "[motion] is a placeholder one-sine pulse: edit it (type = pulse | record | synthetic | harmonic | free | rest)"
)
#: Joint stiffness per unit area of the UDEC-style default contact, Pa/m (stone or brick
#: masonry joints are usually modelled with 1e9 to 1e11 Pa/m).
DEFAULT_JKN_PA_PER_M: float = _COMMON.jkn_pa_per_m
#: Fraction of critical damping of the default beta_s (see :func:`udec_contact`).
DEFAULT_JOINT_DAMPING_RATIO: float = _COMMON.damping_ratio
DEFAULT_FRICTION_ANGLE_DEG: float = _COMMON.friction_angle_deg


def exact(value: float | int | Fraction) -> Fraction:
    """The decimal value of ``value`` as an exact fraction (0.1 -> 1/10)."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, int):
        return Fraction(value)
    return Fraction(repr(float(value)))


def num(value: Fraction | float) -> float:
    """The nearest double of an exact value (for the scene table)."""
    return float(value)


# ---------------------------------------------------------------------- checks


def check_number(
    name: str,
    value: Any,
    lo: float,
    hi: float,
    *,
    lo_open: bool = False,
    hi_open: bool = False,
    unit: str = "",
) -> float:
    """``value`` as a float within [lo, hi] (bounds open as asked), else InputError naming ``name``."""
    return float(Range(lo, hi, unit, lo_open, hi_open).check(name, value))


def check_length(name: str, value: Any, *, zero_ok: bool = False) -> float:
    """A length in (0, the scene's largest length] m ([0, ...] with ``zero_ok``)."""
    return float((LENGTH_OR_ZERO if zero_ok else LENGTH).check(name, value))


def check_count(name: str, value: Any, lo: int, hi: int) -> int:
    """An integer in [lo, hi]."""
    return int(count(lo, hi).check(name, value))


def check_density(name: str, value: Any) -> float:
    """A density within the scene's bounds, kg/m^3 (``BOUNDS["density_kg_m3"]``)."""
    return float(DENSITY.check(name, value))


def check_choice(name: str, value: Any, choices: Sequence[str]) -> str:
    """One of ``choices``."""
    if value not in choices:
        raise InputError(name, f"must be one of {', '.join(choices)}, got {value!r}")
    return str(value)


def digits(count: int) -> int:
    """Zero-padding width for block numbers 1..count (at least 2: c01, c02, ...)."""
    return max(2, len(str(count)))


# ---------------------------------------------------------------------- tables


class Outline(TypedDict, total=False):
    """A block's shape in a ``[[blocks]]`` table: a rectangle (``width_m``, ``height_m``) or a
    polygon in its own frame (``vertices_m``), m."""

    width_m: float
    height_m: float
    vertices_m: list[list[float]]


class BlockTable(Outline, total=False):
    """A generated ``[[blocks]]`` table (the scene format's keys: docs/assemblies.md): its
    outline, a density or a mass and inertia of its own, placed by ``position_m`` (absent in
    a column scene) and turned by ``rotation_rad``."""

    name: Required[str]
    thickness_m: Required[float]
    density_kg_m3: float
    mass_kg: float
    inertia_kgm2: float
    position_m: list[float]
    rotation_rad: float
    fixed: bool


def block_table(
    name: str,
    outline: Outline,
    position_m: Sequence[float | Fraction],
    thickness_m: float,
    density_kg_m3: float,
    *,
    rotation_rad: float = 0.0,
    fixed: bool = False,
) -> BlockTable:
    """A ``[[blocks]]`` table: the name, the outline, thickness, density and position, then
    the rotation and ``fixed`` where they are not the defaults (in the order scene files
    show them)."""
    table: BlockTable = {
        "name": name,
        **outline,
        "thickness_m": float(thickness_m),
        "density_kg_m3": float(density_kg_m3),
        "position_m": [num(position_m[0]), num(position_m[1])],
    }
    if rotation_rad != 0.0:
        table["rotation_rad"] = float(rotation_rad)
    if fixed:
        table["fixed"] = True
    return table


def rect_block(
    name: str,
    width: Fraction,
    height: Fraction,
    x: Fraction,
    y: Fraction,
    thickness_m: float,
    density_kg_m3: float,
    *,
    fixed: bool = False,
) -> BlockTable:
    """A ``[[blocks]]`` table of a rectangle whose base edge centre sits at (x, y), m."""
    outline: Outline = {"width_m": num(width), "height_m": num(height)}
    return block_table(name, outline, (x, y), thickness_m, density_kg_m3, fixed=fixed)


def polygon_block(
    name: str,
    vertices_m: Sequence[Sequence[float]],
    position_m: Sequence[float],
    rotation_rad: float,
    thickness_m: float,
    density_kg_m3: float,
    *,
    fixed: bool = False,
) -> BlockTable:
    """A ``[[blocks]]`` table of a polygon given in its own frame, placed and rotated."""
    outline: Outline = {"vertices_m": [[float(x), float(y)] for x, y in vertices_m]}
    return block_table(name, outline, position_m, thickness_m, density_kg_m3, rotation_rad=rotation_rad, fixed=fixed)


def paper_contact() -> dict[str, str]:
    """``[contact]`` of the paper's calibration (Eqs 10-15 from the block above each bed joint).

    For slender blocks (columns, frames, stacks): the paper's equations need
    1 - 1.5 sin^2(alpha) > 0, i.e. blocks taller than about 1.6 x their width.
    """
    return {"calibration": "paper"}


def udec_contact(
    unit_height_m: float,
    density_kg_m3: float,
    jkn_Pa_per_m: float = DEFAULT_JKN_PA_PER_M,
    damping_ratio: float = DEFAULT_JOINT_DAMPING_RATIO,
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG,
) -> dict[str, float]:
    """``[contact]`` with UDEC-style joint stiffness per unit area and an explicit damping.

    The paper's calibration (Eqs 10-15) holds for slender blocks only, so masonry units
    (often wider than tall) get explicit joints: normal and shear stiffness ``jkn`` per unit
    area (K = jkn x L/2 x t per contact point) and the stiffness-proportional damping
    ``beta_s = 2 zeta / omega`` that gives a unit on its bed joint the fraction ``zeta`` of
    critical damping in vertical vibration, omega = sqrt(jkn / (rho h)) (two points of
    stiffness jkn L t / 2 carrying a mass rho L h t).

    Each argument is checked against its range in the table (InputError naming it).
    """
    h = check_length("unit_height_m", unit_height_m)
    rho = check_param("common", "density_kg_m3", density_kg_m3)
    jkn = check_param("common", "jkn_pa_per_m", jkn_Pa_per_m, "jkn_Pa_per_m")
    zeta = check_param("common", "damping_ratio", damping_ratio)
    phi = check_param("common", "friction_angle_deg", friction_angle_deg)
    omega = math.sqrt(jkn / (rho * h))
    beta = 2.0 * zeta / omega
    return {
        "jkn_Pa_per_m": float(jkn),
        "jks_Pa_per_m": float(jkn),
        "beta_s": float(f"{beta:.3g}"),
        "friction_angle_deg": float(phi),
    }


def pulse_motion(amplitude_g: float = 0.3, period_s: float = 0.5, shape: str = "sine", cycles: int = 1) -> dict:
    """A ``[motion]`` table: an acceleration pulse (see rockyade.motion.types); the arguments
    checked against the table."""
    return {
        "type": "pulse",
        "shape": check_param("common", "pulse_shape", shape, "shape"),
        "amplitude_g": check_param("common", "amplitude_g", amplitude_g),
        "period_s": check_param("common", "period_s", period_s),
        "cycles": check_param("common", "cycles", cycles),
    }


def free_motion(block: str, theta0_rad: float) -> dict:
    """A ``[motion]`` table: free rocking of ``block`` (and what rests on it) from ``theta0_rad``."""
    return {"type": "free", "theta0_rad": check_param("common", "theta0_rad", theta0_rad), "block": block}


def rest_motion() -> dict:
    """A ``[motion]`` table: the base at rest (does the assembly stand?)."""
    return {"type": "rest"}


def record_motion(file: str, load_factor: float = 1.0, **options: Any) -> dict:
    """A ``[motion]`` table: a recorded accelerogram (``file`` relative to the scene file)."""
    table = {"type": "record", "file": str(file), **options}
    if check_param("common", "load_factor", load_factor) != 1.0:
        table["load_factor"] = float(load_factor)
    return table


def default_duration_s(motion: Mapping[str, Any] | None, base_dir: str | Path | None = None) -> float:
    """The simulated time of a generated scene whose ``duration_s`` is not given, s.

    For a ``record`` motion, the record's length plus
    :data:`~rockyade.motion.coverage.RECORD_TAIL_S` (5 s) of free rocking, which decides
    whether a block left rocking by the record's end overturns; the same for a ``synthetic``
    record (its suite's length). Otherwise :data:`DEFAULT_DURATION_S` (3 s, enough for the
    default pulse; ``rockyade run`` warns when a scene ends before its motion).

    Parameters
    ----------
    motion
        The ``[motion]`` table (None: the default pulse).
    base_dir
        Folder a relative record path is relative to (the scene file's folder; default the
        current folder).
    """
    kind = motion.get("type") if isinstance(motion, Mapping) else None
    if kind not in ("record", "synthetic"):
        return DEFAULT_DURATION_S
    from rockyade.motion.coverage import RECORD_TAIL_S
    from rockyade.motion.spec import parse_motion
    from rockyade.motion.types import RecordMotion, SyntheticMotion

    folder = Path(base_dir) if base_dir is not None else Path.cwd()
    try:
        spec = parse_motion(dict(motion or {}), base_dir=folder)
    except InputError as exc:
        raise InputError(
            exc.field, f"{exc.message} (duration_s defaults to the record's length: give duration_s or fix the record)"
        ) from None
    length = 0.0
    if isinstance(spec, SyntheticMotion):
        length = spec.suite_spec().envelope.duration_s
    elif isinstance(spec, RecordMotion):
        length = spec.record().duration_s
    return math.ceil(round((length + RECORD_TAIL_S) * 1000.0, 6)) / 1000.0  # to the ms above


class JointTable(TypedDict):
    """A generated ``[[joints]]`` table: the joint of two blocks by name, with its friction
    angle, deg (:class:`rockyade.scene.description.JointOverride`)."""

    blocks: list[str]
    friction_angle_deg: float


def scene_table(
    blocks: list[BlockTable],
    *,
    contact: Mapping[str, Any] | None,
    motion: Mapping[str, Any] | None,
    duration_s: float | None,
    sample_dt_s: float,
    joints: list[JointTable] | None = None,
) -> dict[str, Any]:
    """The scene dictionary (keys in the order a reader expects them in the file).

    ``contact`` None: the paper's calibration (:func:`paper_contact`).

    ``duration_s`` None: :func:`default_duration_s` of the motion (a record's length plus a
    tail of free rocking, relative paths from the current folder).
    """
    if duration_s is None:
        duration_s = default_duration_s(motion)
    check_param("common", "duration_s", duration_s)
    check_param("common", "sample_dt_s", sample_dt_s)
    check_number("sample_dt_s", sample_dt_s, 0.0, duration_s, lo_open=True, unit="s")
    data: dict[str, Any] = {
        "duration_s": float(duration_s),
        "sample_dt_s": float(sample_dt_s),
        "contact": dict(contact if contact is not None else paper_contact()),
        "motion": dict(motion if motion is not None else DEFAULT_PULSE),
        "blocks": blocks,
    }
    if joints:
        data["joints"] = joints
    return data
