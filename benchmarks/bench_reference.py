"""Speed of the reference DEM.

* Single block (specimen 1, paper calibration), 20 s of free rocking at Eq 7's step,
  after JIT warm-up: wall time and ns per block-step (with and without energy terms).
* Batch API: 1,000 variants of specimen 1 under different harmonic base motions (10 s
  each), through the runner (:func:`rockyade.runner.solve_scenes`) on 1 and 2 threads of
  this process: scenes per second.

Run: ``python benchmarks/bench_reference.py [--quick]`` (``--quick``: 2 s of free rocking and
10 variants, once; a test runs it so that it cannot rot).
"""

from __future__ import annotations

import math
import time

import numpy as np
from quick_option import quick_mode  # type: ignore[import-not-found]

from rockyade.calibration.model_stage import calibrated_model
from rockyade.runner import Executor, solve_scenes
from rockyade.scene import scene_from_dict
from rockyade.solvers.reference import ReferenceSolver, run_model
from rockyade.studies.specimen_scenes import block_table

BLOCK = block_table("1")  # specimen 1 with its experimental parameters (Tables 1, 3)


def free_scene(duration: float = 20.0):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.001,
            "blocks": [BLOCK],
            "contact": {"calibration": "paper"},
            "motion": {"type": "free", "theta0_rad": 0.1175},
        }
    )


def harmonic_scene(freq: float, amp_m: float, duration: float = 10.0):
    dt = 0.005
    t = np.arange(0.0, duration + dt / 2, dt)
    w = 2 * math.pi * freq
    ramp = np.clip(t / 1.0, 0.0, 1.0)
    accel = -amp_m * w * w * np.sin(w * t) * ramp
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": 0.005,
            "blocks": [BLOCK],
            "contact": {"calibration": "paper"},
            "motion": {"type": "sampled", "dt_s": dt, "accel_m_s2": accel.tolist()},
        }
    )


def single_block(duration: float = 20.0, repeat: int = 3) -> dict[str, float]:
    model = calibrated_model(free_scene(duration))
    run_model(calibrated_model(free_scene(0.1)))  # JIT warm-up
    out = {}
    for energy in (False, True):
        best = math.inf
        for _ in range(repeat):
            result = run_model(model, record_energy=energy)
            best = min(best, result.meta.wall_time_s)
        out[f"wall_s_energy_{energy}"] = best
        out[f"ns_per_step_energy_{energy}"] = 1e9 * best / model.n_steps
    out["n_steps"] = model.n_steps
    out["dt_s"] = model.dt_s
    return out


def batch(n: int = 1000) -> dict[str, float]:
    rng = np.random.default_rng(7)
    freqs = rng.uniform(1.0, 7.0, n)
    amps = rng.uniform(0.5e-3, 8e-3, n)
    scenes = [harmonic_scene(f, a) for f, a in zip(freqs, amps, strict=True)]
    solver = ReferenceSolver(record_energy=False, record_contacts=False)
    solve_scenes(solver, scenes[:2], executor=Executor("threads", 2))  # warm-up
    out = {}
    for workers in (1, 2):
        start = time.perf_counter()
        results = solve_scenes(solver, scenes, executor=Executor("threads", workers))
        wall = time.perf_counter() - start
        out[f"scenes_per_s_{workers}_workers"] = n / wall
        out[f"wall_s_{workers}_workers"] = wall
        out["failed"] = sum(r.status == "failed" for r in results)
        out["overturned"] = sum(r.status == "overturned" for r in results)
    return out


def main() -> None:
    quick = quick_mode(__doc__)
    duration = 2.0 if quick else 20.0
    s = single_block(duration, 1 if quick else 3)
    print(
        f"reference DEM, single block, {duration:g} s simulated at dt = {s['dt_s']:.3g} s ({s['n_steps']} steps): "
        f"{s['wall_s_energy_False'] * 1e3:.1f} ms ({s['ns_per_step_energy_False']:.0f} ns/step); "
        f"with energy terms {s['wall_s_energy_True'] * 1e3:.1f} ms ({s['ns_per_step_energy_True']:.0f} ns/step)"
    )
    n = 10 if quick else 1000
    b = batch(n)
    print(
        f"reference DEM batch, {n} x 10 s harmonic variants: {b['scenes_per_s_1_workers']:.1f} scenes/s on 1 thread, "
        f"{b['scenes_per_s_2_workers']:.1f} scenes/s on 2 ({b['wall_s_2_workers']:.1f} s; "
        f"{b['overturned']} overturned, {b['failed']} failed)"
    )


if __name__ == "__main__":
    main()
