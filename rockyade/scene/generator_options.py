"""The parameters of the assembly generators, described once: name, type, unit, default, allowed
range and help of every option of ``rockyade build KIND``.

Two readers: :mod:`rockyade.cli.build` makes its argparse options from :data:`KINDS`,
:data:`OVERBURDEN` and :data:`COMMON` (flag, default, help, metavar), and checks every given
value against its range before anything is built; the generators
(:mod:`rockyade.scene.generators`) check their arguments with :func:`check`, so a value out of
its range is an :class:`~rockyade.errors.InputError` naming the field and the range, whichever
way the generator is called. A parameter's name is the generator's keyword (``unit_height_m``)
and, with dashes, the option (``--unit-height-m``).

The ranges of lengths and densities are the scene's (:data:`rockyade.scene.bounds.BOUNDS`); the
others are those the scene file takes for the same field (the ``[motion]`` and ``[contact]``
tables: :mod:`rockyade.motion.types`, :mod:`rockyade.scene.loading`).

The module imports neither numpy nor numba (``rockyade build --help`` reads it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from types import SimpleNamespace
from typing import Any, NamedTuple

from rockyade.errors import InputError
from rockyade.scene.bounds import BOUNDS


@dataclass(frozen=True)
class Range:
    """The numbers a parameter takes: ``lo`` to ``hi`` (open ends as said), in ``unit``;
    ``integer``: whole numbers only."""

    lo: float = -math.inf
    hi: float = math.inf
    unit: str = ""
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False

    def text(self) -> str:
        """The range in words: ``in (0, 1000] m``, ``> 0 Pa/m``, ``an integer in [1, 200]``."""
        units = f" {self.unit}" if self.unit else ""
        if self.integer:
            return f"an integer in [{self.lo:g}, {self.hi:g}]"
        if math.isinf(self.hi):
            return f"{'>' if self.lo_open else '>='} {self.lo:g}{units}"
        left, right = "(" if self.lo_open else "[", ")" if self.hi_open else "]"
        return f"in {left}{self.lo:g}, {self.hi:g}{right}{units}"

    def holds(self, x: float) -> bool:
        """Whether the number ``x`` lies in the range."""
        low_ok = x > self.lo if self.lo_open else x >= self.lo
        high_ok = x < self.hi if self.hi_open else x <= self.hi
        return low_ok and high_ok

    def check(self, field: str, value: Any) -> Any:
        """``value`` (a float, or an int for an integer range) within the range, else an
        InputError naming ``field`` and the range."""
        if self.integer:
            if isinstance(value, bool) or not isinstance(value, int) or not self.holds(value):
                raise InputError(field, f"must be {self.text()}, got {value!r}")
            return value
        number = isinstance(value, (int, float, Fraction)) and not isinstance(value, bool)
        if not number or not math.isfinite(float(value)):
            raise InputError(field, f"must be a number {self.text()}, got {value!r}")
        x = float(value)
        if not self.holds(x):
            raise InputError(field, f"must be {self.text()}, got {x:g}")
        return x


_LONGEST_M = BOUNDS["length_m"].hi
#: A block's dimension or a distance that cannot be zero, m.
LENGTH = Range(0.0, _LONGEST_M, "m", lo_open=True)
#: A distance that may be zero (a gap, an overhang, a corner's position), m.
LENGTH_OR_ZERO = Range(0.0, _LONGEST_M, "m")
#: A signed distance (an eccentricity, > 0 towards +x), m.
OFFSET = Range(-_LONGEST_M, _LONGEST_M, "m")
DENSITY = Range(BOUNDS["density_kg_m3"].lo, BOUNDS["density_kg_m3"].hi, "kg/m^3")
#: A friction angle, deg (the scene's ``friction_angle_deg``).
FRICTION_DEG = Range(0.0, 90.0, "deg", hi_open=True)


def count(lo: int, hi: int) -> Range:
    """Whole numbers from ``lo`` to ``hi``."""
    return Range(lo, hi, integer=True)


@dataclass(frozen=True)
class Param:
    """One parameter of a generator and its ``build`` option.

    Attributes
    ----------
    name
        The generator's keyword and the option's destination (``unit_height_m``).
    default
        The generator's default (None: worked out from the others, said in ``help``).
    help
        What it is, with its unit.
    range
        The numbers it takes (None: a text or a choice).
    choices
        The words it takes (a choice).
    many
        A comma-separated list of numbers, each in ``range``.
    repeat
        Given again for each item (an opening X,Y,W,H; its items are checked by the generator).
    flag
        The option when it is not the name with dashes.
    aliases
        Other spellings of the option.
    metavar
        The option's placeholder in ``--help`` (default: from its unit).
    """

    name: str
    default: Any
    help: str
    range: Range | None = None
    choices: tuple[str, ...] = ()
    many: bool = False
    repeat: bool = False
    flag: str = ""
    aliases: tuple[str, ...] = ()
    metavar: str | None = None

    @property
    def dest(self) -> str:
        """The argparse destination: the generator's keyword."""
        return self.name

    @property
    def option(self) -> str:
        """The command-line option (``--unit-height-m``)."""
        return self.flag or "--" + self.name.replace("_", "-")

    @property
    def unit(self) -> str:
        """The unit of its numbers ("" for none)."""
        return self.range.unit if self.range is not None else ""

    @property
    def integer(self) -> bool:
        """Whether it takes whole numbers."""
        return self.range is not None and self.range.integer

    @property
    def numeric(self) -> bool:
        """Whether it takes numbers that :meth:`check` checks (one, or a list)."""
        return self.range is not None and not self.repeat

    def check(self, value: Any, field: str | None = None) -> Any:
        """``value`` checked (a number within the range, each of a list, or one of the
        choices); InputError naming ``field`` (default the name) and what it takes otherwise.
        None passes for a parameter whose default is None."""
        field = field or self.name
        if value is None and self.default is None:
            return None
        if self.choices:
            if value not in self.choices:
                raise InputError(field, f"must be one of {', '.join(self.choices)}, got {value!r}")
            return str(value)
        if self.range is None or self.repeat:
            return value
        if self.many and isinstance(value, (list, tuple)):
            return [self.range.check(f"{field}[{i}]", v) for i, v in enumerate(value)]
        return self.range.check(field, value)


class Kind(NamedTuple):
    """A generator: what it makes (``build KIND --help``) and its parameters."""

    text: str
    params: tuple[Param, ...]


#: Blocks of a column or a stack, at most.
MAX_STACK_BLOCKS = 10_000
#: The widths of the default stack, bottom to top, m (a tapered column of four blocks).
STACK_WIDTHS_M = (0.4, 0.35, 0.3, 0.25)

#: Column-like kinds (column, stack) write an assembly or a column scene.
LAYOUT = Param(
    "layout",
    "positioned",
    "positioned: an assembly; column: a column scene (no positions)",
    choices=("positioned", "column"),
)

KINDS: dict[str, Kind] = {
    "wall": Kind(
        "a dry masonry wall in running or stack bond, with openings (in-plane section)",
        (
            Param("courses", 5, "number of courses", count(1, 1000)),
            Param("units_per_course", 6, "whole units per course", count(1, 1000)),
            Param("unit_length_m", 0.4, "unit length along the wall, m", LENGTH),
            Param("unit_height_m", 0.2, "unit height, m", LENGTH),
            Param("unit_thickness_m", 0.2, "unit thickness out of plane, m", LENGTH),
            Param(
                "bond",
                "running",
                "running: half units at both ends of courses 2, 4, ...",
                choices=("running", "stack"),
            ),
            Param(
                "opening",
                None,
                "an opening X,Y,WIDTH,HEIGHT in m (x from the wall's left end, y from the base); repeat for several",
                LENGTH_OR_ZERO,
                repeat=True,
                metavar="X,Y,W,H",
            ),
            Param("lintel", "block", "a lintel block over each opening, or none", choices=("block", "none")),
            Param("lintel_height_m", None, "lintel height, m (default: one unit height)", LENGTH),
            Param(
                "lintel_bearing_m",
                None,
                "lintel bearing each side of the opening, m (default: half a unit)",
                LENGTH_OR_ZERO,
            ),
            Param(
                "min_piece_m",
                None,
                "cut pieces smaller than this are left out, m (default: a quarter of the smaller unit dimension)",
                LENGTH,
            ),
        ),
    ),
    "column": Kind(
        "a column of equal drums (round by default), optionally with a capital (abacus) block on top",
        (
            Param("drums", 8, "number of drums", count(1, MAX_STACK_BLOCKS)),
            Param("diameter_m", 0.3, "drum width in the plane of rocking, m", LENGTH),
            Param("drum_height_m", 0.5, "height of each drum, m", LENGTH),
            Param("thickness_m", None, "out-of-plane thickness, m (default: the diameter)", LENGTH),
            Param("capital_width_m", None, "width of a capital block on top, m (with --capital-height-m)", LENGTH),
            Param("capital_height_m", None, "height of the capital block, m", LENGTH),
            Param(
                "section",
                "round",
                "round: cylinders (mass rho pi D^2/4 h and inertia m (3 r^2 + h^2)/12 written per drum); "
                "square: prisms D x thickness",
                choices=("round", "square"),
            ),
            LAYOUT,
        ),
    ),
    "arch": Kind(
        "a semicircular or pointed arch of n voussoirs on two piers",
        (
            Param("span_m", 2.0, "clear span between the springings, m", LENGTH),
            Param("ring_depth_m", 0.3, "ring depth (extrados minus intrados radius), m", LENGTH),
            Param("thickness_m", 0.5, "out-of-plane thickness, m", LENGTH),
            Param("voussoirs", 11, "number of voussoirs (2-201)", count(2, 201)),
            Param("shape", "semicircular", "arch shape", choices=("semicircular", "pointed")),
            Param(
                "centre_offset_m",
                None,
                "pointed arch: distance of each half's centre from the midspan, m "
                "(default: span/2, the equilateral arch)",
                LENGTH,
            ),
            Param("pier_width_m", 0.6, "pier width, m", LENGTH),
            Param("pier_height_m", 1.0, "pier height, m (0: the arch springs from the base)", LENGTH_OR_ZERO),
            Param("piers", "blocks", "blocks (free) or fixed abutments", choices=("blocks", "fixed")),
        ),
    ),
    "frame": Kind(
        "the rocking frame of Makris & Vassiliou (2013): two free columns and a free cap beam",
        (
            Param("column_width_m", 0.25, "column width 2b, m", LENGTH),
            Param("column_height_m", 1.5, "column height 2h, m", LENGTH),
            Param("span_m", 1.5, "distance between the column axes, m", LENGTH),
            Param("beam_height_m", 0.25, "beam depth, m", LENGTH),
            Param("beam_overhang_m", 0.0, "beam length past each column's outer face, m", LENGTH_OR_ZERO),
            Param("thickness_m", 0.25, "out-of-plane thickness, m", LENGTH),
            Param("beam_density_kg_m3", None, "beam density, kg/m^3 (default: --density-kg-m3)", DENSITY),
            Param(
                "gamma",
                None,
                "instead of a beam density: beam mass / both columns' mass",
                Range(0.0, 100.0, lo_open=True),
            ),
        ),
    ),
    "stack": Kind(
        "a stack of blocks of given sizes (a tapered column)",
        (
            Param(
                "widths_m",
                None,
                "widths bottom to top, m, comma-separated (or --blocks with "
                f"--bottom-width-m and --top-width-m; default {','.join(f'{w:g}' for w in STACK_WIDTHS_M)})",
                LENGTH,
                many=True,
                metavar="W1,W2,...",
            ),
            Param(
                "heights_m",
                [0.6],
                "heights bottom to top, m, comma-separated, or one for all",
                LENGTH,
                many=True,
                metavar="H1,H2,...",
            ),
            Param("blocks", None, "number of blocks of a linear taper", count(1, MAX_STACK_BLOCKS)),
            Param("bottom_width_m", None, "width at the bottom of a linear taper, m", LENGTH),
            Param("top_width_m", None, "width at the top of a linear taper, m", LENGTH),
            Param("thickness_m", 0.4, "out-of-plane thickness, m", LENGTH),
            Param(
                "taper",
                "steps",
                "steps: rectangles; continuous: trapezoids with straight sides",
                choices=("steps", "continuous"),
            ),
            LAYOUT,
        ),
    ),
    "wall-section": Kind(
        "a wall's section out of its plane: height, thickness (through the section) and length (along the wall), "
        "courses, a top free, restrained beside one face or both or under a floor, with or without a gap, "
        "an overburden",
        (
            Param("height_m", 3.0, "the wall's height, m", LENGTH),
            Param("thickness_m", 0.3, "the wall's thickness, through the section (the scene's width_m), m", LENGTH),
            Param("length_m", 1.0, "the wall's length along its plane (the blocks' thickness_m), m", LENGTH),
            Param("courses", 1, "courses (1: one block), equal unless --split", count(1, 200)),
            Param(
                "split",
                None,
                "2 courses: height of the joint between them / the wall's height, in (0, 1) "
                "(the two-block wall of the paper's Fig. 2c; default: equal courses)",
                Range(0.0, 1.0, lo_open=True, hi_open=True),
            ),
            Param(
                "top",
                "free",
                "free; restrained (a fixed block beside each face, with a gap > 0); restrained-far or "
                "restrained-near (one face, x > 0 or x < 0; a zero gap gives the three-hinge mechanism); floor (a "
                "fixed slab over the top, the gap above it)",
                choices=("free", "restrained", "restrained-far", "restrained-near", "floor"),
            ),
            Param(
                "gap_m",
                0.0,
                "restrained, floor: gap between the wall and its restraint (one the wall cannot close "
                "before it overturns is refused), m",
                LENGTH_OR_ZERO,
            ),
            Param("restraint_height_m", 0.3, "restrained, floor: depth of the restraints (the slab), m", LENGTH),
            Param(
                "restraint_width_m",
                0.3,
                "restrained, floor: width of the restraints (the slab's reach past the far face), m",
                LENGTH,
            ),
            Param(
                "restraint_friction_deg",
                0.0,
                "restrained, floor: friction of the wall-restraint joints, deg (0: none)",
                FRICTION_DEG,
            ),
        ),
    ),
    "restrained-wall": Kind(
        "a wall restrained at its top (out-of-plane section, the paper's Fig. 2; an alias of wall-section)",
        (
            Param(
                "wall_height_m",
                3.0,
                "wall height, m (or --height-m, as wall-section)",
                LENGTH,
                aliases=("--height-m",),
            ),
            Param(
                "wall_thickness_m",
                0.3,
                "wall thickness (the section's width), m (or --thickness-m)",
                LENGTH,
                aliases=("--thickness-m",),
            ),
            Param(
                "wall_length_m",
                1.0,
                "wall length along its plane (the blocks' out-of-plane thickness), m (or --length-m)",
                LENGTH,
                aliases=("--length-m",),
            ),
            Param("blocks", 2, "1 or 2 wall blocks", count(1, 2)),
            Param(
                "split",
                0.5,
                "two blocks: lower block height / wall height",
                Range(0.0, 1.0, lo_open=True, hi_open=True),
            ),
            Param(
                "restraint",
                "side",
                "side: a fixed block against the far face at the top; floor: a fixed slab on the wall's top",
                choices=("side", "floor"),
            ),
            Param("restraint_width_m", 0.3, "restraint width (floor: reach past the far face), m", LENGTH),
            Param("restraint_height_m", 0.3, "restraint height (floor: slab depth), m", LENGTH),
            Param("gap_m", 0.0, "gap between the wall and the restraint, m", LENGTH_OR_ZERO),
            Param(
                "restraint_friction_deg",
                0.0,
                "friction angle of the wall-restraint joint, deg (default 0: a frictionless restraint, which the "
                "three-hinge mechanism of Fig. 2 needs, as wall-section's)",
                FRICTION_DEG,
            ),
        ),
    ),
}

#: Kinds that are aliases of another, with how their options map onto it (said in their --help).
ALIASES = {
    "restrained-wall": "It is an alias of `rockyade build wall-section` under its former option names: "
    "--wall-height-m, --wall-thickness-m, --wall-length-m are --height-m, --thickness-m, --length-m; --blocks "
    "(1 or 2) is --courses; --split is --split; --restraint side is --top restrained-far, --restraint floor is "
    "--top floor; the other options are the same, with the same defaults. The blocks carry wall-section's names "
    "(w01, w02; restraint_far or floor).",
}

#: Largest overburden per metre of wall, N/m (100 MN/m: far above any masonry wall's).
MAX_N_PER_M = 1.0e8
#: Largest point overburden, N.
MAX_N = 1.0e9
#: A wall's overburden per metre, N/m (downwards).
LINE_LOAD = Range(0.0, MAX_N_PER_M, "N/m")
#: A point overburden, N (downwards).
POINT_LOAD = Range(0.0, MAX_N, "N")

_SECTION_LOAD = (
    Param("overburden_n_per_m", 0.0, "vertical load per metre of wall on its top, N/m", LINE_LOAD),
    Param("overburden_eccentricity_m", 0.0, "its distance from the wall's axis, m (> 0 towards +x)", OFFSET),
)
_POINT_LOAD = (
    Param("top_load_n", 0.0, "vertical load on the top block, N", POINT_LOAD),
    Param("top_load_eccentricity_m", 0.0, "its distance from the top block's axis, m (> 0 towards +x)", OFFSET),
)


class Overburden(NamedTuple):
    """The overburden options of a kind: how the load is placed
    (:func:`rockyade.scene.generators.overburden.add_overburden`'s ``kind``), its options, and
    whether the generator takes them itself (``wall_section``) rather than ``add_overburden``
    after it."""

    how: str
    params: tuple[Param, ...]
    by_generator: bool = False


#: Overburden options by kind, written as [[loads]] of the generated scene.
OVERBURDEN: dict[str, Overburden] = {
    "wall": Overburden(
        "line", (Param("overburden_n_per_m", 0.0, "vertical load per metre of wall on its top course, N/m", LINE_LOAD),)
    ),
    "wall-section": Overburden("section", _SECTION_LOAD, by_generator=True),
    "restrained-wall": Overburden("section", _SECTION_LOAD),
    "column": Overburden("point", _POINT_LOAD),
    "stack": Overburden("point", _POINT_LOAD),
}

#: Options every kind takes: density, time, motion and joints (the parameters of the scene
#: table and of :func:`~rockyade.scene.generators.pulse_motion`, ``free_motion``,
#: ``record_motion`` and ``udec_contact``).
COMMON: tuple[Param, ...] = (
    Param("density_kg_m3", 2400.0, "density of the blocks, kg/m^3", DENSITY),
    Param(
        "duration_s",
        None,
        "simulated time, s (default: with --motion record, the record's length plus 5 s of free rocking; else 3)",
        Range(0.0, BOUNDS["duration_s"].hi, "s", lo_open=True),
    ),
    Param(
        "sample_dt_s",
        0.002,
        "output sampling interval, s",
        Range(BOUNDS["sample_dt_s"].lo, BOUNDS["sample_dt_s"].hi, "s"),
    ),
    Param(
        "motion",
        "pulse",
        "base motion: a pulse, a record file, free rocking of one block, rest (a drop test), gravity-ramp "
        "(the static check) or pushover (towards +x, lambda rising at 0.05 g/s)",
        choices=("pulse", "record", "free", "rest", "gravity-ramp", "pushover"),
    ),
    Param("pulse_shape", "sine", "pulse shape", choices=("sine", "cosine", "ricker")),
    Param("amplitude_g", 0.3, "pulse amplitude, g", Range(0.0, 100.0, "g", lo_open=True)),
    Param("period_s", 0.5, "pulse period, s", Range(0.0, 100.0, "s", lo_open=True)),
    Param("cycles", 1, "pulse cycles", count(1, 1000)),
    Param(
        "record",
        None,
        "record file (AT2, CSV or one column) for --motion record; written relative to the scene file",
        metavar="FILE",
    ),
    Param(
        "load_factor",
        1.0,
        "multiplies the record's accelerations as read (its samples as in the file)",
        Range(0.0, 100.0),
    ),
    Param(
        "theta0_rad",
        0.05,
        "free rocking: initial tilt, rad",
        Range(-math.pi / 2, math.pi / 2, "rad", lo_open=True, hi_open=True),
    ),
    Param("free_block", None, "free rocking: the block tilted (with what rests on it)", metavar="NAME"),
    Param(
        "contact",
        "auto",
        "joints: auto (udec for walls and arches, paper otherwise), paper or matched "
        "(the paper's calibration, slender blocks), udec (stiffness per unit area)",
        choices=("auto", "paper", "matched", "udec"),
    ),
    Param(
        "jkn_pa_per_m",
        1.0e10,
        "udec: normal (and shear) joint stiffness per unit area, Pa/m",
        Range(BOUNDS["contact.jkn_Pa_per_m"].lo, BOUNDS["contact.jkn_Pa_per_m"].hi, "Pa/m"),
    ),
    Param(
        "damping_ratio",
        0.05,
        "udec: fraction of critical damping of a unit on its bed joint (sets beta_s)",
        Range(0.0, 1.0, hi_open=True),
    ),
    Param("friction_angle_deg", 30.0, "joint friction angle, deg", FRICTION_DEG),
)

#: Generator parameters among the common options.
COMMON_PARAMS = ("density_kg_m3", "duration_s", "sample_dt_s")


def options(kind: str) -> tuple[Param, ...]:
    """Every option of ``build KIND``: its own, its overburden's and the common ones ("common":
    the common ones alone)."""
    if kind == "common":
        return COMMON
    loads = OVERBURDEN[kind].params if kind in OVERBURDEN else ()
    return (*KINDS[kind].params, *loads, *COMMON)


def param(kind: str, name: str) -> Param:
    """The parameter ``name`` of generator ``kind`` (its own, its overburden's or a common one;
    ``kind`` "common": a common one)."""
    for p in options(kind):
        if p.name == name:
            return p
    raise KeyError(f"{kind} has no parameter {name!r}")


def defaults(kind: str) -> SimpleNamespace:
    """The defaults of ``build KIND``'s options by name, for the generator's signature
    (``defaults("wall").unit_height_m``)."""
    return SimpleNamespace(**{p.name: p.default for p in options(kind)})


def check(kind: str, name: str, value: Any, field: str | None = None) -> Any:
    """``value`` of parameter ``name`` of ``kind`` checked against the table (:meth:`Param.check`):
    InputError naming ``field`` (default ``name``) and the range otherwise."""
    return param(kind, name).check(value, field)
