"""Siconos's cost per run against YADE (warm) and the reference DEM, on the same scenes.

* A 30 s single-block run: specimen 1's geometry (0.25 x 1.0 m) under the shipped EC8
  record scaled to 0.15 g (no uplift) and 0.3 g (rocking), each solver warm (YADE's worker
  started and the reference DEM's kernel compiled by a first run): wall time per run, rounds
  in alternation; Siconos at its default step and halved.
* A dry running-bond wall of 33 blocks, 0.1 s at rest and under a 0.2 g sine pulse of
  0.1 s: Siconos's ms per step and what the time step, the friction solver's tolerance, its
  iteration cap and the Newton iterations buy (retried and unconverged steps, the largest
  residual, the peak drift), beside the reference DEM's.

Run: ``python benchmarks/bench_siconos.py [block] [wall] [--repeat=N]`` (prints a table; the load
average is printed with it: on a shared machine compare ratios, not seconds).
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

from rockyade.scene import scene_from_dict
from rockyade.scene.generators import pulse_motion, rest_motion, wall
from rockyade.solvers import make_solver

RECORD = Path(__file__).resolve().parents[1] / "examples" / "records" / "ec8_type2_D_record21.AT2"


def single_block(duration_s: float = 30.0, pga_g: float = 0.15):
    """Specimen 1's geometry under the record at ``pga_g`` (0.15 g: no uplift; 0.3 g: it rocks,
    it does not overturn)."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": 0.01,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503.0}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "record", "file": str(RECORD), "target_pga_m_s2": pga_g * 9.81},
        }
    )


def timed(solver, scene):
    start = time.perf_counter()
    result = solver.run(scene)
    return time.perf_counter() - start, result


def single_block_costs(repeat: int = 3) -> None:
    """Each solver's wall time on the 30 s single-block run, ``repeat`` rounds in alternation
    (one run of each solver per round): the median time and the median of the per-round
    ratios to YADE, which a machine's load shifts less than the seconds."""
    rows = [
        ("yade (warm)", make_solver("yade")),
        ("reference", make_solver("reference")),
        ("siconos (warm, default dt)", make_solver("siconos")),
        ("siconos (warm, dt / 2)", make_solver("siconos", dt_factor=0.5)),
    ]
    for _, solver in rows[:3]:
        solver.run(single_block(1.0))  # warm: worker started, kernel compiled
    for pga_g in (0.15, 0.3):
        scene = single_block(pga_g=pga_g)
        load = os.getloadavg()[0]
        print(
            f"single block, {scene.duration_s:g} s simulated at {pga_g:g} g, {repeat} rounds (load average {load:.1f})"
        )
        seconds: dict[str, list[float]] = {label: [] for label, _ in rows}
        ratios: dict[str, list[float]] = {label: [] for label, _ in rows}
        last = {}
        for _ in range(repeat):
            yade_s = None
            for label, solver in rows:
                elapsed, last[label] = timed(solver, scene)
                yade_s = elapsed if yade_s is None else yade_s
                seconds[label].append(elapsed)
                ratios[label].append(elapsed / yade_s)
        for label, _ in rows:
            result = last[label]
            steps = result.meta.n_steps or 0
            median_s = statistics.median(seconds[label])
            peak = float(abs(result.frame["theta_rad"]).max()) if len(result.frame) else float("nan")
            print(
                f"  {label:28s} {median_s:7.2f} s  ({statistics.median(ratios[label]):4.2f} x YADE, rounds"
                f" {min(ratios[label]):.2f}-{max(ratios[label]):.2f})  dt {result.meta.dt_s or float('nan'):.3g} s"
                f"  {1e6 * median_s / max(steps, 1):7.1f} us/step  peak {peak:.5f} rad  {result.status}"
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

    parts = [a for a in sys.argv[1:] if not a.startswith("--repeat=")] or ["block", "wall"]
    rounds = [int(a.split("=", 1)[1]) for a in sys.argv[1:] if a.startswith("--repeat=")]
    if "block" in parts:
        single_block_costs(rounds[-1] if rounds else 3)
    if "wall" in parts:
        wall_costs()
