"""Speed of the exact Housner solver: free rocking and rocking under a base motion.

Run: ``python benchmarks/bench_housner.py [--quick]`` (``--quick``: 2 s simulated, once; a test
runs it so that it cannot rot)."""

from __future__ import annotations

import math
import time

import numpy as np
from quick_option import quick_mode  # type: ignore[import-not-found]

from rockyade.housner import HousnerModel, solve
from rockyade.motion.ground import GroundMotion


def best_of(fn, repeat: int = 5) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    quick = quick_mode(__doc__)
    duration, repeat = (2.0, 1) if quick else (20.0, 5)
    model = HousnerModel.symmetric(0.235, 3.84, 0.936)
    free = best_of(lambda: solve(model, None, duration, 0.1175), repeat)
    t = np.arange(0.0, duration, 0.01)
    rng = np.random.default_rng(1)
    a = 3.0 * np.sin(2 * math.pi * 2.0 * t) * np.exp(-0.1 * t) + 0.5 * rng.standard_normal(t.size)
    forced = best_of(lambda: solve(model, GroundMotion(t, a), duration), repeat=min(repeat, 3))
    traj = solve(model, GroundMotion(t, a), duration)
    print(f"housner free rocking, {duration:g} s simulated (specimen 1, theta0 = alpha/2): {free * 1e3:.1f} ms")
    print(
        f"housner under a {duration:g} s record at dt = 0.01 s: {forced * 1e3:.0f} ms "
        f"({len(traj.impacts)} impacts, status {traj.status})"
    )


if __name__ == "__main__":
    main()
