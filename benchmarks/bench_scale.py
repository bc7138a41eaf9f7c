"""How the reference DEM's cost grows with the number of blocks.

Scenes (one function builds each, for any n, so that another solver can be timed on the
same scenes: ``scene_for(n, motion)``):

* n = 1: one 0.4 x 0.2 m brick on the base;
* n > 1: a dry running-bond wall of about n bricks (0.4 x 0.2 x 0.2 m, half bricks at the
  ends of every other course), about sixteen times longer than high.

Motions: ``rest`` (gravity alone: the wall stands, the candidate list is built once) and a
one-sine ``pulse`` of 0.8 g, 0.3 s (above the friction coefficient tan 30 deg: the courses
slide, and the list is rebuilt as they move).

Each case is built (the build time includes the statics), run once to warm up, then run
``--repeat`` times; the best run gives the kernel's wall time per step and per block (ns
per block-step, without energy terms, as a batch runs). The peak memory of a run is
measured by ``tracemalloc`` (numpy's arrays, those the numba kernel allocates included, and
the Result frame). The ratio is against the single brick under the same motion. The machine
is shared: the best of several runs is the figure to read.

Run: ``.venv/bin/python benchmarks/bench_scale.py [--sizes 1 10 100 1000] [--duration 0.2] [--quick]``
(``--quick``: 1 and 10 blocks, 0.02 s, once; a test runs it so that it cannot rot).
"""

from __future__ import annotations

import argparse
import math
import time
import tracemalloc
from typing import Any

from rockyade.calibration.model_stage import calibrated_model
from rockyade.scene import Scene, scene_from_dict
from rockyade.solvers.reference import run_model

BRICK = {"width_m": 0.4, "height_m": 0.2, "thickness_m": 0.2, "density_kg_m3": 2000.0}
MOTIONS: dict[str, dict[str, Any]] = {
    "rest": {"type": "rest"},
    "pulse": {"type": "pulse", "shape": "sine", "amplitude_g": 0.8, "period_s": 0.3},
}


def wall_blocks(n: int) -> list[dict[str, Any]]:
    """A running-bond wall of about n bricks (exactly n for n = 1), about sixteen times longer than high."""
    w, h = BRICK["width_m"], BRICK["height_m"]
    if n == 1:
        return [{"name": "b0", **BRICK, "position_m": [0.0, 0.0]}]
    courses = max(1, round(math.sqrt(n / 8.0)))
    units = max(1, round(n / courses))
    blocks: list[dict[str, Any]] = []
    for c in range(courses):
        y = c * h
        if c % 2 == 0:
            xs = [(i + 0.5) * w for i in range(units)]
            widths = [w] * units
        else:
            xs = [0.25 * w] + [(i + 1.0) * w for i in range(units - 1)] + [(units - 0.25) * w]
            widths = [0.5 * w] + [w] * (units - 1) + [0.5 * w]
        for k, (x, width) in enumerate(zip(xs, widths, strict=True)):
            blocks.append({"name": f"c{c}_{k}", **BRICK, "width_m": width, "position_m": [x, y]})
    return blocks


def scene_for(n: int, motion: str = "rest", duration_s: float = 0.2) -> Scene:
    """The benchmark scene of about n blocks under ``motion`` ("rest" or "pulse")."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": 0.002,
            "blocks": wall_blocks(n),
            "contact": {"calibration": "paper"},
            "motion": MOTIONS[motion],
        }
    )


def measure(scene: Scene, repeat: int = 3) -> dict[str, float]:
    """Build and run one scene with the reference DEM: the best of ``repeat`` timed runs."""
    start = time.perf_counter()
    model = calibrated_model(scene)
    build_s = time.perf_counter() - start
    run_model(model, record_energy=False, per_corner=False)  # warm-up (and numba's cache)
    walls = []
    peak = 0
    for _ in range(repeat):
        tracemalloc.start()
        result = run_model(model, record_energy=False, per_corner=False)
        peak = max(peak, tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
        walls.append(result.meta.wall_time_s)
    nb = len(model.bodies)
    wall = min(walls)
    phase = result.meta.extra["broad_phase"]
    return {
        "blocks": nb,
        "status": result.status,
        "dt_s": model.dt_s,
        "steps": model.n_steps,
        "ns_per_step": 1e9 * wall / model.n_steps,
        "ns_per_block_step": 1e9 * wall / model.n_steps / nb,
        "max_pairs": phase["max_candidate_pairs"],
        "rebuilds": phase["rebuilds"],
        "tests_per_pair_step": phase["separating_axis_tests"] / max(1, phase["max_candidate_pairs"] * model.n_steps),
        "build_s": build_s,
        "peak_memory_MB": peak / 1e6,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1, 10, 100, 1000])
    parser.add_argument("--duration", type=float, default=0.2, help="simulated time per case, s")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per case (the best counts)")
    parser.add_argument("--quick", action="store_true", help="1 and 10 blocks, 0.02 s, once")
    args = parser.parse_args()
    if args.quick:
        args.sizes, args.duration, args.repeat = [1, 10], 0.02, 1
    print(
        f"{'motion':6} {'blocks':>6} {'ns/step':>10} {'ns/block-step':>14} {'ratio':>6} {'pairs':>6} "
        f"{'rebuilds':>8} {'SAT/pair-step':>13} {'build s':>8} {'peak MB':>8}  status"
    )
    for motion in MOTIONS:
        single = None
        for n in args.sizes:
            m = measure(scene_for(n, motion, args.duration), args.repeat)
            single = single or m["ns_per_block_step"]
            print(
                f"{motion:6} {m['blocks']:6d} {m['ns_per_step']:10.0f} {m['ns_per_block_step']:14.1f} "
                f"{m['ns_per_block_step'] / single:6.2f} {m['max_pairs']:6d} {m['rebuilds']:8d} "
                f"{m['tests_per_pair_step']:13.3f} {m['build_s']:8.2f} {m['peak_memory_MB']:8.1f}  {m['status']}"
            )


if __name__ == "__main__":
    main()
