"""Siconos beside warm YADE on the masonry of issue 35, and what halving its step and its
tolerance changes.

Parts (each prints a table; the load average is printed with it: on a shared machine compare
the ratios measured in the same run, not seconds):

* ``wall``: the 32-block running-bond wall (``rockyade build wall --courses 5
  --units-per-course 6``) under a 0.3 g one-sine pulse of 0.5 s, 0.4 s simulated: YADE (warm),
  the reference DEM and Siconos at their default steps, Siconos's ratio to YADE, its ms a
  step and the minutes a 25 s record would take at that cost; ``--record`` runs the 25 s
  record itself (the shipped 20 s EC8 record at 0.3 g, then 5 s of free motion).
* ``arch``: the 20-voussoir semicircular arch on fixed piers (mean radius 1 m), 1 s at rest:
  t/R 0.15 stands, t/R 0.08 collapses (status ``overturned``), each beside YADE.
* ``biblock``: the paper's bi-block (``examples/biblock_free.toml``'s blocks) under the
  shipped EC8 record at 0.3 g, 25 s simulated, beside YADE.
* ``block``: specimen 1's geometry, 30 s under the EC8 record at 0.15 g and 0.3 g (rounds in
  alternation, median ratio to YADE).
* ``costs``: each of these scenes' measured time against ``estimate_cost``, Siconos's and
  YADE's (YADE's ratio says how loaded the machine is).
* ``convergence``: Siconos at its default step and tolerance, at half the step and at half the
  tolerance: the wall's top-course peak displacement under a 0.8 g pulse (it slides), the t/R
  0.08 arch's collapse time (sampled every 2 ms), and the t/R 0.15 arch's collapse intensity
  under the 0.5 s pulse (the smallest amplitude that collapses it, by bisection to 0.25 %).

``--quick`` runs every part on small scenes and short durations (the single block at 0.3 g only,
its solvers not warmed up first; a test runs it in seconds);
its numbers check the script, not the targets.

Run: ``python benchmarks/bench_siconos.py [wall] [arch] [biblock] [block] [costs]
[convergence] [--record] [--quick] [--repeat=N]`` (no part: wall, arch, biblock, convergence).
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import pulse_motion, rest_motion, wall
from rockyade.scene.generators.arches import arch
from rockyade.solvers import make_solver

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "examples" / "records" / "ec8_type2_D_record21.AT2"
#: A record's length for the per-record cost, s.
RECORD_S = 25.0
#: The collapse-intensity bisection stops at this relative bracket.
BISECTION_RTOL = 0.0025


@dataclass(frozen=True)
class Size:
    """The scenes' sizes: the issue's (full) or small ones (quick)."""

    courses: int
    units: int
    voussoirs: int
    wall_s: float
    arch_s: float
    record_s: float
    block_s: float
    pulse_s: float


FULL = Size(courses=5, units=6, voussoirs=20, wall_s=0.4, arch_s=1.0, record_s=RECORD_S, block_s=30.0, pulse_s=1.5)
#: Every part and every line, on scenes and runs as short as keep them running (the numbers mean
#: nothing): a run this short costs about the same whatever its length, so fewer runs too
#: (:func:`block_costs`: one intensity, no warm-up runs).
QUICK = Size(courses=2, units=2, voussoirs=6, wall_s=0.02, arch_s=0.05, record_s=0.1, block_s=0.1, pulse_s=0.05)


def wall_scene(size: Size, amplitude_g: float = 0.3, duration_s: float | None = None) -> Any:
    """The running-bond wall under a one-sine pulse of 0.5 s."""
    return scene_from_dict(
        wall(
            courses=size.courses,
            units_per_course=size.units,
            motion=pulse_motion(amplitude_g=amplitude_g, period_s=0.5),
            duration_s=size.wall_s if duration_s is None else duration_s,
            sample_dt_s=0.005,
        )
    )


def wall_record_scene(size: Size) -> Any:
    """The wall under the shipped EC8 record at 0.3 g, ``size.record_s`` simulated."""
    data = wall(courses=size.courses, units_per_course=size.units, motion=rest_motion(), duration_s=size.record_s)
    data["motion"] = {"type": "record", "file": str(RECORD), "target_pga_m_s2": 0.3 * 9.81}
    data["sample_dt_s"] = 0.01
    return scene_from_dict(data)


def arch_scene(
    size: Size, t_over_r: float, motion: dict | None = None, duration_s: float | None = None, sample_dt_s: float = 0.01
) -> Any:
    """The semicircular arch of mean radius 1 m on fixed piers 0.5 m high."""
    return scene_from_dict(
        arch(
            span_m=2.0 * (1.0 - t_over_r / 2.0),
            ring_depth_m=t_over_r,
            voussoirs=size.voussoirs,
            pier_width_m=2.0 * t_over_r,
            pier_height_m=0.5,
            piers="fixed",
            motion=motion or rest_motion(),
            duration_s=size.arch_s if duration_s is None else duration_s,
            sample_dt_s=sample_dt_s,
        )
    )


def biblock_scene(size: Size) -> Any:
    """The paper's bi-block (its blocks as examples/biblock_free.toml) under the EC8 record at 0.3 g."""
    data = load_scene(ROOT / "examples" / "biblock_free.toml").to_dict()
    data.update(
        duration_s=size.record_s,
        sample_dt_s=0.01,
        motion={"type": "record", "file": str(RECORD), "target_pga_m_s2": 0.3 * 9.81},
    )
    return scene_from_dict(data)


def block_scene(duration_s: float, pga_g: float) -> Any:
    """Specimen 1's geometry under the record at ``pga_g``."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": 0.01,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503.0}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "record", "file": str(RECORD), "target_pga_m_s2": pga_g * 9.81},
        }
    )


def timed(solver: Any, scene: Any) -> tuple[float, Any]:
    start = time.perf_counter()
    result = solver.run(scene)
    return time.perf_counter() - start, result


def load() -> str:
    return f"load average {os.getloadavg()[0]:.1f}"


def top_course_peak(result: Any, scene: Any) -> float:
    """The largest horizontal displacement of the top course's blocks from their start, m."""
    frame = result.frame
    if not len(frame):
        return math.nan
    last = max(b.name[:3] for b in scene.blocks)
    names = [b.name for b in scene.blocks if b.name.startswith(last)]
    return max(float(np.max(np.abs(frame[f"{n}_x_m"] - frame[f"{n}_x_m"].iloc[0]))) for n in names)


def largest_rotation(result: Any) -> float:
    """The largest |theta| of any block, rad (a single block's column has no prefix)."""
    frame = result.frame
    if not len(frame):
        return math.nan
    columns = [c for c in frame.columns if c == "theta_rad" or c.endswith("_theta_rad")]
    return max(float(np.max(np.abs(frame[c]))) for c in columns)


def describe(label: str, seconds: float, result: Any, yade_s: float | None = None) -> str:
    m = result.meta
    steps = max(int(m.n_steps or 0), 1)
    dt = m.dt_s or math.nan
    text = f"  {label:30s} {seconds:8.2f} s"
    if yade_s:
        text += f" ({seconds / yade_s:5.2f} x YADE)"
    text += f"  dt {dt:.3g} s, {1e3 * seconds / steps:7.2f} ms/step, {result.status}"
    if m.solver == "siconos":
        per_record = seconds / steps * (RECORD_S / dt) / 60.0
        text += (
            f"; {per_record:.1f} min per {RECORD_S:g} s record at this cost; mean "
            f"{m.extra.get('solver_iterations_mean', math.nan):.1f} iterations, "
            f"{m.unconverged_steps} unconverged, residual {m.extra.get('max_solver_residual', math.nan):.2g}"
        )
    if m.overturn_time_s is not None:
        text += f"; {m.overturned_block} at {m.overturn_time_s:.3f} s"
    if m.failure_reason:
        text += f"; {m.failure_reason}"
    return text


@functools.cache
def warm_yade(size: Size) -> Any:
    """YADE with its worker started (a first short run), once for every part of a run."""
    yade = make_solver("yade")
    yade.run(wall_scene(size, duration_s=0.01))
    return yade


def wall_costs(size: Size, record: bool) -> None:
    """The wall under the 0.3 g pulse: YADE, the reference DEM and Siconos, in one run."""
    scene = wall_scene(size)
    print(f"wall of {len(scene.blocks)} blocks, 0.3 g sine pulse of 0.5 s, {scene.duration_s:g} s ({load()})")
    yade = warm_yade(size)
    yade_s, result = timed(yade, scene)
    print(describe("YADE (warm)", yade_s, result))
    seconds, result = timed(make_solver("reference"), scene)
    print(describe("reference DEM", seconds, result))
    seconds, result = timed(make_solver("siconos", timeout_s=3600.0), scene)
    print(describe("Siconos", seconds, result, yade_s) + f"; top course {1e3 * top_course_peak(result, scene):.3g} mm")
    if record:
        scene = wall_record_scene(size)
        seconds, result = timed(make_solver("siconos", timeout_s=3600.0), scene)
        print(describe(f"Siconos, {scene.duration_s:g} s record", seconds, result) + f" ({seconds / 60:.1f} min)")


#: YADE's joint stiffness for the t/R 0.08 arch, Pa/m: the generator's 1e10 lets its thin
#: piers' joints settle more than the DEMs' check allows (it asks for 1.04e10); Siconos has none.
THIN_ARCH_JKN_PA_PER_M = 2e10


def arch_costs(size: Size) -> None:
    """The arch at rest at t/R 0.15 (stands) and 0.08 (collapses), YADE and Siconos."""
    print(f"arch of {size.voussoirs} voussoirs on fixed piers, {size.arch_s:g} s at rest ({load()})")
    yade = warm_yade(size)
    for t_over_r in (0.15, 0.08):
        scene = arch_scene(size, t_over_r)
        if t_over_r < 0.1:
            data = scene.to_dict()
            data["contact"]["jkn_Pa_per_m"] = THIN_ARCH_JKN_PA_PER_M
            scene = scene_from_dict(data)
        yade_s, result = timed(yade, scene)
        print(describe(f"t/R {t_over_r:g}: YADE (warm)", yade_s, result))
        seconds, result = timed(make_solver("siconos", timeout_s=3600.0), scene)
        print(describe(f"t/R {t_over_r:g}: Siconos", seconds, result, yade_s))


def biblock_costs(size: Size) -> None:
    """The bi-block under the record: YADE and Siconos."""
    scene = biblock_scene(size)
    print(f"bi-block under the EC8 record at 0.3 g, {scene.duration_s:g} s ({load()})")
    yade = warm_yade(size)
    yade_s, result = timed(yade, scene)
    print(describe("YADE (warm)", yade_s, result) + f"; largest rotation {largest_rotation(result):.4g} rad")
    for options in ({}, {"dt_factor": 0.5}):
        seconds, result = timed(make_solver("siconos", timeout_s=3600.0, **options), scene)
        label = "Siconos" + (", dt / 2" if options else "")
        print(describe(label, seconds, result, yade_s) + f"; largest rotation {largest_rotation(result):.4g} rad")


def block_costs(size: Size, repeat: int) -> None:
    """The single block, ``repeat`` rounds in alternation: median time and median ratio to YADE
    (quick: at 0.3 g only, its solvers not warmed up first)."""
    rows = [
        ("YADE (warm)", make_solver("yade")),
        ("reference DEM", make_solver("reference")),
        ("Siconos", make_solver("siconos")),
        ("Siconos, dt / 2", make_solver("siconos", dt_factor=0.5)),
    ]
    for _, solver in rows[:3] if size is not QUICK else ():
        solver.run(block_scene(0.2, 0.15))  # warm: worker started, kernel compiled
    for pga_g in (0.15, 0.3) if size is not QUICK else (0.3,):
        scene = block_scene(size.block_s, pga_g)
        print(f"single block, {scene.duration_s:g} s at {pga_g:g} g, {repeat} rounds ({load()})")
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
            print(
                describe(label, statistics.median(seconds[label]), result)
                + f"; median {statistics.median(ratios[label]):.2f} x YADE (rounds {min(ratios[label]):.2f}-"
                f"{max(ratios[label]):.2f}); peak {largest_rotation(result):.5f} rad"
            )


def estimate_costs(size: Size) -> None:
    """Each scene's measured time against ``estimate_cost``, Siconos's and YADE's (YADE's
    measured-to-estimate factor says how loaded the machine is)."""
    scenes = {
        f"single block, record at 0.3 g, {size.block_s:g} s": block_scene(size.block_s, 0.3),
        f"bi-block, record at 0.3 g, {size.record_s:g} s": biblock_scene(size),
        f"arch t/R 0.15 at rest, {size.arch_s:g} s": arch_scene(size, 0.15),
        f"arch t/R 0.15, 0.2 g pulse, {size.pulse_s:g} s": arch_scene(
            size, 0.15, pulse_motion(amplitude_g=0.2, period_s=0.5), size.pulse_s
        ),
        f"wall, 0.3 g pulse, {size.wall_s:g} s": wall_scene(size),
        f"wall, 0.8 g pulse, {2.5 * size.wall_s:g} s": wall_scene(size, 0.8, 2.5 * size.wall_s),
    }
    print(f"measured against estimate_cost ({load()})")
    yade = warm_yade(size)
    siconos = make_solver("siconos", timeout_s=3600.0)
    for label, scene in scenes.items():
        yade_s, _ = timed(yade, scene)
        seconds, result = timed(siconos, scene)
        estimate = siconos.estimate_cost(scene).wall_time_s
        yade_estimate = yade.estimate_cost(scene).wall_time_s
        print(
            f"  {label:36s} Siconos {seconds:7.2f} s, estimate {estimate:7.3g} s ({seconds / estimate:4.1f}x); "
            f"YADE {yade_s:7.2f} s, estimate {yade_estimate:7.3g} s ({yade_s / yade_estimate:4.1f}x); {result.status}"
        )


def collapses(solver: Any, size: Size, amplitude_g: float) -> bool:
    result = solver.run(arch_scene(size, 0.15, pulse_motion(amplitude_g=amplitude_g, period_s=0.5), size.pulse_s))
    if result.status == "failed":
        raise RuntimeError(f"Siconos failed at {amplitude_g:g} g: {result.meta.failure_reason}")
    return result.status == "overturned"


def collapse_intensity(solver: Any, size: Size, low: float = 0.05, high: float = 0.5) -> tuple[float, int]:
    """The smallest amplitude of the 0.5 s pulse that collapses the t/R 0.15 arch, g (the
    bracket's middle), by bisection; and the runs it took (NaN when [low, high] does not
    bracket it: the quick mode's short runs)."""
    runs = 2
    if collapses(solver, size, low) or not collapses(solver, size, high):
        return math.nan, runs
    while high - low > BISECTION_RTOL * high:
        mid = 0.5 * (low + high)
        runs += 1
        if collapses(solver, size, mid):
            high = mid
        else:
            low = mid
    return 0.5 * (low + high), runs


def change(a: float, b: float) -> str:
    return f"{100.0 * (b - a) / a:+.2f} %" if a and math.isfinite(a) and math.isfinite(b) else "n/a"


def convergence(size: Size) -> None:
    """Siconos at its default step and tolerance, at half each: the answers and their change."""
    base = make_solver("siconos", timeout_s=3600.0)
    tol = base.DEFAULT_TOL[base.integrator]
    variants = [
        ("default", {}),
        ("dt / 2", {"dt_factor": 0.5}),
        ("tolerance / 2", {"solver_tol": tol / 2}),
    ]
    print(f"convergence of the step and the tolerance (default tolerance {tol:g}; {load()})")
    rows: dict[str, list[float]] = {}
    for label, options in variants:
        solver = make_solver("siconos", timeout_s=3600.0, **options)
        start = time.perf_counter()
        scene = wall_scene(size, amplitude_g=0.8, duration_s=2.5 * size.wall_s)
        wall_result = solver.run(scene)
        peak = top_course_peak(wall_result, scene)
        fall = solver.run(arch_scene(size, 0.08, sample_dt_s=0.002))  # the collapse time to 2 ms
        fall_s = fall.meta.overturn_time_s if fall.status == "overturned" else math.nan
        intensity, runs = collapse_intensity(solver, size)
        rows[label] = [peak, fall_s, intensity]
        print(
            f"  {label:14s} wall top course {1e3 * peak:.4g} mm "
            f"(dt {wall_result.meta.dt_s:.3g} s, {wall_result.status}); "
            f"t/R 0.08 arch falls at {fall_s:.4g} s ({fall.meta.overturned_block}); t/R 0.15 arch collapses from "
            f"{intensity:.4g} g ({runs} runs); {time.perf_counter() - start:.0f} s"
        )
    ref = rows["default"]
    for label in ("dt / 2", "tolerance / 2"):
        row = rows[label]
        print(
            f"  {label} against the default: wall peak {change(ref[0], row[0])}, arch collapse time "
            f"{change(ref[1], row[1])}, collapse intensity {change(ref[2], row[2])}"
        )


PARTS = ("wall", "arch", "biblock", "block", "costs", "convergence")


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(
        description="Siconos beside warm YADE on the wall, the arches and the bi-block; the step's and the "
        "tolerance's convergence; a single block; the cost estimates (docs/siconos.md)."
    )
    parser.add_argument(
        "parts",
        nargs="*",
        metavar="PART",
        help=f"what to run, of {', '.join(PARTS)} (default: wall arch biblock convergence)",
    )
    parser.add_argument("--quick", action="store_true", help="small scenes and short runs (the test's mode)")
    parser.add_argument("--record", action="store_true", help="the wall under a 25 s record as well")
    parser.add_argument("--repeat", type=int, default=None, help="repetitions of the single block (1 quick, 3 full)")
    args = parser.parse_args(argv)
    unknown = sorted(set(args.parts) - set(PARTS))
    if unknown:
        parser.error(f"unknown part(s) {', '.join(unknown)}: choose from {', '.join(PARTS)}")
    parts = args.parts or ["wall", "arch", "biblock", "convergence"]
    size = QUICK if args.quick else FULL
    repeat = args.repeat if args.repeat is not None else (1 if size is QUICK else 3)
    if "wall" in parts:
        wall_costs(size, args.record)
    if "arch" in parts:
        arch_costs(size)
    if "biblock" in parts:
        biblock_costs(size)
    if "block" in parts:
        block_costs(size, repeat)
    if "costs" in parts:
        estimate_costs(size)
    if "convergence" in parts:
        convergence(size)


if __name__ == "__main__":
    main(sys.argv[1:])
