"""Runs in groups against one run at a time, per study, on small grids: runs per CPU-second.

Everything runs in this process (the batch's ``threads`` executor, one worker), so that CPU
time (``time.process_time``) counts all of it; the best of ``--repeat`` passes. Prints, per
study, runs per CPU-second one run at a time and grouped, and their ratio, and checks that
both give the same verdicts; and the parent's cost of making a study's tasks.

    .venv/bin/python benchmarks/bench_groups.py [--repeat 3] [--quick]

``--quick``: one pass over 1 record x 2 load factors, 2 samples, amplitudes scanned at omega_p / p = 3
only and up to 3 g tan alpha instead of 15 (a test runs it so that it cannot rot; its numbers mean
little).
"""

from __future__ import annotations

import argparse
import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from scratch import scratch_folder  # type: ignore[import-not-found]

from rockyade.batch import comparable, run_study_tasks
from rockyade.runner import Executor
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.studies import fragility_study, overturning
from rockyade.studies.specimen_scenes import block_table
from rockyade.studies.uncertainty import build_tasks, draw_samples, run_uncertainty, uncertainty_study_from_dict

RECORDS = tuple(range(1, 6))
LOAD_FACTORS = (0.4, 0.8, 1.2, 1.6)
SAMPLES = 4
SCAN_MAX_RATIO: float | None = None  # None: the study's own (overturning.MAX_RATIO)
#: The overturning scans' omega_p / p.
OMEGA_RATIOS = (3.0, 6.0)


def best_cpu(work: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    """Least CPU time of ``repeat`` calls, s, and the last call's value."""
    least, value = math.inf, None
    for _ in range(repeat):
        start = time.process_time()
        value = work()
        least = min(least, time.process_time() - start)
    return least, value


def _folder() -> Path:
    return scratch_folder("rockyade-bench-groups-")


def fragility(solver: str, repeat: int) -> tuple[int, float, float, bool]:
    """Specimen 1, records 1-5 x 4 load factors (25 s runs): (runs, CPU s alone, grouped, same rows)."""
    out = {}
    for grouped in (False, True):

        def work(grouped: bool = grouped) -> Any:
            folder = _folder()
            try:
                tasks = fragility_study.tasks(("1",), RECORDS, LOAD_FACTORS, (solver,))
                return run_study_tasks(
                    tasks, folder, executor=Executor("threads", 1), progress=False, group_runs=grouped
                )
            finally:
                shutil.rmtree(folder, ignore_errors=True)

        out[grouped] = best_cpu(work, repeat)
    same = comparable(out[False][1]).drop(columns="run").equals(comparable(out[True][1]).drop(columns="run"))
    return len(out[True][1]), out[False][0], out[True][0], same


def overturning_scans(repeat: int) -> list[tuple[str, int, float, float, bool]]:
    """Specimen 1, omega_p / p = 3 and 6 (quick: 3): Housner's full scan, the DEM's scan to the first overturn."""
    block = block_table("1")
    alpha, p = block["alpha_rad"], block["p_rad_s"]
    rows = []
    for solver, full in ((HousnerSolver(), True), (ReferenceSolver(record_energy=False, record_contacts=False), False)):
        scans = {}
        for grouped in (False, True):
            scans[grouped] = best_cpu(
                lambda solver=solver, full=full, grouped=grouped: [
                    overturning._scan(overturning.Scan(solver, w, alpha, p, full, grouped, SCAN_MAX_RATIO))
                    for w in OMEGA_RATIOS
                ],
                repeat,
            )
        runs = sum(len(s) for s in scans[True][1])
        rows.append((solver.name, runs, scans[False][0], scans[True][0], scans[False][1] == scans[True][1]))
    return rows


def _uncertainty_study(solvers: list[str]):
    return uncertainty_study_from_dict(
        {
            "name": "bench",
            "solvers": solvers,
            "samples": SAMPLES,
            "seed": 7,
            "duration_s": 25.0,
            "sample_dt_s": 0.01,
            "block": {"specimen": "1"},
            "parameters": {
                "alpha_rad": {"distribution": "uniform", "mean": 0.235, "plus_minus_pct": 5},
                "p_rad_s": {"distribution": "uniform", "mean": 3.84, "plus_minus_pct": 5},
            },
            "motion": {
                "suite": "paper",
                "records": list(RECORDS),
                "load_factors": list(LOAD_FACTORS),
                "pairing": "all",
            },
        }
    )


def uncertainty(solver: str, repeat: int) -> tuple[int, float, float, bool]:
    """Specimen 1, 4 samples (quick: 2) and the nominal block x records 1-5 x 4 load factors."""
    study = _uncertainty_study([solver])
    out = {}
    for grouped in (False, True):

        def work(grouped: bool = grouped) -> Any:
            folder = _folder()
            try:
                return run_uncertainty(
                    study, folder, executor="threads", workers=1, progress=False, figure=False, group_runs=grouped
                ).runs
            finally:
                shutil.rmtree(folder, ignore_errors=True)

        out[grouped] = best_cpu(work, repeat)
    same = comparable(out[False][1]).drop(columns="run").equals(comparable(out[True][1]).drop(columns="run"))
    return len(out[True][1]), out[False][0], out[True][0], same


def task_making(repeat: int) -> list[tuple[str, int, float]]:
    """The parent's CPU per task to make a study's tasks (scenes read, validated, hashed)."""
    frag, tasks = best_cpu(
        lambda: fragility_study.tasks(("1", "2"), tuple(range(1, 11)), (0.4, 0.8, 1.2, 1.6, 2.0)), repeat
    )
    study = _uncertainty_study(["housner", "reference"])
    samples = draw_samples(study)
    unc, utasks = best_cpu(lambda: build_tasks(study, samples), repeat)
    return [("fragility expand", len(tasks), frag), ("uncertainty build_tasks", len(utasks), unc)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="one pass over small grids (module docstring)")
    args = parser.parse_args()
    if args.quick:
        global RECORDS, LOAD_FACTORS, SAMPLES, SCAN_MAX_RATIO, OMEGA_RATIOS  # the grids every part reads
        RECORDS, LOAD_FACTORS, SAMPLES, SCAN_MAX_RATIO, OMEGA_RATIOS = (1,), (0.4, 1.2), 2, 3.0, (3.0,)
        args.repeat = 1
    fragility_study.prepare(("1", "2"))
    print(f"{'study (small grid)':44s} {'runs':>5s} {'alone':>9s} {'grouped':>9s} {'ratio':>6s}  same")
    print(f"{'':44s} {'':5s} {'runs/CPU-s':>20s}")

    def line(label: str, runs: int, alone: float, grouped: float, same: bool) -> None:
        print(f"{label:44s} {runs:5d} {runs / alone:9.1f} {runs / grouped:9.1f} {alone / grouped:5.2f}x  {same}")

    for solver in ("housner", "reference"):
        line(f"fragility, {solver}", *fragility(solver, args.repeat))
    for name, runs, alone, grouped, same in overturning_scans(args.repeat):
        line(f"overturning scans, {name}", runs, alone, grouped, same)
    for solver in ("housner", "reference"):
        line(f"uncertainty, {solver}", *uncertainty(solver, args.repeat))
    for label, n, cpu in task_making(args.repeat):
        print(f"{label:44s} {n:5d} tasks: {1e3 * cpu / n:.3f} ms CPU per task")


if __name__ == "__main__":
    main()
