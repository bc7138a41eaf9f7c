"""One way to run work: many (solver, scene) tasks on an executor.

* :class:`~rockyade.runner.tasks.Task`: a solver and a validated, hashed scene;
* :class:`~rockyade.runner.executor.Executor`: in this process (``threads``), on local
  worker processes (``local``) or on Dask (its threaded scheduler in this process, or a
  scheduler's address);
* :func:`~rockyade.runner.dispatch.run_tasks` / :func:`~rockyade.runner.dispatch.run_jobs`:
  cost checks before anything runs (:mod:`rockyade.runner.cost_limits`), progress on stderr,
  Ctrl-C (the first stops dispatching, the second the running runs), a failed run never
  stopping the others; :func:`~rockyade.runner.dispatch.solve_scenes`: one solver over
  many scenes, Results in order;
* worker processes ignore Ctrl-C, lead their own process group and die with this process
  however it dies (:mod:`rockyade.runner.workers`); no executor opens a port unless given a
  Dask scheduler's address;
* :class:`~rockyade.runner.rows.RunRow`: the one typed row of a study's run;
  :mod:`rockyade.runner.journal`: the journal of finished runs (sealed records, the study's
  identity); :class:`~rockyade.runner.study_folder.StudyFolder`: a study's output folder and its
  whole life (refusals, lock, settle, journal, partial summary, the set swapped in).

Every study runs its runs through :func:`rockyade.batch.run_study` (above the analysis, which
gives each run its verdict and metrics); a script runs scenes with :func:`solve_scenes`::

    from rockyade.runner import Executor, solve_scenes

    results = solve_scenes("reference", scenes, executor=Executor("threads", workers=2))
"""

from rockyade.runner.dispatch import Outcome, run_jobs, run_tasks, solve_scenes
from rockyade.runner.executor import EXECUTORS, IN_THIS_THREAD, Executor
from rockyade.runner.tasks import Task, check_costs, solve

__all__ = [
    "EXECUTORS",
    "IN_THIS_THREAD",
    "Executor",
    "Outcome",
    "Task",
    "check_costs",
    "run_jobs",
    "run_tasks",
    "solve",
    "solve_scenes",
]
