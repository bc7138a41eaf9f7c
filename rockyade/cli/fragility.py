"""``rockyade fragility``: the collapse fragility of any scene under records scaled to stripes
of an intensity measure (docs/howto/is-this-wall-safe.md)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from rockyade.cli.common import Commands, add_command, check_output_dir
from rockyade.cli.fragility_options import (
    DEFAULT_COUNT,
    add_record_source,
    add_run_options,
    executor_from,
    float_list,
    motions_from,
    print_plan,
    solver_from,
    write_tables,
)

if TYPE_CHECKING:  # the parser stays fast: rockyade.assess is imported when a command runs
    pass


def cmd_fragility(args: argparse.Namespace) -> int:
    """collapse fragility of a scene: records scaled to stripes of PGA, PGV or Sa(T), lognormal fit

    Replace the scene's motion by each record scaled (a load factor on its accelerations as read) to stripes of an
    intensity measure, run every run through the runner (local processes, or Dask: --executor), count the runs that
    collapse (a single block: overturned; several blocks: --fallen-blocks fell) and fit a lognormal curve by maximum
    likelihood with a bootstrap band over the records. Writes runs.csv, stripes.csv, records.csv, fragility.json and
    fragility.png in --out, a set replaced as a whole; each run is written to --out/partial/ as it ends, Ctrl-C leaves
    a partial summary there and --resume goes on from it. Exit 0, 1 when a run failed or the scene cannot stand, 2 on
    bad input. See docs/howto/is-this-wall-safe.md.
    """
    from rockyade.assess import fragility_plan, parse_measure, run_fragility
    from rockyade.assess.report_lines import fit_lines
    from rockyade.assess.stripes import StripesInterruptedError, runs_frame
    from rockyade.cli.resumable import file_digest, identity
    from rockyade.errors import BatchInterruptedError
    from rockyade.io.atomic import write_json
    from rockyade.runner.study_folder import FRAGILITY, StudyFolder, check_out
    from rockyade.scene import load_scene

    check_output_dir(args.out, "--out")
    check_out(args.out, FRAGILITY, resume_field="--resume" if args.resume else None)  # before the plan
    measure = parse_measure(args.intensity)
    levels = float_list(args.levels, "--levels") if args.levels else None
    executor = executor_from(args)
    solver = solver_from(args)
    motions = motions_from(args)
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
    with StudyFolder(args.out, FRAGILITY, ident, args.resume, say=print) as folder:
        print(f"fragility of {args.scene}")
        print_plan(plan, args.workers)
        try:
            result = run_fragility(
                plan, executor, allow_large=args.allow_large, progress=not args.quiet, on_round=print, folder=folder
            )
        except StripesInterruptedError as exc:
            path = None
            if exc.rows:
                progress = {"finished": exc.finished, "unfinished": exc.unfinished}
                path = str(folder.write_partial(runs_frame(exc.rows, plan.measure), progress))
            raise BatchInterruptedError(exc.finished, exc.unfinished, path, exc.hard) from None
        if folder.journal.resumed:
            print(f"resumed: {folder.journal.resumed} run(s) read back from {folder.journal_dir}, not run again")
        for line in fit_lines(result):
            print(line)
        from rockyade.figures.wall_assessment import draw_fragility

        with folder.replacing() as stage:
            written = write_tables(stage, result)
            data = result.to_dict()
            data["scene"] = str(args.scene)
            draw_fragility(result, stage / "fragility.png", title=f"{args.scene.name}: collapse fragility")
            written.append("fragility.png")
            write_json(stage / "fragility.json", data)
            written.append("fragility.json")
        folder.finish(result.failed)
    print(f"wrote {', '.join(written)} in {args.out}")
    return 1 if result.failed else 0


def register(sub: Commands) -> None:
    """Add ``rockyade fragility``."""
    p = add_command(sub, cmd_fragility)
    p.add_argument("scene", type=Path, help="scene file (.toml or .json); its motion is replaced")
    add_record_source(p)
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
