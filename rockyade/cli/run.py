"""``rockyade run`` (a scene through a solver) and ``rockyade tables`` (the paper's tables)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.cli.common import (
    SOLVER_NAMES,
    Commands,
    add_allow_large,
    add_command,
    add_yade_timeout,
    check_output_file,
    json_out,
    mu_note_line,
    solvers_from_args,
    total_time,
)
from rockyade.cli.drawings import add_snapshot_options, check_run_drawings, write_run_drawings

if TYPE_CHECKING:
    import pandas as pd

    from rockyade.result import Result
    from rockyade.scene import Scene


def cmd_run(args: argparse.Namespace) -> int:
    """run a scene through a solver

    Run a scene file through a solver; write the result CSV + JSON.
    """
    import contextlib

    from rockyade.io.locking import output_lock
    from rockyade.runner.cost_limits import check_cost
    from rockyade.scene import load_scene

    for option, suffix in (("out", ".csv"), ("plot", ".png")):
        if getattr(args, option):
            check_output_file(getattr(args, option), option, suffix)
    [solver] = solvers_from_args([args.solver], args)
    scene = load_scene(args.scene)
    _warn_if_the_motion_is_cut(scene)
    check_run_drawings(args)
    check_cost(scene, solver, allow_large=args.allow_large)
    if args.out:  # files the solver keeps (YADE's log and scene data) go beside the result
        solver = solver.keeping_files(args.out.parent, args.out.stem)
    with output_lock(args.out) if args.out else contextlib.nullcontext():
        result = solver.run(scene)
        report = _collapse_report(scene, result)
        if args.out:
            out = _result_path(args.out, result)
            json_path = result.write(out)
            print(f"wrote {out} and {json_path}")
            if out != args.out:
                print(f"  (the run failed: {args.out} keeps the complete result of an earlier run)")
            if report is not None:
                _write_collapse(report, args.out.with_name(f"{args.out.stem}_collapse.csv"))
            if scene.motion.type == "pushover" and len(result.frame):
                _write_capacity(scene, result, args.out.with_name(f"{args.out.stem}_capacity.csv"))
    if args.plot:
        from rockyade.figures import plot_results

        plot_results({args.solver: result}, args.plot, title=f"{Path(args.scene).name} ({args.solver})")
        print(f"wrote {args.plot}")
    write_run_drawings(args, scene, result, args.out or Path(Path(args.scene).stem + ".csv"))
    _print_summary(scene, result, total_time(args), report)
    return 0 if result.ok else 1


def _result_path(out: Path, result: Result) -> Path:
    """Where a run's result goes: ``out``, unless the run failed and ``out`` holds a complete
    result of an earlier run, which a failed run never replaces: then ``<stem>_failed.csv``
    beside it (its JSON says ``failed``, and ``partial`` where samples were kept)."""
    if result.ok or not _holds_a_complete_result(out):
        return out
    return out.with_name(f"{out.stem}_failed{out.suffix}")


def _holds_a_complete_result(out: Path) -> bool:
    """Whether ``out`` and its JSON are a complete result of a run that did not fail."""
    from rockyade.result import stored_status

    status = stored_status(out)
    return status is not None and status != "failed"


def _collapse_report(scene: Scene, result: Result) -> pd.DataFrame | None:
    """The state of every block of an assembly's run (written and summarised), else None."""
    if not (scene.positioned and result.ok):
        return None
    from rockyade.analysis.collapse import collapse_report

    return collapse_report(scene, result)


def _warn_if_the_motion_is_cut(scene: Scene) -> None:
    """One warning line on stderr when the scene ends before its base motion does."""
    import sys

    from rockyade.solvers.base import motion_coverage

    coverage = motion_coverage(scene)  # the run's Result then carries it without working it out again
    if coverage["status"] == "cut":
        where = f"{scene.source}: " if scene.source else ""
        print(f"rockyade: warning: {where}{coverage['message']}", file=sys.stderr)


def _write_capacity(scene: Scene, result: Result, path: Path) -> None:
    """A pushover's capacity curve (rockyade.analysis.capacity) and its onset, one line."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.io.atomic import atomic_open

    curve = capacity_curve(result, scene)
    with atomic_open(path) as fh:
        curve.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
    onset = pushover_onset(curve, scene)
    print(f"wrote {path} (capacity curve; onset lambda = {onset.multiplier:.4g}: {onset.rule})")


def _write_collapse(report: pd.DataFrame, path: Path) -> None:
    """Per block: whether and when it fell, rocking and sliding time, residual displacement
    (:func:`rockyade.analysis.collapse.collapse_report`)."""
    from rockyade.io.atomic import atomic_open

    with atomic_open(path) as fh:
        report.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
    print(f"wrote {path} (collapse: the state of every block)")


def _print_summary(scene: Scene, result: Result, total_s: float = math.nan, report: pd.DataFrame | None = None) -> None:
    from rockyade.analysis.metrics import PER_BLOCK_LIMIT, assembly_metrics, run_metrics
    from rockyade.blocks.restitution import MU_EFF_IMPACTS

    meta = result.meta
    wall = meta.wall_time_s if meta.wall_time_s is not None else math.nan
    print(f"solver {meta.solver}: status {result.status}, wall time {wall:.3g} s (solver), {total_s:.3g} s (total)")
    if not result.ok:
        print(f"  failure: {meta.failure_reason}")
        if meta.log_path:
            print(f"  log: {meta.log_path}")
        return
    if scene.positioned:
        a = assembly_metrics(scene, result, report)
        line = f"  {a['n_blocks']} moving blocks: {a['n_fallen']} fell"
        if a["n_fallen"]:
            line += f" (first {a['first_fallen_block']} at t = {a['first_fall_time_s']:.4g} s)"
        if a["n_falling_at_end"]:
            line += (
                f", {a['n_falling_at_end']} still falling when the run ended (not counted as fallen: "
                "a longer duration_s shows where they land)"
            )
        print(line + f"; max |theta| = {a['max_abs_theta_rad']:.4g} rad ({a['max_theta_block']})")
        line = f"  largest residual displacement {a['max_residual_displacement_m']:.4g} m ({a['max_residual_block']})"
        if a["n_moving_at_end"]:
            line += f"; {a['n_moving_at_end']} block(s) still moving at the end: residuals are where they were then"
        print(line)
        _print_structure(a, result, scene)
        if len(scene.blocks) > PER_BLOCK_LIMIT:
            return
    elif len(scene.blocks) > 1:
        from rockyade.analysis.metrics import structure_rotation

        _print_structure(structure_rotation(scene, result), result, scene)
    classical = meta.classical or {}
    for name, m in run_metrics(scene, result, report=report).items():
        theta, ratio = m["max_abs_theta_rad"], m["max_theta_over_alpha"]
        cp = classical.get(name) or {}
        loaded = bool(cp) and (cp["carried_kg"] > 0 or not cp["symmetric"])
        if loaded and len(scene.blocks) <= PER_BLOCK_LIMIT:
            print(f"  {name}: {loaded_words(cp)}")
        side = " of the side it turns to" if loaded else ""
        line = f"  {name}: max |theta| = {theta:.5g} rad ({ratio:.3g} alpha{side})"
        if not math.isnan(m["mu_eff"]):
            line += f", effective mu = {m['mu_eff']:.5g} over {min(m['n_peaks'] - 1, MU_EFF_IMPACTS)} impacts"
        print(line)
    note = mu_note_line(meta)
    if note:
        print(f"  {note}")
    if result.status == "overturned" and not scene.positioned:
        print(f"  overturned at t = {meta.overturn_time_s:.4g} s ({meta.overturned_block})")


def loaded_words(cp: Mapping[str, Any]) -> str:
    """A loaded (or asymmetric) block's classical parameters, each direction its own, in words
    (``meta.classical``: :func:`rockyade.solvers.base.classical_meta`)."""
    from rockyade.constants import G

    sides = [cp["right"], cp["left"]]  # towards +x first
    carried = f"with the {cp['carried_kg']:.5g} kg its loads carry, " if cp["carried_kg"] > 0 else ""
    each = "; ".join(
        f"towards {s['turns_to']}: alpha = {s['alpha_rad']:.4f} rad, R = {s['R_m']:.4g} m, p = {s['p_rad_s']:.4g} "
        f"rad/s, mu = {s['mu']:.4f}, uplift at {s['uplift_accel_m_s2']:.4g} m/s^2 ({s['uplift_accel_m_s2'] / G:.4g} g)"
        for s in sides
    )
    return f"rocks as one body of {cp['mass_kg']:.5g} kg ({carried}centroid {cp['centroid_height_m']:.4g} m up): {each}"


def _print_structure(m: dict[str, Any], result: Any, scene: Any) -> None:
    """The whole's own measure: a stack's rotation about its base corner against its alpha,
    or, for an assembly that has none, its peak base acceleration to set against the
    collapse acceleration of ``rockyade limit`` (the per-block ratios use each block's own alpha)."""
    if m["structure"] == "none":
        from rockyade.constants import G

        peak = float(abs(result.frame["ag_m_s2"]).max()) if "ag_m_s2" in result.frame else math.nan
        source = f" {Path(scene.source).name}" if scene.source else ""
        print(
            f"  as one body: {m['structure_note']}; set its peak base acceleration, {peak / G:.3g} g "
            f"({peak:.4g} m/s^2), against the collapse acceleration of 'rockyade limit{source}'"
        )
    elif math.isfinite(m["structure_max_theta_rad"]):
        print(
            f"  as one body ({m['structure']}): max rotation about its base corner "
            f"{abs(m['structure_max_theta_rad']):.4g} rad = {m['structure_max_theta_over_alpha']:.3g} of its own "
            f"alpha {m['structure_alpha_rad']:.4g} rad (the ratios below use each block's own alpha)"
        )


def cmd_tables(args: argparse.Namespace) -> int:
    """the paper's Tables 1-6 reproduced

    Tables 1-6: paper value, ours, difference and a flag where the printed number does not follow from the paper's own
    equations.
    """
    from rockyade.paper.tables import format_report, reproduction_report

    if args.out:
        from rockyade.cli.common import check_output_dir

        check_output_dir(args.out, "out")
    report = reproduction_report()
    if args.out:
        from rockyade.io.atomic import atomic_open

        for number, group in report.groupby("table"):
            with atomic_open(args.out / f"table{int(number)}_reproduced.csv") as fh:
                group.to_csv(fh, index=False, lineterminator="\n")
        with atomic_open(args.out / "tables_reproduced.csv") as fh:
            report.to_csv(fh, index=False, lineterminator="\n")
        print(f"wrote {args.out}/tables_reproduced.csv and one CSV per table")
    if args.json:
        json_out(report.to_dict(orient="records"))
    else:
        print(format_report(report))
    return 0


def register(sub: Commands) -> None:
    """Add ``run`` and ``tables``."""
    p = add_command(sub, cmd_run)
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument(
        "--solver",
        default="housner",
        choices=SOLVER_NAMES,
        help="housner (exact classical), reference (standalone DEM), yade or siconos (nonsmooth contact dynamics)",
    )
    p.add_argument("--out", type=Path, help="result CSV (the metadata JSON is written beside it)")
    p.add_argument("--plot", type=Path, help="PNG figure of the time history")
    add_yade_timeout(p)
    add_snapshot_options(p)
    add_allow_large(p)

    p = add_command(sub, cmd_tables)
    p.add_argument("--out", type=Path, help="directory for CSV files")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
