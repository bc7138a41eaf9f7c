"""An uncertainty study run and reported: its runs in its output folder (the study's one folder,
:class:`rockyade.runner.study_folder.StudyFolder`: ``runs/`` and ``summary.csv`` as a batch's,
resumable), then the report, a set replaced as a whole (:mod:`rockyade.studies.uncertainty`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from rockyade.batch.summary import summarised_runs
from rockyade.io.atomic import atomic_open, write_json
from rockyade.runner import Executor
from rockyade.runner.executor import SCHEDULER_TIMEOUT_S
from rockyade.runner.study_folder import UNCERTAINTY, StudyFolder
from rockyade.studies.uncertainty.sample_tasks import build_tasks, draw_samples, prepare, record_measures, with_measures
from rockyade.studies.uncertainty.study_file import UncertaintyStudy


@dataclass
class UncertaintyResult:
    """What an uncertainty study produced (frames also written as CSV in ``out``)."""

    study: UncertaintyStudy
    out: Path
    samples: pd.DataFrame
    runs: pd.DataFrame
    probabilities: pd.DataFrame
    fragility: pd.DataFrame
    spread: pd.DataFrame | None
    figure: Path | None


def run_uncertainty(
    study: UncertaintyStudy,
    out: str | Path,
    *,
    executor: str = "local",
    workers: int = 2,
    scheduler: str | None = None,
    scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
    resume: bool = False,
    progress: bool = True,
    figure: bool = True,
    accel_unit: str = "g",
    group_runs: bool = True,
) -> UncertaintyResult:
    """Draw the samples, run every task (:func:`rockyade.batch.study_runs.run_study`) and write
    the report (``accel_unit``: "g" or "m/s2", the unit of a PGA axis in the figure).

    With ``group_runs`` the runs of one sample (one block: every record and load factor)
    go to the solver as groups (:func:`rockyade.batch.running.job_key`: one model, the same
    rows); False: one run per job.

    Each run is written as it ends (the study's journal: ``runs/``); ``resume`` keeps the runs
    an interrupted study of the same name, samples and seed left (another's is refused, and so
    is an ``out`` holding another command's results); the report files are a set replaced as a
    whole (:mod:`rockyade.io.resultset`)."""
    how = Executor(executor, workers, scheduler, scheduler_timeout_s)
    samples = draw_samples(study)
    prepare(study)
    tasks = build_tasks(study, samples)
    identity = {"study": study.name, "samples": study.samples, "seed": study.seed}
    with StudyFolder(out, UNCERTAINTY, identity, resume, field="out") as folder:
        summary, _runs = summarised_runs(
            folder, tasks, how, resume=resume, progress=progress, desc=study.name, group_runs=group_runs
        )
        with folder.replacing() as stage:
            _write_csv(stage / "samples.csv", samples)
            return _report(study, folder.out, stage, samples, summary, figure, accel_unit)


def _report(
    study: UncertaintyStudy,
    out: Path,
    stage: Path,
    samples: pd.DataFrame,
    summary: pd.DataFrame,
    figure: bool,
    accel_unit: str,
) -> UncertaintyResult:
    """Write the report's files in ``stage`` (swapped in for the set in ``out`` after)."""
    from rockyade.probability.exceedance import exceedance_table, fragility_table, spread_table

    runs = with_measures(summary, record_measures(study))
    runs["overturned"] = runs["status"] == "overturned"
    _write_csv(stage / "runs.csv", runs)
    sampled = runs[~runs["nominal"].astype(bool)]
    probabilities = exceedance_table(sampled, study.levels)
    _write_csv(stage / "probabilities.csv", probabilities)
    fragility = fragility_table(sampled, study.measures)
    _write_csv(stage / "fragility.csv", fragility)
    spread = spread_table(runs) if study.pairing == "all" else None
    if spread is not None:
        _write_csv(stage / "spread.csv", spread)
    fig_path = None
    if figure:
        from rockyade.figures.uncertainty_bands import plot_uncertainty

        fig_path = out / "uncertainty.png"
        stage_png = stage / "uncertainty.png"
        plot_uncertainty(study, probabilities, sampled, fragility, spread, stage_png, accel_unit=accel_unit)
    write_json(
        stage / "uncertainty.json",
        {
            "name": study.name,
            "source": study.source,
            "solvers": list(study.solvers),
            "samples": study.samples,
            "seed": study.seed,
            "pairing": study.pairing,
            "records": [label for label, _ in study.motions],
            "load_factors": list(study.load_factors),
            "parameters": study.describe_parameters(),
            "nominal": study.nominal,
            "runs": len(runs),
            "failed_runs": int((runs["status"] == "failed").sum()),
            "probabilities": probabilities.to_dict(orient="records"),
            "fragility": fragility.to_dict(orient="records"),
            "spread": None if spread is None else spread.to_dict(orient="records"),
        },
    )
    return UncertaintyResult(study, out, samples, runs, probabilities, fragility, spread, fig_path)


def _write_csv(path: Path, frame: pd.DataFrame) -> None:
    with atomic_open(path) as fh:
        frame.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")


__all__ = ["UncertaintyResult", "run_uncertainty"]
