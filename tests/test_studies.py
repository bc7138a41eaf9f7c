"""The paper study: failed runs are counted, listed and make it exit non-zero; progress is
shown; its figures say when blocks never uplift, keep overlapping solvers visible, flag
extrapolated medians, and name the rocking patterns in words."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgb

from rockyade.constants import G
from rockyade.dem.statics import column_uplift
from rockyade.figures.styles import SOLVER_STYLES
from rockyade.motion.analytic import Harmonic
from rockyade.scene import scene_from_dict
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.studies import fragility_study, harmonic, overturning, paper, pattern_map
from rockyade.studies.report import Report, no_uplift_note
from rockyade.studies.specimen_scenes import biblock_blocks, block_table, scene_dict


def _legend_texts(fig) -> list[str]:
    return [t.get_text() for ax in fig.axes if ax.get_legend() for t in ax.get_legend().get_texts()]


# ------------------------------------------------------------------ failed runs


@pytest.mark.slow
def test_paper_exits_nonzero_and_lists_every_failed_run(tmp_path, monkeypatch, capsys):
    """YADE made unreachable (its module path points nowhere): every YADE run of the
    free-rocking part fails for real; the study says so everywhere and exits 1. 23 DEM cases:
    of the 24, one matched calibration is out of the DEM's reach. (The command's ``main`` in
    this process, from the test's folder: a process of its own only added its start-up.)"""
    from rockyade.cli import main
    from rockyade.yade import backend

    nowhere = str(tmp_path / "no-yade-here")
    monkeypatch.setenv("ROCKYADE_YADE_PY", nowhere)  # for any process the study starts
    monkeypatch.setattr(backend, "YADE_PY_DIR", nowhere)  # read when rockyade.yade.backend is imported
    monkeypatch.chdir(tmp_path)
    code = main(["paper", "--only", "free", "--out", "out/paper"])
    proc = capsys.readouterr()
    assert code == 1, proc.out + proc.err
    assert "23 of 60 runs FAILED" in proc.out
    assert "[free] yade, 23 run(s)" in proc.out and "YADE is not installed" in proc.out
    index = (tmp_path / "out/paper/index.md").read_text()
    assert "**Status: 23 of 60 runs FAILED** (free: 23)" in index
    assert "YADE: all 23 runs failed" in index and "reference DEM: all 23 runs succeeded" in index
    assert "**23 FAILED**" in index
    failed = pd.read_csv(tmp_path / "out/paper/failed_runs.csv")
    assert len(failed) == 23 and set(failed.solver) == {"yade"} and set(failed.part) == {"free"}
    # progress of the free-rocking part, on stderr
    assert "free rocking: reference DEM" in proc.err and "23/23" in proc.err


def test_a_part_that_raises_is_a_failure_and_the_study_goes_on(tmp_path, monkeypatch):
    from rockyade.studies import sensitivity

    def broken(report):
        report.section("Sensitivity")
        raise RuntimeError("the variant table is empty")

    monkeypatch.setattr(sensitivity, "run", broken)
    report = paper.run_paper_study(tmp_path, parts=("sensitivity", "tables"))
    [failure] = report.failures()
    assert failure.part == "sensitivity" and "RuntimeError: the variant table is empty" in failure.reason
    index = report.index_path.read_text()
    assert "**This part stopped with an error**" in index and "Tables 1-6 reproduced" in index
    assert "**Status: 1 of 1 runs FAILED** (sensitivity: 1)" in index
    assert "Traceback" in (tmp_path / "sensitivity_error.log").read_text()


def test_failures_that_differ_only_by_their_run_files_are_grouped(tmp_path):
    report = Report(tmp_path)
    report.part = "fragility"
    report.section("Fragility")
    for run_hash in ("9e30328ec611424b", "8b3fb1e9218edfbf"):
        report.record(f"run {run_hash[:3]}", "yade", "failed", f"No such file: 'runs/{run_hash}_yade.yade.json'")
    report.record("run x", "yade", "failed", "timeout")
    groups = report.failure_groups()
    assert [(len(runs), reason) for _, _, reason, runs in groups] == [
        (2, "No such file: 'runs/<hash>_yade.yade.json'"),
        (1, "timeout"),
    ]


def test_all_runs_succeeded_is_stated(tmp_path):
    report = Report(tmp_path)
    report.part = "demo"
    report.section("Demo")
    report.record("a", "housner", "completed")
    report.record("b", "reference", "overturned")
    report.close_part("demo")
    text = report.write_index("t", "p").read_text()
    assert (
        "all 2 runs ended without failure" in text and "**Runs:** 2 (1 completed, 1 overturned); none failed." in text
    )


# ------------------------------------------------------------------ uplift


def test_uplift_of_one_block_is_g_tan_alpha():
    scene = scene_from_dict(scene_dict([block_table("3")], {"type": "free", "theta0_rad": 0.01}, 1.0))
    up = column_uplift(scene)
    assert up.accel_m_s2 == pytest.approx(G * math.tan(0.154), rel=1e-12)
    assert up.mechanism == "specimen3 rocking on the base"


def test_uplift_of_the_biblock_is_its_weakest_mechanism():
    """Upper block alone on the lower one (g tan alpha_U) against the stack as one body on
    the lower block's equivalent base b = h_L tan alpha_L (h_L = 0.3 m, Table 2)."""
    scene = scene_from_dict(scene_dict(biblock_blocks(), {"type": "free", "theta0_rad": 0.01}, 1.0))
    upper_alone = G * math.tan(0.229)
    h_stack = (204 * 0.3 + 91 * (0.6 + 0.3)) / (204 + 91)
    stack = G * 0.3 * math.tan(0.366) / h_stack
    up = column_uplift(scene)
    assert up.accel_m_s2 == pytest.approx(min(upper_alone, stack), rel=1e-12)
    assert up.mechanism == "upper rocking on lower"


def _harmonic_case(key: str, freq: float, amp: float, cycles: int = 3) -> dict:
    h = Harmonic(amp, freq, cycles, 2)
    d = scene_dict([block_table(key)], harmonic._motion(freq, amp) | {"cycles": cycles}, h.phases_s["end_s"] + 1.0)
    scene = scene_from_dict(d)
    results = {
        "housner": HousnerSolver().run(scene),
        "reference": ReferenceSolver(record_energy=False, record_contacts=False).run(scene),
    }
    return {
        "name": f"specimen{key}_{freq:g}Hz_{amp:g}mm",
        "fig": "Fig. x",
        "scene": scene,
        "harmonic": h,
        "results": results,
    }


def test_a_harmonic_test_without_uplift_says_so_on_a_fixed_scale(tmp_path):
    """Specimen 3 at 3 Hz / 4 mm: 1.42 m/s^2 < g tan(0.154) = 1.52 m/s^2 (paper Fig. 14b)."""
    report = Report(tmp_path)
    report.section("Harmonic")
    case = _harmonic_case("3", 3.0, 4.0)
    fig = harmonic.draw_figure(report, case).figure_
    assert "NO UPLIFT" in fig._suptitle.get_text()
    assert fig.axes[1].get_ylim() == pytest.approx((-1.1, 1.1))
    assert fig.axes[1].get_ylabel() == "specimen3: theta / alpha"
    assert any("No uplift: the largest base acceleration" in t.get_text() for t in fig.axes[1].texts)
    assert "**No uplift" in report.sections[-1][1][-1]
    assert (tmp_path / "harmonic_specimen3_3Hz_4mm.png").stat().st_size > 10_000


def test_a_harmonic_test_that_rocks_is_not_flagged(tmp_path):
    """Specimen 1 at 3.3 Hz / 6 mm: 2.58 m/s^2 > g tan(0.235) = 2.35 m/s^2: it rocks."""
    report = Report(tmp_path)
    report.section("Harmonic")
    case = _harmonic_case("1", 3.3, 6.0)
    assert no_uplift_note(case["scene"], case["results"]) == ""
    fig = harmonic.draw_figure(report, case).figure_
    assert "NO UPLIFT" not in fig._suptitle.get_text()
    peak = max(np.max(np.abs(r.series("theta_rad"))) for r in case["results"].values()) / 0.235
    assert peak > 0.05 and fig.axes[1].get_ylim()[1] >= peak


# ------------------------------------------------------------------ figure styles


def test_dem_and_yade_stay_distinguishable_where_they_overlap():
    """Identical curves: the DEM is a wide translucent band, YADE a dashed line drawn on top."""
    dem, yade = SOLVER_STYLES["reference"], SOLVER_STYLES["yade"]
    assert dem["lw"] >= 2.5 * yade["lw"] and dem["alpha"] < 1.0
    assert yade["ls"] != "-" and yade["zorder"] > dem["zorder"]
    assert to_rgb(dem["color"]) != to_rgb(yade["color"]) != to_rgb(SOLVER_STYLES["housner"]["color"])


def _summary(specimen: str, solver: str, collapses: dict[float, int], n_records: int = 10, status=None) -> list[dict]:
    rows = []
    for lf in fragility_study.LOAD_FACTORS:
        for k in range(n_records):
            rows.append(
                {
                    "specimen": specimen,
                    "solver": solver,
                    "load_factor": lf,
                    "record": k + 1,
                    "status": status or ("overturned" if k < collapses.get(lf, 0) else "completed"),
                    "collapsed": status is None and k < collapses.get(lf, 0),
                    "failure_reason": "YADE exited with code 1" if status == "failed" else None,
                }
            )
    return rows


@pytest.mark.slow
def test_fragility_flags_extrapolated_medians_and_explains_a_missing_curve(tmp_path):
    summary = pd.DataFrame(
        _summary("specimen1", "reference", {1.3: 1, 1.4: 2, 1.5: 3})  # median far above 1.5 x 2.8 m/s^2
        + _summary(
            "specimen2", "reference", {lf: round(10 * min(1.0, lf / 0.8) ** 3) for lf in fragility_study.LOAD_FACTORS}
        )
        + _summary("specimen2", "yade", {}, status="failed")
    )
    stripes, fits = fragility_study.fit_table(summary)
    fit1 = fits[(fits.specimen == "specimen1")].iloc[0]
    assert fit1.status == "fitted" and fit1.median_pga_m_s2 > 1.5 * 2.8 and bool(fit1.extrapolated)
    fit2 = fits[(fits.specimen == "specimen2") & (fits.solver == "reference")].iloc[0]
    assert fit2.median_pga_m_s2 < 1.5 * 2.8 and not bool(fit2.extrapolated)
    yade = fits[fits.solver == "yade"].iloc[0]
    assert yade.status.startswith("not fitted: 150 of 150 runs failed") and yade.failure_reason

    report = Report(tmp_path)
    report.section("Fragility")
    fig = fragility_study.draw_figure(report, stripes, fits)
    assert any("EXTRAPOLATED" in t for t in _legend_texts(fig))
    assert any("YADE: no curve" in t and "YADE exited with code 1" in t for t in _legend_texts(fig))
    assert "median extrapolated" in report.sections[-1][1][-1] and "YADE: no curve" in report.sections[-1][1][-1]


def test_pattern_legend_is_in_words(tmp_path):
    cells = pd.DataFrame(
        {
            "frequency_hz": [1.0, 2.0, 4.0, 7.0],
            "amplitude_mm": [0.5, 1.0, 5.0, 8.0],
            "status": ["completed"] * 3 + ["overturned"],
            "pattern_dem": ["rest", "3", "2", "overturn-upper"],
        }
    )
    cells["pattern_paper"] = [
        pattern_map.paper_pattern(f, a) for f, a in zip(cells.frequency_hz, cells.amplitude_mm, strict=True)
    ]
    cells["agree"] = [
        None if p is None else p == d for p, d in zip(cells.pattern_paper, cells.pattern_dem, strict=True)
    ]
    report = Report(tmp_path)
    report.section("Patterns")
    fig = pattern_map.draw_figure(report, cells, {"2": (1, 1), "3": (1, 2)}).figure_
    labels = _legend_texts(fig)
    assert "2: both rock, opposite ways" in labels and "3: the stack rocks as one body" in labels
    assert "OT upper: the upper block overturns" in labels
    assert not [label for label in labels if label.strip().isdigit()]


def test_overturning_draws_housner_dots_in_housner_colour(tmp_path):
    scan = pd.DataFrame(
        {
            "solver": ["housner"] * 3 + ["reference"],
            "omega_ratio": [2.0, 2.0, 3.0, 2.0],
            "amplitude_ratio": [2.0, 2.5, 3.0, 2.1],
            "overturned": [True, True, True, True],
        }
    )
    spectrum = pd.DataFrame(
        {"omega_ratio": [2.0, 3.0], "housner_min_ratio": [2.0, 3.0], "reference_min_ratio": [2.1, 3.2]}
    )
    report = Report(tmp_path)
    report.section("Overturning")
    fig = overturning.draw_figure(report, scan, spectrum).figure_
    dots = fig.axes[0].collections[0]
    assert "Housner" in dots.get_label()
    assert tuple(dots.get_facecolor()[0][:3]) == pytest.approx(to_rgb(SOLVER_STYLES["housner"]["color"]))
    lines = {line.get_label(): line for line in fig.axes[0].lines}
    assert to_rgb(lines["Housner: minimum"].get_color()) == to_rgb(SOLVER_STYLES["housner"]["color"])


def test_overturning_marks_frequencies_where_a_solver_never_overturned(tmp_path):
    """A missing point is not a gap in the line: it says the block survived every amplitude scanned."""
    scan = pd.DataFrame(
        {"solver": ["reference"], "omega_ratio": [10.0], "amplitude_ratio": [14.4], "overturned": [True]}
    )
    spectrum = pd.DataFrame(
        {"omega_ratio": [9.5, 10.0], "housner_min_ratio": [13.5, np.nan], "reference_min_ratio": [13.0, 14.4]}
    )
    report = Report(tmp_path)
    report.section("Overturning")
    fig = overturning.draw_figure(report, scan, spectrum).figure_
    lines = {line.get_label(): line for line in fig.axes[0].lines}
    marker = lines[f"Housner: no overturn up to {overturning.MAX_RATIO:g} (the scan's limit)"]
    assert list(marker.get_xdata()) == [10.0] and list(marker.get_ydata()) == [overturning.MAX_RATIO]
    assert not any(label.startswith("reference DEM: no overturn") for label in lines)


@pytest.mark.slow
def test_overturning_scan_shows_progress(tmp_path, monkeypatch, capfd):
    monkeypatch.setattr(overturning, "FREQUENCY_RATIOS", (6.0,))
    monkeypatch.setattr(overturning, "MAX_RATIO", 2.0)
    report = Report(tmp_path)
    report.part = "overturning"
    spectrum = overturning.run(report, workers=2)
    err = capfd.readouterr().err
    assert "overturning: frequency scans" in err and "2/2" in err
    assert len(spectrum) == 1 and report.counts("overturning")


def test_fragility_compares_yade_and_the_reference_run_for_run():
    """The YADE subset's curve is fitted on three stripes; the report also puts both DEMs side
    by side on the same runs, where they can be compared without a fit."""
    rows = []
    for record in (1, 2):
        for lf, (y, r) in {
            0.4: ("completed", "completed"),
            1.2: ("overturned", "completed" if record == 1 else "overturned"),
        }.items():
            for solver, status in (("yade", y), ("reference", r)):
                rows.append(
                    {
                        "specimen": "specimen2",
                        "record": record,
                        "load_factor": lf,
                        "solver": solver,
                        "status": status,
                    }
                )
    rows.append(
        {
            "specimen": "specimen2",
            "record": 3,
            "load_factor": 1.2,
            "solver": "reference",
            "status": "overturned",
        }
    )
    table = fragility_study.same_runs_table(pd.DataFrame(rows)).set_index("load_factor")
    assert table.loc[0.4, "runs"] == 2 and table.loc[0.4, "same_outcome"] == 2
    assert table.loc[1.2, "runs"] == 2  # record 3 has no YADE run: not compared
    assert table.loc[1.2, "yade_overturned"] == 2 and table.loc[1.2, "reference_overturned"] == 1
    assert table.loc[1.2, "same_outcome"] == 1
