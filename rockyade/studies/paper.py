"""The paper study: the seed paper reproduced end to end (``rockyade paper``).

Parts, in order: the tables (1-6), free rocking (Figs 9, 13), harmonic tests (Figs 14,
18, 19), random motion (Fig. 15), the bi-block pattern map (Section 7.2), sensitivity to
the classical parameters, collapse fragility over the synthetic suite, the overturning
spectrum under pulses, and the cross-check of the solvers under earthquakes (collapse
intensities paired by record, :mod:`rockyade.studies.paper_crosscheck`). Everything lands
in one directory with an ``index.md``.

Every run is logged in the report: a failed run (or a part that stops with an error) is
counted and listed in its part of ``index.md``, in ``failed_runs.csv`` and in the summary
the command prints, and makes ``rockyade paper`` exit non-zero.
"""

from __future__ import annotations

import sys
import time
import traceback
from pathlib import Path

from rockyade import __version__
from rockyade.io.atomic import write_text
from rockyade.studies.report import Report, cpu_seconds

PARTS = ("tables", "free", "harmonic", "random", "patterns", "sensitivity", "fragility", "overturning", "crosscheck")


def run_tables(report: Report) -> None:
    """Tables 1-6: paper value, ours, difference, consistency flag."""
    from rockyade.paper.tables import reproduction_report

    table = reproduction_report()
    report.section(
        "Tables 1-6 reproduced",
        "Each printed value beside what the paper's own equations give (rockyade.paper.tables); "
        "`consistent` is false where the printed number does not follow from the equations.",
    )
    for number in range(1, 7):
        part = table[table.table == number]
        n_bad = int((~part.consistent).sum())
        report.table(
            f"table{number}_reproduced.csv",
            part,
            f"Table {number}: paper value, ours, difference (%), equation, flag ({n_bad} of {len(part)} flagged).",
        )


def solvers_line(parts: tuple[str, ...], use_yade: bool) -> str:
    """The report header's sentence naming every solver the chosen parts run, and where."""
    from rockyade.siconos.backend import siconos_available

    out = ["Housner (exact classical, one block)", "the reference DEM (numba)"]
    if {"patterns", "crosscheck"} & set(parts):
        out.append("the exact two-block solver (`twoblock`: the bi-block's pattern map and cross-check)")
    if use_yade:
        out.append("YADE (Debian 2023.02a) on the same scenes")
    if "crosscheck" in parts:
        out.append(
            "Siconos (Debian's python3-siconos) on a subset of the cross-check"
            if siconos_available()
            else "not Siconos (python3-siconos is not installed: its subset of the cross-check is left out)"
        )
    tail = "" if use_yade else " (YADE off: --no-yade)"
    return f"Solvers: {', '.join(out[:-1])} and {out[-1]}{tail}."


def run_paper_study(
    out: str | Path, workers: int = 2, parts: tuple[str, ...] = PARTS, use_yade: bool = True, accel_unit: str = "g"
) -> Report:
    """Run the chosen parts; return the report (``index_path``, ``runs``, ``failures()``).
    ``accel_unit``: "g" (default) or "m/s2", the unit of the fragility figure's PGA axis.

    A part that raises is logged as a failed run with its error (the traceback goes to
    ``<part>_error.log``), and the next part runs.
    """
    from rockyade.studies import (
        fragility_study,
        free_rocking,
        harmonic,
        overturning,
        paper_crosscheck,
        pattern_map,
        random_motion,
        sensitivity,
    )

    report = Report(Path(out))
    report.out.mkdir(parents=True, exist_ok=True)
    timings: dict[str, tuple[float, float]] = {}
    steps = {
        "tables": lambda: run_tables(report),
        "free": lambda: free_rocking.run(report, workers, use_yade),
        "harmonic": lambda: harmonic.run(report, workers, use_yade),
        "random": lambda: random_motion.run(report, workers, use_yade),
        "patterns": lambda: pattern_map.run(report, workers),
        "sensitivity": lambda: sensitivity.run(report),
        "fragility": lambda: fragility_study.run(report, workers, use_yade, accel_unit),
        "overturning": lambda: overturning.run(report, workers),
        "crosscheck": lambda: paper_crosscheck.run(report, workers, use_yade),
    }
    for part in PARTS:
        if part not in parts:
            continue
        report.part = part
        start, cpu_start = time.perf_counter(), cpu_seconds()
        print(f"[paper] {part} ...", flush=True)
        sections_before = len(report.sections)
        try:
            steps[part]()
        except Exception as exc:  # a part that stops is reported, and the study goes on
            log = report.out / f"{part}_error.log"
            write_text(log, traceback.format_exc())
            reason = f"{type(exc).__name__}: {exc} (traceback in {log.name})"
            if len(report.sections) == sections_before:
                report.section(f"Part '{part}'")
            report.note(f"**This part stopped with an error** and its results are missing or partial: {reason}.")
            report.record(f"part '{part}'", "-", "failed", reason)
            print(f"[paper] {part} FAILED: {reason}", file=sys.stderr, flush=True)
        timings[part] = (time.perf_counter() - start, cpu_seconds() - cpu_start)
        report.close_part(part)
        n_failed = len(report.failures(part))
        tail = f", {n_failed} FAILED run(s)" if n_failed else ""
        wall, cpu = timings[part]
        print(f"[paper] {part} done in {wall:.0f} s ({cpu:.0f} s of CPU){tail}", flush=True)
    report.part = "run"
    report.section(
        "Run",
        "Wall time of each part (s; CPU time, all processes, in brackets): "
        + ", ".join(f"{k} {wall:.0f} ({cpu:.0f})" for k, (wall, cpu) in timings.items())
        + f"; rockyade {__version__}, {workers} worker(s), YADE {'on' if use_yade else 'off'}.",
    )
    report.write_index(
        "rockyade: the seed paper reproduced",
        "Generated by `rockyade paper` (`make run`) from the paper *Modeling the dynamic behavior of masonry walls "
        "as rigid blocks*. Conventions: SI units; theta > 0 pivots on the left corner; base acceleration > 0 "
        "towards +x; the paper's K read as MN/m. " + solvers_line(parts, use_yade),
    )
    return report
