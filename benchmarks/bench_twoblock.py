"""The exact two-block solver's speed against the reference DEM on the same scenes, and its
independence of the output sampling and its step.

* Speed: the paper's bi-block (Table 2, the geometry's own alpha, p, mu) under the shipped EC8
  record (25 s) at 0.2, 0.3 and 0.45 g, each solver warm (kernels compiled by a first run),
  ``--repeat`` rounds in alternation: runs per second of each and their ratio (measured in one
  process: on a shared machine compare the ratio, not the seconds).
* The outcomes of both on the same runs (status, the block that fell), and the twoblock
  runs' events (impacts, mode changes).
* Sampling: the same runs sampled at 0.01 s and 0.001 s give the same impact times (the
  largest difference, s; event-driven, it must be 0).
* Step: the largest Runge-Kutta step halved (``dt_factor = 0.5``): the largest relative
  change of the impact times, of the peak rotations (as a fraction of each block's alpha),
  and whether the outcome changes.

Run: ``python benchmarks/bench_twoblock.py [--quick] [--repeat=N]`` (``--quick``: 5 s of the
record at one level, one round: a check that it runs, not a measurement).
"""

from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np
from quick_option import quick_parser  # type: ignore[import-not-found]

from rockyade.constants import G
from rockyade.scene import scene_from_dict
from rockyade.solvers import make_solver
from rockyade.studies.specimen_scenes import biblock_blocks

RECORD = Path(__file__).resolve().parents[1] / "examples" / "records" / "ec8_type2_D_record21.AT2"


def biblock(pga_g: float, duration_s: float = 25.0, sample_dt_s: float = 0.01):
    """The paper's bi-block, geometric parameters, under the EC8 record scaled to ``pga_g``."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": sample_dt_s,
            "blocks": biblock_blocks("theoretical"),
            "contact": {"calibration": "paper"},
            "motion": {"type": "record", "file": str(RECORD), "target_pga_m_s2": pga_g * G},
        }
    )


def speed(levels: list[float], duration_s: float, repeat: int) -> dict[str, list[float]]:
    """Wall time of each solver per run, rounds in alternation; prints runs per second."""
    solvers = {"twoblock": make_solver("twoblock"), "reference": make_solver("reference", record_energy=False)}
    for solver in solvers.values():
        solver.run(biblock(levels[0], 0.5))  # compiled, warm
    times: dict[str, list[float]] = {name: [] for name in solvers}
    outcomes: dict[str, list[str]] = {name: [] for name in solvers}
    for r in range(repeat):
        for pga in levels:
            scene = biblock(pga, duration_s)
            for name, solver in solvers.items():
                start = time.perf_counter()
                result = solver.run(scene)
                times[name].append(time.perf_counter() - start)
                if r == 0:
                    fell = f" ({result.meta.overturned_block})" if result.status == "overturned" else ""
                    extra = result.meta.extra.get("event_counts")
                    events = f", {extra['impacts']} impacts, {extra['mode_changes']} mode changes" if extra else ""
                    outcomes[name].append(f"{pga:g} g: {result.status}{fell}{events}")
    load = os.getloadavg()[0]
    print(f"the bi-block under the EC8 record, {duration_s:g} s simulated, {repeat} round(s) (load average {load:.1f})")
    for name in solvers:
        per_run = float(np.median(times[name]))
        print(f"  {name:9s}: {1.0 / per_run:8.2f} runs/s (median {per_run * 1e3:.1f} ms a run)")
        for line in outcomes[name]:
            print(f"      {line}")
    ratio = np.median(np.array(times["reference"]) / np.array(times["twoblock"]))
    print(f"  twoblock runs {ratio:.1f}x as many runs per second as the reference DEM (median of paired runs)")
    return times


def independence(levels: list[float], duration_s: float) -> None:
    """Impact times against the sampling interval and the step (module docstring)."""
    exact, half = make_solver("twoblock"), make_solver("twoblock", dt_factor=0.5)
    print("dt-independence (impact times, s; peaks, rad)")
    for pga in levels:
        coarse = exact.run(biblock(pga, duration_s, 0.01))
        fine = exact.run(biblock(pga, duration_s, 0.001))
        halved = half.run(biblock(pga, duration_s, 0.01))
        a, b, c = (np.array(r.meta.extra["impacts"]).reshape(-1, 8)[:, 0] for r in (coarse, fine, halved))
        same = a.size == b.size
        sampling = float(np.max(np.abs(a - b), initial=0.0)) if same else math.inf
        n = min(a.size, c.size)
        step = float(np.max(np.abs(c[:n] / a[:n] - 1.0), initial=0.0))
        peaks = _peak_change(coarse, halved)
        print(
            f"  {pga:g} g: sampling 0.01 vs 0.001 s: {a.size} and {b.size} impacts (the first 200 kept), largest "
            f"difference {sampling:.3g} s; step halved: impact times within {step:.2g} (relative), peaks within "
            f"{peaks:.2g} of alpha, outcome {coarse.status} -> {halved.status}"
        )


def _peak_change(a, b) -> float:
    """The largest change of a recorded peak rotation between two runs, per block as a
    fraction of its alpha (the first 200 peaks, matched in order)."""
    worst = 0.0
    for i, name in enumerate(a.meta.blocks):
        alpha = a.meta.classical[name]["alpha_rad"]
        pa, pb = (np.array(r.meta.extra["peaks"]).reshape(-1, 3) for r in (a, b))
        pa, pb = pa[pa[:, 1] == i, 2], pb[pb[:, 1] == i, 2]
        m = min(pa.size, pb.size)
        worst = max(worst, float(np.max(np.abs(pa[:m] - pb[:m]), initial=0.0)) / alpha)
    return worst


def main() -> None:
    parser = quick_parser(__doc__)
    parser.add_argument("--repeat", type=int, default=3, help="repetitions of each timing (best of)")
    args = parser.parse_args()
    quick, repeat = args.quick, args.repeat
    levels = [0.3] if quick else [0.2, 0.3, 0.45]
    duration = 5.0 if quick else 25.0
    speed(levels, duration, 1 if quick else repeat)
    independence(levels, duration)


if __name__ == "__main__":
    main()
