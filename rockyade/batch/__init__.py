"""Batches, and the one way every study runs its runs.

Four rooms, one idea each:

* :mod:`rockyade.batch.study`: the study file (its grammar and errors) and a
  :class:`~rockyade.batch.study.Study`: the base scenes read once, the grid, its points made
  one at a time;
* :mod:`rockyade.batch.running`: a study's tasks and what one run (or one job of runs that
  share a structure) does: solve, the collapse verdict and the metrics the study asks for, its
  record and files; its row (:class:`rockyade.runner.rows.RunRow`);
* :mod:`rockyade.batch.study_runs`: :func:`~rockyade.batch.study_runs.run_study`, the one
  entry point of every study's runs (resume from the journal, costs, groups, the runner,
  Ctrl-C);
* :mod:`rockyade.batch.summary`: the summary rows and ``summary.csv``, and the batch itself
  (:func:`~rockyade.batch.summary.run_study_tasks`).

::

    from rockyade.batch import load_study, run_study_tasks, study_tasks

    study = load_study("examples/studies/harmonic_sweep.toml")
    summary = run_study_tasks(study_tasks(study), "reports/sweep", workers=2)
"""

from rockyade.batch.running import BatchTask, batch_task, expand, study_tasks
from rockyade.batch.study import MAX_RUNS, MAX_RUNS_ALLOWED, Study, load_study, make_study
from rockyade.batch.study_runs import StudyInterruptedError, StudyRuns, run_scenes, run_study
from rockyade.batch.summary import comparable, failures, run_name, run_study_tasks

__all__ = [
    "MAX_RUNS",
    "MAX_RUNS_ALLOWED",
    "BatchTask",
    "Study",
    "StudyInterruptedError",
    "StudyRuns",
    "batch_task",
    "comparable",
    "expand",
    "failures",
    "load_study",
    "make_study",
    "run_name",
    "run_scenes",
    "run_study",
    "run_study_tasks",
    "study_tasks",
]
