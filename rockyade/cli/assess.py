"""``rockyade assess``: the code's kinematic checks of a wall, and the rocking dynamics beside
them (docs/howto/is-this-wall-safe.md)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.cli.common import check_output_dir, json_out, print_wrote
from rockyade.cli.fragility_options import (
    DEFAULT_COUNT,
    add_run_options,
    count_and_seed,
    executor_from,
    float_list,
    print_plan,
    refuse_suite_options_with_records,
    solver_from,
    write_tables,
)
from rockyade.cli.resumable import write_partial
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: rockyade.assess is imported when a command runs
    from rockyade.assess import DynamicSettings, Position
    from rockyade.assess.site import AnySite

#: Exit code of a scene that cannot stand (the answer is not a number).
EXIT_UNSTABLE = 1


def _site(args: argparse.Namespace) -> AnySite:
    """The site: NTC 2018's spectrum unless EC8's is asked for (``--spectrum ec8``, or its own
    options ``--spectrum-type`` and ``--ground``)."""
    from rockyade.assess import Site, parse_acceleration
    from rockyade.assess.site import NtcSite
    from rockyade.constants import CODE_GRAVITY as G

    ec8_given = [o for o in ("spectrum_type", "ground", "importance") if getattr(args, o) is not None]
    ntc_given = [
        o for o in ("f0", "tc_star", "soil", "topography", "topography_height_ratio") if getattr(args, o) is not None
    ]
    if args.spectrum is None and ec8_given and ntc_given:
        raise InputError(
            "--" + ntc_given[0].replace("_", "-"),
            f"mixes the NTC 2018 site (--{ntc_given[0].replace('_', '-')}) with an EC8 option "
            f"(--{ec8_given[0].replace('_', '-')}): give one site, or --spectrum to say which",
        )
    spectrum = args.spectrum or ("ec8" if ec8_given else "ntc2018")
    ag = parse_acceleration(args.ag, "--ag")
    if spectrum == "ec8":
        if ntc_given:
            raise InputError(
                "--" + ntc_given[0].replace("_", "-"), "is an NTC 2018 site parameter, not with the EC8 spectrum"
            )
        for option in ("spectrum_type", "ground"):
            if getattr(args, option) is None:
                raise InputError("--" + option.replace("_", "-"), "is required with the EC8 spectrum")
        return Site(args.spectrum_type, args.ground, ag, 1.0 if args.importance is None else args.importance)
    if ec8_given:
        raise InputError(
            "--" + ec8_given[0].replace("_", "-"),
            "is an EC8 option, not with the NTC 2018 spectrum (give --spectrum ec8 for EC8's)",
        )
    for option in ("f0", "tc_star", "soil"):
        if getattr(args, option) is None:
            raise InputError(
                "--" + option.replace("_", "-"),
                "is required with the NTC 2018 spectrum (the default with --code ntc2018): the site's ag, F0 and TC* "
                "(NTC 2018 Allegato A) and its soil category; or give --spectrum ec8 with --spectrum-type and --ground",
            )
    return NtcSite(
        ag / G,
        args.f0,
        args.tc_star,
        args.soil,
        args.topography or "T1",
        1.0 if args.topography_height_ratio is None else args.topography_height_ratio,
    )


def _position(args: argparse.Namespace) -> Position:
    from rockyade.assess import Position

    return Position(args.z, args.building_height, args.storeys, args.t1)


def _dynamic(args: argparse.Namespace) -> DynamicSettings | None:
    """The dynamic settings, or None with ``--static-only`` (which then takes no dynamic option)."""
    from rockyade.assess import DynamicSettings, records_in_folder

    if args.static_only:
        for option in ("records", "solver", "load_factors", "count", "seed", "units", "yade_timeout"):
            if getattr(args, option) is not None:
                raise InputError("--" + option.replace("_", "-"), "applies to the dynamic part, not with --static-only")
        return None
    records = None
    if args.records is not None:
        refuse_suite_options_with_records(args)
        records = records_in_folder(args.records, args.units)
    elif args.units is not None:
        raise InputError("--units", "applies to --records")
    count, seed = count_and_seed(args)
    settings: dict[str, Any] = {
        "records": records,
        "count": count,
        "seed": seed,
        "solver": solver_from(args),
        "extend": not args.no_extend,
        "fallen_blocks": args.fallen_blocks,
        "sample_dt_s": args.sample_dt,
        "tail_s": args.tail,
    }
    if args.load_factors is not None:
        settings["load_factors"] = float_list(args.load_factors, "--load-factors")
    return DynamicSettings(**settings)


def cmd_assess(args: argparse.Namespace) -> int:
    """The checks, the dynamics, the text (or JSON), and with --out the files."""
    from rockyade.assess import assess
    from rockyade.assess.code import check_code, confidence_factor
    from rockyade.assess.report_lines import assessment_lines
    from rockyade.cli.resumable import file_digest, finish, identity, study_output
    from rockyade.errors import BatchInterruptedError
    from rockyade.limit.crushing import check_fm
    from rockyade.limit.rigid_blocks import check_friction_angle
    from rockyade.scene import load_scene

    check_code(args.code)
    if args.out is not None:
        check_output_dir(args.out, "--out")
    elif args.resume:
        raise InputError("--resume", "needs --out (the folder whose finished runs it keeps)")
    fc, fc_source = confidence_factor(args.knowledge_level, args.fc)
    friction = None
    if args.friction_angle_deg is not None:
        friction = check_friction_angle(args.friction_angle_deg, "--friction-angle-deg")
    from rockyade.limit.analysis import check_friction_rule

    rule = None if args.friction_rule is None else check_friction_rule(args.friction_rule, "--friction-rule")
    fm = None if args.fm is None else check_fm(args.fm, "--fm")
    site, position = _site(args), _position(args)
    dynamic = _dynamic(args)
    if dynamic is not None and dynamic.records is None and site.spectrum_code != "ec8":
        from rockyade.assess.assessment import NTC_SUITE_MESSAGE

        raise InputError("--records", NTC_SUITE_MESSAGE)
    executor = executor_from(args)
    scene = load_scene(args.scene)
    direction = None if args.direction == "both" else args.direction

    result = assess(
        scene,
        site,
        code=args.code,
        position=position,
        fc=fc,
        fc_source=fc_source,
        direction=direction,
        friction_angle_deg=friction,
        sliding=not args.no_sliding,
        friction_rule=rule,
        fm_MPa=fm,
    )
    if not args.json:
        print("\n".join(assessment_lines(result, str(args.scene))), flush=True)
    data: dict[str, Any]
    if dynamic is not None and args.out is not None:
        with study_output(
            args.out, identity("assess", args, file_digest(args.scene)), args.resume, ASSESS_SET, ASSESS_LAST
        ) as output:
            try:
                _dynamics(args, result, scene, dynamic, executor, output.journal)
            except BatchInterruptedError as exc:
                _interrupted(args, result, exc, output)
                raise type(exc)(exc.finished, exc.unfinished, exc.summary_path, exc.hard) from None
            if output.journal.resumed and not args.json:
                print(f"resumed: {output.journal.resumed} run(s) read back from {output.partial}, not run again")
            data = _finish(args, result, scene)
            _write(args, result, data)
            finish(output)
        return 0
    if dynamic is not None:
        try:
            _dynamics(args, result, scene, dynamic, executor, None)
        except BatchInterruptedError as exc:
            if args.json:  # the static answer, kept
                json_out({**_static_data(args, result), "partial": True})
            raise type(exc)(exc.finished, exc.unfinished, None, exc.hard, "--out DIR (then --resume)") from None
    data = _finish(args, result, scene)
    if args.out is not None:
        with study_output(
            args.out, identity("assess", args, file_digest(args.scene)), False, ASSESS_SET, ASSESS_LAST
        ) as output:
            _write(args, result, data)
            finish(output)
    return 0


#: The files of an assessment's result set, and the one that marks it complete (last in).
ASSESS_SET = ("runs.csv", "stripes.csv", "records.csv", "assess.png", "assess.json")
ASSESS_LAST = "assess.json"


def _dynamics(args: argparse.Namespace, result: Any, scene: Any, dynamic: Any, executor: Any, journal: Any) -> None:
    from rockyade.assess.assessment import add_dynamics

    def on_plan(plan: Any) -> None:
        if not args.json:
            print(f"dynamics: the same scene under records scaled to the site ({plan.runs_planned} runs planned)")
            print_plan(plan, args.workers, indent="  ")

    add_dynamics(
        result,
        scene,
        dynamic,
        executor,
        allow_large=args.allow_large,
        progress=not args.quiet,
        on_plan=on_plan,
        journal=journal,
    )


def _static_data(args: argparse.Namespace, result: Any) -> dict[str, Any]:
    data: dict[str, Any] = result.to_dict()
    data["scene"] = str(args.scene)
    return data


def _interrupted(args: argparse.Namespace, result: Any, exc: Any, output: Any) -> None:
    """After Ctrl-C: the static answer (``partial/assess.json``, marked partial) and the runs
    that finished (``partial/runs.csv``), for ``--resume`` to go on from."""
    from rockyade.assess.stripes import runs_frame
    from rockyade.io.atomic import write_json

    data = {
        **_static_data(args, result),
        "partial": True,
        "dynamic_interrupted": {"finished": exc.finished, "unfinished": exc.unfinished},
    }
    write_json(output.partial / "assess.json", data)
    rows = getattr(exc, "rows", [])
    plan = getattr(exc, "plan", None)
    exc.summary_path = str(output.partial / "assess.json")
    if rows and plan is not None:  # the message names the runs' list (the static answer is beside it)
        exc.summary_path = str(write_partial(output, runs_frame(rows, plan.measure), data["dynamic_interrupted"]))
    if args.json:
        json_out(data)


def _finish(args: argparse.Namespace, result: Any, scene: Any) -> dict[str, Any]:
    """The pushover, the dynamics' text, the JSON."""
    from rockyade.assess.report_lines import dynamic_lines

    if args.pushover:
        from rockyade.assess.assessment import add_pushover
        from rockyade.assess.report_lines import pushover_lines

        add_pushover(result, scene)
        if not args.json:
            print("\n".join(pushover_lines(result)), flush=True)
    if not args.json:
        print("\n".join(dynamic_lines(result)))
    data = _static_data(args, result)
    if args.json:
        json_out(data)
    return data


def _write(args: argparse.Namespace, result: Any, data: dict[str, Any]) -> None:
    """The result set, replaced as a whole (:mod:`rockyade.io.resultset`)."""
    from rockyade.figures.wall_assessment import draw_assessment
    from rockyade.io.atomic import write_json
    from rockyade.io.resultset import replacing_set

    out: Path = args.out
    with replacing_set(out, ASSESS_SET, ASSESS_LAST) as stage:
        written = []
        if result.dynamic is not None:
            written += write_tables(stage, result.dynamic)
        draw_assessment(result, stage / "assess.png", title=args.scene.name)
        written.append("assess.png")
        write_json(stage / "assess.json", data)
        written.append("assess.json")
    print_wrote(Path(f"{', '.join(written)} in {out}"), args.json)


def register(sub: Any) -> None:
    """Add ``rockyade assess``."""
    p = sub.add_parser(
        "assess",
        help="the code's kinematic checks of a wall (NTC 2018) and the rocking dynamics beside them",
        description="The collapse mechanism and the kinematic quantities by limit analysis (alpha0, M*, e*, a0*, "
        "d0*, du*, Ts), the checks of NTC 2018 (Circolare 2019 C8.7.1) against the site's NTC 2018 spectrum "
        "(or EC8's), "
        "each with its clause and formula, the checks not made listed, and, "
        "unless --static-only, the same scene under a spectrum-compatible suite scaled to the site (or your "
        "records), at stripes of load factors on that scaling: the fraction of records that collapse it at the "
        "code's demand, the fragility median and beta in ag, and their ratio to the code's capacity. Exit 0 with "
        "a verdict (verified or not), 1 when the scene cannot stand, 2 on bad input. See "
        "docs/howto/is-this-wall-safe.md.",
    )
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument("--code", default="ntc2018", help="the code whose checks are made: ntc2018 (default)")
    p.add_argument(
        "--ag",
        required=True,
        help="the site's peak ground acceleration on type A ground, with its unit: 0.25g or 2.45m/s2 "
        "(g: standard gravity, 9.80665 m/s^2, as for records in g and in a0* = alpha0 g / (e* FC)); "
        "NTC 2018: ag of Allegato A for the limit "
        "state's return period; EC8: agR",
    )
    p.add_argument(
        "--spectrum",
        choices=("ntc2018", "ec8"),
        help="whose elastic spectrum: ntc2018 (the default with --code ntc2018, NTC 2018 3.2.3.2.1) or ec8 "
        "(EN 1998-1 3.2.2.2; also chosen by giving --spectrum-type and --ground)",
    )
    ntc = p.add_argument_group("the NTC 2018 site (3.2.3.2.1; ag, F0, TC* from Allegato A)")
    ntc.add_argument("--f0", type=float, help="F0, the spectrum's maximum amplification")
    ntc.add_argument("--tc-star", type=float, metavar="S", help="TC*, s")
    ntc.add_argument("--soil", help="subsoil category A, B, C, D or E (Tab. 3.2.II; SS and CC of Tab. 3.2.IV)")
    ntc.add_argument(
        "--topography", help="topographic category T1, T2, T3 or T4 (Tab. 3.2.III; ST of Tab. 3.2.V; default T1)"
    )
    ntc.add_argument(
        "--topography-height-ratio",
        type=float,
        metavar="R",
        help="the site's height above the base of the relief over the relief's height, in [0, 1]: ST falls "
        "linearly from Tab. 3.2.V's value at the top (1, the default) to 1 at the base",
    )
    ec8 = p.add_argument_group("the EC8 site (EN 1998-1 3.2.2.2)")
    ec8.add_argument("--spectrum-type", type=int, help="EC8 elastic spectrum type: 1 or 2")
    ec8.add_argument("--ground", help="EC8 ground type: A, B, C, D or E")
    ec8.add_argument("--importance", type=float, help="importance factor gamma_I, in [0.5, 2] (default 1)")
    p.add_argument(
        "--knowledge-level",
        metavar="LC",
        help="the knowledge level of the building, LC1, LC2 or LC3: FC = 1.35, 1.20, 1.00 (NTC 2018 8.5.4, "
        "Circolare 2019 C8.5.4 Tab. C8.5.IV); this or --fc is required",
    )
    p.add_argument("--fc", type=float, help="the code's confidence factor FC, in [1, 10], instead of --knowledge-level")
    p.add_argument(
        "--direction",
        choices=("both", "+x", "-x"),
        default="both",
        help="the sense of the static load (default both: the smaller a0* governs)",
    )
    joints = p.add_mutually_exclusive_group()
    joints.add_argument(
        "--friction-angle-deg", type=float, metavar="DEG", help="friction angle of every joint, degrees in [0, 89.9]"
    )
    joints.add_argument("--no-sliding", action="store_true", help="no joint slides (rocking mechanisms only)")
    p.add_argument(
        "--friction-rule",
        metavar="RULE",
        help="the limit analysis's friction: associated (alone: sliding joints dilate, an upper bound) or coulomb "
        "(alone: non-dilatant, iterated: see rockyade limit); default: associated, and where its mechanism slides "
        "with friction a coulomb pass too, the check taking the lower multiplier (both printed)",
    )
    p.add_argument(
        "--fm",
        type=float,
        metavar="MPA",
        help="the masonry's compressive strength fm, MPa (> 0): the hinges move into their joints by the stress "
        "block 0.85 fm (NTC 2018 7.8.2.2.1), iterated with the limit analysis' normal forces; default: rigid blocks",
    )
    height = p.add_argument_group("a mechanism at height (default: at ground level)")
    height.add_argument("--z", type=float, metavar="M", help="height of the mechanism above the foundation, m")
    height.add_argument("--building-height", type=float, metavar="M", help="height H of the building, m")
    height.add_argument("--storeys", type=int, metavar="N", help="storeys N of the building")
    height.add_argument(
        "--t1", type=float, metavar="S", help="period T1 of the building, s (default Ct H^(3/4), Ct = 0.05)"
    )
    p.add_argument(
        "--pushover",
        action="store_true",
        help="also push the scene in the reference DEM (held levels around alpha0, the governing direction): "
        "its onset against alpha0 and its capacity curve at the mechanism's control point, in the code's "
        "a*-d* coordinates, over the code's curve (a few seconds of run; off by default)",
    )
    dyn = p.add_argument_group("the dynamics beside the code")
    dyn.add_argument("--static-only", action="store_true", help="the code's checks only, no runs")
    dyn.add_argument(
        "--records",
        type=Path,
        metavar="DIR",
        help="your records (a folder of .at2/.csv/.txt/.dat files), each scaled to PGA = ag S at load factor 1 "
        "(default: a synthetic suite compatible with the site's spectrum)",
    )
    dyn.add_argument(
        "--load-factors",
        help="stripes: load factors on the site's scaling, comma-separated (1, the code's demand, is always run; "
        "default 0.35, 0.5, 0.71, 1, 1.41, 2, 2.83, extended to bracket the median)",
    )
    p.add_argument("--out", type=Path, help="write assess.json, assess.png and the runs' CSVs in this directory")
    p.add_argument("--json", action="store_true", help="print the answer as JSON")
    add_run_options(p, f"records of the site's synthetic suite (default {DEFAULT_COUNT})")
    # "-x" is a value of --direction, not an option
    p._negative_number_matcher = re.compile(r"^-x$|^-\d+$|^-\d*\.\d+$")
    p.set_defaults(func=cmd_assess)
