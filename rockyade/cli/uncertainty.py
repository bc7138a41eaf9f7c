"""``rockyade uncertainty``: propagate the uncertainty of alpha, p, mu through a record suite."""

from __future__ import annotations

import argparse
from pathlib import Path

from rockyade.cli.common import Commands, add_accel_units, add_command


def cmd_uncertainty(args: argparse.Namespace) -> int:
    """probability of overturning with alpha, p, mu drawn from distributions (Latin hypercube)

    Draw alpha, p, mu (normal, lognormal, uniform, or an identification's joint normal) by Latin hypercube, run every
    sample under the records and load factors (each multiplies the records' accelerations as read) with each solver
    (batch engine, local or Dask), and report P(overturn) and P(theta/alpha >= level) with 95 % Wilson bands,
    fragility fits against intensity measures and the spread due to the parameters. See docs/identification.md.
    """
    from rockyade.cli.common import check_output_dir
    from rockyade.runner.study_folder import UNCERTAINTY, check_out
    from rockyade.studies.uncertainty import load_uncertainty_study, run_uncertainty

    check_output_dir(args.out, "--out")
    check_out(args.out, UNCERTAINTY, resume_field="--resume" if args.resume else None)  # before reading it
    study = load_uncertainty_study(args.study)
    if args.samples is not None or args.seed is not None:
        if args.samples is not None and args.samples < 1:
            from rockyade.errors import InputError

            raise InputError("samples", f"must be >= 1, got {args.samples}")
        study = study.with_samples(args.samples or study.samples, args.seed)
    n_runs_per_sample = len(study.load_factors) * len(study.solvers)
    records = 1 if study.pairing == "sampled" else len(study.motions)
    total = (study.samples * records + (len(study.motions) if study.include_nominal else 0)) * n_runs_per_sample
    print(
        f"{study.name}: {study.samples} samples (seed {study.seed}), {total} runs "
        f"({', '.join(study.solvers)}) -> {args.out}"
    )
    for name, text in study.describe_parameters().items():
        print(f"  {name}: {text}")
    result = run_uncertainty(
        study,
        args.out,
        executor=args.executor,
        workers=args.workers,
        scheduler=args.scheduler,
        scheduler_timeout_s=args.scheduler_timeout,
        resume=args.resume,
        progress=not args.quiet,
        accel_unit=args.accel_units,
    )
    p = result.probabilities
    print("P(overturn) per load factor (x the records' accelerations as read) [95 % Wilson band]:")
    for row in p.itertuples(index=False):
        print(
            f"  {row.solver:9s} x{row.load_factor:<5g} {row.p_overturn:.3f} [{row.p_overturn_lo:.3f}, "
            f"{row.p_overturn_hi:.3f}] of {row.n_runs} runs" + (f" ({row.n_failed} failed)" if row.n_failed else "")
        )
    print("fragility (lognormal, maximum likelihood):")
    for row in result.fragility.itertuples(index=False):
        median = _measure_text(row.median, row.measure, args.accel_units)
        fit = f"median {median}, beta {row.beta:.3g}" if row.status == "fitted" else row.status
        if row.status == "separated":
            fit += f" (every overturning run is above every other: a threshold near {median}, no slope)"
        print(f"  {row.solver:9s} {row.measure:24s} {fit}")
    if result.spread is not None:
        print("spread caused by the parameters alone (per-sample P(overturn) 5-95 %, nominal):")
        for row in result.spread.itertuples(index=False):
            print(
                f"  {row.solver:9s} x{row.load_factor:<5g} "
                f"{row.p_overturn_sample_q05:.3f}-{row.p_overturn_sample_q95:.3f} "
                f"(nominal {row.p_overturn_nominal:.3f}); "
                f"records with mixed outcomes {100 * row.records_mixed_fraction:.0f} %"
            )
    written = ["samples.csv", "summary.csv", "runs.csv", "probabilities.csv", "fragility.csv"]
    written += ["spread.csv"] if result.spread is not None else []
    written += ["uncertainty.png"] if result.figure else []
    print(f"wrote {', '.join(written)}, uncertainty.json in {args.out}")
    failed = int((result.runs["status"] == "failed").sum())
    return 1 if failed else 0


def _measure_text(value: float, measure: str, unit: str) -> str:
    """An intensity value as printed: a PGA in ``unit`` with the other unit beside it."""
    if measure != "pga_m_s2":
        return f"{value:.4g}"
    from rockyade.constants import STANDARD_GRAVITY

    g_text, si_text = f"{value / STANDARD_GRAVITY:.4g} g", f"{value:.4g} m/s^2"
    return f"{g_text} ({si_text})" if unit == "g" else f"{si_text} ({g_text})"


def register(sub: Commands) -> None:
    """Add ``rockyade uncertainty``."""
    from rockyade.cli.resumable import add_executor_options

    p = add_command(sub, cmd_uncertainty)
    p.add_argument("study", type=Path, help="uncertainty study file (.toml)")
    p.add_argument("--out", type=Path, required=True, help="output directory")
    p.add_argument("--samples", type=int, help="override the number of parameter samples")
    p.add_argument("--seed", type=int, help="override the seed of the Latin hypercube")
    add_executor_options(p, "skip runs already completed by an interrupted run of the same study")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    add_accel_units(
        p,
        "unit of PGA medians and axes: g (standard gravity, 9.80665 m/s^2; the default) or m/s2; the other "
        "unit is given beside it (the CSV files keep m/s^2, named so)",
    )
