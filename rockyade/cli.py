"""The ``rockyade`` command line.

Commands: ``params`` (classical parameters of a block), ``calibrate`` (DEM contact
parameters), ``run`` (a scene through a solver), ``tables`` (the paper's tables
reproduced); later modules add theirs through :data:`EXTRA_COMMANDS`.

Exit codes: 0 success, 1 a run failed, 2 bad input (the message names the field),
3 a solver that is not available here.
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from rockyade import __version__
from rockyade.errors import (
    CalibrationError,
    InputError,
    RockyadeError,
    SolverFailedError,
    SolverUnavailableError,
)

#: Calibration methods offered by ``rockyade calibrate``.
CALIBRATION_METHODS = ["paper", "matched"]

#: Functions that add sub-commands: f(subparsers) -> None (motion, compare, batch, paper ...)
EXTRA_COMMANDS: list[str] = [
    "rockyade.cli_motion",
    "rockyade.cli_studies",
]


def _json_out(data: Any) -> None:
    from rockyade.atomic import json_text

    print(json_text(data))


# ------------------------------------------------------------------ block input


def _add_block_arguments(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("block (one of: --specimen, --scene, dimensions or --vertices)")
    g.add_argument("--specimen", help="a specimen of the paper: 1-4, upper, lower")
    g.add_argument("--scene", type=Path, help="a scene file (.toml or .json)")
    g.add_argument("--block", help="block name in the scene (default: every block)")
    g.add_argument("--width", type=float, help="base width 2b, m")
    g.add_argument("--height", type=float, help="height 2h, m")
    g.add_argument("--vertices", help='convex polygon "x,y x,y ..." in m, base on y = 0')
    g.add_argument("--chamfer", type=float, help="45-degree base chamfer leg, m (with --width/--height)")
    g.add_argument("--thickness", type=float, help="thickness, m")
    g.add_argument("--mass", type=float, help="mass, kg")
    g.add_argument("--density", type=float, help="density, kg/m^3")
    g.add_argument("--inertia", type=float, help="rotational inertia about the centroid, kg m^2")


def _blocks_from_args(args: argparse.Namespace) -> list[tuple[str, Any, dict[str, float]]]:
    """(name, Block, classical overrides) for each block the arguments describe."""
    from rockyade import paper
    from rockyade.geometry import Block, chamfered_rectangle_vertices, rectangle_vertices
    from rockyade.scene import load_scene

    chosen = [x for x in (args.specimen, args.scene, args.width or args.vertices) if x]
    if len(chosen) != 1:
        raise InputError(
            "block", "give exactly one of --specimen, --scene, or dimensions (--width/--height or --vertices)"
        )
    if args.specimen:
        spec = paper.specimen(args.specimen)
        return [(spec.name, spec.block(), {})]
    if args.scene:
        scene = load_scene(args.scene)
        specs = [b for b in scene.blocks if args.block in (None, b.name)]
        if not specs:
            raise InputError("block", f"no block {args.block!r} in {args.scene}")
        out = []
        for b in specs:
            overrides = {k: getattr(b, k) for k in ("alpha_rad", "p_rad_s", "mu") if getattr(b, k) is not None}
            out.append((b.name, b.block(), overrides))
        return out
    if args.thickness is None:
        raise InputError("thickness", "is required with dimensions (--thickness, m)")
    if args.vertices:
        try:
            verts = [[float(c) for c in pair.split(",")] for pair in args.vertices.split()]
        except ValueError:
            raise InputError("vertices", 'must look like "x,y x,y x,y" (metres)') from None
    else:
        if args.height is None:
            raise InputError("height", "is required with --width (m)")
        verts = (
            chamfered_rectangle_vertices(args.width, args.height, args.chamfer)
            if args.chamfer
            else rectangle_vertices(args.width, args.height)
        )
        for name in ("width", "height"):
            value = getattr(args, name)
            if not value > 0:
                raise InputError(name, f"must be > 0 m, got {value}")
    block = Block.polygon(
        verts,
        args.thickness,
        mass_kg=args.mass,
        density_kg_m3=args.density,
        inertia_kgm2=args.inertia,
        name="block",
    )
    return [("block", block, {})]


# ------------------------------------------------------------------ commands


def cmd_params(args: argparse.Namespace) -> int:
    """Classical parameters of one or more blocks."""
    from rockyade.classical import classical_parameters

    out = {}
    for name, block, overrides in _blocks_from_args(args):
        cp = classical_parameters(block, **overrides)
        out[name] = {
            "alpha_rad": cp.alpha_rad,
            "p_rad_s": cp.p_rad_s,
            "mu": cp.mu,
            "R_m": cp.R_m,
            "I_O_kgm2": cp.I_O_kgm2,
            "I_c_kgm2": cp.I_c_kgm2,
            "mass_kg": cp.mass_kg,
            "uplift_accel_m_s2": cp.uplift_accel_m_s2,
            "centroid_height_m": cp.centroid_height_m,
            "symmetric": cp.symmetric,
            "mu_left_to_right": cp.mu_left_to_right,
            "mu_right_to_left": cp.mu_right_to_left,
            "pivots": {"left": cp.left.__dict__, "right": cp.right.__dict__},
            "source": cp.source,
        }
    if args.json:
        _json_out(out[next(iter(out))] if len(out) == 1 else out)
        return 0
    for name, d in out.items():
        alpha_src = "Eq 2" if d["source"]["alpha_rad"] == "geometry" else "override"
        print(f"{name}:")
        print(f"  alpha = {d['alpha_rad']:.6g} rad ({alpha_src})")
        print(f"  p     = {d['p_rad_s']:.6g} 1/s (p^2 = M g R / I_O; Eq 3 for rectangles)")
        print(f"  mu    = {d['mu']:.6g} (angular momentum about the new pivot; Eq 4 for rectangles)")
        print(f"  R     = {d['R_m']:.6g} m, I_O = {d['I_O_kgm2']:.6g} kg m^2, I_c = {d['I_c_kgm2']:.6g} kg m^2")
        print(f"  M     = {d['mass_kg']:.6g} kg")
        print(f"  uplift when |a_g| > g tan(alpha) = {d['uplift_accel_m_s2']:.6g} m/s^2")
        if not d["symmetric"]:
            print(f"  asymmetric: mu L->R = {d['mu_left_to_right']:.6g}, R->L = {d['mu_right_to_left']:.6g}")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    """DEM contact parameters (paper Eqs 7-15, or matched to mu)."""
    from rockyade import paper
    from rockyade.calibration import paper_calibration, xi_min_eq15

    if args.specimen is None:
        raise InputError("specimen", "is required: 1, 2, 3, 4, upper or lower")
    spec = paper.specimen(args.specimen)
    block = spec.block()
    if args.parameters == "experimental":
        params = spec.experimental
    else:
        from rockyade.classical import classical_parameters

        cp = classical_parameters(block)
        params = {"alpha_rad": cp.alpha_rad, "p_rad_s": cp.p_rad_s, "mu": cp.mu}
    cal = paper_calibration(
        block, **params, stiffness_scale=args.stiffness_scale, friction_angle_deg=args.friction_angle
    )
    result: dict[str, Any] = {
        "specimen": spec.key,
        "parameters": args.parameters,
        "classical": params,
        "method": args.method,
        "K_N_per_m": cal.K_N_per_m,
        "Ks_N_per_m": cal.Ks_N_per_m,
        "beta_s": cal.beta_s,
        "beta_eq13_s": cal.beta_eq13_s,
        "xi_min": cal.xi_min,
        "f_min_hz": cal.f_min_hz,
        "b_eq_m": cal.b_eq_m,
        "dt_s": cal.dt_eq7_s,
        "friction_angle_deg": cal.friction_angle_deg,
        "cohesion_Pa": cal.cohesion_Pa,
        "stiffness_scale": cal.stiffness_reading,
        "stiffness_scale_factor": cal.stiffness_scale,
        "K_paper_units": cal.K_paper,
        "gamma": cal.gamma,
        "settlement_m": cal.settlement_m,
        "notes": list(cal.notes),
    }
    if args.method == "matched":
        from rockyade.matching import match_beta

        matched = match_beta(
            block, **params, stiffness_scale=args.stiffness_scale, friction_angle_deg=args.friction_angle
        )
        result.update(matched.as_cli_dict())
        result["xi_min"] = xi_min_eq15(matched.beta_s, cal.f_min_hz)  # Eq 15 with the matched b
    if args.json:
        _json_out(result)
        return 0
    if args.method == "matched":
        beta_src = f"matched to mu; Eq 13 gives {cal.beta_eq13_s:.6g} s"
    else:
        beta_src = f"Eq 13, Gamma = {cal.gamma:.6g} (Eq 12)"
    a, p, mu = params["alpha_rad"], params["p_rad_s"], params["mu"]
    print(f"{spec.label}, {args.parameters} parameters: alpha = {a:.4g} rad, p = {p:.4g} 1/s, mu = {mu:.4g}")
    print(f"  K = Ks   = {cal.K_N_per_m:.6g} N/m (Eq 10: {cal.K_paper:.6g}, read as {cal.stiffness_reading})")
    print(f"  beta     = {result['beta_s']:.6g} s ({beta_src})")
    print(f"  xi_min   = {result['xi_min']:.6g} (Eq 15), f_min = {cal.f_min_hz:.6g} Hz (Eq 14), Rayleigh a = 0")
    print(f"  b_eq     = {cal.b_eq_m:.6g} m (Eq 11; 2 b_eq = {2 * cal.b_eq_m:.4g} m)")
    print(f"  dt       = {cal.dt_eq7_s:.6g} s (Eq 7, frac 0.1)")
    print(f"  friction = {cal.friction_angle_deg:g} deg, cohesion = 0 Pa")
    print(f"  static settlement M g / K = {cal.settlement_m:.3g} m")
    if args.method == "matched":
        lo, hi = result["mu_reachable_min"], result["mu_reachable_max"]
        print(f"  matched  : reference DEM effective mu {result['mu_eff_matched']:.5f}; reachable {lo:.4f}-{hi:.4f}")
    for note in result["notes"]:
        print(f"  note: {note}")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    """Run a scene through a solver."""
    from rockyade.scene import load_scene
    from rockyade.solvers import get_solver

    scene = load_scene(args.scene)
    solver = get_solver(args.solver)
    if args.solver == "yade" and args.out:
        # YADE's log and scene data are kept beside the result
        result = solver(scene, workdir=args.out.parent, name=args.out.stem)
    else:
        result = solver(scene)
    if args.out:
        json_path = result.write(args.out)
        print(f"wrote {args.out} and {json_path}")
    if args.plot:
        from rockyade.figures import plot_results

        plot_results({args.solver: result}, args.plot, title=f"{Path(args.scene).name} ({args.solver})")
        print(f"wrote {args.plot}")
    _print_summary(scene, result)
    return 0 if result.ok else 1


def _print_summary(scene: Any, result: Any) -> None:
    from rockyade.analysis import run_metrics

    meta = result.meta
    wall = meta.get("wall_time_s", math.nan)
    print(f"solver {meta['solver']}: status {result.status}, wall time {wall:.3g} s")
    if not result.ok:
        print(f"  failure: {meta.get('failure_reason')}")
        if meta.get("log_path"):
            print(f"  log: {meta['log_path']}")
        return
    for name, m in run_metrics(scene, result).items():
        theta, ratio = m["max_abs_theta_rad"], m["max_theta_over_alpha"]
        line = f"  {name}: max |theta| = {theta:.5g} rad ({ratio:.3g} alpha)"
        if not math.isnan(m["mu_eff"]):
            line += f", effective mu = {m['mu_eff']:.5g} over {min(m['n_peaks'] - 1, 5)} impacts"
        print(line)
    if result.status == "overturned":
        print(f"  overturned at t = {meta['overturn_time_s']:.4g} s ({meta.get('overturned_block')})")


def cmd_tables(args: argparse.Namespace) -> int:
    """Tables 1-6 of the paper reproduced."""
    from rockyade.tables import format_report, reproduction_report

    report = reproduction_report()
    if args.out:
        from rockyade.atomic import atomic_open

        args.out.mkdir(parents=True, exist_ok=True)
        for number, group in report.groupby("table"):
            with atomic_open(args.out / f"table{int(number)}_reproduced.csv") as fh:
                group.to_csv(fh, index=False, lineterminator="\n")
        with atomic_open(args.out / "tables_reproduced.csv") as fh:
            report.to_csv(fh, index=False, lineterminator="\n")
        print(f"wrote {args.out}/tables_reproduced.csv and one CSV per table")
    if args.json:
        _json_out(report.to_dict(orient="records"))
    else:
        print(format_report(report))
    return 0


# ------------------------------------------------------------------ parser


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    from rockyade.solvers import solver_names

    parser = argparse.ArgumentParser(
        prog="rockyade",
        description="Seismic rocking of rigid blocks: classical (Housner) parameters, exact "
        "Housner solver, DEM calibration from the classical parameters, reference DEM and YADE.",
    )
    parser.add_argument("--version", action="version", version=f"rockyade {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    p = sub.add_parser(
        "params",
        help="classical parameters alpha, p, mu of a block",
        description="Classical rocking parameters (paper Eqs 2-4, general polygon forms).",
    )
    _add_block_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_params)

    p = sub.add_parser(
        "calibrate",
        help="DEM contact parameters from classical parameters",
        description="DEM contact parameters of a specimen: K (Eq 10), b_eq (Eq 11), beta (Eq 13 or "
        "matched to mu with the reference DEM), xi_min (Eq 15), f_min (Eq 14), dt (Eq 7).",
    )
    p.add_argument("--specimen", required=True, help="1, 2, 3, 4, upper or lower")
    p.add_argument(
        "--parameters",
        choices=["theoretical", "experimental"],
        default="experimental",
        help="classical parameters: from the geometry (theoretical) or the paper's Tables 3-4 E column",
    )
    p.add_argument(
        "--method",
        choices=CALIBRATION_METHODS,
        default="paper",
        help="damping: Eq 13 (paper) or matched so that the reference DEM's effective mu equals mu",
    )
    p.add_argument(
        "--stiffness-scale",
        default="MN/m",
        help="reading of the paper's K: N/m, kN/m, MN/m (default) or a factor",
    )
    p.add_argument("--friction-angle", type=float, default=30.0, help="joint friction angle, degrees (default 30)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=cmd_calibrate)

    p = sub.add_parser(
        "run",
        help="run a scene through a solver",
        description="Run a scene file through a solver; write the result CSV + JSON.",
    )
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument(
        "--solver",
        default="housner",
        choices=solver_names(),
        help="housner (exact classical), reference (standalone DEM) or yade",
    )
    p.add_argument("--out", type=Path, help="result CSV (the metadata JSON is written beside it)")
    p.add_argument("--plot", type=Path, help="PNG figure of the time history")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser(
        "tables",
        help="the paper's Tables 1-6 reproduced",
        description="Tables 1-6: paper value, ours, difference and a flag where the printed number "
        "does not follow from the paper's own equations.",
    )
    p.add_argument("--out", type=Path, help="directory for CSV files")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=cmd_tables)

    import importlib

    for module_name in EXTRA_COMMANDS:
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as exc:
            if exc.name == module_name:
                continue
            raise
        register: Callable[[Any], None] = module.register
        register(sub)
    return parser


def _coerce_scale(value: str) -> str | float:
    try:
        return float(value)
    except ValueError:
        return value


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rockyade`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if hasattr(args, "stiffness_scale") and isinstance(args.stiffness_scale, str):
        args.stiffness_scale = _coerce_scale(args.stiffness_scale)
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"rockyade: error: {exc}", file=sys.stderr)
        return 2
    except SolverUnavailableError as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 3
    except (CalibrationError, SolverFailedError) as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 1
    except RockyadeError as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
