"""Siconos's cost per run against YADE (warm) and the reference DEM, on the same scenes.

* A 30 s single-block run: specimen 1's geometry (0.25 x 1.0 m) under the shipped EC8
  record scaled to 0.15 g, each solver warm (YADE's worker started and the reference DEM's
  kernel compiled by a first run): wall time per run; Siconos at its default step and halved.
* A dry running-bond wall of 33 blocks, 0.1 s at rest and under a 0.2 g sine pulse of
  0.1 s: Siconos's ms per step and what the time step, the friction solver's tolerance, its
  iteration cap and the Newton iterations buy (retried and unconverged steps, the largest
  residual, the peak drift), beside the reference DEM's.

Run: ``python benchmarks/bench_siconos.py [block] [wall]`` (prints a table; the load
average is printed with it: on a shared machine compare ratios, not seconds).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from rockyade.scene import scene_from_dict
from rockyade.scene.generators import pulse_motion, rest_motion, wall
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


def wall_costs(duration_s: float = 0.1) -> None:
    """The 33-block wall at rest, then under a small pulse at several time steps, friction
    tolerances and iteration caps: ms per step, the retried steps (nonsmooth Newton failed,
    a fallback solver took the step), and the peak drift of any block."""
    rest = scene_from_dict(
        wall(courses=6, units_per_course=5, motion=rest_motion(), duration_s=duration_s, sample_dt_s=0.005)
    )
    pulse = scene_from_dict(
        wall(
            courses=6,
            units_per_course=5,
            motion=pulse_motion(amplitude_g=0.2, period_s=0.1),
            duration_s=duration_s,
            sample_dt_s=0.005,
        )
    )
    print(f"running-bond wall of {len(rest.blocks)} blocks, {duration_s:g} s (load average {os.getloadavg()[0]:.1f})")
    seconds, ref = timed(make_solver("reference"), pulse)
    print(f"  reference DEM, pulse: {seconds:.2f} s ({ref.meta.n_steps} steps), peak drift {drift(ref):.3g} mm")
    for label, scene, options in (
        ("rest", rest, {"dt_s": 1e-3}),
        ("pulse", pulse, {"dt_s": 1e-3}),
        ("pulse", pulse, {"dt_s": 5e-4}),
        ("pulse", pulse, {"dt_s": 1e-3, "solver_tol": 1e-4}),
        ("pulse", pulse, {"dt_s": 1e-3, "solver_tol": 1e-6}),
        ("pulse", pulse, {"dt_s": 1e-3, "solver_max_iter": 100}),
        ("pulse", pulse, {"dt_s": 1e-3, "newton_max_iter": 3}),
    ):
        seconds, result = timed(make_solver("siconos", timeout_s=1200.0, **options), scene)
        m = result.meta
        steps = max(int(m.n_steps or 0), 1)
        print(
            f"  siconos {label} {options}: {1e3 * (m.wall_time_s or seconds) / steps:8.1f} ms/step, "
            f"{m.extra.get('retried_steps')} retried ({m.extra.get('fallback_steps')} by a fallback), "
            f"{m.unconverged_steps} of {m.extra.get('solver_calls')} unconverged, "
            f"residual {m.extra.get('max_solver_residual', float('nan')):.2g}, "
            f"mean {m.extra.get('solver_iterations_mean', float('nan')):.0f} iterations, "
            f"peak drift {drift(result):.4g} mm, {result.status}"
        )


def drift(result) -> float:
    """The largest displacement of any block from its start, mm."""
    frame = result.frame
    if not len(frame):
        return float("nan")
    out = 0.0
    for name in result.meta.blocks:
        for axis in ("x", "y"):
            col = frame[f"{name}_{axis}_m"].to_numpy()
            out = max(out, float(abs(col - col[0]).max()))
    return 1e3 * out


if __name__ == "__main__":
    import sys

    parts = sys.argv[1:] or ["block", "wall"]
    if "block" in parts:
        single_block_costs()
    if "wall" in parts:
        wall_costs()
