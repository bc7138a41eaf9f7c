"""``rockyade build KIND`` (generate an assembly scene) and ``rockyade draw`` (draw a scene).

Also the snapshot and animation options that ``rockyade run`` shares with ``draw``
(:func:`add_snapshot_options`, :func:`write_run_drawings`).

Option defaults are written here as literals (importing the generators would load numpy
and slow down ``rockyade --help``); tests check that they equal the Python defaults.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import shlex
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rockyade.cli.common import check_output_file
from rockyade.cli.drawings import add_snapshot_options, check_run_drawings, write_run_drawings
from rockyade.errors import InputError


@dataclass(frozen=True)
class Opt:
    """One generator option: flag (``--unit-length-m``), default, help; ``dest`` is the
    generator's parameter name."""

    flag: str
    default: Any
    help: str
    type: Any = float
    choices: tuple[str, ...] | None = None
    metavar: str | None = None
    append: bool = False
    aliases: tuple[str, ...] = ()

    @property
    def dest(self) -> str:
        """The argparse destination of the option (its name without dashes, '-' as '_')."""
        return self.flag[2:].replace("-", "_")


def _floats(text: str) -> list[float]:
    """A comma-separated list of numbers (argparse type)."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be numbers separated by commas, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("needs at least one number")
    return values


#: Column-like kinds (column, stack) write an assembly or a column scene.
LAYOUT_OPT = Opt(
    "--layout",
    "positioned",
    "positioned: an assembly; column: a column scene (no positions)",
    str,
    ("positioned", "column"),
)

KINDS: dict[str, tuple[str, list[Opt]]] = {
    "wall": (
        "a dry masonry wall in running or stack bond, with openings (in-plane section)",
        [
            Opt("--courses", 5, "number of courses", int),
            Opt("--units-per-course", 6, "whole units per course", int),
            Opt("--unit-length-m", 0.4, "unit length along the wall, m"),
            Opt("--unit-height-m", 0.2, "unit height, m"),
            Opt("--unit-thickness-m", 0.2, "unit thickness out of plane, m"),
            Opt(
                "--bond", "running", "running: half units at both ends of courses 2, 4, ...", str, ("running", "stack")
            ),
            Opt(
                "--opening",
                None,
                "an opening X,Y,WIDTH,HEIGHT in m (x from the wall's left end, y from the base); repeat for several",
                _floats,
                metavar="X,Y,W,H",
                append=True,
            ),
            Opt("--lintel", "block", "a lintel block over each opening, or none", str, ("block", "none")),
            Opt("--lintel-height-m", None, "lintel height, m (default: one unit height)"),
            Opt("--lintel-bearing-m", None, "lintel bearing each side of the opening, m (default: half a unit)"),
            Opt(
                "--min-piece-m",
                None,
                "cut pieces smaller than this are left out, m (default: a quarter of the smaller unit dimension)",
            ),
        ],
    ),
    "column": (
        "a column of equal drums (round by default), optionally with a capital (abacus) block on top",
        [
            Opt("--drums", 8, "number of drums", int),
            Opt("--diameter-m", 0.3, "drum width in the plane of rocking, m"),
            Opt("--drum-height-m", 0.5, "height of each drum, m"),
            Opt("--thickness-m", None, "out-of-plane thickness, m (default: the diameter)"),
            Opt("--capital-width-m", None, "width of a capital block on top, m (with --capital-height-m)"),
            Opt("--capital-height-m", None, "height of the capital block, m"),
            Opt(
                "--section",
                "round",
                "round: cylinders (mass rho pi D^2/4 h and inertia m (3 r^2 + h^2)/12 written per drum); "
                "square: prisms D x thickness",
                str,
                ("round", "square"),
            ),
            LAYOUT_OPT,
        ],
    ),
    "arch": (
        "a semicircular or pointed arch of n voussoirs on two piers",
        [
            Opt("--span-m", 2.0, "clear span between the springings, m"),
            Opt("--ring-depth-m", 0.3, "ring depth (extrados minus intrados radius), m"),
            Opt("--thickness-m", 0.5, "out-of-plane thickness, m"),
            Opt("--voussoirs", 11, "number of voussoirs (2-201)", int),
            Opt("--shape", "semicircular", "arch shape", str, ("semicircular", "pointed")),
            Opt(
                "--centre-offset-m",
                None,
                "pointed arch: distance of each half's centre from the midspan, m "
                "(default: span/2, the equilateral arch)",
            ),
            Opt("--pier-width-m", 0.6, "pier width, m"),
            Opt("--pier-height-m", 1.0, "pier height, m (0: the arch springs from the base)"),
            Opt("--piers", "blocks", "blocks (free) or fixed abutments", str, ("blocks", "fixed")),
        ],
    ),
    "frame": (
        "the rocking frame of Makris & Vassiliou (2013): two free columns and a free cap beam",
        [
            Opt("--column-width-m", 0.25, "column width 2b, m"),
            Opt("--column-height-m", 1.5, "column height 2h, m"),
            Opt("--span-m", 1.5, "distance between the column axes, m"),
            Opt("--beam-height-m", 0.25, "beam depth, m"),
            Opt("--beam-overhang-m", 0.0, "beam length past each column's outer face, m"),
            Opt("--thickness-m", 0.25, "out-of-plane thickness, m"),
            Opt("--beam-density-kg-m3", None, "beam density, kg/m^3 (default: --density-kg-m3)"),
            Opt("--gamma", None, "instead of a beam density: beam mass / both columns' mass"),
        ],
    ),
    "stack": (
        "a stack of blocks of given sizes (a tapered column)",
        [
            Opt(
                "--widths-m",
                None,
                "widths bottom to top, m, comma-separated (or --blocks with "
                "--bottom-width-m and --top-width-m; default 0.4,0.35,0.3,0.25)",
                _floats,
                metavar="W1,W2,...",
            ),
            Opt(
                "--heights-m",
                [0.6],
                "heights bottom to top, m, comma-separated, or one for all",
                _floats,
                metavar="H1,H2,...",
            ),
            Opt("--blocks", None, "number of blocks of a linear taper", int),
            Opt("--bottom-width-m", None, "width at the bottom of a linear taper, m"),
            Opt("--top-width-m", None, "width at the top of a linear taper, m"),
            Opt("--thickness-m", 0.4, "out-of-plane thickness, m"),
            Opt(
                "--taper",
                "steps",
                "steps: rectangles; continuous: trapezoids with straight sides",
                str,
                ("steps", "continuous"),
            ),
            LAYOUT_OPT,
        ],
    ),
    "wall-section": (
        "a wall's section out of its plane: height, thickness (through the section) and length (along the wall), "
        "courses, a top free, restrained beside one face or both or under a floor, with or without a gap, "
        "an overburden",
        [
            Opt("--height-m", 3.0, "the wall's height, m"),
            Opt("--thickness-m", 0.3, "the wall's thickness, through the section (the scene's width_m), m"),
            Opt("--length-m", 1.0, "the wall's length along its plane (the blocks' thickness_m), m"),
            Opt("--courses", 1, "courses (1: one block), equal unless --split", int),
            Opt(
                "--split",
                None,
                "2 courses: height of the joint between them / the wall's height, in (0, 1) "
                "(the two-block wall of the paper's Fig. 2c; default: equal courses)",
            ),
            Opt(
                "--top",
                "free",
                "free; restrained (a fixed block beside each face, with a gap > 0); restrained-far or "
                "restrained-near (one face, x > 0 or x < 0; a zero gap gives the three-hinge mechanism); floor (a "
                "fixed slab over the top, the gap above it)",
                str,
                ("free", "restrained", "restrained-far", "restrained-near", "floor"),
            ),
            Opt(
                "--gap-m",
                0.0,
                "restrained, floor: gap between the wall and its restraint (one the wall cannot close "
                "before it overturns is refused), m",
            ),
            Opt("--restraint-height-m", 0.3, "restrained, floor: depth of the restraints (the slab), m"),
            Opt(
                "--restraint-width-m",
                0.3,
                "restrained, floor: width of the restraints (the slab's reach past the far face), m",
            ),
            Opt(
                "--restraint-friction-deg",
                0.0,
                "restrained, floor: friction of the wall-restraint joints, deg (0: none)",
            ),
            Opt("--overburden-n-per-m", 0.0, "vertical load per metre of wall on its top, N/m"),
            Opt("--overburden-eccentricity-m", 0.0, "its distance from the wall's axis, m (> 0 towards +x)"),
        ],
    ),
    "restrained-wall": (
        "a wall restrained at its top (out-of-plane section, the paper's Fig. 2; an alias of wall-section)",
        [
            Opt("--wall-height-m", 3.0, "wall height, m (or --height-m, as wall-section)", aliases=("--height-m",)),
            Opt(
                "--wall-thickness-m",
                0.3,
                "wall thickness (the section's width), m (or --thickness-m)",
                aliases=("--thickness-m",),
            ),
            Opt(
                "--wall-length-m",
                1.0,
                "wall length along its plane (the blocks' out-of-plane thickness), m (or --length-m)",
                aliases=("--length-m",),
            ),
            Opt("--blocks", 2, "1 or 2 wall blocks", int),
            Opt("--split", 0.5, "two blocks: lower block height / wall height"),
            Opt(
                "--restraint",
                "side",
                "side: a fixed block against the far face at the top; floor: a fixed slab on the wall's top",
                str,
                ("side", "floor"),
            ),
            Opt("--restraint-width-m", 0.3, "restraint width (floor: reach past the far face), m"),
            Opt("--restraint-height-m", 0.3, "restraint height (floor: slab depth), m"),
            Opt("--gap-m", 0.0, "gap between the wall and the restraint, m"),
            Opt(
                "--restraint-friction-deg",
                0.0,
                "friction angle of the wall-restraint joint, deg (default 0: a frictionless restraint, which the "
                "three-hinge mechanism of Fig. 2 needs, as wall-section's)",
            ),
        ],
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

#: Options every kind takes (density, time, motion, contact); not generator parameters
#: except density, duration and sample interval.
COMMON: list[Opt] = [
    Opt("--density-kg-m3", 2400.0, "density of the blocks, kg/m^3"),
    Opt(
        "--duration-s",
        None,
        "simulated time, s (default: with --motion record, the record's length plus 5 s of free rocking; else 3)",
    ),
    Opt("--sample-dt-s", 0.002, "output sampling interval, s"),
    Opt(
        "--motion",
        "pulse",
        "base motion: a pulse, a record file, free rocking of one block, rest (a drop test), gravity-ramp "
        "(the static check) or pushover (towards +x, lambda rising at 0.05 g/s)",
        str,
        ("pulse", "record", "free", "rest", "gravity-ramp", "pushover"),
    ),
    Opt("--pulse-shape", "sine", "pulse shape", str, ("sine", "cosine", "ricker")),
    Opt("--amplitude-g", 0.3, "pulse amplitude, g"),
    Opt("--period-s", 0.5, "pulse period, s"),
    Opt("--cycles", 1, "pulse cycles", int),
    Opt(
        "--record",
        None,
        "record file (AT2, CSV or one column) for --motion record; written relative to the scene file",
        str,
        metavar="FILE",
    ),
    Opt("--load-factor", 1.0, "multiplies the record's accelerations as read (its samples as in the file)"),
    Opt("--theta0-rad", 0.05, "free rocking: initial tilt, rad"),
    Opt("--free-block", None, "free rocking: the block tilted (with what rests on it)", str, metavar="NAME"),
    Opt(
        "--contact",
        "auto",
        "joints: auto (udec for walls and arches, paper otherwise), paper or matched "
        "(the paper's calibration, slender blocks), udec (stiffness per unit area)",
        str,
        ("auto", "paper", "matched", "udec"),
    ),
    Opt("--jkn-pa-per-m", 1.0e10, "udec: normal (and shear) joint stiffness per unit area, Pa/m"),
    Opt("--damping-ratio", 0.05, "udec: fraction of critical damping of a unit on its bed joint (sets beta_s)"),
    Opt("--friction-angle-deg", 30.0, "joint friction angle, deg"),
]

#: Overburden options by kind (not generator parameters: :func:`rockyade.scene.generators.overburden.
#: add_overburden` adds them as [[loads]] to the generated scene): kind -> (overburden kind, options).
OVERBURDEN: dict[str, tuple[str, list[Opt]]] = {
    "wall": ("line", [Opt("--overburden-n-per-m", 0.0, "vertical load per metre of wall on its top course, N/m")]),
    "restrained-wall": (
        "section",
        [
            Opt("--overburden-n-per-m", 0.0, "vertical load per metre of wall on its top, N/m"),
            Opt("--overburden-eccentricity-m", 0.0, "its distance from the wall's axis, m (> 0 towards +x)"),
        ],
    ),
    "column": (
        "point",
        [
            Opt("--top-load-n", 0.0, "vertical load on the top block, N"),
            Opt("--top-load-eccentricity-m", 0.0, "its distance from the top block's axis, m (> 0 towards +x)"),
        ],
    ),
}
OVERBURDEN["stack"] = OVERBURDEN["column"]

#: Generator parameters among the common options.
COMMON_PARAMS = ("density_kg_m3", "duration_s", "sample_dt_s")
UDEC_KINDS = ("wall", "arch")


#: Short metavars from the unit at the end of an option's name.
UNIT_METAVARS = {"-m": "M", "-s": "S", "-kg-m3": "KG/M3", "-pa-per-m": "PA/M", "-deg": "DEG", "-rad": "RAD"}


def _metavar(opt: Opt) -> str | None:
    if opt.metavar or opt.choices:
        return opt.metavar
    for suffix, metavar in sorted(UNIT_METAVARS.items(), key=lambda item: -len(item[0])):
        if opt.flag.endswith(suffix):
            return metavar
    return "N" if opt.type is int else "X"


class _DefaultsFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Shows "(default: ...)" for options that have a default value (not for None)."""

    def _get_help_string(self, action: argparse.Action) -> str:
        if action.default is None or action.default is argparse.SUPPRESS or isinstance(action.default, bool):
            return action.help or ""
        if isinstance(action.default, list):
            return f"{action.help} (default: {','.join(f'{v:g}' for v in action.default)})"
        if isinstance(action.default, float):
            return f"{action.help} (default: {action.default:g})"
        return super()._get_help_string(action) or ""


def _add(parser: argparse.ArgumentParser | Any, opt: Opt) -> None:
    kwargs: dict[str, Any] = {"default": opt.default, "help": opt.help, "dest": opt.dest, "metavar": _metavar(opt)}
    if opt.append:
        kwargs.update(action="append", type=opt.type)
    else:
        kwargs.update(type=opt.type, choices=opt.choices)
    parser.add_argument(opt.flag, *opt.aliases, **kwargs)


# ---------------------------------------------------------------------- build


def _motion_table(args: argparse.Namespace, out: Path) -> dict[str, Any]:
    from rockyade.scene.generators import free_motion, pulse_motion, record_motion, rest_motion

    if args.motion == "pulse":
        return pulse_motion(args.amplitude_g, args.period_s, args.pulse_shape, args.cycles)
    if args.motion == "rest":
        return rest_motion()
    if args.motion in ("gravity-ramp", "pushover"):
        return {"type": args.motion}
    if args.motion == "free":
        if args.free_block is None:
            raise InputError("--free-block", "is required with --motion free: the name of the block to tilt")
        return free_motion(args.free_block, args.theta0_rad)
    if args.record is None:
        raise InputError("--record", "is required with --motion record: the record file")
    record = Path(args.record)
    if not record.is_file():
        raise InputError("--record", f"file not found: {record}")
    relative = os.path.relpath(record.resolve(), out.resolve().parent)
    return record_motion(Path(relative).as_posix(), args.load_factor)


def _default_duration(args: argparse.Namespace, motion: dict[str, Any]) -> float:
    """--duration-s when not given: a record's length plus a tail of free rocking, else 3 s."""
    from rockyade.scene.generators.scene_tables import default_duration_s

    if motion.get("type") != "record":
        return default_duration_s(motion)
    duration = default_duration_s({**motion, "file": str(Path(args.record).resolve())})
    print(f"duration_s = {duration:g} s: the record's length plus 5 s of free rocking (--duration-s to change)")
    return duration


def _contact_table(args: argparse.Namespace, kind: str, unit_height_m: float) -> dict[str, Any] | None:
    from rockyade.scene.generators import udec_contact

    choice = args.contact
    if choice == "auto":
        choice = "udec" if kind in UDEC_KINDS else "paper"
    if choice == "udec":
        if not (math.isfinite(args.jkn_pa_per_m) and args.jkn_pa_per_m > 0):
            raise InputError("--jkn-pa-per-m", f"must be > 0 Pa/m, got {args.jkn_pa_per_m:g}")
        if not 0.0 <= args.damping_ratio < 1.0:
            raise InputError("--damping-ratio", f"must be in [0, 1), got {args.damping_ratio:g}")
        return udec_contact(
            unit_height_m, args.density_kg_m3, args.jkn_pa_per_m, args.damping_ratio, args.friction_angle_deg
        )
    return {"calibration": choice, "friction_angle_deg": args.friction_angle_deg}


#: An option that means nothing without another: (option, its dest, the other's dest, the other option).
_NEEDS = [
    ("--overburden-eccentricity-m", "overburden_eccentricity_m", "overburden_n_per_m", "--overburden-n-per-m"),
    ("--top-load-eccentricity-m", "top_load_eccentricity_m", "top_load_n", "--top-load-n"),
]


def _check_counts_and_pairs(args: argparse.Namespace, kind: str) -> None:
    """Refuse, before anything is built, a count the generator would divide by (``--courses 0``)
    and an option that would be silently ignored (an eccentricity without its load)."""
    if kind == "wall-section" and not 1 <= args.courses <= 200:
        raise InputError("--courses", f"must be an integer in [1, 200], got {args.courses} (nothing written)")
    for option, dest, other, other_option in _NEEDS:
        if getattr(args, dest, 0.0) != 0.0 and getattr(args, other, 0.0) == 0.0:
            raise InputError(
                option, f"has no load to place: give {other_option} > 0 with it, or leave it out (nothing written)"
            )


def _unit_height(args: argparse.Namespace, kind: str) -> float:
    """The block height that sets the default damping of udec joints, m."""
    return {
        "wall": lambda: args.unit_height_m,
        "arch": lambda: args.ring_depth_m,
        "column": lambda: args.drum_height_m,
        "frame": lambda: args.beam_height_m,
        "stack": lambda: min(args.heights_m),
        "restrained-wall": lambda: args.wall_height_m * (min(args.split, 1 - args.split) if args.blocks == 2 else 1),
        "wall-section": lambda: (
            args.height_m
            * (min(args.split, 1 - args.split) if args.split is not None and args.courses == 2 else 1 / args.courses)
        ),
    }[kind]()


def _generator_kwargs(args: argparse.Namespace, kind: str) -> dict[str, Any]:
    kwargs = {opt.dest: getattr(args, opt.dest) for opt in KINDS[kind][1]}
    kwargs.update({name: getattr(args, name) for name in COMMON_PARAMS})
    if kind == "wall":
        kwargs["openings"] = kwargs.pop("opening") or []
    elif kind == "stack":
        _stack_widths(kwargs)
        kwargs["heights_m"] = kwargs["heights_m"][0] if len(kwargs["heights_m"]) == 1 else kwargs["heights_m"]
    return kwargs


def _stack_widths(kwargs: dict[str, Any]) -> None:
    """--widths-m, or --blocks with --bottom-width-m and --top-width-m (a linear taper)."""
    from rockyade.scene.generators import tapered_widths

    n, bottom, top = kwargs.pop("blocks"), kwargs.pop("bottom_width_m"), kwargs.pop("top_width_m")
    taper_given = [x is not None for x in (n, bottom, top)]
    if any(taper_given):
        if kwargs["widths_m"] is not None:
            raise InputError("--widths-m", "give --widths-m or --blocks/--bottom-width-m/--top-width-m, not both")
        if not all(taper_given):
            raise InputError("--blocks", "a linear taper needs --blocks, --bottom-width-m and --top-width-m")
        kwargs["widths_m"], kwargs["top_width_m"] = tapered_widths(n, bottom, top, kwargs["taper"])
    elif kwargs["widths_m"] is None:
        kwargs["widths_m"] = [0.4, 0.35, 0.3, 0.25]


def _flag_for(field: str, kind: str) -> str:
    """The CLI option behind a generator's error field (``openings[1].x_m`` -> ``--opening #2 x_m``)."""
    opening = re.fullmatch(r"openings\[(\d+)\](?:\.(\w+))?", field)
    if opening:
        return f"--opening #{int(opening.group(1)) + 1}" + (f" {opening.group(2)}" if opening.group(2) else "")
    match = re.match(r"[A-Za-z0-9_]+", field)
    base = match.group(0) if match else field
    names = _flags(kind)
    return names[base] + field[len(base) :] if base in names else field


def _flags(kind: str) -> dict[str, str]:
    """Generator parameter name -> CLI flag."""
    extra = OVERBURDEN[kind][1] if kind in OVERBURDEN else []
    names = {opt.dest: opt.flag for opt in [*KINDS[kind][1], *extra, *COMMON]}
    names.update({"overburden_N_per_m": "--overburden-n-per-m", "overburden_N": "--top-load-n"})
    if kind in ("column", "stack"):
        names["overburden_eccentricity_m"] = "--top-load-eccentricity-m"
    return names


def _cli_words(message: str, kind: str) -> str:
    """A generator's message with its parameter names replaced by the CLI flags."""
    flags = _flags(kind)
    return re.sub(r"\b[a-z][a-z0-9]*_[a-z0-9_]*\b", lambda m: flags.get(m.group(0), m.group(0)), message)


def _command_line(args: argparse.Namespace, kind: str) -> str:
    """The ``rockyade build`` command that makes this scene (options that differ from their default)."""
    words = ["rockyade", "build", kind]
    extra = OVERBURDEN[kind][1] if kind in OVERBURDEN else []
    for opt in [*KINDS[kind][1], *extra, *COMMON]:
        value = getattr(args, opt.dest)
        if value == opt.default or value is None:
            continue
        if opt.append:
            for item in value:
                words += [opt.flag, ",".join(f"{v:g}" for v in item)]
        elif isinstance(value, list):
            words += [opt.flag, ",".join(f"{v:g}" for v in value)]
        else:
            words += [opt.flag, f"{value:g}" if isinstance(value, float) else str(value)]
    words += ["--out", Path(args.out).name]
    return shlex.join(words)


def _summary(scene) -> str:
    from rockyade.scene.placement import placed_blocks

    placed = placed_blocks(scene)
    pts = [b.vertices_m for b in placed]
    xs = [float(p[:, 0].min()) for p in pts] + [float(p[:, 0].max()) for p in pts]
    ys = [float(p[:, 1].max()) for p in pts]
    moving = [spec for spec in scene.blocks if not spec.fixed]
    mass = sum(spec.block().mass_kg for spec in moving)
    n_fixed = len(scene.blocks) - len(moving)
    fixed = f" and {n_fixed} fixed" if n_fixed else ""
    return (
        f"{len(moving)} moving blocks{fixed}, {max(xs) - min(xs):.4g} m wide, {max(ys):.4g} m tall, "
        f"moving mass {mass:.6g} kg"
    )


def _check_the_dem_takes_it(scene: Any) -> None:
    """Build the DEM model (joints, statics) before writing: a scene that ``run`` would refuse
    (joints too soft for the wall's weight) is refused here, naming the option to change."""
    if scene.contact.calibration == "matched" and scene.contact.beta_s is None:
        return  # the matched stage runs the DEM: too slow for a check; run checks it
    from rockyade.calibration.model_stage import calibrated_model

    try:
        calibrated_model(scene)
    except InputError as exc:
        flag = {"contact.jkn_Pa_per_m": "--jkn-pa-per-m"}.get(exc.field, exc.field)
        raise InputError(flag, f"{exc.message} (nothing written)") from None


def _with_overburden(args: argparse.Namespace, kind: str, data: dict[str, Any]) -> dict[str, Any]:
    """The generated scene with the overburden options as [[loads]] (none given: unchanged)."""
    if kind not in OVERBURDEN:
        return data
    from rockyade.scene.generators.overburden import add_overburden

    how, _ = OVERBURDEN[kind]
    if how == "point":
        return add_overburden(data, how, force_N=args.top_load_n, eccentricity_m=args.top_load_eccentricity_m)
    return add_overburden(
        data, how, force_N_per_m=args.overburden_n_per_m, eccentricity_m=getattr(args, "overburden_eccentricity_m", 0.0)
    )


def _overburden_mass(args: argparse.Namespace, data: dict[str, Any]) -> dict[str, Any]:
    """``--overburden-mass none``: the overburden's [[loads]] without mass (mass_kg = 0)."""
    if getattr(args, "overburden_mass", "carried") != "none" or not data.get("loads"):
        return data
    return {**data, "loads": [{**q, "mass_kg": 0.0} for q in data["loads"]]}


def cmd_build(args: argparse.Namespace) -> int:
    """Generate an assembly scene and write it."""
    from rockyade import __version__
    from rockyade.scene import scene_from_dict
    from rockyade.scene.generators import GENERATORS, write_scene

    kind = args.kind
    out = Path(args.out)
    check_output_file(out, "--out", (".toml", ".json"))
    if args.draw:
        check_output_file(args.draw, "--draw", ".png")
    _check_counts_and_pairs(args, kind)
    kwargs = _generator_kwargs(args, kind)
    kwargs["motion"] = _motion_table(args, out)
    if kwargs["duration_s"] is None:
        kwargs["duration_s"] = _default_duration(args, kwargs["motion"])
    kwargs["contact"] = _contact_table(args, kind, _unit_height(args, kind))
    try:
        data = GENERATORS[kind](**kwargs)
        data = _with_overburden(args, kind, data)
        data = _overburden_mass(args, data)
    except InputError as exc:
        raise InputError(_flag_for(exc.field, kind), _cli_words(exc.message, kind)) from None
    out.parent.mkdir(parents=True, exist_ok=True)  # relative record paths resolve from there
    scene = scene_from_dict(data, source=str(out), base_dir=out.parent)
    _check_the_dem_takes_it(scene)
    floor = {"restrained-wall": ("restraint", "--restraint side"), "wall-section": ("top", "--top restrained-far")}
    if kind in floor and getattr(args, floor[kind][0]) == "floor" and not args.gap_m:
        import sys

        print(
            f"rockyade: warning: --{floor[kind][0]} floor with no --gap-m: the fixed floor rests on the wall's top and "
            f"clamps it (it cannot rise, hence cannot rock); leave a gap, or use {floor[kind][1]}",
            file=sys.stderr,
        )
    summary = _summary(scene)
    header = "\n".join(
        [
            f"{KINDS[kind][0][0].upper()}{KINDS[kind][0][1:]}.",
            f"Made by rockyade {__version__}: {_command_line(args, kind)}",
            summary + ".",
            "Positions are base-frame m (docs/assemblies.md); [motion] and [contact] are starting points to edit.",
        ]
    )
    write_scene(out, data, header)
    print(f"wrote {out}: {summary}")
    if args.draw:
        from rockyade.figures.assembly import draw_assembly

        draw_assembly(scene, args.draw)
        print(f"wrote {args.draw}")
    return 0


# ---------------------------------------------------------------------- draw


def cmd_draw(args: argparse.Namespace) -> int:
    """Draw a scene at rest; with --result, snapshots and an animation of that run."""
    from rockyade.figures.assembly import draw_assembly, drawn_names
    from rockyade.scene import load_scene

    scene = load_scene(args.scene)
    out = Path(args.out)
    check_output_file(out, "--out", ".png")
    check_run_drawings(args)
    result = _result_of(scene, args) if args.snapshots or args.animation else None
    _, ax = draw_assembly(scene, out, title=args.title, labels=not args.no_labels)
    skipped = len(scene.blocks) - len(drawn_names(ax))
    note = f" ({skipped} block names too small to print)" if skipped and not args.no_labels else ""
    print(f"wrote {out}{note}")
    if result is not None:
        if result.meta.scene_hash not in (None, scene.scene_hash):
            print(f"note: {args.result} was computed from another version of this scene (scene hash differs)")
        write_run_drawings(args, scene, result, out)
    return 0


def _result_of(scene: Any, args: argparse.Namespace) -> Any:
    """The --result to draw, read and checked against the scene before anything is written."""
    if args.result is None:
        raise InputError("--result", "is required with --snapshots or --animation: a result CSV of this scene")
    from rockyade.result import Result

    result = Result.read(args.result)
    moving = [b.name for b in scene.blocks if not b.fixed]
    missing = [name for name in moving if name not in result.blocks]
    if missing:
        shown = ", ".join(missing[:5]) + (f" and {len(missing) - 5} more" if len(missing) > 5 else "")
        raise InputError(
            "--result",
            f"{args.result} has no history of the scene's block(s) {shown}: it is a result of another scene "
            f"(its blocks: {', '.join(result.blocks[:5])})",
        )
    return result


# ---------------------------------------------------------------------- parser


def register(sub: Any) -> None:
    """Add ``build`` (one sub-command per kind) and ``draw``."""
    p = sub.add_parser(
        "build",
        help="generate an assembly scene: wall, column, arch, frame, stack, restrained-wall, wall-section",
        description="Generate a scene file of a masonry assembly (every block placed by position_m) that you "
        "can read and edit. Options are SI, with units in their names.",
    )
    kinds = p.add_subparsers(dest="kind", required=True, metavar="KIND")
    for kind, (text, options) in KINDS.items():
        k = kinds.add_parser(
            kind,
            help=text,
            description=f"Generate {text}." + (f" {ALIASES[kind]}" if kind in ALIASES else ""),
            formatter_class=_DefaultsFormatter,
        )
        for opt in options:
            _add(k, opt)
        if kind in OVERBURDEN or kind == "wall-section":
            loads = k.add_argument_group("overburden (written as [[loads]], with the mass of its weight by default)")
            for opt in OVERBURDEN.get(kind, ("", []))[1]:
                _add(loads, opt)
            loads.add_argument(
                "--overburden-mass",
                choices=("carried", "none"),
                default="carried",
                help="carried: the load's mass (its weight / g) shakes with the wall, as the code counts the loads "
                "a wall carries (Circolare 2019 C8.7.1); none: a force without mass (its horizontal force goes "
                "elsewhere) (default: carried)",
            )
        group = k.add_argument_group("material, time, motion and joints")
        for opt in COMMON:
            _add(group, opt)
        k.add_argument("--out", type=Path, required=True, help="scene file to write (.toml or .json)")
        k.add_argument("--draw", type=Path, metavar="PNG", help="also draw the scene (PNG)")
        k.set_defaults(func=cmd_build)

    d = sub.add_parser(
        "draw",
        help="draw a scene's blocks with their names (and snapshots of a run)",
        description="Draw an assembly at rest: block names, fixed blocks grey and hatched, the base, axes in m. "
        "With --result (a run of this scene) also snapshots at chosen times and an animation.",
    )
    d.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    d.add_argument("--out", type=Path, required=True, help="PNG of the assembly at rest")
    d.add_argument("--title", help="figure title (default: the file name and block counts)")
    d.add_argument("--no-labels", action="store_true", help="leave out the block names")
    d.add_argument("--result", type=Path, help="result CSV of a run of this scene (for snapshots and animation)")
    add_snapshot_options(d)
    d.set_defaults(func=cmd_draw)
