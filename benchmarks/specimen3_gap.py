"""What moves specimen 3's Housner / reference DEM gap under the EC8 suite (docs/verification.md).

Specimen 3 (matched calibration) over the first records of the EC8 suite (Type 1, ground B,
ag 0.25 g), Housner against the reference DEM by ``rockyade crosscheck``'s study, in variants:

* ``base``: as the paper gives it (alpha 0.154 rad, p 3.61 rad/s, mu 0.978), dt x 1, 0.5, 0.25;
* ``stiff10``: contacts ten times stiffer (K and Ks; beta matched again), dt x 1, 0.5;
* ``p_geom``: the geometry's p (3.82 rad/s) in place of the experimental one, dt x 1, 0.5;
* ``theoretical``: the geometry's alpha, p and mu, dt x 1, 0.5.

Usage (minutes each on a quiet 2-core machine)::

    .venv/bin/python benchmarks/specimen3_gap.py --variants base,stiff10,p_geom,theoretical --count 6

``--quick``: the ``base`` variant at dt x 1 and 0.5 on 2 records, bisection to 10 %, in threads (a
test runs it so that it cannot rot; a pool's start cost more than its runs).
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from rockyade.assess import ec8_suite, parse_measure
from rockyade.calibration.model_stage import calibrated_model
from rockyade.constants import G
from rockyade.runner import Executor
from rockyade.scene import Scene, scene_from_dict
from rockyade.studies.crosscheck import crosscheck_plan, run_crosscheck
from rockyade.studies.specimen_scenes import block_table, scene_dict

#: Specimen 3's contact stiffness in the matched calibration, N/m.
K_N_PER_M = 1658536960.7001035
#: The geometry's p of specimen 3 (rockyade.blocks.classical), rad/s.
P_GEOMETRY_RAD_S = 3.8223


def scene(parameters: str = "experimental", overrides: dict | None = None, **contact: float) -> Scene:
    """Specimen 3 as a scene (its motion replaced by each run)."""
    block = block_table("3", parameters)
    block.update(overrides or {})
    motion = {"type": "synthetic", "suite": "paper", "record": 1}
    return scene_from_dict(scene_dict([block], motion, 25.0, 0.01, "matched", **contact), source="specimen 3")


VARIANTS = {
    "base": lambda: (scene(), (1.0, 0.5, 0.25)),
    "stiff10": lambda: (scene(K_N_per_m=10 * K_N_PER_M, Ks_N_per_m=10 * K_N_PER_M), (1.0, 0.5)),
    "p_geom": lambda: (scene(overrides={"p_rad_s": P_GEOMETRY_RAD_S}), (1.0, 0.5)),
    "theoretical": lambda: (scene("theoretical"), (1.0, 0.5)),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", default=",".join(VARIANTS))
    parser.add_argument("--count", type=int, default=6, help="records of the EC8 suite (default 6)")
    parser.add_argument("--resolution", type=float, default=0.02)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path("runs/specimen3_gap"))
    parser.add_argument("--quick", action="store_true", help="the base variant, a little of it (see above)")
    args = parser.parse_args()
    if args.quick:
        args.variants, args.count, args.resolution = "base", 2, 0.1
    executor = Executor("threads" if args.quick else "local", args.workers)
    for name in args.variants.split(","):
        the_scene, factors = VARIANTS[name]()
        factors = factors[:2] if args.quick else factors
        params = calibrated_model(the_scene).joints.params[0]
        print(f"[{name}] K {params.K_N_per_m:.4g} N/m, beta {params.beta_s:.4g} s", flush=True)
        start = time.perf_counter()
        plan = crosscheck_plan(
            the_scene,
            ec8_suite(1, "B", 0.25 * G, args.count),
            parse_measure("pga"),
            ["housner", "reference"],
            dt_factors=factors,
            resolution=args.resolution,
            executor=executor,
            progress=False,
        )
        print(f"[{name}] {plan.cost_line(args.workers)}", flush=True)
        summary = run_crosscheck(plan, args.out / name, executor, progress=False, say=lambda _s: None)
        print(f"[{name}] {len(summary.runs)} runs in {time.perf_counter() - start:.0f} s", flush=True)
        for _, r in summary.pairs.iterrows():
            print(
                f"[{name}] {r.solver_a} dt x {r.dt_factor_a:g} / {r.solver_b} dt x {r.dt_factor_b:g}: "
                f"{r.median_ratio:.4f} ({r.ratio_low:.4f}-{r.ratio_high:.4f}), {r.records} records",
                flush=True,
            )


if __name__ == "__main__":
    main()
