"""How long limit analysis takes as a wall grows: the model, the programme (HiGHS), the
mechanism and the code's quantities.

Scenes: running-bond walls of the project's generator (``rockyade build wall``: 0.4 x 0.2 m
units, half units at the ends of every other course) of about 100, 300 and 1,000 blocks,
about three times longer than high. Joints: friction 30 degrees (the generator's), or no
sliding. Each programme is solved ``--repeat`` times and the best time counts (the machine
may be shared); ``--methods`` compares HiGHS's methods (the multipliers must agree).

Run: ``.venv/bin/python benchmarks/bench_limit.py [--sizes 100 300 1000] [--repeat 3]``.
"""

from __future__ import annotations

import argparse
import time

from rockyade.limit.kinematic import kinematic_quantities
from rockyade.limit.lp import solve_equilibrium
from rockyade.limit.mechanism import mechanism_of
from rockyade.limit.rigid_blocks import rigid_block_model
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import wall

#: (courses, units per course) of the walls of about 100, 300 and 1,000 blocks.
SHAPES = {100: (6, 16), 300: (10, 30), 1000: (18, 55)}


def shape_for(n: int) -> tuple[int, int]:
    """Courses and units per course of a running-bond wall of about n blocks."""
    if n in SHAPES:
        return SHAPES[n]
    courses = max(1, round((n / 3.0) ** 0.5))
    return courses, max(1, round(n / courses))


def best_of(repeat: int, func):
    """(best wall time, last value) of ``repeat`` calls."""
    times, value = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        value = func()
        times.append(time.perf_counter() - start)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 300, 1000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--methods", nargs="+", default=["highs"], choices=["highs", "highs-ds", "highs-ipm"])
    args = parser.parse_args()
    print(
        f"{'blocks':>6} {'joints':>7} {'sliding':>8} {'method':>9} {'model s':>8} {'LP s':>7} "
        f"{'mech s':>7} {'kinematic s':>11} {'lambda':>9} {'hinges':>6} {'slides':>6}"
    )
    for n in args.sizes:
        courses, units = shape_for(n)
        scene = scene_from_dict(wall(courses=courses, units_per_course=units))
        for sliding in (True, False):
            t_model, model = best_of(1, lambda sc=scene, s=sliding: rigid_block_model(sc, sliding=s))
            for method in args.methods:
                t_lp, sol = best_of(args.repeat, lambda m=model, k=method: solve_equilibrium(m, "+x", method=k))
                t_mech, mech = best_of(1, lambda m=model, s=sol: mechanism_of(m, s))
                t_kin, _ = best_of(
                    1, lambda m=model, me=mech, s=sol: kinematic_quantities(m, me, s.load_multiplier, "+x")
                )
                print(
                    f"{len(scene.blocks):6d} {len(model.interfaces):7d} {sliding!s:>8} {method:>9} "
                    f"{t_model:8.2f} {t_lp:7.3f} {t_mech:7.3f} {t_kin:11.3f} {sol.load_multiplier:9.5f} "
                    f"{len(mech.hinges):6d} {len(mech.sliding):6d}"
                )


if __name__ == "__main__":
    main()
