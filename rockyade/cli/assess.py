"""``rockyade assess``: the code's kinematic checks of a wall, and the rocking dynamics beside
them (docs/howto/is-this-wall-safe.md)."""

from __future__ import annotations

import argparse
import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.cli.common import Commands, add_command, add_joint_options, check_output_dir, json_out, print_wrote
from rockyade.cli.fragility_options import (
    DEFAULT_COUNT,
    accept_negative_values,
    add_run_options,
    count_and_seed,
    executor_from,
    float_list,
    print_plan,
    refuse_suite_options_with_records,
    solver_from,
    write_tables,
)
from rockyade.cli.site_options import add_period_option, add_site_options, site_from
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: rockyade.assess is imported when a command runs
    from collections.abc import Callable

    from rockyade.assess import Assessment, DynamicSettings, Position
    from rockyade.assess.fragility_analysis import FragilityPlan
    from rockyade.assess.stripes import StripesInterruptedError
    from rockyade.runner import Executor
    from rockyade.runner.study_folder import StudyFolder
    from rockyade.scene import Scene

#: Exit code of a scene that cannot stand (the answer is not a number).
EXIT_UNSTABLE = 1


def _position(args: argparse.Namespace) -> Position:
    from rockyade.assess import Position

    def ratio(pct: float | None) -> float | None:
        return None if pct is None else pct / 100.0

    return Position(
        args.z,
        args.building_height,
        args.storeys,
        args.t1,
        args.code_form,
        ratio(args.building_damping_pct),
        args.mechanism_period,
        ratio(args.mechanism_damping_pct),
    )


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


def cmd_assess(args: argparse.Namespace, parser: argparse.ArgumentParser | None = None) -> int:
    """the code's kinematic checks of a wall (NTC 2018) and the rocking dynamics beside them

    The collapse mechanism and the kinematic quantities by limit analysis (alpha0, M*, e*, a0*, d0*, du*, Ts), the
    checks of NTC 2018 (Circolare 2019 C8.7.1) against the site's NTC 2018 spectrum (or EC8's), each with its clause
    and formula, the checks not made listed, and, unless --static-only, the same scene under a spectrum-compatible
    suite scaled to the site (or your records), at stripes of load factors on that scaling: the fraction of records
    that collapse it at the code's demand, the fragility median and beta in ag, and their ratio to the code's
    capacity. Exit 0 with a verdict (verified or not), 1 when the scene cannot stand, 2 on bad input. See
    docs/howto/is-this-wall-safe.md.

    Parameters
    ----------
    args
        The parsed command line.
    parser
        The command's parser, which tells the options given from rockyade's defaults.
    """
    from rockyade.assess import assess
    from rockyade.assess.code import check_code, confidence_factor
    from rockyade.assess.report_lines import assessment_lines
    from rockyade.assess.stripes import StripesInterruptedError
    from rockyade.cli.resumable import file_digest, identity
    from rockyade.errors import BatchInterruptedError
    from rockyade.limit.crushing import check_fm
    from rockyade.limit.rigid_blocks import check_friction_angle
    from rockyade.runner.study_folder import ASSESS, StudyFolder, check_out
    from rockyade.scene import load_scene

    check_code(args.code)
    if args.out is not None:
        check_output_dir(args.out, "--out")
        check_out(args.out, ASSESS, resume_field="--resume" if args.resume else None)  # before any work
    elif args.resume:
        raise InputError("--resume", "needs --out (the folder whose finished runs it keeps)")
    if args.report is not None:
        _check_report_option(args)
    fc, fc_source = confidence_factor(args.knowledge_level, args.fc)
    friction = None
    if args.friction_angle_deg is not None:
        friction = check_friction_angle(args.friction_angle_deg, "--friction-angle-deg")
    from rockyade.limit.analysis import check_friction_rule

    rule = None if args.friction_rule is None else check_friction_rule(args.friction_rule, "--friction-rule")
    fm = None if args.fm is None else check_fm(args.fm, "--fm")
    site, position = site_from(args), _position(args)
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
    data: dict[str, object]
    if dynamic is not None and args.out is not None:
        ident = identity("assess", args, file_digest(args.scene))
        with StudyFolder(args.out, ASSESS, ident, args.resume, say=_say(args)) as folder:
            try:
                _dynamics(args, result, scene, dynamic, executor, folder)
            except StripesInterruptedError as exc:
                path = _interrupted(args, result, exc, folder)
                raise BatchInterruptedError(exc.finished, exc.unfinished, path, exc.hard) from None
            if folder.journal.resumed and not args.json:
                print(f"resumed: {folder.journal.resumed} run(s) read back from {folder.journal_dir}, not run again")
            data = _finish(args, result, scene)
            _write(folder, args, result, data)
            folder.finish(result.dynamic.failed if result.dynamic is not None else 0)
        _report(args, parser, result, data)
        return 0
    if dynamic is not None:
        try:
            _dynamics(args, result, scene, dynamic, executor, None)
        except BatchInterruptedError as exc:
            if args.json:  # the static answer, kept
                json_out({**_static_data(args, result), "partial": True})
            raise BatchInterruptedError(
                exc.finished, exc.unfinished, None, exc.hard, "--out DIR (then --resume)"
            ) from None
    data = _finish(args, result, scene)
    if args.out is not None:
        ident = identity("assess", args, file_digest(args.scene))
        with StudyFolder(args.out, ASSESS, ident, False, say=_say(args)) as folder:
            _write(folder, args, result, data)
            folder.finish()
    _report(args, parser, result, data)
    return 0


def _say(args: argparse.Namespace) -> Callable[[str], None]:
    """Where the output folder's notes go: the text, or nowhere beside the JSON."""
    return (lambda _line: None) if args.json else print


def _check_report_option(args: argparse.Namespace) -> None:
    """--report: a folder that is not --out and holds nothing but a previous report (before any work)."""
    from rockyade.studies.assess_report import check_report_folder

    check_output_dir(args.report, "--report")
    if args.out is not None and Path(args.report).resolve() == Path(args.out).resolve():
        raise InputError("--report", "must be another folder than --out (the report is a set of its own)")
    check_report_folder(args.report)


def _report(
    args: argparse.Namespace, parser: argparse.ArgumentParser | None, result: Assessment, data: dict[str, object]
) -> None:
    """With --report: the page, written from ``data`` (what assess.json holds) as a set of its own."""
    if args.report is None:
        return
    from rockyade.cli.assess_options import options_defaulted, options_given
    from rockyade.studies.assess_report import provenance, write_report

    solver = result.dynamic.plan.stripes.solver.name if result.dynamic is not None else None
    prov = provenance(args.scene, options_given(args, parser), options_defaulted(args, parser, result), solver)
    written = write_report(args.report, result, data, prov)
    print_wrote(Path(f"{', '.join(written)} in {args.report}"), args.json)


def _dynamics(
    args: argparse.Namespace,
    result: Assessment,
    scene: Scene,
    dynamic: DynamicSettings,
    executor: Executor,
    folder: StudyFolder | None,
) -> None:
    from rockyade.assess.assessment import add_dynamics

    def on_plan(plan: FragilityPlan) -> None:
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
        folder=folder,
    )


def _static_data(args: argparse.Namespace, result: Assessment) -> dict[str, object]:
    data: dict[str, object] = result.to_dict()
    data["scene"] = str(args.scene)
    return data


def _interrupted(
    args: argparse.Namespace, result: Assessment, exc: StripesInterruptedError, folder: StudyFolder
) -> str:
    """After Ctrl-C: the static answer (``partial/assess.json``, marked partial) and the runs
    that finished (``partial/runs.csv``), for ``--resume`` to go on from; what the message names."""
    from rockyade.assess.stripes import runs_frame
    from rockyade.io.atomic import write_json

    progress = {"finished": exc.finished, "unfinished": exc.unfinished}
    data = {**_static_data(args, result), "partial": True, "dynamic_interrupted": progress}
    write_json(folder.partial / "assess.json", data)
    path = str(folder.partial / "assess.json")
    plan = getattr(exc, "plan", None)
    if exc.rows and plan is not None:  # the message names the runs' list (the static answer is beside it)
        path = str(folder.write_partial(runs_frame(exc.rows, plan.measure), progress))
    if args.json:
        json_out(data)
    return path


def _finish(args: argparse.Namespace, result: Assessment, scene: Scene) -> dict[str, object]:
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


def _write(folder: StudyFolder, args: argparse.Namespace, result: Assessment, data: dict[str, object]) -> None:
    """The result set, replaced as a whole (:mod:`rockyade.io.resultset`)."""
    from rockyade.figures.wall_assessment import draw_assessment
    from rockyade.io.atomic import write_json

    out: Path = args.out
    with folder.replacing() as stage:
        written = []
        if result.dynamic is not None:
            written += write_tables(stage, result.dynamic)
        draw_assessment(result, stage / "assess.png", title=args.scene.name)
        written.append("assess.png")
        write_json(stage / "assess.json", data)
        written.append("assess.json")
    print_wrote(Path(f"{', '.join(written)} in {out}"), args.json)


def register(sub: Commands) -> None:
    """Add ``rockyade assess``."""
    p = add_command(sub, cmd_assess)
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument("--code", default="ntc2018", help="the code whose checks are made: ntc2018 (default)")
    add_site_options(p)
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
    add_joint_options(
        p,
        "friction angle of every joint, degrees in [0, 89.9]",
        "the limit analysis's friction: associated (alone: sliding joints dilate, an upper bound) or coulomb "
        "(alone: non-dilatant, iterated: see rockyade limit); default: associated, and where its mechanism slides "
        "with friction a coulomb pass too, the check taking the lower multiplier (both printed)",
        "the masonry's compressive strength fm, MPa (> 0): the hinges move into their joints by the stress "
        "block 0.85 fm (NTC 2018 7.8.2.2.1), iterated with the limit analysis' normal forces; default: rigid blocks",
    )
    height = p.add_argument_group("a mechanism at height (default: at ground level)")
    height.add_argument("--z", type=float, metavar="M", help="height of the mechanism above the foundation, m")
    height.add_argument("--building-height", type=float, metavar="M", help="height H of the building, m")
    height.add_argument("--storeys", type=int, metavar="N", help="storeys N of the building")
    add_period_option(height, "its floor spectrum's (default Ct H^(3/4), Ct = 0.05)")
    p.add_argument(
        "--code-form",
        "--height-check",
        dest="code_form",
        choices=("circolare2019", "circolare2009"),
        help="the form of the checks, at ground level and at height: circolare2019 (the default: Circolare 2019 "
        "C8.7.1.2.1, the nonlinear check at T_SLV with the mechanism's damping, at height on the floor spectra of "
        "C7.2.3) or circolare2009 (the superseded Circolare 2009 C8A.4.2.3 form: at ground level the nonlinear check "
        "at Ts and 5 %%, at height Se(T1) psi gamma / q, linear only); --height-check is its former name",
    )
    height.add_argument(
        "--building-damping-pct",
        type=float,
        metavar="PCT",
        help="the building's equivalent viscous damping xi1 of the floor spectrum, %% in [2, 30] (default 5; more "
        "where the building yields at the site's shaking, Circolare 2019 C7.2.3)",
    )
    height.add_argument(
        "--mechanism-period",
        type=float,
        metavar="S",
        help="the mechanism's period T0 in the linear check, s in [0, 4] (default 0: rigid until it moves, the "
        "demand is the floor's peak acceleration; Circolare 2019 C8.7.1.2.1.5)",
    )
    p.add_argument(
        "--mechanism-damping-pct",
        type=float,
        metavar="PCT",
        help="the mechanism's equivalent damping in the nonlinear check of the 2019 form, at ground level and at "
        "height, %% in [2, 30] (default 8, Circolare 2019 C8.7.1.2.1.8 for SLV)",
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
        help="your records (a folder of .at2/.asc/.csv/.txt/.dat files), each scaled to PGA = ag S at load factor 1, "
        "or a selection written by 'rockyade motion select' for this site (each record scaled by its factor) "
        "(default: a synthetic suite compatible with the site's spectrum)",
    )
    dyn.add_argument(
        "--load-factors",
        help="stripes: load factors on the site's scaling, comma-separated (1, the code's demand, is always run; "
        "default 0.35, 0.5, 0.71, 1, 1.41, 2, 2.83, extended to bracket the median)",
    )
    p.add_argument("--out", type=Path, help="write assess.json, assess.png and the runs' CSVs in this directory")
    p.add_argument(
        "--report",
        type=Path,
        metavar="DIR",
        help="write the assessment's page in this directory: report.html (self-contained, the figures embedded) and "
        "its Markdown twin report.md with the figures as PNG files beside it, from the numbers of assess.json",
    )
    p.add_argument("--json", action="store_true", help="print the answer as JSON")
    add_run_options(p, f"records of the site's synthetic suite (default {DEFAULT_COUNT})")
    # "-x" is a value of --direction, not an option; nor is a negative number (refused by its option)
    accept_negative_values(p, also="-x$")
    p.set_defaults(func=functools.partial(cmd_assess, parser=p))
