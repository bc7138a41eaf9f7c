"""``rockyade build KIND`` (generate an assembly scene) and ``rockyade draw`` (draw a scene).

Also the snapshot and animation options that ``rockyade run`` shares with ``draw``
(:func:`add_snapshot_options`, :func:`write_run_drawings`).

The options of ``build KIND`` are made from the generators' table of parameters
(:mod:`rockyade.scene.generator_options`: name, unit, default, range, help; numpy-free, so that
``rockyade --help`` stays quick), and every number given is checked against its range there
before anything is built.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
from pathlib import Path
from typing import Any

from rockyade.cli.common import Commands, add_command, add_command_group, check_output_file
from rockyade.cli.drawings import add_snapshot_options, check_run_drawings, write_run_drawings
from rockyade.errors import InputError
from rockyade.scene.generator_options import ALIASES, COMMON, COMMON_PARAMS, KINDS, OVERBURDEN, Param, options

__all__ = ["COMMON", "COMMON_PARAMS", "KINDS", "OVERBURDEN", "add_snapshot_options", "register", "write_run_drawings"]


def _floats(text: str) -> list[float]:
    """A comma-separated list of numbers (argparse type)."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be numbers separated by commas, got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("needs at least one number")
    return values


UDEC_KINDS = ("wall", "arch")
#: Placeholders of options by unit (others: N for counts, X for numbers).
UNIT_METAVARS = {"kg/m^3": "KG/M3", "Pa/m": "PA/M", "N/m": "N/M", "N": "NEWTONS"}


def _metavar(p: Param) -> str | None:
    if p.metavar or p.choices or p.range is None:
        return p.metavar
    if p.integer:
        return "N"
    return UNIT_METAVARS.get(p.unit, p.unit.upper() or "X")


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


def _integer(p: Param) -> Any:
    """The argparse type of a count: an integer, else the error names its range (``--courses nan``)."""

    def parse(text: str) -> int:
        try:
            return int(text)
        except ValueError:
            what = p.range.text() if p.range else "an integer"
            raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None

    return parse


def _add(parser: argparse._ActionsContainer, p: Param) -> None:
    """The argparse option of a parameter of the table."""
    kind = _floats if p.many or p.repeat else str if p.range is None else _integer(p) if p.integer else float
    kwargs: dict[str, Any] = {"default": p.default, "help": p.help, "dest": p.dest, "metavar": _metavar(p)}
    if p.repeat:
        kwargs.update(action="append", type=kind)
    else:
        kwargs.update(type=kind, choices=p.choices or None)
    parser.add_argument(p.option, *p.aliases, **kwargs)


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
        return udec_contact(
            unit_height_m, args.density_kg_m3, args.jkn_pa_per_m, args.damping_ratio, args.friction_angle_deg
        )
    return {"calibration": choice, "friction_angle_deg": args.friction_angle_deg}


#: An option that means nothing without another: (option, its dest, the other's dest, the other option).
_NEEDS = [
    ("--overburden-eccentricity-m", "overburden_eccentricity_m", "overburden_n_per_m", "--overburden-n-per-m"),
    ("--top-load-eccentricity-m", "top_load_eccentricity_m", "top_load_n", "--top-load-n"),
]


def _check_options(args: argparse.Namespace, kind: str) -> None:
    """Refuse, before anything is built, a number out of its range in the generators' table (a
    count the generator would divide by, ``--courses 0``; a negative or zero unit height or
    density, which the joints' damping would take a square root of or divide by; NaN,
    infinity), naming the option and the range; and an option that would be silently ignored
    (an eccentricity without its load)."""
    for p in options(kind):
        if p.numeric or p.choices:
            p.check(getattr(args, p.dest), p.option)
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
    """The generator's keywords from the options (the overburden's where the generator takes it)."""
    own = list(KINDS[kind].params)
    if kind in OVERBURDEN and OVERBURDEN[kind].by_generator:
        own += OVERBURDEN[kind].params
    kwargs = {p.dest: getattr(args, p.dest) for p in own}
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
        del kwargs["widths_m"]  # the generator's default


def _flag_for(field: str, kind: str) -> str:
    """The CLI option behind a generator's or the scene's error field (``openings[1].x_m`` ->
    ``--opening #2 x_m``; ``motion.amplitude_g`` -> ``--amplitude-g``)."""
    opening = re.fullmatch(r"openings\[(\d+)\](?:\.(\w+))?", field)
    if opening:
        return f"--opening #{int(opening.group(1)) + 1}" + (f" {opening.group(2)}" if opening.group(2) else "")
    table = re.fullmatch(r"(?:motion|contact)\.(\w+)", field)
    if table:
        flag = _flags(kind).get(table.group(1).lower())
        return flag or {"shape": "--pulse-shape", "beta_s": "--damping-ratio"}.get(table.group(1), field)
    match = re.match(r"[A-Za-z0-9_]+", field)
    base = match.group(0) if match else field
    names = _flags(kind)
    return names[base] + field[len(base) :] if base in names else field


def _flags(kind: str) -> dict[str, str]:
    """Generator parameter name -> CLI flag."""
    names = {p.dest: p.option for p in options(kind)}
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
    for p in options(kind):
        value = getattr(args, p.dest)
        if value == p.default or value is None:
            continue
        if p.repeat:
            for item in value:
                words += [p.option, ",".join(f"{v:g}" for v in item)]
        elif isinstance(value, list):
            words += [p.option, ",".join(f"{v:g}" for v in value)]
        else:
            words += [p.option, f"{value:g}" if isinstance(value, float) else str(value)]
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


def _check_the_dem_takes_it(scene: Any, kind: str) -> None:
    """Build the DEM model (joints, statics) before writing: a scene that ``run`` would refuse
    (joints too soft for the wall's weight) is refused here, naming the option to change."""
    if scene.contact.calibration == "matched" and scene.contact.beta_s is None:
        return  # the matched stage runs the DEM: too slow for a check; run checks it
    from rockyade.calibration.model_stage import calibrated_model

    try:
        calibrated_model(scene)
    except InputError as exc:
        raise InputError(_flag_for(exc.field, kind), f"{exc.message} (nothing written)") from None


def _with_overburden(args: argparse.Namespace, kind: str, data: dict[str, Any]) -> dict[str, Any]:
    """The generated scene with the overburden options as [[loads]] (none given: unchanged)."""
    if kind not in OVERBURDEN or OVERBURDEN[kind].by_generator:
        return data
    from rockyade.scene.generators.overburden import add_overburden

    how = OVERBURDEN[kind].how
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
    _check_options(args, kind)
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
    try:
        scene = scene_from_dict(data, source=str(out), base_dir=out.parent)
    except InputError as exc:
        flag = _flag_for(exc.field, kind)
        if flag == exc.field:
            raise
        raise InputError(flag, f"{exc.message} (nothing written)") from None
    _check_the_dem_takes_it(scene, kind)
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
            f"{KINDS[kind].text[0].upper()}{KINDS[kind].text[1:]}.",
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
    """draw a scene's blocks with their names (and snapshots of a run)

    Draw an assembly at rest: block names, fixed blocks grey and hatched, the base, axes in m. With --result (a run of
    this scene) also snapshots at chosen times and an animation.
    """
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


def register(sub: Commands) -> None:
    """Add ``build`` (one sub-command per kind) and ``draw``."""
    kinds = add_command_group(
        sub,
        "build",
        "generate an assembly scene: wall, column, arch, frame, stack, restrained-wall, wall-section",
        "Generate a scene file of a masonry assembly (every block placed by position_m) that you "
        "can read and edit. Options are SI, with units in their names.",
        "kind",
    )
    for kind, (text, params) in KINDS.items():
        k = kinds.add_parser(
            kind,
            help=text,
            description=f"Generate {text}." + (f" {ALIASES[kind]}" if kind in ALIASES else ""),
            formatter_class=_DefaultsFormatter,
        )
        for param in params:
            _add(k, param)
        if kind in OVERBURDEN:
            loads = k.add_argument_group("overburden (written as [[loads]], with the mass of its weight by default)")
            for param in OVERBURDEN[kind].params:
                _add(loads, param)
            loads.add_argument(
                "--overburden-mass",
                choices=("carried", "none"),
                default="carried",
                help="carried: the load's mass (its weight / g) shakes with the wall, as the code counts the loads "
                "a wall carries (Circolare 2019 C8.7.1); none: a force without mass (its horizontal force goes "
                "elsewhere)",
            )
        group = k.add_argument_group("material, time, motion and joints")
        for param in COMMON:
            _add(group, param)
        k.add_argument("--out", type=Path, required=True, help="scene file to write (.toml or .json)")
        k.add_argument("--draw", type=Path, metavar="PNG", help="also draw the scene (PNG)")
        k.set_defaults(func=cmd_build)

    d = add_command(sub, cmd_draw)
    d.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    d.add_argument("--out", type=Path, required=True, help="PNG of the assembly at rest")
    d.add_argument("--title", help="figure title (default: the file name and block counts)")
    d.add_argument("--no-labels", action="store_true", help="leave out the block names")
    d.add_argument("--result", type=Path, help="result CSV of a run of this scene (for snapshots and animation)")
    add_snapshot_options(d)
