"""Free rocking of each specimen and each block of the bi-block (paper Figs 9 and 13).

Each block alone on a rigid base, released at alpha / 2, with theoretical (geometry) and
experimental (Tables 3-4) parameters; Housner's exact solution beside the reference DEM
and YADE, each with the paper's calibration (Eq 13) and the matched one. A matched
calibration that cannot reach mu is reported as such, with the reachable range.
"""

from __future__ import annotations

import math

import pandas as pd
from matplotlib.figure import Figure

from rockyade import paper
from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.calibration.matched import build_matched_model
from rockyade.errors import CalibrationError
from rockyade.figures import new_figure, save_figure
from rockyade.scene import scene_from_dict
from rockyade.solvers import housner, reference
from rockyade.studies.common import (
    PARAMETER_SETS,
    SOLVER_LABELS,
    Report,
    block_alpha,
    block_table,
    fmt,
    max_difference,
    plot_solver,
    run_each,
    run_state,
    run_yade,
    scene_dict,
)

DURATION_S = 4.0
N_IMPACTS = MU_EFF_IMPACTS
CALIBRATIONS = ("paper", "matched")


def _mu(result, alpha: float) -> tuple[float, float]:
    if not result.ok:
        return math.nan, math.nan
    peaks = find_peaks(result.t, result.series("theta_rad"), 1e-3 * alpha)
    first = float(peaks.amplitude_rad[0]) if len(peaks) else math.nan
    return effective_restitution(peaks, alpha, N_IMPACTS), first


def run(report: Report, workers: int = 2, use_yade: bool = True) -> pd.DataFrame:
    """Run the free-rocking comparison; write ``free_rocking.csv`` and one figure per block."""
    report.section(
        "Free rocking (paper Figs 9 and 13)",
        "Each block alone on a rigid base, released at alpha/2 (theoretical parameters from the geometry, "
        "experimental ones from Tables 3-4). Effective restitution over the first "
        f"{N_IMPACTS} impacts after the release.",
    )
    cases = []
    for key in paper.ALL_SPECIMENS:
        for params in PARAMETER_SETS:
            alpha = block_alpha(key, params)
            for cal in CALIBRATIONS:
                d = scene_dict(
                    [block_table(key, params)], {"type": "free", "theta0_rad": alpha / 2}, DURATION_S, 0.002, cal
                )
                scene = scene_from_dict(d)
                note, beta = "", math.nan
                try:
                    beta = build_matched_model(scene).bodies[0].joint.beta_s
                except CalibrationError as exc:
                    note = f"matched calibration not reachable: {exc}"
                    scene = None
                cases.append(
                    {
                        "key": key,
                        "params": params,
                        "calibration": cal,
                        "alpha": alpha,
                        "scene": scene,
                        "beta_s": beta,
                        "note": note,
                    }
                )
    runnable = [c for c in cases if c["scene"] is not None]
    dem_results = run_each(
        [c["scene"] for c in runnable],
        lambda scene: reference.run_scene(scene, record_energy=False, record_contacts=False),
        "free rocking: reference DEM",
    )
    for c, r in zip(runnable, dem_results, strict=True):
        c["reference"] = r
    if use_yade:
        yade_results = run_yade([c["scene"] for c in runnable], workers, "free rocking: YADE")
        for c, r in zip(runnable, yade_results, strict=True):
            c["yade"] = r
    keys = [(key, params) for key in paper.ALL_SPECIMENS for params in PARAMETER_SETS]

    def exact_run(key_params: tuple[str, str]):
        key, params = key_params
        alpha = block_alpha(key, params)
        d = scene_dict([block_table(key, params)], {"type": "free", "theta0_rad": alpha / 2}, DURATION_S, 0.002)
        return housner.run_scene(scene_from_dict(d))

    exact = dict(zip(keys, run_each(keys, exact_run, "free rocking: Housner"), strict=True))
    for (key, params), result in exact.items():
        report.record_result(f"{paper.specimen(key).label}, {params}", result)
    for c in cases:
        label = f"{paper.specimen(c['key']).label}, {c['params']}, {c['calibration']} calibration"
        for solver in ("reference", "yade"):
            if c["scene"] is None and (solver == "reference" or use_yade):
                report.record(label, solver, "not run", c["note"])
            elif c.get(solver) is not None:
                report.record_result(label, c[solver])
    rows = []
    for (key, params), result in exact.items():
        alpha = block_alpha(key, params)
        mu, first = _mu(result, alpha)
        target = result.meta["classical"][next(iter(result.meta["classical"]))]["mu"]
        rows.append(
            {
                "block": key,
                "parameters": params,
                "solver": "housner",
                "calibration": "-",
                "beta_s": math.nan,
                "mu_target": target,
                "mu_eff": mu,
                "first_peak_rad": first,
                "status": result.status,
                "note": "",
            }
        )
    for c in cases:
        target = (
            paper.specimen(c["key"]).experimental["mu"]
            if c["params"] == "experimental"
            else exact[(c["key"], c["params"])].meta["classical"][paper.specimen(c["key"]).name]["mu"]
        )
        for solver in ("reference", "yade"):
            result = c.get(solver)
            if result is None and (solver == "reference" or use_yade):
                rows.append(
                    {
                        "block": c["key"],
                        "parameters": c["params"],
                        "solver": solver,
                        "calibration": c["calibration"],
                        "beta_s": math.nan,
                        "mu_target": target,
                        "mu_eff": math.nan,
                        "first_peak_rad": math.nan,
                        "status": "not run",
                        "note": c["note"],
                    }
                )
                continue
            if result is None:
                continue
            mu, first = _mu(result, c["alpha"])
            rows.append(
                {
                    "block": c["key"],
                    "parameters": c["params"],
                    "solver": solver,
                    "calibration": c["calibration"],
                    "beta_s": c["beta_s"],
                    "mu_target": target,
                    "mu_eff": mu,
                    "first_peak_rad": first,
                    "status": result.status,
                    "note": result.meta.get("failure_reason") or "",
                }
            )
    table = pd.DataFrame(rows)
    n_dem = len(runnable)
    states = [f"reference DEM: {run_state(report, 'reference', n_dem)}"]
    if use_yade:
        states.append(f"YADE: {run_state(report, 'yade', n_dem)}")
    report.note(
        f"Runs: Housner: {run_state(report, 'housner', len(exact))}; "
        + "; ".join(states)
        + f" ({len(cases) - n_dem} DEM case(s) not run: "
        "matched calibration not reachable)."
    )
    report.table(
        "free_rocking.csv",
        table,
        "effective restitution of every block, parameter set, solver and calibration, with the target mu, "
        "the damping constant beta (s) and notes (unreachable matched calibrations).",
    )
    for key in paper.ALL_SPECIMENS:
        draw_figure(report, key, exact, cases, table)
    return table


def draw_figure(report: Report, key: str, exact, cases, table: pd.DataFrame) -> Figure:
    """theta(t): rows = parameter sets, columns = calibrations; Housner in every panel."""
    spec = paper.specimen(key)
    name = f"free_rocking_{spec.name}.png"
    fig, axes = new_figure(report.out / name, 2, 2, figsize=(12, 7.5), sharex=True)
    for row, params in zip(axes, PARAMETER_SETS, strict=True):
        h = exact[(key, params)]
        alpha = block_alpha(key, params)
        for ax, cal in zip(row, CALIBRATIONS, strict=True):
            if h.ok:
                plot_solver(ax, "housner", h.t, h.series("theta_rad"))
            case = next(c for c in cases if c["key"] == key and c["params"] == params and c["calibration"] == cal)
            if case["scene"] is None:
                ax.text(
                    0.5,
                    0.08,
                    "matched calibration not reachable\n(see free_rocking.csv)",
                    transform=ax.transAxes,
                    ha="center",
                    fontsize=8,
                    color="0.3",
                )
            for solver in ("reference", "yade"):
                r = case.get(solver)
                if r is None:
                    continue
                if not r.ok:
                    ax.plot([], [], label=f"{SOLVER_LABELS[solver]}: FAILED, no curve", **_failed_style())
                    continue
                sel = table[
                    (table.block == key)
                    & (table.parameters == params)
                    & (table.solver == solver)
                    & (table.calibration == cal)
                ]
                mu = sel["mu_eff"].iloc[0] if len(sel) else math.nan
                label = f"{'reference DEM' if solver == 'reference' else 'YADE'} (mu_eff {fmt(mu)})"
                dem = case.get("reference")
                if solver == "yade" and dem is not None and dem.ok:
                    label += f", max |YADE - DEM| {max_difference(r, dem):.1e} rad"
                plot_solver(ax, solver, r.t, r.series("theta_rad"), label)
            ax.set_title(f"{params} parameters (alpha = {alpha:.3f} rad), {cal} calibration", fontsize=9)
            ax.axhline(0, color="0.5", lw=0.5)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="best")
        row[0].set_ylabel("theta (rad)")
    for ax in axes[-1]:
        ax.set_xlabel("time t (s)")
    fig.suptitle(f"Free rocking of the {spec.label}, released at alpha / 2", fontsize=11)
    save_figure(fig, report.out / name)
    unreachable = [c for c in cases if c["key"] == key and c["scene"] is None]
    extra = (
        " Matched calibration not reachable (see free_rocking.csv) for the "
        + " and ".join(f"{c['params']} parameters" for c in unreachable)
        + "."
        if unreachable
        else ""
    )
    failed = sorted(
        {s for c in cases if c["key"] == key for s in ("reference", "yade") if c.get(s) is not None and not c[s].ok}
    )
    if failed:
        extra += f" No curve for the failed runs of: {', '.join(failed)} (see free_rocking.csv)."
    report.figure(
        name,
        f"Free rocking of the {spec.label}: theta(t) by Housner (thin blue), the reference DEM (wide orange band) "
        f"and YADE (dashed green, with its largest difference from the DEM), paper (Eq 13, left) and matched "
        f"(right) calibration, theoretical (top) and experimental (bottom) parameters.{extra}",
    )
    return fig


def _failed_style() -> dict:
    return {"color": "red", "ls": "none", "marker": "x"}
