"""A task: one (solver, scene) run, with the scene validated and hashed when the task is made.

A task pickles small: the Scene is data (a record is named by its file, read where the run
happens; a synthetic record by its suite and number) and the Solver a few options.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from rockyade.errors import RockyadeError
from rockyade.result import Result, failed_result
from rockyade.runner.cost_limits import cost_refusal
from rockyade.scene import Scene
from rockyade.solvers.base import Solver

#: A value of a table a study writes (a task's label, a cell of a run's row): strict JSON's
#: scalars (NaN and infinity written as null).
Cell = float | int | str | bool | None


def run_name(scene_hash: str, solver: str) -> str:
    """A run's name, ``<scene hash>_<solver>``: its file stem in a study's folder, and what a
    resumed study finds it by (every study names its runs so)."""
    return f"{scene_hash}_{solver}"


@dataclass(frozen=True)
class Task:
    """One run.

    Attributes
    ----------
    index
        Position in the study (the order of its results).
    solver
        The solver, with its options.
    scene
        The validated scene.
    labels
        What names the run to a reader (grid values, base scene), for summaries and errors.
    scene_hash
        The scene's hash (set from ``scene``).
    """

    index: int
    solver: Solver
    scene: Scene
    labels: Mapping[str, Cell] = field(default_factory=dict)
    scene_hash: str = field(init=False, default="")

    def __post_init__(self) -> None:
        object.__setattr__(self, "scene_hash", self.scene.scene_hash)

    @property
    def name(self) -> str:
        """The run's name (:func:`run_name`): its file stem in a study's folder."""
        return run_name(self.scene_hash, self.solver.name)

    def describe(self) -> str:
        """``run 3 (base = s, motion.record = 2)``: the run as named in errors."""
        labels = ", ".join(f"{k} = {v}" for k, v in self.labels.items())
        return f"run {self.index}" + (f" ({labels})" if labels else "")


def solve(task: Task) -> Result:
    """Run one task: its Result, or a failed Result with the reason (never an exception)."""
    try:
        return task.solver.run(task.scene)
    except Exception as exc:  # one failed run never stops the others
        return failed_task(task, f"{type(exc).__name__}: {exc}")


def failed_task(task: Task, reason: str) -> Result:
    """The failed Result of a task that gave none (its worker died, say)."""
    return failed_result(task.solver.name, task.scene_hash, reason)


def check_costs(tasks: Iterable[Task], allow_large: bool = False) -> None:
    """Refuse the lot, before any run, if one run's cost is above the limits
    (:data:`rockyade.runner.cost_limits.LIMITS`; ``allow_large`` lifts them).

    Raises
    ------
    InputError
        Field ``allow_large``, naming the run (:meth:`Task.describe`), what is too large and
        what to change. A run whose cost cannot be estimated is left to fail and say why.
    """
    if allow_large:
        return
    for task in tasks:
        try:
            estimate = task.solver.estimate_cost(task.scene)
        except RockyadeError:
            continue  # not a cost refusal: the run itself fails and says why
        refusal = cost_refusal(estimate, task.scene.source, task.describe())
        if refusal is not None:
            raise refusal
