"""Sensitivity to the classical parameters (the paper's conclusion that small changes matter).

Specimen 1 with its experimental parameters; alpha, p and mu changed by +/-5 % one at a
time. Responses: free rocking from a fixed tilt (0.1175 rad) - the 5th peak amplitude and
its time; and the 3.3 Hz / 6 mm table sine - max |theta|. Housner's exact solution and the
reference DEM (matched calibration, redone for each variant; a variant whose mu the DEM
cannot reach is reported as such).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rockyade import paper
from rockyade.blocks.restitution import find_peaks
from rockyade.errors import CalibrationError
from rockyade.figures.parameter_sensitivity import SensitivityDisplay
from rockyade.scene import scene_from_dict
from rockyade.solvers.base import Solver
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.studies.report import Report
from rockyade.studies.specimen_scenes import block_table, scene_dict

CHANGE = 0.05
THETA0 = 0.1175
PEAK = 5
SOLVERS: tuple[Solver, ...] = (HousnerSolver(), ReferenceSolver(record_energy=False, record_contacts=False))


def _responses(block: dict, solver: Solver, report: Report, label: str) -> dict[str, float]:
    """The three responses of one variant by one solver (NaN where a run failed); runs logged."""
    free = scene_from_dict(scene_dict([block], {"type": "free", "theta0_rad": THETA0}, 4.0, 0.001, "matched"))
    sine = scene_from_dict(
        scene_dict(
            [block], {"type": "harmonic", "amplitude_mm": 6.0, "frequency_hz": 3.3, "cycles": 20}, 9.0, 0.002, "matched"
        )
    )
    out: dict[str, float] = {}
    r = solver.run(free)
    report.record_result(f"{label}, free rocking", r)
    peaks = find_peaks(r.t, r.series("theta_rad"), 1e-4) if r.ok else None
    if peaks is not None and len(peaks) >= PEAK:
        amplitude, time = float(peaks.amplitude_rad[PEAK - 1]), float(peaks.t_s[PEAK - 1])
    else:
        amplitude = time = math.nan
    out[f"free rocking: peak {PEAK} amplitude (rad)"] = amplitude
    out[f"free rocking: peak {PEAK} time (s)"] = time
    r = solver.run(sine)
    report.record_result(f"{label}, 3.3 Hz / 6 mm sine", r)
    out["3.3 Hz / 6 mm sine: max |theta| (rad)"] = float(np.max(np.abs(r.series("theta_rad")))) if r.ok else math.nan
    return out


def run(report: Report) -> pd.DataFrame:
    """Run the variants; write ``sensitivity.csv`` and its figure."""
    report.section(
        "Sensitivity to alpha, p and mu (+/-5 %)",
        "Specimen 1, experimental parameters; one parameter changed at a time.",
    )
    base_block = block_table("1")
    rows = []
    base = {s.name: _responses(base_block, s, report, "base parameters") for s in SOLVERS}
    for parameter in ("alpha_rad", "p_rad_s", "mu"):
        for sign in (-1, 1):
            block = dict(base_block)
            block[parameter] = base_block[parameter] * (1 + sign * CHANGE)
            for solver in SOLVERS:
                try:
                    values = _responses(block, solver, report, f"{parameter} {100 * sign * CHANGE:+g} %")
                    note = ""
                except CalibrationError as exc:
                    values = {k: math.nan for k in base[solver.name]}
                    note = f"DEM cannot be matched: {str(exc).split(':')[0]}"
                    report.record(f"{parameter} {100 * sign * CHANGE:+g} %", solver.name, "not run", note)
                for response, value in values.items():
                    ref = base[solver.name][response]
                    rows.append(
                        {
                            "parameter": parameter,
                            "change_pct": 100 * sign * CHANGE,
                            "value_changed_to": block[parameter],
                            "solver": solver.name,
                            "response": response,
                            "value": value,
                            "base_value": ref,
                            "relative_change_pct": 100 * (value / ref - 1) if ref else math.nan,
                            "note": note,
                        }
                    )
    table = pd.DataFrame(rows)
    report.table(
        "sensitivity.csv",
        table,
        "each response with alpha, p or mu changed by -5 % and +5 %, its base value and the relative change (%).",
    )
    draw_figure(report, table)
    spread = table.groupby("parameter")["relative_change_pct"].apply(lambda s: np.nanmax(np.abs(s)))
    report.note(
        "Largest relative change of any response: "
        + ", ".join(f"{p} {v:.0f} %" for p, v in spread.items())
        + " for a 5 % change of the parameter."
    )
    return table


def draw_figure(report: Report, table: pd.DataFrame) -> SensitivityDisplay:
    """The change of each response (%) when alpha, p or mu changes by -5 % or +5 %, one panel
    per response, Housner beside the reference DEM (``sensitivity.png`` in the report's folder), drawn by
    :class:`rockyade.figures.parameter_sensitivity.SensitivityDisplay`.

    Parameters
    ----------
    report
        The report the figure is written to.
    table
        One row per response, solver, parameter and change (%): the response's relative change (%).

    Returns
    -------
    SensitivityDisplay
        The display drawn (its ``figure_`` written as PNG).
    """
    name = "sensitivity.png"
    display = SensitivityDisplay(table).plot(path=report.out / name)
    report.figure(
        name,
        "Relative change of each response when alpha, p or mu of specimen 1 changes by -5 % or +5 % "
        f"(Housner and the reference DEM; missing bars: the DEM cannot be matched to that mu). "
        f"Base: {paper.specimen(1).label}, experimental parameters.",
    )
    return display
