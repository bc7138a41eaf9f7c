"""``rockyade compare`` (and, later, batch and study commands)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from rockyade.errors import InputError


def cmd_compare(args: argparse.Namespace) -> int:
    """Run one scene through several solvers and tabulate their agreement."""
    from rockyade.atomic import atomic_open
    from rockyade.compare import compare
    from rockyade.figures import plot_results
    from rockyade.scene import load_scene
    from rockyade.solvers import get_solver, solver_names

    scene = load_scene(args.scene)
    solvers = [s.strip() for s in args.solvers.split(",") if s.strip()]
    unknown = [s for s in solvers if s not in solver_names()]
    if unknown or not solvers:
        raise InputError(
            "solvers", f"must be a comma-separated list of {', '.join(solver_names())}, got {args.solvers!r}"
        )
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    stem = args.scene.stem
    results = {}
    for name in solvers:
        run = get_solver(name)
        result = run(scene, workdir=out, name=stem) if name == "yade" else run(scene)
        result.write(out / f"{stem}_{name}.csv")
        results[name] = result
        status = result.status if result.ok else f"failed ({result.meta.get('failure_reason')})"
        print(f"{name}: {status}, wall time {result.meta.get('wall_time_s', float('nan')):.3g} s")
    table = compare(scene, results, args.reference)
    with atomic_open(out / f"{stem}_compare.csv") as fh:
        table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
    plot_results(results, out / f"{stem}_compare.png", title=f"{stem}: {', '.join(solvers)}")
    view = table[
        table["metric"].isin(
            [
                "peak1_amplitude_rad",
                "peak5_time_s",
                "mu_eff",
                "max_abs_theta_rad",
                "rms_theta_difference_rad",
                "overturned",
            ]
        )
    ]
    print(view.to_string(index=False, float_format=lambda v: f"{v:.5g}"))
    print(f"wrote {out / f'{stem}_compare.csv'} and {out / f'{stem}_compare.png'}")
    return 0 if all(r.ok for r in results.values()) else 1


def register(sub: Any) -> None:
    """Add ``rockyade compare``."""
    p = sub.add_parser(
        "compare",
        help="one scene through several solvers, with agreement metrics",
        description="Run a scene through several solvers; write each result, a CSV of agreement "
        "metrics (peaks, peak times, effective mu, max |theta|, overturn, RMS of theta differences) "
        "and a figure of theta(t).",
    )
    p.add_argument("scene", type=Path, help="scene file")
    p.add_argument("--solvers", default="housner,reference,yade", help="comma-separated solvers")
    p.add_argument("--reference", help="solver the others are compared with (default: reference)")
    p.add_argument("--out", type=Path, default=Path("compare"), help="output directory")
    p.set_defaults(func=cmd_compare)
