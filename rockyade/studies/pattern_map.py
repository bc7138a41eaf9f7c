"""The bi-block rocking pattern map (paper Section 7.2, Fig. 17).

Frequency 1-7 Hz x displacement amplitude 0.5-8 mm table sines (``CYCLES`` stationary
cycles between 2-cycle ramps), experimental parameters, run by the reference DEM (the paper's
Eq 13 damping) and by the exact two-block solver (``twoblock``: the DEM's corners and inertia,
impacts conserving angular momentum). The dominant pattern of each cell (over the stationary
state) is set beside the regions the paper reports:

* pattern 2 at 4-5 Hz above 4 mm, at 6 Hz above 3 mm, at 7 Hz above 1 mm;
* pattern 3 at 1-5 Hz below 4 mm.

Cells on a region's boundary or outside both are "not reported".
"""

from __future__ import annotations

from dataclasses import replace

import pandas as pd

from rockyade.batch import expand, run_study_tasks
from rockyade.figures.canvas import new_figure, save_figure
from rockyade.figures.rocking_patterns import PatternMapDisplay
from rockyade.motion.analytic import Harmonic
from rockyade.motion.spec import MotionSpec
from rockyade.motion.types import HarmonicMotion
from rockyade.studies.report import Report, run_state
from rockyade.studies.specimen_scenes import biblock_blocks, scene_dict

FREQUENCIES_HZ = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0)
AMPLITUDES_MM = (0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0)
CYCLES = 10
#: The solvers of the map, and the suffix of their columns in the cells (``pattern_dem``, ...).
SOLVERS = {"reference": "dem", "twoblock": "exact"}
#: Each solver in words (the figure, the notes), by suffix.
SOLVER_LABELS = {"dem": "reference DEM", "exact": "exact two-block solver"}


def paper_pattern(freq: float, amp: float) -> str | None:
    """The pattern the paper reports for a cell, or None where it reports none."""
    if (4.0 <= freq <= 5.0 and amp > 4.0) or (freq == 6.0 and amp > 3.0) or (freq == 7.0 and amp > 1.0):
        return "2"
    if 1.0 <= freq <= 5.0 and amp < 4.0:
        return "3"
    return None


def _frequency_hz(motion: MotionSpec) -> float:
    """The frequency of a map cell's harmonic base motion, Hz."""
    if not isinstance(motion, HarmonicMotion):
        raise TypeError(f"the pattern map runs harmonic motions only, got {motion.type!r}")
    return motion.frequency_hz


def run(report: Report, workers: int = 2) -> pd.DataFrame:
    """Run the map; write ``pattern_map.csv`` and its figure; return the cells."""
    report.section(
        "Bi-block rocking pattern map (paper Section 7.2)",
        f"Reference DEM and the exact two-block solver, table sines of {CYCLES} stationary cycles; dominant "
        "pattern over the stationary state "
        "(Fig. 16: 1 same way, 2 opposite ways, 3 as one body, 4 upper only). Thresholds: a block rocks when "
        "|theta| (upper: relative to the lower one) exceeds 1 % of its alpha; windows of 1 s.",
    )
    base = scene_dict(
        biblock_blocks(),
        {"type": "harmonic", "amplitude_mm": 1.0, "frequency_hz": 1.0, "cycles": CYCLES},
        10.0,
        0.002,
        "paper",
    )
    tasks = []
    for freq in FREQUENCIES_HZ:
        end = Harmonic(1.0, freq, CYCLES, 2).phases_s["end_s"]
        d = dict(base, duration_s=round(end + 1.0, 6))
        d["motion"] = dict(d["motion"], frequency_hz=freq)
        tasks += expand(
            [(f"{freq:g}Hz", d)],
            {"motion.amplitude_mm": list(AMPLITUDES_MM)},
            list(SOLVERS),
            save_history=False,
        )
    tasks = [
        replace(t, index=i, labels={**t.labels, "frequency_hz": _frequency_hz(t.scene.motion)}, save_history=False)
        for i, t in enumerate(tasks)
    ]
    summary = run_study_tasks(
        tasks, report.out / "pattern_map_runs", workers=workers, desc="pattern map", resume_option=None
    )
    report.record_summary(summary, lambda row: f"{row['frequency_hz']:g} Hz, {row['motion.amplitude_mm']:g} mm")
    report.note(
        "Ran: "
        + "; ".join(f"{name}, {run_state(report, name, int((summary.solver == name).sum()))}" for name in SOLVERS)
        + "."
    )
    cells = None
    for name, key in SOLVERS.items():
        part = summary[summary.solver == name][["frequency_hz", "motion.amplitude_mm", "status", "pattern"]]
        part = part.rename(
            columns={"motion.amplitude_mm": "amplitude_mm", "pattern": f"pattern_{key}", "status": f"status_{key}"}
        )
        part[f"pattern_{key}"] = part[f"pattern_{key}"].where(part[f"status_{key}"] != "failed", "failed")
        cells = part if cells is None else cells.merge(part, on=["frequency_hz", "amplitude_mm"])
    assert cells is not None  # SOLVERS is not empty
    cells["pattern_paper"] = [paper_pattern(f, a) for f, a in zip(cells.frequency_hz, cells.amplitude_mm, strict=True)]
    for key in SOLVERS.values():
        cells[f"agree_{key}"] = [
            None if pd.isna(p) else bool(p == d)
            for p, d in zip(cells.pattern_paper, cells[f"pattern_{key}"], strict=True)
        ]
    report.table(
        "pattern_map.csv",
        cells,
        "dominant pattern of every cell, per solver (reference DEM, exact two-block solver), and the paper's "
        "where it reports one.",
    )
    same = int((cells.pattern_dem == cells.pattern_exact).sum())
    report.note(
        f"The exact solver and the reference DEM give the same dominant pattern in {same} of {len(cells)} cells."
    )
    stats = agreement(cells, "dem")
    draw_figure(report, cells, stats)
    return cells


def agreement(cells: pd.DataFrame, key: str) -> dict[str, tuple[int, int]]:
    """Pattern -> (cells where the solver of column suffix ``key`` agrees with the paper, cells
    in the paper's region), for patterns 2 and 3."""
    reported = cells.dropna(subset=["pattern_paper"])
    out: dict[str, tuple[int, int]] = {}
    for pattern in ("2", "3"):
        sel = reported[reported.pattern_paper == pattern]
        out[pattern] = (int(sel[f"agree_{key}"].astype(bool).sum()), len(sel))
    return out


def draw_figure(report: Report, cells: pd.DataFrame, stats: dict[str, tuple[int, int]]) -> PatternMapDisplay:
    """The map of rocking patterns over base-motion frequency (Hz) and amplitude (mm)
    (``pattern_map.png`` in the report's folder): one panel per solver (the reference DEM's,
    then the exact solver's where the cells have it), the paper's regions outlined on each,
    drawn by :class:`rockyade.figures.rocking_patterns.PatternMapDisplay`.

    Parameters
    ----------
    report
        The report the figure is written to.
    cells
        One row per frequency (Hz) and amplitude (mm): the DEM's dominant pattern
        (``pattern_dem``; ``agree`` or ``agree_dem``), the exact solver's where it ran
        (``pattern_exact``, ``agree_exact``) and the paper's.
    stats
        Pattern -> (cells where the DEM agrees with the paper, cells in the paper's region).

    Returns
    -------
    PatternMapDisplay
        The last panel's display (its ``figure_``, the whole figure, written as PNG).
    """
    name = "pattern_map.png"
    keys = [k for k in SOLVERS.values() if f"pattern_{k}" in cells]
    fig, axes = new_figure(report.out / name, nrows=len(keys), figsize=(10.5, 6 * len(keys)), squeeze=False)
    display = None
    words = []
    for ax, key in zip(axes[:, 0], keys, strict=True):
        agree = cells[f"agree_{key}"] if f"agree_{key}" in cells else cells["agree"]
        panel = cells.assign(pattern_dem=cells[f"pattern_{key}"], agree=agree)
        display = PatternMapDisplay(panel, FREQUENCIES_HZ, AMPLITUDES_MM, SOLVER_LABELS[key]).plot(ax)
        st = stats if key == "dem" else agreement(cells, key)
        words.append(
            f"{SOLVER_LABELS[key]}: pattern 2 {st['2'][0]} of {st['2'][1]} cells, pattern 3 {st['3'][0]} of "
            f"{st['3'][1]} cells"
        )
    save_figure(fig, report.out / name)
    assert display is not None  # the DEM's panel is always drawn
    report.figure(
        name,
        "Dominant pattern per cell (colour) with the paper's reported regions outlined (blue: pattern 2, red: "
        "pattern 3; solid where the solver agrees, dashed where not); one panel per solver. Agreement: "
        + "; ".join(words)
        + ".",
    )
    report.note(
        "Agreement with the paper's regions: "
        + "; ".join(words)
        + ". Much of the paper's pattern-3 region (low frequency, small amplitude) lies below the uplift "
        "acceleration of a rigid stack (a_g < g tan alpha): there both solvers stay at rest."
    )
    return display
