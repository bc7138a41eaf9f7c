"""Time to generate the paper's 30-record synthetic suite on one core (no cache).

Run: ``python benchmarks/bench_synthetic.py [--quick]`` (``--quick``: 3 records; a test runs it
so that it cannot rot)."""

from __future__ import annotations

import dataclasses
import os
import time

from quick_option import quick_mode  # type: ignore[import-not-found]
from scratch import scratch_folder  # type: ignore[import-not-found]

from rockyade.motion.suite_cache import generate_suite
from rockyade.motion.synthetic import compatibility_report, paper_suite


def main() -> None:
    os.environ["ROCKYADE_CACHE"] = str(scratch_folder("rockyade-bench-"))
    spec = paper_suite()
    if quick_mode(__doc__):
        spec = dataclasses.replace(spec, count=3)
    start = time.perf_counter()
    records = generate_suite(spec)
    wall = time.perf_counter() - start
    report = compatibility_report(records, spec.target)
    iterations = [r.extra["iterations"] for r in records]
    print(
        f"synthetic suite, {spec.count} EC8 Type 2 / D records of 20 s: {wall:.2f} s on one core "
        f"({wall / spec.count * 1e3:.0f} ms per record, {min(iterations)}-{max(iterations)} corrections); "
        f"mean/target {report['ratio_min']:.3f}-{report['ratio_max']:.3f} over 0.05-2 s, "
        f"mean PGA {report['mean_pga_m_s2']:.3f} m/s^2"
    )


if __name__ == "__main__":
    main()
