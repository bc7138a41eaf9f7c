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
from rockyade.batch import run_scenes
from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.calibration.model_stage import calibrated_model
from rockyade.errors import CalibrationError
from rockyade.figures.solver_panels import Curve, Panel, SolverPanelsDisplay
from rockyade.figures.styles import SOLVER_LABELS
from rockyade.result import Result
from rockyade.runner import Executor
from rockyade.scene import scene_from_dict
from rockyade.solvers.base import Solver
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver
from rockyade.studies.report import Report, fmt, max_difference, run_state
from rockyade.studies.specimen_scenes import PARAMETER_SETS, block_alpha, block_table, scene_dict

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
    cases = _cases()
    runnable = [c for c in cases if c["scene"] is not None]
    scenes = [c["scene"] for c in runnable]
    on = Executor("threads", workers)
    dem = ReferenceSolver(record_energy=False, record_contacts=False)
    solvers: dict[str, tuple[Solver, str]] = {"reference": (dem, "free rocking: reference DEM")}
    if use_yade:
        solvers["yade"] = (YadeSolver(), "free rocking: YADE")
    for name, (solver, desc) in solvers.items():
        for c, r in zip(runnable, run_scenes(solver, scenes, executor=on, desc=desc), strict=True):
            c[name] = r
    keys = [(key, params) for key in paper.ALL_SPECIMENS for params in PARAMETER_SETS]
    exact_scenes = [_free_scene(key, params) for key, params in keys]
    found = run_scenes(HousnerSolver(), exact_scenes, executor=on, desc="free rocking: Housner")
    exact = dict(zip(keys, found, strict=True))
    _record_runs(report, exact, cases, use_yade)
    table = pd.DataFrame(_exact_rows(exact) + _dem_rows(cases, exact, use_yade))
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


def _free_scene(key: str, params: str, calibration: str = "matched"):
    """A specimen alone, released at alpha / 2."""
    alpha = block_alpha(key, params)
    motion = {"type": "free", "theta0_rad": alpha / 2}
    return scene_from_dict(scene_dict([block_table(key, params)], motion, DURATION_S, 0.002, calibration))


def _cases() -> list[dict]:
    """Every specimen x parameter set x calibration, with its DEM scene (None where the
    matched calibration cannot reach mu: the note says why) and its damping constant."""
    cases = []
    for key in paper.ALL_SPECIMENS:
        for params in PARAMETER_SETS:
            for cal in CALIBRATIONS:
                scene = _free_scene(key, params, cal)
                note, beta = "", math.nan
                try:
                    joint = calibrated_model(scene).bodies[0].joint
                    assert joint is not None  # a calibrated model's bodies carry their joint
                    beta = joint.beta_s
                except CalibrationError as exc:
                    note = f"matched calibration not reachable: {exc}"
                    scene = None
                cases.append(
                    {
                        "key": key,
                        "params": params,
                        "calibration": cal,
                        "alpha": block_alpha(key, params),
                        "scene": scene,
                        "beta_s": beta,
                        "note": note,
                    }
                )
    return cases


def _record_runs(report: Report, exact: dict, cases: list[dict], use_yade: bool) -> None:
    """Log every run in the report (a DEM case that could not run as "not run", with why)."""
    for (key, params), result in exact.items():
        report.record_result(f"{paper.specimen(key).label}, {params}", result)
    for c in cases:
        label = f"{paper.specimen(c['key']).label}, {c['params']}, {c['calibration']} calibration"
        for solver in ("reference", "yade"):
            if c["scene"] is None and (solver == "reference" or use_yade):
                report.record(label, solver, "not run", c["note"])
            elif c.get(solver) is not None:
                report.record_result(label, c[solver])


def _exact_rows(exact: dict) -> list[dict]:
    """The table's rows of Housner's exact solutions."""
    rows = []
    for (key, params), result in exact.items():
        mu, first = _mu(result, block_alpha(key, params))
        target = result.meta.classical[next(iter(result.meta.classical))]["mu"]
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
    return rows


def _dem_rows(cases: list[dict], exact: dict, use_yade: bool) -> list[dict]:
    """The table's rows of the DEM runs (and of the cases that could not run)."""
    rows = []
    for c in cases:
        target = (
            paper.specimen(c["key"]).experimental["mu"]
            if c["params"] == "experimental"
            else exact[(c["key"], c["params"])].meta.classical[paper.specimen(c["key"]).name]["mu"]
        )
        for solver in ("reference", "yade"):
            result = c.get(solver)
            if result is None and not (solver == "reference" or use_yade):
                continue
            mu, first = _mu(result, c["alpha"]) if result is not None else (math.nan, math.nan)
            rows.append(
                {
                    "block": c["key"],
                    "parameters": c["params"],
                    "solver": solver,
                    "calibration": c["calibration"],
                    "beta_s": c["beta_s"] if result is not None else math.nan,
                    "mu_target": target,
                    "mu_eff": mu,
                    "first_peak_rad": first,
                    "status": result.status if result is not None else "not run",
                    "note": (result.meta.failure_reason or "") if result is not None else c["note"],
                }
            )
    return rows


def draw_figure(report: Report, key: str, exact, cases, table: pd.DataFrame) -> SolverPanelsDisplay:
    """theta(t): rows = parameter sets, columns = calibrations; Housner in every panel
    (drawn by :class:`rockyade.figures.solver_panels.SolverPanelsDisplay`)."""
    spec = paper.specimen(key)
    name = f"free_rocking_{spec.name}.png"
    rows = [
        [_panel(key, params, cal, exact[(key, params)], cases, table) for cal in CALIBRATIONS]
        for params in PARAMETER_SETS
    ]
    display = SolverPanelsDisplay(rows, title=f"Free rocking of the {spec.label}, released at alpha / 2").plot(
        path=report.out / name, figsize=(12, 7.5)
    )
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
    with_yade = any(c.get("yade") is not None for c in cases if c["key"] == key)
    report.figure(name, figure_caption(spec.label, with_yade, extra))
    return display


def figure_caption(label: str, with_yade: bool, extra: str = "") -> str:
    """The caption of a block's free-rocking figure: it names YADE only where YADE ran
    (``--no-yade`` draws no YADE curve)."""
    solvers = (
        "Housner (thin blue), the reference DEM (wide orange band) and YADE (dashed green, with its largest "
        "difference from the DEM)"
        if with_yade
        else "Housner (thin blue) and the reference DEM (wide orange band); YADE off"
    )
    return (
        f"Free rocking of the {label}: theta(t) by {solvers}, paper (Eq 13, left) and matched "
        f"(right) calibration, theoretical (top) and experimental (bottom) parameters.{extra}"
    )


def _panel(key: str, params: str, cal: str, housner: Result, cases: list[dict], table: pd.DataFrame) -> Panel:
    """One panel of the free-rocking figure: Housner, the reference DEM and YADE for one
    parameter set and calibration, each DEM with its effective mu."""
    curves = [Curve("housner", SOLVER_LABELS["housner"], housner.t, housner.series("theta_rad"))] if housner.ok else []
    case = next(c for c in cases if c["key"] == key and c["params"] == params and c["calibration"] == cal)
    for solver in ("reference", "yade"):
        r = case.get(solver)
        if r is None:
            continue
        if not r.ok:
            curves.append(Curve(solver, f"{SOLVER_LABELS[solver]}: FAILED, no curve"))
            continue
        sel = table[
            (table.block == key) & (table.parameters == params) & (table.solver == solver) & (table.calibration == cal)
        ]
        mu = sel["mu_eff"].iloc[0] if len(sel) else math.nan
        label = f"{'reference DEM' if solver == 'reference' else 'YADE'} (mu_eff {fmt(mu)})"
        dem = case.get("reference")
        if solver == "yade" and dem is not None and dem.ok:
            label += f", max |YADE - DEM| {max_difference(r, dem):.1e} rad"
        curves.append(Curve(solver, label, r.t, r.series("theta_rad")))
    return Panel(
        curves=curves,
        title=f"{params} parameters (alpha = {block_alpha(key, params):.3f} rad), {cal} calibration",
        ylabel="theta (rad)" if cal == CALIBRATIONS[0] else "",
        note="matched calibration not reachable (see free_rocking.csv)" if case["scene"] is None else "",
    )
