"""``rockyade compare``, ``rockyade batch`` and ``rockyade paper``."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from rockyade.cli.common import (
    SOLVER_NAMES,
    Commands,
    add_accel_units,
    add_allow_large,
    add_command,
    add_yade_timeout,
    check_output_dir,
    mu_note_line,
    solver_options,
    solvers_from_args,
    total_time,
)
from rockyade.cli.resumable import add_executor_options
from rockyade.errors import InputError


def cmd_compare(args: argparse.Namespace) -> int:
    """one scene through several solvers, with agreement metrics

    Run a scene through several solvers; write each result, a CSV of agreement metrics (peaks, peak times, effective
    mu, max |theta|, overturn, RMS of theta differences) against the reference solver (never a solver against itself)
    and a figure of theta(t); print a one-line verdict: the outcome agreement, the peak difference, and whether
    halving the time step changed the peaks more than the solvers differ.
    """
    solvers = [s.strip() for s in args.solvers.split(",") if s.strip()]
    unknown = [s for s in solvers if s not in SOLVER_NAMES]
    if unknown or not solvers or len(set(solvers)) != len(solvers):
        raise InputError(
            "solvers", f"must be a comma-separated list of distinct {', '.join(SOLVER_NAMES)}, got {args.solvers!r}"
        )
    if args.reference is not None and args.reference not in solvers:
        raise InputError("reference", f"must be one of the solvers run ({', '.join(solvers)}), got {args.reference!r}")
    if len(solvers) < 2:  # one solver was compared with itself: a table of zeros and "same outcome"
        raise InputError("solvers", f"must name at least two solvers to compare, got {args.solvers!r}")
    out: Path = args.out
    check_output_dir(out, "out")
    from rockyade.runner.study_folder import check_no_study

    check_no_study(out, "compare")  # its files would be mixed with a study's set
    runners = solvers_from_args(solvers, args)
    runners, finer = _with_dt_factor(runners, args.dt_factor, not args.no_dt_check)

    from rockyade.analysis.compare import compare, verdict
    from rockyade.figures import plot_results
    from rockyade.io.atomic import atomic_open
    from rockyade.io.locking import output_lock
    from rockyade.runner.cost_limits import check_cost, check_study_time
    from rockyade.scene import load_scene
    from rockyade.solvers.base import check_scene
    from rockyade.solvers.cost_estimate import duration_text

    scene = load_scene(args.scene)
    estimates = []
    for solver in [*runners, *finer]:
        check_scene(solver, scene)
        estimates.append(check_cost(scene, solver, allow_large=args.allow_large))
    seconds = sum(e.wall_time_s for e in estimates) + sum({e.solver: e.compile_s for e in estimates}.values())
    print(
        f"cost: {len(estimates)} run(s), about {duration_text(seconds)} in all, one after another on an idle machine ("
        + ", ".join(
            f"{e.solver}{' at dt x ' + format(getattr(s, 'dt_factor', 1.0), 'g') if k >= len(runners) else ''}: "
            f"{duration_text(e.wall_time_s)}"
            for k, (s, e) in enumerate(zip([*runners, *finer], estimates, strict=True))
        )
        + ")",
        flush=True,
    )
    if not args.allow_large:
        check_study_time(seconds, "the comparison")
    stem = args.scene.stem
    results = {}
    out.mkdir(parents=True, exist_ok=True)
    with output_lock(out):
        for solver in runners:
            result = solver.keeping_files(out, stem).run(scene)  # YADE's files: <out>/<stem>.yade.*
            result.write(out / f"{stem}_{solver.name}.csv")
            results[solver.name] = result
            status = result.status if result.ok else f"failed ({result.meta.failure_reason})"
            wall = result.meta.wall_time_s if result.meta.wall_time_s is not None else float("nan")
            print(f"{solver.name}: {status}, wall time {wall:.3g} s")
            note = mu_note_line(result.meta)
            if note:
                print(f"  {note}")
        halved = {}
        for solver in finer:
            result = solver.keeping_files(out, f"{stem}_halfdt").run(scene)
            result.write(out / f"{stem}_{solver.name}_halfdt.csv")
            halved[solver.name] = result
        table = compare(scene, results, args.reference)
        with atomic_open(out / f"{stem}_compare.csv") as fh:
            table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
        plot_results(results, out / f"{stem}_compare.png", title=f"{stem}: {', '.join(solvers)}")
    view = table[
        table["metric"].isin(
            [
                "peak1_amplitude_rad",
                "peak5_time_s",
                "mu_eff",
                "max_abs_theta_rad",
                "rms_theta_difference_rad",
                "overturned",
            ]
        )
    ]
    print(view.to_string(index=False, float_format=lambda v: f"{v:.5g}"))
    reference = args.reference or ("reference" if "reference" in results else next(iter(results)))
    print(f"verdict: {verdict(scene, results, reference, halved if finer else None)}")
    print(f"wrote {out / f'{stem}_compare.csv'} and {out / f'{stem}_compare.png'}")
    print(f"total wall time {total_time(args):.3g} s")
    return 0 if all(r.ok for r in results.values()) else 1


def _with_dt_factor(solvers: list[Any], factor: float, check: bool) -> tuple[list[Any], list[Any]]:
    """The solvers at ``--dt-factor`` and, with ``check``, each one that takes ``dt_factor`` at
    half of it (the convergence check of the verdict).

    Raises
    ------
    InputError
        ``--dt-factor`` out of [0.001, 1], or given to a solver without the option.
    """
    from dataclasses import replace

    from rockyade.solvers.base import DT_FACTOR_MIN, check_dt_factor

    factor = check_dt_factor(factor, "--dt-factor")
    takes = [s for s in solvers if "dt_factor" in type(s).OPTIONS]
    if factor != 1.0:
        lacking = [s.name for s in solvers if s not in takes]
        if lacking:
            raise InputError("--dt-factor", f"the {', '.join(lacking)} solver has no time-step factor")
        solvers = [replace(s, dt_factor=factor) for s in solvers]
        takes = solvers
    finer = [replace(s, dt_factor=factor / 2) for s in takes] if check and factor / 2 >= DT_FACTOR_MIN else []
    return solvers, finer


def cmd_batch(args: argparse.Namespace) -> int:
    """run a study file (grid of scenes x solvers) on local processes or Dask

    Expand a study file into scenes and run them; one result per run (named by scene hash and solver) and a summary
    table. A failed run never stops the batch.
    """
    check_output_dir(args.out, "out")
    from rockyade.batch import failures, load_study, run_study_tasks, study_tasks
    from rockyade.runner import Executor
    from rockyade.runner.study_folder import BATCH, check_out

    check_out(args.out, BATCH, resume_field="--resume" if args.resume else None)  # before the study is read

    how = Executor(args.executor, args.workers, args.scheduler, args.scheduler_timeout)  # checked before any work
    study = load_study(args.study, *solver_options(args), allow_large=args.allow_large)
    print(f"{study.name}: {study.run_count} runs ({', '.join(study.solver_names)}) -> {args.out}", flush=True)
    summary = run_study_tasks(
        study_tasks(study),
        args.out,
        executor=how,
        resume=args.resume,
        progress=not args.quiet,
        desc=study.name,
        allow_large=args.allow_large,
        identity={"command": "batch", "study": study.name},  # runs are found by scene hash and solver
    )
    failed = failures(summary)
    counts = summary["status"].value_counts().to_dict()
    print(f"wrote {args.out}/summary.csv: " + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())))
    if len(failed):
        print(f"{len(failed)} failed run(s):")
        print(failed.to_string(index=False))
    return 0 if failed.empty else 1


def cmd_paper(args: argparse.Namespace) -> int:
    """reproduce the seed paper end to end (make run)

    Tables 1-6, free rocking, harmonic and random tests, the bi-block pattern map, sensitivity, collapse fragility and
    the overturning spectrum: CSV, PNG and index.md.
    """
    from rockyade.studies.paper import PARTS, run_paper_study
    from rockyade.studies.report import describe_failures

    parts = tuple(p.strip() for p in args.only.split(",")) if args.only else PARTS
    unknown = [p for p in parts if p not in PARTS]
    if unknown:
        raise InputError("only", f"parts must be among {', '.join(PARTS)}, got {unknown}")
    from rockyade.runner import Executor

    try:  # before any part: a part would stop on it, exit 1
        Executor("local", args.workers)
    except InputError as exc:
        raise InputError("--workers", exc.message) from None
    check_paper_out(args.out)
    report = run_paper_study(args.out, args.workers, parts, use_yade=not args.no_yade, accel_unit=args.accel_units)
    failed = report.failures()
    print(f"wrote {report.index_path}")
    print("runs per part: " + "; ".join(_part_line(report, part) for part in parts))
    if not failed:
        print(f"all {len(report.runs)} runs ended without failure")
        return 0
    print(f"{len(failed)} of {len(report.runs)} runs FAILED (each listed in {report.out / 'failed_runs.csv'}):")
    for part, solver, reason, runs in report.failure_groups():
        print(f"  [{part}] {describe_failures(solver, reason, runs)}")
    return 1


def check_paper_out(out: Path) -> None:
    """Refuse, before anything is written, a paper ``--out`` that is a symbolic link or that holds
    another command's results (:func:`rockyade.runner.study_folder.check_no_study`): the paper's
    tables, figures and index.md would be mixed into them (InputError naming ``--out``)."""
    from rockyade.io.folders import refuse_link
    from rockyade.runner.study_folder import check_no_study

    refuse_link(out, "--out")
    check_output_dir(out, "--out")
    check_no_study(out, "paper")


def _part_line(report: Any, part: str) -> str:
    counts = report.counts(part)
    total = sum(counts.values())
    failed = counts.get("failed", 0)
    if not total:
        return f"{part}: no solver runs"
    return f"{part} {total}" + (f" ({failed} FAILED)" if failed else "")


def register(sub: Commands) -> None:
    """Add ``rockyade compare``, ``rockyade batch`` and ``rockyade paper``."""
    p = add_command(sub, cmd_batch)
    p.add_argument("study", type=Path, help="study file (.toml)")
    p.add_argument("--out", type=Path, required=True, help="output directory")
    add_executor_options(p, "skip runs already completed; re-run failed ones")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_yade_timeout(p)
    add_allow_large(p)

    p = add_command(sub, cmd_paper)
    p.add_argument("--out", type=Path, default=Path("reports/paper"), help="output directory (default reports/paper)")
    p.add_argument("--workers", type=int, default=2, help="parallel workers (default 2)")
    p.add_argument(
        "--only",
        help="comma-separated parts: tables,free,harmonic,random,patterns,sensitivity,fragility,overturning,crosscheck",
    )
    p.add_argument("--no-yade", action="store_true", help="skip the YADE runs")
    add_accel_units(
        p,
        "unit of the fragility figure's PGA axis: g (standard gravity; the default) or m/s2, the other "
        "unit on the opposite axis (the CSV files keep m/s^2)",
    )

    p = add_command(sub, cmd_compare)
    p.add_argument("scene", type=Path, help="scene file")
    p.add_argument(
        "--solvers",
        default="housner,reference,yade",
        help=f"comma-separated solvers, at least two, among {', '.join(SOLVER_NAMES)} (default housner,reference,yade)",
    )
    p.add_argument("--reference", help="solver the others are compared with (default: reference)")
    p.add_argument(
        "--dt-factor",
        type=float,
        default=1.0,
        help="factor in [0.001, 1] on every solver's own time step (default 1); each solver is also run at half of "
        "it for the verdict's convergence check",
    )
    p.add_argument("--no-dt-check", action="store_true", help="skip the runs at half the time step")
    p.add_argument("--out", type=Path, default=Path("compare"), help="output directory")
    add_yade_timeout(p)
    add_allow_large(p)
