"""``rockyade fragility``: the collapse fragility of any scene under records scaled to stripes
of an intensity measure (docs/howto/is-this-wall-safe.md)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.cli.common import SOLVER_NAMES, add_allow_large, check_output_dir
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: these are imported when a command runs
    from rockyade.assess import SyntheticSuite
    from rockyade.assess.fragility import FragilityPlan, FragilityResult
    from rockyade.assess.motions import MotionSet
    from rockyade.runner import Executor
    from rockyade.solvers.base import Solver

#: Records of a synthetic suite, and its seed, by default.
DEFAULT_COUNT = 20
DEFAULT_SEED = 1


def float_list(text: str, option: str) -> tuple[float, ...]:
    """``"0.1,0.2, 0.4"`` as numbers (InputError naming ``option``)."""
    try:
        values = tuple(float(v) for v in str(text).split(",") if v.strip())
    except ValueError:
        raise InputError(option, f"must be numbers separated by commas, got {text!r}") from None
    if not values:
        raise InputError(option, "needs at least one number")
    return values


def executor_from(args: argparse.Namespace) -> Executor:
    """The executor of ``--executor``, ``--workers`` and ``--scheduler`` (as ``batch``)."""
    from rockyade.cli.resumable import executor_from as from_args

    return from_args(args)


def solver_from(args: argparse.Namespace) -> Solver | None:
    """The ``--solver`` with ``--yade-timeout`` (None: the default for the scene)."""
    if args.solver is None:
        if args.yade_timeout is not None:
            raise InputError("--yade-timeout", "applies to --solver yade")
        return None
    from rockyade.cli.run import solvers_from_args

    [solver] = solvers_from_args([args.solver], args)
    return solver


def suite_from(args: argparse.Namespace) -> SyntheticSuite:
    """The synthetic suite of ``--suite`` (ec8: ``--spectrum-type``, ``--ground``, ``--ag``)."""
    from rockyade.assess import ec8_suite, paper_suite_set, parse_acceleration

    if args.suite == "paper":
        for option in ("spectrum_type", "ground", "ag"):
            if getattr(args, option) is not None:
                raise InputError("--" + option.replace("_", "-"), "applies to --suite ec8 (the paper's suite is fixed)")
        if args.seed is not None:
            raise InputError("--seed", "applies to --suite ec8 (the paper's suite has its own)")
        return paper_suite_set(args.count or 30)
    missing = [o for o in ("spectrum_type", "ground", "ag") if getattr(args, o) is None]
    if missing:
        flags = ", ".join("--" + o.replace("_", "-") for o in missing)
        raise InputError(
            missing[0].replace("_", "-"), f"--suite ec8 needs {flags} (e.g. --spectrum-type 1 --ground B --ag 0.25g)"
        )
    ag = parse_acceleration(args.ag, "--ag")
    return ec8_suite(args.spectrum_type, args.ground, ag, *count_and_seed(args))


def count_and_seed(args: argparse.Namespace) -> tuple[int, int]:
    """``--count`` and ``--seed`` of a synthetic suite, or their defaults."""
    count = DEFAULT_COUNT if args.count is None else args.count
    return count, DEFAULT_SEED if args.seed is None else args.seed


def refuse_suite_options_with_records(args: argparse.Namespace) -> None:
    """``--count`` and ``--seed`` are a synthetic suite's: refused with ``--records``."""
    for option in ("count", "seed"):
        if getattr(args, option) is not None:
            raise InputError("--" + option, "applies to a synthetic suite, not to --records")


def add_run_options(p: argparse.ArgumentParser, count_help: str) -> None:
    """Options shared by ``fragility`` and ``assess``: solver, workers, records, collapse, sampling."""
    from rockyade.cli.resumable import add_executor_options
    from rockyade.cli.run import add_yade_timeout

    p.add_argument(
        "--solver",
        choices=SOLVER_NAMES,
        help="housner, reference or yade (default: housner for a single block, the reference DEM otherwise)",
    )
    add_yade_timeout(p)
    add_executor_options(p)
    p.add_argument("--count", type=int, help=count_help)
    p.add_argument("--seed", type=int, help=f"seed of the synthetic suite (default {DEFAULT_SEED})")
    p.add_argument("--units", help="units of record files that do not name theirs: g, m/s2, cm/s2 (default m/s2)")
    p.add_argument(
        "--fallen-blocks",
        type=int,
        default=1,
        metavar="N",
        help="a run of a scene of several blocks collapses when N blocks fell (rockyade.analysis.collapse; default 1)",
    )
    p.add_argument(
        "--sample-dt", type=float, default=0.01, metavar="S", help="output sampling of every run, s (default 0.01)"
    )
    p.add_argument("--tail", type=float, default=5.0, metavar="S", help="free motion after each record, s (default 5)")
    p.add_argument("--no-extend", action="store_true", help="run the levels as given, without adding any")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_allow_large(p)


def print_plan(plan: FragilityPlan, workers: int, indent: str = "") -> None:
    """The plan and its cost, before anything runs."""
    from rockyade.assess.report import plan_lines

    for line in [*plan_lines(plan), plan.cost_line(workers)]:
        print(indent + line, flush=True)


def write_tables(out: Path, result: FragilityResult, prefix: str = "") -> list[str]:
    """``runs.csv``, ``stripes.csv`` and ``records.csv`` of a fragility result; their names."""
    from rockyade.io.atomic import atomic_open

    names = []
    for name, frame in (("runs", result.runs), ("stripes", result.stripes), ("records", result.plan.records)):
        path = out / f"{prefix}{name}.csv"
        with atomic_open(path) as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
        names.append(path.name)
    return names


#: The files of a fragility result set, and the one that marks it complete (last in).
FRAGILITY_SET = ("runs.csv", "stripes.csv", "records.csv", "fragility.png", "fragility.json")
FRAGILITY_LAST = "fragility.json"


def cmd_fragility(args: argparse.Namespace) -> int:
    """Run the stripes, fit the curve, write the CSVs, JSON and figure (a set replaced as a
    whole); Ctrl-C writes a partial summary that ``--resume`` goes on from."""
    from rockyade.assess import fragility_plan, parse_measure, records_in_folder, run_fragility
    from rockyade.assess.report import fit_lines
    from rockyade.assess.stripes import runs_frame
    from rockyade.cli.resumable import file_digest, finish, identity, study_output, write_partial
    from rockyade.errors import BatchInterruptedError
    from rockyade.io.atomic import write_json
    from rockyade.io.resultset import replacing_set
    from rockyade.scene import load_scene

    check_output_dir(args.out, "--out")
    measure = parse_measure(args.intensity)
    levels = float_list(args.levels, "--levels") if args.levels else None
    executor = executor_from(args)
    solver = solver_from(args)
    if args.records is not None:
        for option in ("spectrum_type", "ground", "ag"):
            if getattr(args, option) is not None:
                raise InputError("--" + option.replace("_", "-"), "applies to --suite ec8, not to --records")
        refuse_suite_options_with_records(args)
        motions: MotionSet = records_in_folder(args.records, args.units)
    else:
        if args.units is not None:
            raise InputError("--units", "applies to --records")
        motions = suite_from(args)
    scene = load_scene(args.scene)
    # every check (the levels' load factors included) before --out is made
    plan = fragility_plan(
        scene,
        motions,
        measure,
        solver,
        levels=levels,
        extend=False if args.no_extend else None,
        executor=executor,
        fallen_blocks=args.fallen_blocks,
        sample_dt_s=args.sample_dt,
        tail_s=args.tail,
        progress=not args.quiet,
    )
    ident = identity("fragility", args, file_digest(args.scene))
    with study_output(args.out, ident, args.resume, FRAGILITY_SET, FRAGILITY_LAST) as output:
        print(f"fragility of {args.scene}")
        print_plan(plan, args.workers)
        try:
            result = run_fragility(
                plan,
                executor,
                allow_large=args.allow_large,
                progress=not args.quiet,
                on_round=print,
                journal=output.journal,
            )
        except BatchInterruptedError as exc:
            rows = getattr(exc, "rows", [])
            if rows:
                exc.summary_path = str(
                    write_partial(output, runs_frame(rows, plan.measure), {"finished": exc.finished,
                                                                          "unfinished": exc.unfinished})
                )
            raise type(exc)(exc.finished, exc.unfinished, exc.summary_path, exc.hard) from None
        if output.journal.resumed:
            print(f"resumed: {output.journal.resumed} run(s) read back from {output.partial}, not run again")
        for line in fit_lines(result):
            print(line)
        from rockyade.figures.assess import draw_fragility

        with replacing_set(args.out, FRAGILITY_SET, FRAGILITY_LAST) as stage:
            written = write_tables(stage, result)
            data = result.to_dict()
            data["scene"] = str(args.scene)
            draw_fragility(result, stage / "fragility.png", title=f"{args.scene.name}: collapse fragility")
            written.append("fragility.png")
            write_json(stage / "fragility.json", data)
            written.append("fragility.json")
        finish(output)
    print(f"wrote {', '.join(written)} in {args.out}")
    return 1 if result.failed else 0


def register(sub: Any) -> None:
    """Add ``rockyade fragility``."""
    p = sub.add_parser(
        "fragility",
        help="collapse fragility of a scene: records scaled to stripes of PGA, PGV or Sa(T), lognormal fit",
        description="Replace the scene's motion by each record scaled (a load factor on its accelerations as read) "
        "to stripes of an intensity measure, run every run through the runner (local processes, or Dask: "
        "--executor), count the runs that collapse (a single block: overturned; several blocks: --fallen-blocks "
        "fell) and fit a lognormal curve by maximum likelihood with a bootstrap band over the records. Writes "
        "runs.csv, stripes.csv, records.csv, fragility.json and fragility.png in --out, a set replaced as a whole; "
        "each run is written to --out/partial/ as it ends, Ctrl-C leaves a partial summary there and --resume goes "
        "on from it. Exit 0, 1 when a run failed or the scene cannot stand, 2 on bad input. See "
        "docs/howto/is-this-wall-safe.md.",
    )
    p.add_argument("scene", type=Path, help="scene file (.toml or .json); its motion is replaced")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--records", type=Path, metavar="DIR", help="a folder of record files (.at2, .csv, .txt, .dat)")
    source.add_argument(
        "--suite",
        choices=("ec8", "paper"),
        help="a spectrum-compatible synthetic suite: ec8 (with --spectrum-type, --ground, --ag) or the paper's",
    )
    p.add_argument("--spectrum-type", type=int, help="EC8 spectrum type of --suite ec8: 1 or 2")
    p.add_argument("--ground", help="EC8 ground type of --suite ec8: A, B, C, D or E")
    p.add_argument("--ag", help="design ground acceleration of --suite ec8, with its unit: 0.25g or 2.45m/s2")
    p.add_argument(
        "--intensity",
        default="pga",
        help="the intensity measure: pga (in g), pgv (m/s) or sa(T) (in g, 5 %% damped, T in s; quote it: "
        "'sa(0.5)'); default pga",
    )
    p.add_argument(
        "--levels",
        help="the stripes, in the measure's unit (g, or m/s for pgv), comma-separated (default: from the scene's "
        "static collapse acceleration, extended to bracket the median)",
    )
    p.add_argument("--out", type=Path, required=True, help="output directory")
    add_run_options(p, f"records of a synthetic suite (default {DEFAULT_COUNT})")
    p.set_defaults(func=cmd_fragility)
