"""Batches: a study file expands into scenes; they run on local processes or a Dask cluster.

Study file (TOML)::

    name = "harmonic-sweep"
    solvers = ["reference", "housner"]     # each scene runs with each solver
    save_histories = true                  # the time history of every run (else summary only)
    yade_timeout_s = 600                   # optional: wall-clock limit of each YADE run, s

    [base]                                 # base scenes: one file, or several
    files = ["examples/specimen1_harmonic.toml", "examples/specimen3_free.toml"]

    [grid]                                 # product of the lists; keys are dotted paths
    "motion.frequency_hz" = [2.0, 3.3]     # into the scene ("blocks.0.mu", "motion", ...)
    "motion.amplitude_mm" = [2.0, 6.0]

Each run is named ``<scene hash>_<solver>``; ``runs/<name>.json`` (metadata and metrics) is
written for every run, ``runs/<name>.csv`` with the time history when asked. The summary
(``summary.csv``, and ``summary.parquet`` when pyarrow is installed) has one row per run:
the grid values, status, failure reason, wall time and per-block metrics (see
:func:`rockyade.analysis.run_metrics`, and the rocking pattern for stacks).

A failed run never stops the batch: its row says why (a full disk too: the run fails with
that reason and the batch goes on). ``resume`` skips runs whose JSON says they completed
(or overturned) for the same scene hash and re-runs failed ones. The summary is sorted by
run order, so the same inputs give the same summary on either executor (wall times aside).

Before any run, the cost of every run is estimated and the batch is refused if one is above
the limits of :mod:`rockyade.cost` (``allow_large`` lifts them). One batch at a time may
write an output directory (a lock); what a killed batch left (temporary files, a result
between its two renames) is settled when the next one starts.

Executors: ``local`` runs each task in a pool of worker processes; ``dask`` without a
scheduler runs them on Dask's threaded scheduler inside this process (no socket is opened:
the ``distributed`` LocalCluster would start HTTP servers), and with ``scheduler`` on a
``distributed`` cluster at that address.

Ctrl-C (SIGINT): the first stops dispatching (queued runs never start) and lets the
running runs finish; the second stops them at once (their worker processes are killed).
Either way ``summary.csv`` is written with what finished, the unfinished runs listed with
status ``unfinished``, and :class:`~rockyade.errors.BatchInterruptedError` is raised.
Worker processes ignore SIGINT, lead their own process group and are killed by the kernel
if this process dies, however it dies (``prctl(PR_SET_PDEATHSIG, SIGKILL)``,
:mod:`rockyade.io.lifetime`); a YADE process dies the same way with the worker that started it.
"""

from __future__ import annotations

import collections
import contextlib
import copy
import itertools
import json
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import pandas as pd

from rockyade.errors import BatchInterruptedError, InputError, RockyadeError, os_error_message
from rockyade.io.atomic import atomic_open, remove_stale_temporaries, write_json
from rockyade.io.fields import TableReader
from rockyade.io.lifetime import die_with_parent
from rockyade.io.locking import output_lock
from rockyade.solvers import solver_names

EXECUTORS = ("local", "dask")
TIMING_COLUMNS = ("wall_time_s", "elapsed_s")
#: Seconds to wait for a Dask scheduler to answer.
SCHEDULER_TIMEOUT_S = 10.0
#: Status of a run that a Ctrl-C stopped or kept from starting (summary only).
UNFINISHED = "unfinished"


@dataclass(frozen=True)
class Task:
    """One run: a scene (canonical dictionary) and a solver.

    Attributes
    ----------
    index
        Position in the study (the summary's order).
    scene
        The scene as a dictionary (record files as absolute paths).
    solver
        Solver name.
    labels
        Grid values and base-scene name, for the summary.
    out_dir
        Where ``runs/`` is.
    save_history
        Write the time history as well as the metadata.
    """

    index: int
    scene: dict[str, Any]
    solver: str
    labels: dict[str, Any]
    out_dir: str
    save_history: bool = True
    extra: dict[str, Any] = field(default_factory=dict)
    yade_timeout_s: float | None = None


@dataclass(frozen=True)
class Study:
    """A parsed study: its tasks and settings."""

    name: str
    tasks: tuple[Task, ...]
    solvers: tuple[str, ...]


def _set_path(d: dict[str, Any], dotted: str, value: Any, source: str | None) -> None:
    parts = dotted.split(".")
    target: Any = d
    for i, part in enumerate(parts[:-1]):
        key: Any = int(part) if isinstance(target, list) else part
        try:
            target = target[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise InputError(f"grid.{dotted}", f"no '{'.'.join(parts[: i + 1])}' in the base scene", source) from None
    last: Any = int(parts[-1]) if isinstance(target, list) else parts[-1]
    target[last] = copy.deepcopy(value)


def _scene_dict(path: Path) -> dict[str, Any]:
    from rockyade.scene import load_scene

    return load_scene(path).to_dict()


def load_study(path: str | Path, out_dir: str | Path) -> Study:
    """Read a study file and expand it into tasks (scenes are validated now)."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("study", f"file not found: {path}")
    from rockyade.io.fields import plain_data
    from rockyade.scene.loading import parse_text_file

    data = plain_data(parse_text_file(path, "study"), "study", source)
    r = TableReader(data, "", source)
    name = r.string("name", path.stem)
    solvers = r.raw("solvers", ["reference"])
    if not isinstance(solvers, list) or not solvers or any(s not in solver_names() for s in solvers):
        raise r.error("solvers", f"must be a list of {', '.join(solver_names())}, got {solvers!r}")
    save = r.boolean("save_histories", True)
    from rockyade.solvers.yade import MAX_TIMEOUT_S

    timeout = r.number("yade_timeout_s", None, lo=0.0, lo_open=True, hi=MAX_TIMEOUT_S, unit="s")
    base = r.sub("base")
    files = base.raw("files", None)
    single = base.raw("file", None)
    if (files is None) == (single is None):
        raise base.error("files", "give exactly one of file and files")
    file_list = [single] if single is not None else files
    if not isinstance(file_list, list) or not all(isinstance(f, str) for f in file_list):
        raise base.error("files", "must be a list of scene file paths")
    base.finish()
    grid_table = r.raw("grid", {})
    if not isinstance(grid_table, dict):
        raise r.error("grid", "must be a table of dotted paths to lists of values")
    for key, values in grid_table.items():
        if not isinstance(values, list) or not values:
            raise InputError(f"grid.{key}", "must be a non-empty list of values", source)
    r.finish()
    bases = [(Path(f).stem, _scene_dict(path.parent / f)) for f in file_list]
    tasks = [replace(t, yade_timeout_s=timeout) for t in expand(bases, grid_table, solvers, out_dir, save, source)]
    return Study(name, tuple(tasks), tuple(solvers))


def expand(
    bases: list[tuple[str, dict[str, Any]]],
    grid: dict[str, list[Any]],
    solvers: Iterable[str],
    out_dir: str | Path,
    save_history: bool = True,
    source: str | None = None,
) -> list[Task]:
    """Tasks for every base scene x grid point x solver (validated scenes)."""
    from rockyade.cost import estimate_cost, estimate_dict
    from rockyade.scene import scene_from_dict

    keys = list(grid)
    tasks = []
    index = 0
    for base_name, base in bases:
        for values in itertools.product(*(grid[k] for k in keys)):
            d = copy.deepcopy(base)
            for key, value in zip(keys, values, strict=True):
                _set_path(d, key, value, source)
            scene = scene_from_dict(d, source=source)
            canonical = scene.to_dict()
            if "file" in canonical["motion"]:
                canonical["motion"]["file"] = str(Path(canonical["motion"]["file"]).resolve())
            labels = {"base": base_name, **{k: _label(v) for k, v in zip(keys, values, strict=True)}}
            for solver in solvers:
                try:
                    extra = {"cost": estimate_dict(estimate_cost(scene, solver))}
                except RockyadeError:
                    extra = {}  # the run itself will fail and say why
                tasks.append(Task(index, canonical, solver, labels, str(out_dir), save_history, extra))
                index += 1
    return tasks


def _label(value: Any) -> Any:
    return value if isinstance(value, (int, float, str, bool)) else json.dumps(value, sort_keys=True)


# ---------------------------------------------------------------------- one run


def run_name(scene_hash: str, solver: str) -> str:
    """File stem of a run."""
    return f"{scene_hash}_{solver}"


def run_task(task: Task) -> dict[str, Any]:
    """Run one task; return its summary row. Never raises: failures become rows."""
    from rockyade.analysis.metrics import PER_BLOCK_LIMIT, assembly_metrics, run_metrics
    from rockyade.result import failed_result
    from rockyade.scene import scene_from_dict
    from rockyade.solvers import get_solver

    start = time.perf_counter()
    runs = Path(task.out_dir) / "runs"
    runs.mkdir(parents=True, exist_ok=True)
    scene = None
    try:
        scene = scene_from_dict(task.scene)
        name = run_name(scene.scene_hash, task.solver)
        solver = get_solver(task.solver)
        if task.solver == "yade":
            result = solver(scene, workdir=runs / "yade", name=name, timeout_s=task.yade_timeout_s)
        else:
            result = solver(scene)
    except Exception as exc:  # one failed run never stops the batch
        scene_hash = scene.scene_hash if scene is not None else "invalid"
        name = run_name(scene_hash, task.solver)
        result = failed_result(task.solver, scene_hash, f"{type(exc).__name__}: {exc}")
    row: dict[str, Any] = {
        "index": task.index,
        "run": name,
        "scene_hash": result.meta.get("scene_hash"),
        "solver": task.solver,
        **task.labels,
        "status": result.status,
        "failure_reason": result.meta.get("failure_reason") or "",
        "overturn_time_s": result.meta.get("overturn_time_s"),
        "overturned_block": result.meta.get("overturned_block") or "",
        "wall_time_s": result.meta.get("wall_time_s"),
    }
    if result.ok and scene is not None:
        if scene.positioned:
            row.update(assembly_metrics(scene, result))
        if not scene.positioned or len(scene.blocks) <= PER_BLOCK_LIMIT:
            metrics = run_metrics(scene, result)
            single = len(scene.blocks) == 1
            for block, values in metrics.items():
                for key, value in values.items():
                    row[key if single else f"{block}_{key}"] = value
        if len(scene.blocks) == 2:
            from rockyade.analysis.patterns import classify_result

            pattern = classify_result(scene, result)
            row["pattern"] = pattern.dominant
            row["pattern_fractions"] = json.dumps(pattern.fractions, sort_keys=True)
    row["elapsed_s"] = time.perf_counter() - start
    try:
        if task.save_history and result.ok:
            result.write(runs / f"{name}.csv", {"summary": row})  # the JSON, last, marks it complete
        else:
            write_json(runs / f"{name}.json", {**result.meta, "summary": row})
    except OSError as exc:  # a full disk: this run fails with the reason, the batch goes on
        row = _write_failure(task, row, exc)
    return row


def _write_failure(task: Task, row: dict[str, Any], exc: OSError) -> dict[str, Any]:
    """The row of a run whose result could not be written (no file of it is left half-written)."""
    keep = (*LEADING_COLUMNS, *task.labels, "wall_time_s", "elapsed_s")
    return {
        **{k: v for k, v in row.items() if k in keep},
        "status": "failed",
        "failure_reason": f"cannot write the result: {os_error_message(exc)}",
        "overturn_time_s": None,
        "overturned_block": "",
    }


def _completed_row(task: Task) -> dict[str, Any] | None:
    """The summary row of a run already completed (or overturned) for the same scene."""
    from rockyade.scene import scene_from_dict

    try:
        scene_hash = scene_from_dict(task.scene).scene_hash
    except Exception:
        return None
    path = Path(task.out_dir) / "runs" / f"{run_name(scene_hash, task.solver)}.json"
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError):
        return None
    if data.get("status") in ("completed", "overturned") and data.get("scene_hash") == scene_hash and "summary" in data:
        row = dict(data["summary"])
        row["index"] = task.index
        row.update(task.labels)
        return row
    return None


# ---------------------------------------------------------------------- Ctrl-C


class StopRequest:
    """Counts Ctrl-C (SIGINT) during a batch: the first asks to stop dispatching, the second
    to stop at once. Installed only in the main thread (elsewhere Python delivers no signal).

    Parameters
    ----------
    raise_on_second
        Raise KeyboardInterrupt on the second Ctrl-C (executors whose runs are threads of
        this process cannot be killed: the caller then ends the process).
    """

    def __init__(self, raise_on_second: bool = False) -> None:
        self.count = 0
        self.event = threading.Event()
        self.raise_on_second = raise_on_second
        self._previous: Any = None
        self._installed = False

    @property
    def requested(self) -> bool:
        """A first Ctrl-C came: start no new run."""
        return self.count >= 1

    @property
    def now(self) -> bool:
        """A second Ctrl-C came: stop the running runs."""
        return self.count >= 2

    def _handler(self, signum: int, frame: Any) -> None:
        self.count += 1
        self.event.set()
        if self.count == 1:
            _say("Ctrl-C: no new run starts; waiting for the running runs to finish (Ctrl-C again stops them now)")
        elif self.count == 2:
            _say("Ctrl-C again: stopping the running runs now")
            if self.raise_on_second:
                raise KeyboardInterrupt

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handler)
            self._installed = True
        return self

    def __exit__(self, *exc: object) -> None:
        if self._installed:
            signal.signal(signal.SIGINT, self._previous)
            self._installed = False


def _say(message: str) -> None:
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(f"\n{message}\n")
        sys.stderr.flush()


# ---------------------------------------------------------------------- executors


def _progress(total: int, enabled: bool, desc: str):
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, desc=desc, unit="run", smoothing=0.05)


def _worker_init(parent_pid: int) -> None:
    """Pool worker set-up: ignore Ctrl-C (the parent decides), own process group, killed with
    the parent (and a YADE process it started with it)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(OSError):
        os.setpgid(0, 0)
    die_with_parent(parent_pid)
    if threading.current_thread() is threading.main_thread():
        threading.Thread(target=_watch_parent, args=(parent_pid,), daemon=True, name="watch-parent").start()


def _watch_parent(parent_pid: int) -> None:
    """Where prctl is missing: poll the parent and end this worker's group when it is gone."""
    while True:
        time.sleep(0.5)
        if os.getppid() != parent_pid:
            with contextlib.suppress(OSError):
                os.killpg(os.getpgrp(), signal.SIGKILL)
            os._exit(1)


def _kill_workers(pool: ProcessPoolExecutor) -> None:
    """SIGKILL every worker of the pool and the processes they started."""
    processes = dict(getattr(pool, "_processes", None) or {})
    for pid in processes:
        try:
            os.killpg(pid, signal.SIGKILL)
        except OSError:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)


def _crashed_row(task: Task, reason: str) -> dict[str, Any]:
    return _placeholder_row(task, "failed", reason)


def _run_local(
    tasks: list[Task], workers: int, on_done: Callable[[dict[str, Any]], None], stop: StopRequest, started: set[int]
) -> list[Task]:
    """Run tasks on a pool of worker processes; return the tasks that did not finish.

    At most ``workers`` tasks are handed to the pool at a time, so a stop request leaves
    the others unstarted.
    """
    import multiprocessing

    ctx = multiprocessing.get_context("fork" if os.name == "posix" else "spawn")
    pending = collections.deque(tasks)
    running: dict[Future[dict[str, Any]], Task] = {}
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init, initargs=(os.getpid(),))
    killed = False
    try:
        while pending or running:
            while pending and len(running) < workers and not stop.requested:
                task = pending.popleft()
                try:
                    running[pool.submit(run_task, task)] = task
                    started.add(task.index)
                except BrokenProcessPool:
                    pending.appendleft(task)
                    pool = _fresh_pool(pool, ctx, workers)
            if not running:
                break
            done, _ = wait(running, timeout=0.2, return_when=FIRST_COMPLETED)
            broken = False
            for future in done:
                task = running.pop(future)
                try:
                    on_done(future.result())
                except BrokenProcessPool:
                    broken = True
                    on_done(_crashed_row(task, "the worker process died (killed, or out of memory)"))
            if stop.now:
                _kill_workers(pool)
                killed = True
                break
            if broken:
                for future, task in list(running.items()):
                    running.pop(future)
                    on_done(_crashed_row(task, "the worker process died (killed, or out of memory)"))
                pool = _fresh_pool(pool, ctx, workers)
    except BaseException:
        _kill_workers(pool)
        killed = True
        raise
    finally:
        pool.shutdown(wait=not killed, cancel_futures=True)
    return [*running.values(), *pending]


def _fresh_pool(pool: ProcessPoolExecutor, ctx: Any, workers: int) -> ProcessPoolExecutor:
    _kill_workers(pool)
    pool.shutdown(wait=False, cancel_futures=True)
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_worker_init, initargs=(os.getpid(),))


def _run_dask_in_process(
    tasks: list[Task], workers: int, on_done: Callable[[dict[str, Any]], None], stop: StopRequest, started: set[int]
) -> list[Task]:
    """Dask's threaded scheduler in this process: no cluster, no socket. Returns the tasks
    that did not finish (a stop request makes the unstarted ones return at once)."""
    from concurrent.futures import ThreadPoolExecutor

    try:
        import dask.threaded
        from dask.callbacks import Callback
    except ImportError:
        raise InputError("executor", "the dask executor needs dask: pip install 'rockyade[dask]'") from None

    finished: set[int] = set()

    def guarded(task: Task) -> dict[str, Any] | None:
        if stop.event.is_set():
            return None
        started.add(task.index)
        return run_task(task)

    def posttask(key: Any, row: Any, dsk: Any, state: Any, worker_id: Any) -> None:
        if row is not None:
            finished.add(row["index"])
            on_done(row)

    graph = {f"run-{task.index}": (guarded, task) for task in tasks}
    pool = ThreadPoolExecutor(max_workers=workers, thread_name_prefix="rockyade-dask")
    clean = False
    try:
        with Callback(posttask=posttask):
            dask.threaded.get(graph, list(graph), pool=pool)
        clean = True
    finally:
        # after a second Ctrl-C the running runs are threads that cannot be killed: the
        # command line ends the process (BatchInterruptedError.hard)
        pool.shutdown(wait=clean, cancel_futures=True)
    return [t for t in tasks if t.index not in finished]


SCHEDULER_ADDRESS = re.compile(r"^(tcp|tls|ucx|inproc)://\S+$")


def _run_dask_remote(
    tasks: list[Task],
    scheduler: str,
    on_done: Callable[[dict[str, Any]], None],
    stop: StopRequest,
    timeout_s: float,
    started: set[int],
) -> list[Task]:
    """A ``distributed`` cluster at ``scheduler``; Ctrl-C cancels what has not finished."""
    try:
        from dask.distributed import Client
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise InputError(
            "executor", "the dask executor needs dask[distributed]: pip install 'rockyade[dask]'"
        ) from None
    if not SCHEDULER_ADDRESS.match(scheduler):
        raise InputError("scheduler", f"must be an address like tcp://host:8786 or tls://host:8786, got {scheduler!r}")
    try:
        client = Client(scheduler, timeout=timeout_s)
    except (OSError, TimeoutError) as exc:
        raise InputError(
            "scheduler", f"no Dask scheduler answered at {scheduler} within {timeout_s:g} s ({exc})"
        ) from None
    finished: set[int] = set()
    try:
        futures = client.map(run_task, tasks, pure=False)
        started.update(t.index for t in tasks)  # the cluster decides when: cancelled ones count as stopped
        pending = dask_completed(futures)
        while not pending.is_empty():
            batch = pending.next_batch(block=False)
            for future in batch:
                row = future.result()
                finished.add(row["index"])
                on_done(row)
            if stop.requested:
                client.cancel([f for f in futures if not f.done()])
                break
            if not batch:
                stop.event.wait(0.1)
    finally:
        client.close()
    return [t for t in tasks if t.index not in finished]


def _placeholder_row(task: Task, status: str, reason: str) -> dict[str, Any]:
    """A summary row for a run that produced no result (unfinished, or its worker died)."""
    from rockyade.scene import scene_from_dict

    try:
        scene_hash = scene_from_dict(task.scene).scene_hash
    except Exception:  # a scene that does not even load: its run would have failed the same way
        scene_hash = "invalid"
    return {
        "index": task.index,
        "run": run_name(scene_hash, task.solver),
        "scene_hash": scene_hash,
        "solver": task.solver,
        **task.labels,
        "status": status,
        "failure_reason": reason,
        "overturn_time_s": None,
        "overturned_block": "",
        "wall_time_s": None,
    }


def check_task_costs(tasks: list[Task], allow_large: bool = False) -> None:
    """Refuse the batch, before any run, if a run's cost is above :data:`rockyade.cost.LIMITS`."""
    if allow_large:
        return
    from rockyade.cost import CostEstimate, check_cost
    from rockyade.scene import scene_from_dict

    for task in tasks:
        label = f"run {task.index} ({', '.join(f'{k} = {v}' for k, v in task.labels.items())})"
        cost = task.extra.get("cost")
        if cost is not None:
            if CostEstimate(**cost).over_limits():
                check_cost(scene_from_dict(task.scene), task.solver, label=label)
            continue
        try:
            scene = scene_from_dict(task.scene)
        except RockyadeError:
            continue  # the run fails and says why
        try:
            check_cost(scene, task.solver, label=label)
        except InputError as exc:
            if exc.field == "allow_large":
                raise
            continue  # not a cost refusal: the run itself fails and says why
        except RockyadeError:
            continue


def run_study_tasks(
    tasks: list[Task],
    out_dir: str | Path,
    *,
    executor: str = "local",
    workers: int = 2,
    scheduler: str | None = None,
    resume: bool = False,
    progress: bool = True,
    desc: str = "runs",
    allow_large: bool = False,
    scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
) -> pd.DataFrame:
    """Run tasks and write the summary; return it (sorted by task order).

    Parameters
    ----------
    executor
        "local" (worker processes) or "dask" (``scheduler`` address, or Dask's threaded
        scheduler in this process).
    resume
        Skip runs already completed for the same scene hash; re-run failed ones.
    allow_large
        Run even if a run's cost estimate is above the limits of :mod:`rockyade.cost`.

    Raises
    ------
    InputError
        Bad settings, a run above the cost limits, an output another batch is writing.
    BatchInterruptedError
        After Ctrl-C, once the summary of what finished is written.
    """
    if executor not in EXECUTORS:
        raise InputError("executor", f"must be one of {', '.join(EXECUTORS)}, got {executor!r}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InputError("workers", f"must be an integer >= 1, got {workers!r}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with output_lock(out, "out"):
        _settle(out)
        check_task_costs(tasks, allow_large)
        return _run_locked(tasks, out, executor, workers, scheduler, resume, progress, desc, scheduler_timeout_s)


def _settle(out: Path) -> None:
    """What a killed batch left: finish or drop half-replaced results, remove temporary files."""
    from rockyade.result import settle_results

    remove_stale_temporaries(out)
    if (out / "runs").is_dir():
        settle_results(out / "runs")


def _run_locked(
    tasks: list[Task],
    out: Path,
    executor: str,
    workers: int,
    scheduler: str | None,
    resume: bool,
    progress: bool,
    desc: str,
    scheduler_timeout_s: float,
) -> pd.DataFrame:
    rows: list[dict[str, Any]] = []
    todo = []
    for task in tasks:
        done = _completed_row(task) if resume else None
        if done is not None:
            rows.append(done)
        else:
            todo.append(task)
    bar = _progress(len(tasks), progress, desc)
    bar.update(len(rows))

    def on_done(row: dict[str, Any]) -> None:
        rows.append(row)
        bar.update(1)
        if row["status"] == "failed":
            bar.write(f"failed: {row['run']}: {row['failure_reason']}")

    unfinished: list[Task] = []
    started: set[int] = set()
    stopped_now = False
    in_process_dask = executor == "dask" and not scheduler
    with StopRequest(raise_on_second=in_process_dask) as stop:
        try:
            if executor == "local":
                unfinished = _run_local(todo, workers, on_done, stop, started)
            elif in_process_dask:
                unfinished = _run_dask_in_process(todo, workers, on_done, stop, started)
            else:
                unfinished = _run_dask_remote(todo, scheduler or "", on_done, stop, scheduler_timeout_s, started)
        except KeyboardInterrupt:
            if not stop.requested:
                raise
            stopped_now = True
            finished = {row["index"] for row in rows}
            unfinished = [t for t in todo if t.index not in finished]
        finally:
            bar.close()
    interrupted = stop.requested and bool(unfinished)  # a Ctrl-C after the last run changes nothing
    if interrupted:
        for task in sorted(unfinished, key=lambda t: t.index):
            reason = "stopped by Ctrl-C" if task.index in started else "not started: Ctrl-C"
            rows.append(_placeholder_row(task, UNFINISHED, reason))
    summary = _ordered(pd.DataFrame(rows).sort_values("index").reset_index(drop=True), tasks)
    write_summary(summary, out)
    if interrupted:
        if stop.now or stopped_now:
            _settle(out)
        raise BatchInterruptedError(
            len(tasks) - len(unfinished), len(unfinished), str(out / "summary.csv"), hard=stop.now or stopped_now
        )
    return summary


LEADING_COLUMNS = ("index", "run", "scene_hash", "solver")
STATUS_COLUMNS = ("status", "failure_reason", "overturn_time_s", "overturned_block", "wall_time_s", "elapsed_s")


def _ordered(summary: pd.DataFrame, tasks: list[Task]) -> pd.DataFrame:
    """Columns in one canonical order (fresh, resumed or Dask rows alike)."""
    labels = list(tasks[0].labels) if tasks else []
    first = [c for c in (*LEADING_COLUMNS, *labels, *STATUS_COLUMNS) if c in summary.columns]
    rest = sorted(c for c in summary.columns if c not in first)
    return summary[first + rest]


def write_summary(summary: pd.DataFrame, out: Path) -> None:
    """``summary.csv`` (and ``summary.parquet`` when pyarrow is installed), atomically."""
    with atomic_open(out / "summary.csv") as fh:
        summary.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return
    with atomic_open(out / "summary.parquet", "wb") as fh:
        summary.to_parquet(fh, index=False)


def failures(summary: pd.DataFrame) -> pd.DataFrame:
    """Rows of failed runs with their reasons."""
    return summary.loc[summary["status"] == "failed", ["run", "solver", "failure_reason"]]


def comparable(summary: pd.DataFrame) -> pd.DataFrame:
    """The summary without timing columns (equal for equal inputs on any executor)."""
    return summary.drop(columns=[c for c in TIMING_COLUMNS if c in summary.columns])


__all__ = [
    "Study",
    "Task",
    "comparable",
    "expand",
    "failures",
    "load_study",
    "run_study_tasks",
    "run_task",
    "write_summary",
]
