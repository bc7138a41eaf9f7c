"""``rockyade crosscheck``: several solvers on one scene over a record set, compared by their
collapse intensities paired by record, with the convergence in the time step beside
(docs/verification.md, docs/howto/which-solver.md)."""

from __future__ import annotations

import argparse
from pathlib import Path

from rockyade.cli.common import Commands, add_allow_large, add_command, check_output_dir
from rockyade.cli.fragility_options import add_record_source
from rockyade.cli.resumable import add_executor_options
from rockyade.errors import InputError


def _fraction(text: str, option: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise InputError(option, f"must be a number, got {text!r}") from None


def _records_per_solver(text: str | None, names: tuple[str, ...]) -> dict[str, int]:
    """``yade=5,siconos=10`` as solver -> how many of the records (the first ones) it runs."""
    out: dict[str, int] = {}
    for item in (text or "").split(","):
        if not item.strip():
            continue
        name, _, count = item.partition("=")
        name = name.strip()
        try:
            value = int(count)
        except ValueError:
            value = 0
        if name not in names or name in out or value < 1:
            raise InputError(
                "--records-per-solver",
                f"must be SOLVER=N pairs (a solver of --solvers, N >= 1 records), comma-separated, got {text!r}",
            )
        out[name] = value
    return out


def cmd_crosscheck(args: argparse.Namespace) -> int:
    """several solvers on one scene over a record set: collapse intensities paired by record, with intervals

    For each solver, each time-step factor and each record, find the collapse intensity (the smallest scale of the
    record, in the intensity measure, at which the scene collapses) by a scan then bisection; compare the solvers by
    the median of their paired ratios with a bootstrap 95 % interval, the share of runs with the same verdict and the
    fragility per solver; rerun each solver with dt halved and report its own change beside. Writes
    collapse_intensities.csv, pairs.csv, runs.csv, crosscheck.json, crosscheck.png and index.md, a set replaced as a
    whole when done; each run is written to --out/partial/ as it ends. Exit 0, 1 when a run failed, 2 on bad input,
    130 after Ctrl-C (--resume finishes it). See docs/verification.md.
    """
    from rockyade.assess import parse_measure
    from rockyade.cli.common import solver_options
    from rockyade.cli.fragility_options import float_list, motions_from
    from rockyade.runner import Executor
    from rockyade.scene import load_scene
    from rockyade.studies.crosscheck import (
        check_dt_factors,
        check_out,
        crosscheck_plan,
        parse_solvers,
        run_crosscheck,
    )
    from rockyade.studies.crosscheck.reporting import subsets_text

    check_output_dir(args.out, "--out")
    check_out(args.out, args.resume)
    names = parse_solvers(args.solvers)
    subsets = _records_per_solver(args.records_per_solver, names)
    measure = parse_measure(args.intensity)
    levels = float_list(args.levels, "--levels") if args.levels else None
    dt_factors = check_dt_factors(float_list(args.dt_factors, "--dt-factors"))
    resolution = _fraction(args.resolution, "--resolution")
    tolerance = _fraction(args.tolerance, "--tolerance")
    try:
        how = Executor(args.executor, args.workers, args.scheduler, args.scheduler_timeout)
    except InputError as exc:
        raise InputError("--" + exc.field.replace("_", "-"), exc.message) from None
    options, _flags = solver_options(args)
    if "timeout_s" in options and "yade" not in names:
        raise InputError("--yade-timeout", "applies to the yade solver; this cross-check does not run it")
    motions = motions_from(args)
    scene = load_scene(args.scene)
    record_executor = how if how.kind == "local" else Executor("local", args.workers)
    plan = crosscheck_plan(
        scene,
        motions,
        measure,
        names,
        levels=levels,
        dt_factors=dt_factors,
        resolution=resolution,
        tolerance=tolerance,
        records_per_solver=subsets,
        solver_options=options,
        executor=record_executor,
        fallen_blocks=args.fallen_blocks,
        sample_dt_s=args.sample_dt,
        tail_s=args.tail,
        progress=not args.quiet,
        allow_large=args.allow_large,
        workers=args.workers,
    )
    print(f"crosscheck of {args.scene}: {', '.join(names)} over {motions.describe()}{subsets_text(plan)}", flush=True)
    print(
        f"levels ({measure.unit}): {', '.join(f'{measure.shown(v):.4g}' for v in plan.scan_si)} "
        f"({plan.stripes.levels_source})",
        flush=True,
    )
    print(plan.cost_line(args.workers), flush=True)
    summary = run_crosscheck(
        plan, args.out, how, resume=args.resume, progress=not args.quiet, allow_large=args.allow_large
    )
    for line in summary.verdicts:
        print(line)
    print(f"wrote {args.out}/index.md, collapse_intensities.csv, pairs.csv, runs.csv, crosscheck.json, crosscheck.png")
    failed = int(summary.runs["collapsed"].isna().sum()) if len(summary.runs) else 0
    if failed:
        print(f"{failed} run(s) failed (status and reason in {args.out}/runs.csv)")
    return 1 if failed else 0


def register(sub: Commands) -> None:
    """Add ``rockyade crosscheck``."""
    from rockyade.cli.common import SOLVER_NAMES, add_yade_timeout

    p = add_command(sub, cmd_crosscheck)
    p.add_argument("scene", type=Path, help="scene file (.toml or .json); its motion is replaced")
    add_record_source(p)
    p.add_argument("--count", type=int, help="records of a synthetic suite (default 20; the paper's: 30)")
    p.add_argument("--seed", type=int, help="seed of the synthetic suite (default 1)")
    p.add_argument("--units", help="units of record files that do not name theirs: g, m/s2, cm/s2 (default m/s2)")
    p.add_argument(
        "--solvers",
        default="housner,reference",
        help=f"comma-separated solvers, at least two, among {', '.join(SOLVER_NAMES)} (default housner,reference)",
    )
    p.add_argument(
        "--records-per-solver",
        metavar="SOLVER=N,...",
        help="run a costly solver on the first N records only, e.g. yade=5 (default: every solver on every record; "
        "the pairs are over the records both solvers ran)",
    )
    p.add_argument(
        "--intensity",
        default="pga",
        help="the intensity measure: pga (g), pgv (m/s) or 'sa(T)' (g; T in s); default pga",
    )
    p.add_argument(
        "--levels",
        help="the scan's levels in the measure's unit, comma-separated (default: the scene's static collapse "
        "acceleration times 1 to 8, as rockyade fragility; a single block's is tan(alpha) g with the scene's "
        "classical alpha, the one the solvers run)",
    )
    p.add_argument("--resolution", default="0.01", help="bisection to a bracket of ratio 1 + this (default 0.01)")
    p.add_argument(
        "--tolerance",
        default="0.05",
        help="agreement: median ratio within 1 +/- this, interval within twice (default 0.05)",
    )
    p.add_argument(
        "--dt-factors",
        default="1,0.5",
        help="time-step factors in [0.001, 1], the first 1 (default 1,0.5: the convergence check)",
    )
    p.add_argument("--out", type=Path, required=True, help="output directory (replaced as a whole when done)")
    add_executor_options(p, "finish an interrupted cross-check without repeating a run (failed runs run again)")
    p.add_argument(
        "--fallen-blocks",
        type=int,
        default=1,
        metavar="N",
        help="several blocks: a run collapses when N fell (default 1)",
    )
    p.add_argument("--sample-dt", type=float, default=0.01, metavar="S", help="output sampling, s (default 0.01)")
    p.add_argument("--tail", type=float, default=5.0, metavar="S", help="free motion after each record, s (default 5)")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_yade_timeout(p)
    add_allow_large(p)
