"""Random-motion tests (paper Fig. 15): specimen 2 under record 21 at load factor 0.6 and
specimen 3 under record 18 at load factor 0.5, of the EC8 Type 2 / D synthetic suite.

The paper reports that its model predicted the collapse of both specimens. Our suite is
generated anew (same target spectrum, our seed), so records 21 and 18 are not the
paper's: the comparison is between solvers, and with the paper's verdict only loosely.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rockyade.batch import run_scenes
from rockyade.figures.solver_panels import Curve, Panel, SolverPanelsDisplay
from rockyade.figures.styles import SOLVER_LABELS
from rockyade.result import Result
from rockyade.runner import Executor
from rockyade.scene import Scene, scene_from_dict
from rockyade.solvers.base import Solver
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver
from rockyade.studies.report import Report, fmt, max_difference, no_uplift_note, run_state
from rockyade.studies.specimen_scenes import block_table, scene_dict

CASES = (("2", 21, 0.6), ("3", 18, 0.5))
DURATION_S = 25.0


def run(report: Report, workers: int = 2, use_yade: bool = True) -> pd.DataFrame:
    """Run the two random tests; write ``random.csv`` and a figure per test."""
    report.section(
        "Random motion (paper Fig. 15)",
        "Synthetic records of the EC8 Type 2 / ground D suite (ag S = 2.8 m/s^2) at the paper's load factors; "
        "experimental parameters, matched calibration. The paper's records are not available: ours are "
        "spectrum-compatible with the same target but are other realisations.",
    )
    rows = []
    cases: list[tuple[str, int, float, Scene, dict[str, Result]]] = []  # key, record, load factor, scene, results
    for key, record, factor in CASES:
        motion = {"type": "synthetic", "suite": "paper", "record": record, "load_factor": factor}
        scene = scene_from_dict(scene_dict([block_table(key)], motion, DURATION_S, 0.005, "matched"))
        cases.append((key, record, factor, scene, {}))
    scenes = [c[3] for c in cases]
    solvers: list[tuple[Solver, str]] = [
        (HousnerSolver(), "Housner"),
        (ReferenceSolver(record_energy=False), "reference DEM"),
    ]
    if use_yade:
        solvers.append((YadeSolver(), "YADE"))
    on = Executor("threads", workers)
    for solver, who in solvers:
        found = run_scenes(solver, scenes, executor=on, desc=f"random: {who}")
        for case, r in zip(cases, found, strict=True):
            case[4][solver.name] = r
    for key, record, factor, scene, results in cases:
        alpha = scene.blocks[0].alpha_rad
        for solver_name, r in results.items():
            report.record_result(f"specimen {key}, record {record} x {factor}", r)
            theta = r.series("theta_rad") if r.ok else np.array([np.nan])
            rows.append(
                {
                    "specimen": key,
                    "record": record,
                    "load_factor": factor,
                    "solver": solver_name,
                    "status": r.status,
                    "collapse": r.status == "overturned",
                    "overturn_time_s": r.meta.overturn_time_s,
                    "max_theta_over_alpha": float(np.nanmax(np.abs(theta)) / alpha),
                    "paper_collapse": True,
                    "failure_reason": r.meta.failure_reason or "",
                }
            )
        draw_figure(report, key, record, factor, scene, results)
    table = pd.DataFrame(rows)
    report.table(
        "random.csv",
        table,
        "collapse predicted or not by each solver (the paper reports collapse for both), "
        "overturn time and max |theta| / alpha.",
    )
    states = [f"{SOLVER_LABELS[s]}: {run_state(report, s, len(cases))}" for s in cases[0][4]]
    report.note("Runs: " + "; ".join(states) + ".")
    return table


def draw_figure(
    report: Report, key: str, record: int, factor: float, scene: Scene, results: dict[str, Result]
) -> SolverPanelsDisplay:
    """One specimen under one synthetic record: the base acceleration (m/s^2) and each
    solver's rotation over alpha (-) against time (s)
    (``random_specimen<key>_record<record>.png`` in the report's folder).

    Parameters
    ----------
    report
        The report the figure is written to.
    key, record, factor
        The specimen, the record's number and its load factor (-).
    scene
        The scene that was run.
    results
        The Results, by solver name.

    Returns
    -------
    SolverPanelsDisplay
        The display drawn (its ``figure_`` written as PNG).
    """
    gm = scene.motion.ground_motion(scene.duration_s)
    alpha = scene.blocks[0].alpha_rad
    assert gm is not None and alpha is not None  # a synthetic record; the specimens' measured alpha (specimens.py)
    name = f"random_specimen{key}_record{record}.png"
    note = no_uplift_note(scene, results)
    curves = []
    for solver, r in results.items():
        if not r.ok:
            curves.append(Curve(solver, f"{SOLVER_LABELS[solver]}: FAILED, no curve"))
            continue
        verdict = f"collapse at {r.meta.overturn_time_s:.2f} s" if r.status == "overturned" else "no collapse"
        label = f"{SOLVER_LABELS[solver]}: {verdict}"
        if solver == "yade" and results.get("reference") is not None and results["reference"].ok:
            label += f" (max |YADE - DEM| = {max_difference(r, results['reference']) / alpha:.2g} alpha)"
        curves.append(Curve(solver, label, r.t, r.series("theta_rad") / alpha))
    base = Panel(trace=(gm.t_s, gm.ah_m_s2), ylabel="a_g (m/s²)", hlines=())
    rotation = Panel(
        curves=curves,
        ylabel="theta / alpha",
        ylim=(-1.5, 1.5),
        hlines=((1.0, "--"), (-1.0, "--")),
        note=note,
        legend_loc="upper right",
    )
    title = f"Specimen {key}, synthetic record {record}, load factor {factor}" + (": NO UPLIFT" if note else "")
    display = SolverPanelsDisplay([[base], [rotation]], title=title, height_ratios=(1, 2)).plot(
        path=report.out / name, figsize=(10, 5.8)
    )
    verdicts = "; ".join(
        f"{s}: {'collapse' if r.status == 'overturned' else r.status}"
        + (f" ({r.meta.failure_reason})" if not r.ok else "")
        for s, r in results.items()
    )
    report.figure(
        name,
        (f"**{note}** " if note else "")
        + f"Specimen {key} under record {record} x {factor} (PGA {fmt(gm.pga_m_s2, 3)} m/s²): base "
        f"acceleration and theta/alpha (beyond +/-1 the block passes its critical angle). {verdicts}.",
    )
    return display
