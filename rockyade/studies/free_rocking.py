"""Free rocking of each specimen and each block of the bi-block (paper Figs 9 and 13).

Each block alone on a rigid base, released at alpha / 2, with theoretical (geometry) and
experimental (Tables 3-4) parameters; Housner's exact solution beside the reference DEM
and YADE, each with the paper's calibration (Eq 13) and the matched one. A matched
calibration that cannot reach mu is reported as such, with the reachable range.
"""

from __future__ import annotations

import math

import pandas as pd

from rockyade import paper
from rockyade.blocks.restitution import effective_restitution, find_peaks
from rockyade.dem.matching import build_matched_model
from rockyade.errors import CalibrationError
from rockyade.figures import plt, save_figure
from rockyade.scene import scene_from_dict
from rockyade.solvers import housner, reference
from rockyade.solvers import yade as yade_backend
from rockyade.studies.common import PARAMETER_SETS, Report, block_alpha, block_table, fmt, scene_dict

DURATION_S = 4.0
N_IMPACTS = 4
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
    for c in runnable:
        c["reference"] = reference.run_scene(c["scene"], record_energy=False, record_contacts=False)
    if use_yade:
        yade_results = yade_backend.run_many([c["scene"] for c in runnable], workers=workers)
        for c, r in zip(runnable, yade_results, strict=True):
            c["yade"] = r
    exact = {}
    for key in paper.ALL_SPECIMENS:
        for params in PARAMETER_SETS:
            alpha = block_alpha(key, params)
            d = scene_dict([block_table(key, params)], {"type": "free", "theta0_rad": alpha / 2}, DURATION_S, 0.002)
            exact[(key, params)] = housner.run_scene(scene_from_dict(d))
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
    report.table(
        "free_rocking.csv",
        table,
        "effective restitution of every block, parameter set, solver and calibration, with the target mu, "
        "the damping constant beta (s) and notes (unreachable matched calibrations).",
    )
    for key in paper.ALL_SPECIMENS:
        _figure(report, key, exact, cases, table)
    return table


def _figure(report: Report, key: str, exact, cases, table: pd.DataFrame) -> None:
    spec = paper.specimen(key)
    fig, axes = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
    styles = {
        ("reference", "paper"): ("C1", "--"),
        ("yade", "paper"): ("C2", ":"),
        ("reference", "matched"): ("C3", "--"),
        ("yade", "matched"): ("C4", ":"),
    }
    for ax, params in zip(axes, PARAMETER_SETS, strict=True):
        h = exact[(key, params)]
        ax.plot(h.t, h.series("theta_rad"), color="C0", lw=1.6, label="Housner (exact)")
        for c in cases:
            if c["key"] != key or c["params"] != params:
                continue
            for solver in ("reference", "yade"):
                r = c.get(solver)
                if r is None or not r.ok:
                    continue
                colour, style = styles[(solver, c["calibration"])]
                sel = table[
                    (table.block == key)
                    & (table.parameters == params)
                    & (table.solver == solver)
                    & (table.calibration == c["calibration"])
                ]
                mu = sel["mu_eff"].iloc[0] if len(sel) else math.nan
                ax.plot(
                    r.t,
                    r.series("theta_rad"),
                    color=colour,
                    ls=style,
                    lw=1.1,
                    label=f"{solver}, {c['calibration']} (mu_eff {fmt(mu)})",
                )
        target = table[(table.block == key) & (table.parameters == params) & (table.solver == "housner")]
        ax.set_title(
            f"{spec.label}, {params} parameters: alpha = {block_alpha(key, params):.3f} rad, "
            f"mu = {fmt(target['mu_target'].iloc[0])}",
            fontsize=10,
        )
        ax.set_ylabel("theta (rad)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right", ncol=2)
        ax.axhline(0, color="0.5", lw=0.5)
    axes[-1].set_xlabel("time t (s)")
    name = f"free_rocking_{spec.name}.png"
    save_figure(fig, report.out / name)
    unreachable = [c for c in cases if c["key"] == key and c["scene"] is None]
    extra = (
        " Matched calibration not reachable (see free_rocking.csv) for the "
        + " and ".join(f"{c['params']} parameters" for c in unreachable)
        + "."
        if unreachable
        else ""
    )
    report.figure(
        name,
        f"Free rocking of the {spec.label}: theta(t) by Housner, the reference DEM and YADE, "
        f"paper (Eq 13) and matched calibration, theoretical (top) and experimental (bottom) parameters.{extra}",
    )
