"""Siconos's cost per run against YADE (warm) and the reference DEM, on the same scenes.

* A 30 s single-block run: specimen 1's geometry (0.25 x 1.0 m) under the shipped EC8
  record scaled to 0.15 g, each solver warm (YADE's worker started and the reference DEM's
  kernel compiled by a first run): wall time per run; Siconos at its default step and halved.
* A dry running-bond wall of about 33 blocks at rest, 0.05 s: Siconos's ms per step and what
  the time step, the friction solver's tolerance and the Newton iterations buy (its
  unconverged steps and the largest residual), beside the reference DEM's.

Run: ``python benchmarks/bench_siconos.py`` (prints a table; the load average is printed
with it: on a shared machine compare ratios, not seconds).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, wall
from rockyade.solvers import make_solver

RECORD = Path(__file__).resolve().parents[1] / "examples" / "records" / "ec8_type2_D_record21.AT2"


def single_block(duration_s: float = 30.0):
    """Specimen 1's geometry under the record at 0.15 g (it rocks, it does not overturn)."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": 0.01,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503.0}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "record", "file": str(RECORD), "target_pga_m_s2": 0.15 * 9.81},
        }
    )


def timed(solver, scene):
    start = time.perf_counter()
    result = solver.run(scene)
    return time.perf_counter() - start, result


def single_block_costs() -> None:
    scene = single_block()
    print(f"single block, {scene.duration_s:g} s simulated (load average {os.getloadavg()[0]:.1f})")
    rows = [
        ("yade (warm)", make_solver("yade")),
        ("reference", make_solver("reference")),
        ("siconos (warm, default dt)", make_solver("siconos")),
        ("siconos (warm, dt / 2)", make_solver("siconos", dt_factor=0.5)),
    ]
    for _, solver in rows[:3]:
        solver.run(single_block(1.0))  # warm: worker started, kernel compiled
    yade_s = None
    for label, solver in rows:
        seconds, result = timed(solver, scene)
        yade_s = seconds if label.startswith("yade") else yade_s
        steps = result.meta.n_steps or 0
        peak = float(abs(result.frame["theta_rad"]).max()) if len(result.frame) else float("nan")
        ratio = seconds / yade_s if yade_s else float("nan")
        print(
            f"  {label:28s} {seconds:7.2f} s  ({ratio:4.1f} x YADE)  dt {result.meta.dt_s or float('nan'):.3g} s"
            f"  {1e6 * seconds / max(steps, 1):7.1f} us/step  peak {peak:.5f} rad  {result.status}"
        )


def wall_costs() -> None:
    data = wall(courses=6, units_per_course=5, motion=rest_motion(), duration_s=0.05, sample_dt_s=0.005)
    scene = scene_from_dict(data)
    print(f"running-bond wall of {len(scene.blocks)} blocks at rest, {scene.duration_s:g} s")
    seconds, ref = timed(make_solver("reference"), scene)
    print(f"  reference DEM: {seconds:.2f} s ({ref.meta.n_steps} steps of {ref.meta.dt_s:.3g} s)")
    for options in (
        {"dt_s": 1e-3},
        {"dt_s": 5e-4},
        {"dt_s": 1e-3, "solver_tol": 1e-4},
        {"dt_s": 1e-3, "solver_max_iter": 10_000},
        {"dt_s": 1e-3, "newton_max_iter": 3},
    ):
        seconds, result = timed(make_solver("siconos", timeout_s=600.0, **options), scene)
        m = result.meta
        steps = max(int(m.get("n_steps") or 0), 1)
        print(
            f"  siconos {options}: {1e3 * m.get('wall_time_s', seconds) / steps:8.1f} ms/step, "
            f"{m.get('unconverged_steps')} of {m.get('solver_calls')} solves unconverged, "
            f"residual {m.get('max_solver_residual', float('nan')):.2g}, "
            f"mean {m.get('solver_iterations_mean', float('nan')):.0f} iterations, {result.status}"
        )


if __name__ == "__main__":
    single_block_costs()
    wall_costs()
