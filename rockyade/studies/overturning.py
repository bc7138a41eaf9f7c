"""Overturning spectrum under one-sine acceleration pulses.

For specimen 1 (experimental alpha and p), the minimum pulse amplitude that overturns the
block, a_p / (g tan alpha), against omega_p / p. The overturning region is not simply
connected (a stronger pulse can leave the block standing where a weaker one overturned
it), so for each frequency the amplitude is scanned upward from uplift in steps of
``STEP`` and the first amplitude that overturns is taken. Housner's exact solution and the
reference DEM (matched calibration); Housner also gives the full overturn map of the scan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from rockyade.analysis.metrics import uplift_threshold_rad
from rockyade.calibration.model_stage import calibrated_model
from rockyade.constants import G
from rockyade.figures.overturning_spectrum import OverturningSpectrumDisplay
from rockyade.figures.styles import SOLVER_LABELS
from rockyade.runner import Executor, run_jobs
from rockyade.scene import Scene, scene_from_dict
from rockyade.solvers.base import GroupSolver, Solver
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.studies.report import Report, run_state
from rockyade.studies.specimen_scenes import block_table, scene_dict

FREQUENCY_RATIOS = tuple(np.round(np.arange(1.0, 10.01, 0.5), 2))
STEP = 0.05
MAX_RATIO = 15.0
FREE_TIME_S = 4.0
#: Amplitudes run as one group in a scan that stops at the first overturn (the runs after it
#: in the group are not kept: at most CHUNK - 1 runs more than one at a time).
CHUNK = 8


def _scene(ratio_a: float, ratio_w: float, alpha: float, p: float):
    period = 2 * math.pi / (ratio_w * p)
    motion = {"type": "pulse", "shape": "sine", "amplitude_m_s2": ratio_a * G * math.tan(alpha), "period_s": period}
    return scene_from_dict(scene_dict([block_table("1")], motion, period + FREE_TIME_S, 0.002, "matched"))


@dataclass(frozen=True)
class Scan:
    """The amplitude scan at one pulse frequency.

    Attributes
    ----------
    solver
        The solver.
    ratio_w
        omega_p / p (-).
    alpha, p
        The block's alpha (rad) and p (rad/s).
    full
        Scan every amplitude up to ``max_ratio`` (else stop at the first overturn).
    grouped
        Run the amplitudes in groups where the solver can (:func:`run_scenes`; the same
        verdicts), else one run at a time.
    max_ratio
        Largest a_p / (g tan alpha) scanned (-); None: :data:`MAX_RATIO`.
    """

    solver: Solver
    ratio_w: float
    alpha: float
    p: float
    full: bool
    grouped: bool = True
    max_ratio: float | None = None


def amplitude_ratios(max_ratio: float | None = None) -> list[float]:
    """The amplitudes a_p / (g tan alpha) scanned, from uplift upward in steps of :data:`STEP`
    (the same accumulated sums as one step at a time), up to ``max_ratio`` (default :data:`MAX_RATIO`)."""
    top = MAX_RATIO if max_ratio is None else max_ratio
    ratios = []
    ratio_a = 1.0 + STEP
    while ratio_a <= top + 1e-9:
        ratios.append(ratio_a)
        ratio_a += STEP
    return ratios


def run_scenes(solver: Solver, scenes: list[Scene], alpha: float) -> list[tuple[str, str]]:
    """(status, failure reason) of each scene's run: together when the solver runs them as one
    group (``group_key``, ``run_group``: each run's own result), else one at a time."""
    if isinstance(solver, GroupSolver) and len(scenes) > 1:
        keys = {solver.group_key(s) for s in scenes}
        if len(keys) == 1 and None not in keys:
            try:
                runs = solver.run_group(scenes, uplift_threshold_rad(alpha))
                return [(one.status, one.meta.failure_reason or "") for one in runs]
            except Exception:  # a run of its own says what went wrong
                pass
    out = []
    for scene in scenes:
        result = solver.run(scene)
        out.append((result.status, result.meta.failure_reason or ""))
    return out


def _scan(scan: Scan) -> list[dict]:
    """Scan amplitudes upward at one frequency; stop at the first overturn unless ``full``.

    Grouped, a full scan runs every amplitude at once and a scan that stops runs
    :data:`CHUNK` amplitudes at a time, keeping the rows up to the first overturn."""
    solver = scan.solver
    ratios = amplitude_ratios(scan.max_ratio)
    size = 1 if not scan.grouped else len(ratios) if scan.full else CHUNK
    rows = []
    for start in range(0, len(ratios), max(1, size)):
        part = ratios[start : start + size]
        scenes = [_scene(ratio_a, scan.ratio_w, scan.alpha, scan.p) for ratio_a in part]
        for ratio_a, (status, reason) in zip(part, run_scenes(solver, scenes, scan.alpha), strict=True):
            rows.append(
                {
                    "solver": solver.name,
                    "omega_ratio": scan.ratio_w,
                    "amplitude_ratio": round(ratio_a, 4),
                    "overturned": status == "overturned",
                    "status": status,
                    "failure_reason": reason,
                }
            )
            if status == "overturned" and not scan.full:
                return rows
    return rows


def run(report: Report, workers: int = 2, grouped: bool = True) -> pd.DataFrame:
    """Compute the spectrum; write ``overturning_spectrum.csv``, the scan and the figure
    (``grouped``: amplitudes run in groups where the solver can, :class:`Scan`)."""
    report.section(
        "Overturning spectrum under one-sine pulses",
        "Specimen 1, experimental alpha = 0.235 rad and p = 3.84 1/s; minimum a_p / (g tan alpha) that overturns the "
        f"block, scanning the amplitude upward in steps of {STEP} (the overturning region is not simply connected).",
    )
    block = block_table("1")
    alpha, p = block["alpha_rad"], block["p_rad_s"]
    calibrated_model(_scene(2.0, 2.0, alpha, p))  # matched beta once, before the workers fork
    dem = ReferenceSolver(record_energy=False, record_contacts=False)
    jobs = [Scan(HousnerSolver(), w, alpha, p, True, grouped) for w in FREQUENCY_RATIOS] + [
        Scan(dem, w, alpha, p, False, grouped) for w in FREQUENCY_RATIOS
    ]
    scans = run_jobs(
        jobs, _scan, executor=Executor("local", workers), progress=True, desc="overturning: frequency scans"
    )
    if scans.unfinished:
        raise KeyboardInterrupt
    scan = pd.DataFrame([row for rows in scans.in_order() for row in rows])
    report.record_summary(
        scan,
        lambda row: f"pulse omega_p / p = {row['omega_ratio']:g}, a_p / (g tan alpha) = {row['amplitude_ratio']:g}",
    )
    report.note(
        "Ran: "
        + "; ".join(
            f"{SOLVER_LABELS[s]}: {run_state(report, s, int((scan.solver == s).sum()))}"
            for s in ("housner", "reference")
        )
        + "."
    )
    minima = []
    for (solver, w), group in scan.groupby(["solver", "omega_ratio"]):
        over = group[group.overturned]
        minima.append(
            {
                "solver": solver,
                "omega_ratio": w,
                "min_overturn_amplitude_ratio": float(over.amplitude_ratio.min()) if len(over) else math.nan,
            }
        )
    spectrum = (
        pd.DataFrame(minima)
        .pivot(index="omega_ratio", columns="solver", values="min_overturn_amplitude_ratio")
        .reset_index()
    )
    spectrum.columns.name = None
    spectrum = spectrum.rename(columns={"housner": "housner_min_ratio", "reference": "reference_min_ratio"})
    report.table(
        "overturning_spectrum.csv",
        spectrum,
        "minimum overturning amplitude a_p / (g tan alpha) per omega_p / p "
        "(NaN: no overturn up to the largest amplitude scanned).",
    )
    report.table("overturning_scan.csv", scan, "every pulse run of the scan: overturned or not.")
    draw_figure(report, scan, spectrum)
    return spectrum


def draw_figure(report: Report, scan: pd.DataFrame, spectrum: pd.DataFrame) -> OverturningSpectrumDisplay:
    """The overturning spectrum (``overturning_spectrum.png`` in the report's folder, drawn by
    :class:`rockyade.figures.overturning_spectrum.OverturningSpectrumDisplay`).

    Parameters
    ----------
    report
        The report the figure is written to.
    scan
        The runs scanned: one row per solver, frequency ratio and amplitude ratio (-), and
        whether the block overturned.
    spectrum
        The minimum overturning amplitude ratio (-) against the frequency ratio (-).

    Returns
    -------
    OverturningSpectrumDisplay
        The display drawn (its ``figure_`` written as PNG).
    """
    name = "overturning_spectrum.png"
    display = OverturningSpectrumDisplay.from_frames(scan, spectrum, MAX_RATIO).plot(path=report.out / name)
    report.figure(
        name,
        "Minimum overturning amplitude of a one-sine acceleration pulse against its frequency (lines), "
        "and every amplitude at which Housner's block overturns (dots): above the minimum there are "
        "bands where the block survives (the region is not simply connected). Open triangles at the "
        f"top: no overturn up to {MAX_RATIO:g} g tan alpha, the largest amplitude scanned.",
    )
    return display
