"""How long limit analysis takes as a wall grows: the model, the programme (HiGHS), the
mechanism and the code's quantities, against the estimate ``rockyade limit`` prints.

Scenes: running-bond walls of the project's generator (``rockyade build wall``: 0.4 x 0.2 m
units, half units at the ends of every other course) of about 100, 300 and 1,000 blocks
(``--sizes``; 3,000 and 10,000 run too, in minutes), about three times longer than high, or as
``SHAPES`` gives. Joints: friction 30 degrees (the generator's), or no sliding. Each programme is
solved ``--repeat`` times and the best time counts (the machine may be shared); ``--methods``
compares HiGHS's methods (the multipliers must agree). Times are CPU seconds of this process and
its children (a programme from ``lp.CHILD_COLUMNS`` columns runs in a child process), the
estimate is :func:`rockyade.limit.analysis_cost.estimate_limit_cost`'s.

Run: ``.venv/bin/python benchmarks/bench_limit.py [--sizes 100 300 1000] [--repeat 3]``;
``--quick``: the 100-block wall once, the default method and HiPO (a test runs it so that it cannot rot).
"""

from __future__ import annotations

import argparse
import os
import resource
import time

from rockyade.limit.analysis_cost import estimate_limit_cost
from rockyade.limit.kinematic import kinematic_quantities
from rockyade.limit.lp import METHODS, solve_equilibrium
from rockyade.limit.mechanism import mechanism_of
from rockyade.limit.rigid_blocks import rigid_block_model
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import wall
from rockyade.scene.generators.scene_tables import udec_contact
from rockyade.scene.generators.walls import WALL

#: (courses, units per course) of the walls of about 100, 300, 1,000, 3,000 and 10,000 blocks (the
#: last two as issue 34 measured them: 50 x 60 and 100 x 100).
SHAPES = {100: (6, 16), 300: (10, 30), 1000: (18, 55), 3000: (50, 60), 10000: (100, 100)}


def shape_for(n: int) -> tuple[int, int]:
    """Courses and units per course of a running-bond wall of about n blocks."""
    if n in SHAPES:
        return SHAPES[n]
    courses = max(1, round((n / 3.0) ** 0.5))
    return courses, max(1, round(n / courses))


def cpu_s() -> float:
    """CPU seconds of this process and its children so far."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def best_of(repeat: int, func):
    """(best CPU time, last value) of ``repeat`` calls."""
    times, value = [], None
    for _ in range(repeat):
        start = cpu_s()
        value = func()
        times.append(cpu_s() - start)
    return min(times), value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100, 300, 1000])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--methods", nargs="+", default=["highs"], choices=list(METHODS))
    parser.add_argument("--quick", action="store_true", help="the 100-block wall once, highs and highs-hipo")
    args = parser.parse_args()
    if args.quick:
        args.sizes, args.repeat, args.methods = [100], 1, ["highs", "highs-hipo"]
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; CPU seconds", flush=True)
    print(
        f"{'blocks':>6} {'joints':>7} {'sliding':>8} {'method':>10} {'model s':>8} {'LP s':>7} {'estimate s':>10} "
        f"{'mech s':>7} {'kinematic s':>11} {'lambda':>9} {'hinges':>6} {'slides':>6}"
    )
    for n in args.sizes:
        courses, units = shape_for(n)
        jkn = 3e10 if courses > 50 else 2e10  # stiff enough that the base course does not sink (build wall)
        contact = udec_contact(0.2, WALL.density_kg_m3, jkn_Pa_per_m=jkn)
        scene = scene_from_dict(wall(courses=courses, units_per_course=units, contact=contact))
        lambdas = []
        for sliding in (True, False):
            t_model, model = best_of(1, lambda sc=scene, s=sliding: rigid_block_model(sc, sliding=s))
            estimate = estimate_limit_cost(model).seconds_per_programme
            for method in args.methods:
                t_lp, sol = best_of(args.repeat, lambda m=model, k=method: solve_equilibrium(m, "+x", method=k))
                t_mech, mech = best_of(1, lambda m=model, s=sol: mechanism_of(m, s))
                t_kin, _ = best_of(
                    1, lambda m=model, me=mech, s=sol: kinematic_quantities(m, me, s.load_multiplier, "+x")
                )
                lambdas.append((sliding, sol.load_multiplier))
                print(
                    f"{len(scene.blocks):6d} {len(model.interfaces):7d} {sliding!s:>8} {method:>10} "
                    f"{t_model:8.2f} {t_lp:7.3f} {estimate:10.3f} {t_mech:7.3f} {t_kin:11.3f} "
                    f"{sol.load_multiplier:9.5f} {len(mech.hinges):6d} {len(mech.sliding):6d}",
                    flush=True,
                )
        for sliding in (True, False):
            values = [lam for s, lam in lambdas if s == sliding]
            spread = (max(values) - min(values)) / max(abs(max(values)), 1e-300)
            if spread > 1e-6:
                raise SystemExit(f"the methods' multipliers differ by {spread:.1e} (relative) on {n} blocks")


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"done in {time.perf_counter() - start:.1f} s of wall time")
