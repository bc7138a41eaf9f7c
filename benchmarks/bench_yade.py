"""YADE against the reference DEM on the same scene, in one process.

* Specimen 1, 20 s of free rocking at Eq 7's step: YADE's own run time (O.run) per
  simulated second, its start-up cost (process, imports, scene building), and the
  reference DEM's kernel time on the same model: the ratio per simulated second.
* Runs per minute with two parallel YADE workers (8 runs of 5 s simulated).
"""

from __future__ import annotations

import time

from rockyade.dem.matching import build_matched_model
from rockyade.scene import scene_from_dict
from rockyade.solvers import yade as yade_backend
from rockyade.solvers.reference import run_model
from rockyade.studies.common import block_table

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


def main() -> None:
    if not yade_backend.yade_available():
        print("YADE is not installed: no YADE figures")
        return
    model = build_matched_model(scene(20.0))
    run_model(build_matched_model(scene(0.1)), record_energy=False)  # JIT warm-up
    ref = min(run_model(model, record_energy=False).meta["wall_time_s"] for _ in range(3))
    y = yade_backend.run_model(model)
    assert y.ok, y.meta.get("failure_reason")
    yade_run, startup = y.meta["wall_time_s"], y.meta["startup_time_s"]
    print(
        f"specimen 1, 20 s simulated, dt = {model.dt_s:.3g} s ({model.n_steps} steps): YADE {yade_run:.2f} s "
        f"({yade_run / 20 * 1e3:.0f} ms per simulated s, {1e6 * yade_run / model.n_steps:.1f} us/step) + "
        f"{startup:.2f} s start-up; reference DEM {ref * 1e3:.1f} ms ({ref / 20 * 1e3:.2f} ms per simulated s)"
    )
    print(
        f"reference DEM / YADE per simulated second: {yade_run / ref:.0f}x faster "
        f"({(yade_run + startup) / ref:.0f}x counting YADE's start-up)"
    )
    scenes = [scene(5.0, 0.05 + 0.01 * k) for k in range(8)]
    for workers in (1, 2):
        start = time.perf_counter()
        results = yade_backend.run_many(scenes, workers=workers)
        wall = time.perf_counter() - start
        ok = sum(r.ok for r in results)
        rate = 60 * len(scenes) / wall
        print(f"YADE, 8 runs of 5 s simulated on {workers} worker(s): {wall:.1f} s, {rate:.0f} runs/min ({ok} ok)")


if __name__ == "__main__":
    main()
