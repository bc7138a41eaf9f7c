"""The collapse study as a batch: 1,200 reference-DEM runs of 25 s (4 specimens x 30
synthetic records x load factors 0.1-1.0), on 2 local processes and on a 2-worker Dask
LocalCluster (loopback): wall time and runs per second.

Run: ``python benchmarks/bench_batch.py [--quick]`` (``--quick``: specimen 1, 3 records, 2 load
factors, local processes only; a test runs it so that it cannot rot)."""

from __future__ import annotations

import time

from quick_option import quick_mode  # type: ignore[import-not-found]
from scratch import scratch_folder  # type: ignore[import-not-found]

from rockyade.paper import SINGLE_SPECIMENS
from rockyade.studies import fragility_study

LOAD_FACTORS = tuple(round(0.1 * k, 1) for k in range(1, 11))


def main() -> None:
    quick = quick_mode(__doc__)
    grid = (
        {"specimens": ("1",), "records": range(1, 4), "load_factors": (0.3, 0.6)}
        if quick
        else {"load_factors": LOAD_FACTORS}
    )
    fragility_study.prepare(grid.get("specimens", SINGLE_SPECIMENS))
    out = scratch_folder("rockyade-bench-batch-")
    tasks = fragility_study.tasks(**grid, solvers=("reference",))
    from rockyade.batch import run_study_tasks

    start = time.perf_counter()
    summary = run_study_tasks(tasks, out / "local", workers=2, progress=False)
    local = time.perf_counter() - start
    n = len(summary)
    print(
        f"collapse batch, {n} reference-DEM runs of 25 s: local processes (2): {local:.1f} s, {n / local:.1f} runs/s "
        f"({(summary.status == 'overturned').sum()} overturned, {(summary.status == 'failed').sum()} failed)"
    )
    if quick:
        return
    try:
        from dask.distributed import LocalCluster
    except ImportError:
        print("dask.distributed not installed: no Dask figure")
        return
    tasks = fragility_study.tasks(**grid, solvers=("reference",))
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        start = time.perf_counter()
        summary = run_study_tasks(
            tasks, out / "dask", executor="dask", scheduler=cluster.scheduler_address, progress=False
        )
        dask = time.perf_counter() - start
    print(
        f"collapse batch, {len(summary)} runs: Dask LocalCluster (2 workers, loopback): {dask:.1f} s, "
        f"{len(summary) / dask:.1f} runs/s (includes the workers' start-up and numba cache loads)"
    )


if __name__ == "__main__":
    main()
