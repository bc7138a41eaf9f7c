"""YADE against the reference DEM on the same scene, in one process.

* Specimen 1, 20 s of free rocking at Eq 7's step: YADE's own run time (O.run) per
  simulated second, its start-up cost (process, imports, scene building), and the
  reference DEM's kernel time on the same model: the ratio per simulated second.
* Runs per minute with two parallel YADE workers (8 runs of 5 s simulated).
* YADE kept warm against one process per run (:func:`warm_vs_cold`): 20 runs of specimen 1,
  20 s each, under harmonic motions of different amplitudes, a cold and a warm run of each
  in turn in this process: runs per minute (wall), CPU time per run (this process and
  YADE's), the per-run start-up cost (everything but YADE's own loop) each way, the load
  average, and the results compared bit for bit (``python benchmarks/bench_yade.py warm
  [RUNS]`` runs only this).
* Assemblies: dry running-bond walls of about 10 and 100 blocks under a one-sine pulse,
  us per block-step and start-up time of YADE beside the reference DEM's
  (:func:`assembly_costs`, which ``bench_scale.py`` can call).

Run: ``python benchmarks/bench_yade.py [--quick]`` (``--quick``: the 10-block wall, 1 s of
free rocking, 2 runs of 0.5 s, 1 warm/cold pair of 1 s; a test runs it so that it cannot rot).
"""

from __future__ import annotations

import math
import os
import resource
import sys
import time
from pathlib import Path

from quick_option import quick_parser  # type: ignore[import-not-found]

from rockyade.calibration.model_stage import calibrated_model
from rockyade.errors import InputError
from rockyade.io import warm_program
from rockyade.runner import Executor, solve_scenes
from rockyade.scene import scene_from_dict
from rockyade.solvers.reference import run_model
from rockyade.solvers.yade import YadeSolver
from rockyade.studies.specimen_scenes import block_table
from rockyade.yade import backend as yade_backend

BLOCK = block_table("1")  # specimen 1 with its experimental parameters (Tables 1, 3)


def scene(duration: float, theta0: float = 0.1175):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.001,
            "blocks": [BLOCK],
            "contact": {"calibration": "paper"},
            "motion": {"type": "free", "theta0_rad": theta0},
        }
    )


def running_bond_wall(n_blocks: int, duration: float = 0.3, unit_m: float = 0.25):
    """A dry running-bond wall of about ``n_blocks`` square units (half units at the ends of
    odd courses, as wide as tall at most), under a one-sine pulse of 0.3 g."""
    units = max(2, round(math.sqrt(n_blocks / 1.1)))
    courses = max(2, round(n_blocks / (units + 0.5)))
    blocks = []
    for c in range(courses):
        if c % 2 == 0:
            row = [(i * unit_m, unit_m) for i in range(units)]
        else:
            half = unit_m / 2
            row = (
                [(0.0, half)]
                + [(half + i * unit_m, unit_m) for i in range(units - 1)]
                + [(units * unit_m - half, half)]
            )
        for k, (x0, w) in enumerate(row):
            blocks.append(
                {
                    "name": f"c{c}u{k}",
                    "width_m": w,
                    "height_m": unit_m,
                    "thickness_m": 0.2,
                    "density_kg_m3": 2200.0,
                    "position_m": [x0 + w / 2, c * unit_m],
                }
            )
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.002,
            "blocks": blocks,
            "contact": {"K_N_per_m": 1e9, "beta_s": 5e-5, "friction_angle_deg": 35.0},
            "motion": {"type": "pulse", "shape": "sine", "amplitude_g": 0.3, "period_s": 0.3},
        }
    )


def _wall_builder():
    """The scale benchmark's scenes when it is there (``bench_scale.scene_for``: the reference
    DEM is timed on the same walls), else :func:`running_bond_wall`."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    try:
        from bench_scale import scene_for  # type: ignore[import-not-found]
    except ImportError:
        return running_bond_wall
    finally:
        sys.path.pop(0)
    return lambda n, duration: scene_for(n, "pulse", duration)


def assembly_costs(sizes=(10, 100), duration: float = 0.3) -> list[dict[str, object]]:
    """YADE beside the reference DEM on walls of about ``sizes`` blocks under a pulse: us per
    block-step (each solver's own run time; YADE's includes its recorder), YADE's start-up
    (process, imports, scene building), or why a solver could not run."""
    build = _wall_builder()
    rows = []
    for n in sizes:
        model = calibrated_model(build(n, duration))
        nb = len(model.bodies)
        row: dict[str, object] = {"blocks": nb, "steps": model.n_steps, "dt_s": model.dt_s}
        y = yade_backend.run_model(model)
        if y.ok:
            row["yade_us_per_block_step"] = 1e6 * y.meta.wall_time_s / (model.n_steps * nb)
            row["yade_startup_s"] = y.meta.startup_time_s
        else:
            row["yade_error"] = y.meta.failure_reason
        try:
            run_model(model, record_energy=False)  # compile and warm up
            r = min((run_model(model, record_energy=False) for _ in range(3)), key=lambda x: x.meta.wall_time_s)
            row["reference_us_per_block_step"] = 1e6 * r.meta.wall_time_s / (model.n_steps * nb)
        except InputError as exc:
            row["reference_error"] = str(exc)
        rows.append(row)
    return rows


def harmonic_scene(amplitude_mm: float, duration: float = 20.0):
    """Specimen 1 under a 3.3 Hz sine of ``amplitude_mm`` (20 cycles between 2-cycle ramps,
    then free rocking until ``duration`` s; ``examples/specimen1_harmonic.toml``)."""
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.001,
            "blocks": [BLOCK],
            "contact": {"calibration": "matched"},
            "motion": {
                "type": "harmonic",
                "amplitude_mm": amplitude_mm,
                "frequency_hz": 3.3,
                "cycles": 20,
                "ramp_cycles": 2,
            },
        }
    )


def _worker_cpu_s() -> float:
    """CPU time (user + system) of this thread's warm YADE worker so far, s (0 without one)."""
    box = warm_program.slot(yade_backend.YADE.label).box
    if not box or not box[-1].alive():
        return 0.0
    fields = Path(f"/proc/{box[-1].proc.pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def warm_vs_cold(runs: int = 20, duration: float = 20.0) -> dict[str, float]:
    """``runs`` YADE runs, each in a process of its own (``warm=False``) and in this thread's
    warm worker, taken in pairs (cold, warm) so that both see the same load.

    Returns
    -------
    dict
        ``cold_runs_per_min``, ``warm_runs_per_min`` (1/min of wall time), ``cold_cpu_s`` and
        ``warm_cpu_s`` (CPU time per run, s: this process plus YADE's), ``cold_startup_s`` and
        ``warm_startup_s`` (the median per-run wall time outside YADE's own loop, s; the warm
        worker's first run, which starts it, is left out unless it is the only one),
        ``yade_loop_s`` (the median of YADE's own loop, wall, s), ``load_average`` (1 min, before
        and after, the larger) and
        ``identical`` (1.0 when every warm result equals its cold one bit for bit).
    """
    scenes = [harmonic_scene(4.0 + 0.2 * k, duration) for k in range(runs)]
    solvers = {"cold": YadeSolver(warm=False), "warm": YadeSolver()}
    wall = {"cold": 0.0, "warm": 0.0}
    cpu = {"cold": 0.0, "warm": 0.0}
    results: dict[str, list] = {"cold": [], "warm": []}
    load = os.getloadavg()[0]
    for s in scenes:
        for name, solver in solvers.items():
            children = resource.getrusage(resource.RUSAGE_CHILDREN)
            worker = _worker_cpu_s()
            own, start = time.process_time(), time.perf_counter()
            result = solver.run(s)
            wall[name] += time.perf_counter() - start
            used = time.process_time() - own
            if name == "cold":  # its process has ended and been reaped
                after = resource.getrusage(resource.RUSAGE_CHILDREN)
                used += after.ru_utime + after.ru_stime - children.ru_utime - children.ru_stime
            else:
                used += _worker_cpu_s() - worker
            cpu[name] += used
            assert result.ok, result.meta.failure_reason
            results[name].append(result)
    yade_backend.close_workers()
    out: dict[str, float] = {"load_average": max(load, os.getloadavg()[0])}
    for name in solvers:
        first = 1 if name == "warm" and runs > 1 else 0  # one run only: its worker may be warm already
        startups = sorted(r.meta.startup_time_s for r in results[name][first:])
        out[f"{name}_runs_per_min"] = 60 * runs / wall[name]
        out[f"{name}_cpu_s"] = cpu[name] / runs
        out[f"{name}_startup_s"] = startups[len(startups) // 2]
    loops = sorted(r.meta.wall_time_s for r in results["warm"])
    out["yade_loop_s"] = loops[len(loops) // 2]
    out["identical"] = float(
        all(w.frame.equals(c.frame) for w, c in zip(results["warm"], results["cold"], strict=True))
    )
    return out


def print_warm_vs_cold(runs: int = 20, duration: float = 20.0) -> None:
    r = warm_vs_cold(runs, duration)
    print(
        f"YADE, {runs} runs of specimen 1 ({duration:g} s, harmonic), cold and warm in pairs: "
        f"one process per run {r['cold_runs_per_min']:.1f} runs/min ({r['cold_startup_s']:.2f} s start-up per run), "
        f"kept warm {r['warm_runs_per_min']:.1f} runs/min ({r['warm_startup_s']:.2f} s): "
        f"{r['warm_runs_per_min'] / r['cold_runs_per_min']:.2f}x (wall); "
        f"CPU per run {r['cold_cpu_s']:.2f} s cold, {r['warm_cpu_s']:.2f} s warm: "
        f"{r['cold_cpu_s'] / r['warm_cpu_s']:.2f}x; YADE's loop {r['yade_loop_s']:.2f} s (wall); "
        f"load average {r['load_average']:.2f} on {os.cpu_count()} cores; "
        f"bit for bit the same: {bool(r['identical'])}"
    )


def main(quick: bool = False) -> None:
    if not yade_backend.yade_available():
        print("YADE is not installed: no YADE figures")
        return
    free_s, runs = (1.0, 2) if quick else (20.0, 8)
    for row in assembly_costs((10,), 0.05) if quick else assembly_costs():
        yade = (
            f"YADE {row['yade_us_per_block_step']:.2f} us/block-step + {row['yade_startup_s']:.2f} s start-up"
            if "yade_us_per_block_step" in row
            else f"YADE failed: {row['yade_error']}"
        )
        ref = (
            f"reference {row['reference_us_per_block_step']:.3f} us/block-step"
            if "reference_us_per_block_step" in row
            else f"reference: {row['reference_error']}"
        )
        print(f"wall of {row['blocks']} blocks, {row['steps']} steps of {row['dt_s']:.3g} s: {yade}; {ref}")
    model = calibrated_model(scene(free_s))
    run_model(calibrated_model(scene(0.1)), record_energy=False)  # JIT warm-up
    ref = min(run_model(model, record_energy=False).meta.wall_time_s for _ in range(3))
    y = yade_backend.run_model(model)
    assert y.ok, y.meta.failure_reason
    yade_run, startup = y.meta.wall_time_s, y.meta.startup_time_s
    print(
        f"specimen 1, {free_s:g} s simulated, dt = {model.dt_s:.3g} s ({model.n_steps} steps): YADE {yade_run:.2f} s "
        f"({yade_run / free_s * 1e3:.0f} ms per simulated s, {1e6 * yade_run / model.n_steps:.1f} us/step) + "
        f"{startup:.2f} s start-up; reference DEM {ref * 1e3:.1f} ms ({ref / free_s * 1e3:.2f} ms per simulated s)"
    )
    print(
        f"reference DEM / YADE per simulated second: {yade_run / ref:.0f}x faster "
        f"({(yade_run + startup) / ref:.0f}x counting YADE's start-up)"
    )
    scenes = [scene(0.5 if quick else 5.0, 0.05 + 0.01 * k) for k in range(runs)]
    for workers in (1, 2):
        start = time.perf_counter()
        results = solve_scenes(YadeSolver(), scenes, executor=Executor("threads", workers))
        wall = time.perf_counter() - start
        ok = sum(r.ok for r in results)
        rate = 60 * len(scenes) / wall
        print(
            f"YADE, {len(scenes)} runs of {scenes[0].duration_s:g} s simulated on {workers} worker(s): {wall:.1f} s, "
            f"{rate:.0f} runs/min ({ok} ok)"
        )


if __name__ == "__main__":
    parser = quick_parser(__doc__)
    parser.add_argument("mode", nargs="?", choices=["warm"], help="warm: a warm worker against cold processes")
    parser.add_argument("runs", nargs="?", type=int, help="with warm: how many runs")
    args = parser.parse_args()
    if args.mode == "warm":
        print_warm_vs_cold(*([args.runs] if args.runs is not None else []))
    elif args.quick:
        main(quick=True)
        print_warm_vs_cold(1, 1.0)  # the worker warm from main(): one pair, one cold process
    else:
        main()
        print_warm_vs_cold()
