"""Batches: a study file's grid of scenes x solvers, run on the runner, one summary row per run.

Three rooms, one idea each:

* :mod:`rockyade.batch.study`: the study file (its grammar and errors) and a
  :class:`~rockyade.batch.study.Study`: the base scenes read once, the grid, its points made
  one at a time;
* :mod:`rockyade.batch.running`: a study's tasks, what one run does, handing them to
  :mod:`rockyade.runner` (costs, executors, Ctrl-C, the output's lock);
* :mod:`rockyade.batch.summary`: the summary rows, the rows of runs finished earlier
  (resume, :mod:`rockyade.runner.journal`) and ``summary.csv``.

::

    from rockyade.batch import load_study, run_study_tasks, study_tasks

    study = load_study("examples/studies/harmonic_sweep.toml")
    summary = run_study_tasks(study_tasks(study), "reports/sweep", workers=2)
"""

from rockyade.batch.running import BatchTask, batch_task, expand, run_study_tasks, study_tasks
from rockyade.batch.study import MAX_RUNS, MAX_RUNS_ALLOWED, Study, load_study, make_study
from rockyade.batch.summary import comparable, failures, run_name

__all__ = [
    "MAX_RUNS",
    "MAX_RUNS_ALLOWED",
    "BatchTask",
    "Study",
    "batch_task",
    "comparable",
    "expand",
    "failures",
    "load_study",
    "make_study",
    "run_name",
    "run_study_tasks",
    "study_tasks",
]
