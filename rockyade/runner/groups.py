"""Tasks grouped into jobs: runs that share a structure go to one job, which the solver
answers at once (:meth:`rockyade.solvers.reference.ReferenceSolver.run_group`); every other
task is a job of its own.

A group keeps its tasks in study order and is cut into jobs of at most ``max_runs`` runs, so
that the workers share the groups.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Sequence
from typing import TypeVar

T = TypeVar("T")


def group_jobs(tasks: Sequence[T], key: Callable[[T], Hashable | None], max_runs: int) -> list[tuple[T, ...]]:
    """Jobs of the tasks: each task whose ``key`` is None alone, the others by key in chunks
    of at most ``max_runs``; jobs in the order of their first task.

    Parameters
    ----------
    key
        The task's group (None: it runs alone).
    max_runs
        Most runs in one job (>= 1).
    """
    groups: dict[Hashable, list[T]] = {}
    order: list[tuple[str, object]] = []
    for task in tasks:
        k = key(task)
        if k is None:
            order.append(("one", task))
            continue
        if k not in groups:
            groups[k] = []
            order.append(("group", k))
        groups[k].append(task)
    jobs: list[tuple[T, ...]] = []
    size = max(1, int(max_runs))
    for kind, item in order:
        if kind == "one":
            jobs.append((item,))  # type: ignore[arg-type]
            continue
        members = groups[item]
        n_jobs = -(-len(members) // size)
        per = -(-len(members) // n_jobs)  # even chunks
        jobs.extend(tuple(members[i : i + per]) for i in range(0, len(members), per))
    return jobs
