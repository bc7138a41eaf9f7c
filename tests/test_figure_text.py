"""No text drawn over text in the paper study's and the how-to's figures (issue 26 item 8):
:func:`rockyade.figures.legibility.overlapping_texts` compares the window extents of every visible
text after a draw. The figures are built from small data (or cheap commands) so that this is quick."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
from matplotlib.figure import Figure

from rockyade.cli import main
from rockyade.figures.legibility import covered_markers, overlapping_texts
from rockyade.studies import fragility_study, overturning
from rockyade.studies.report import Report

from .conftest import EC8_LC1

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_the_check_finds_two_labels_drawn_over_each_other():
    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    ax.text(0.5, 0.5, "one label")
    ax.text(0.52, 0.5, "another label")
    assert overlapping_texts(fig) == [("one label", "another label")]
    ax.plot([0.05], [0.95], "o", label="a point")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(loc="upper left")
    assert covered_markers(fig) == ["a point"]


def _summary(specimen: str, solver: str, collapses: dict[float, int], n_records: int = 4) -> list[dict]:
    return [
        {
            "specimen": specimen,
            "solver": solver,
            "load_factor": lf,
            "record": k + 1,
            "status": "overturned" if k < collapses.get(lf, 0) else "completed",
            "collapsed": k < collapses.get(lf, 0),
            "failure_reason": None,
        }
        for lf in fragility_study.LOAD_FACTORS
        for k in range(n_records)
    ]


@pytest.mark.parametrize("accel_unit", ["g", "m/s2"])
def test_the_paper_fragility_figure_has_no_overlapping_text(tmp_path, accel_unit):
    rows = []
    for n, specimen in enumerate(("specimen1", "specimen2", "specimen3", "specimen4")):
        for solver in ("reference", "housner"):
            rows += _summary(
                specimen, solver, {lf: min(4, round(4 * lf / (0.6 + 0.2 * n))) for lf in (1.2, 1.3, 1.4, 1.5)}
            )
    stripes, fits = fragility_study.fit_table(pd.DataFrame(rows))
    report = Report(tmp_path)
    report.section("Fragility")
    fig = fragility_study.draw_figure(report, stripes, fits, accel_unit)
    assert overlapping_texts(fig) == []
    caption = report.sections[-1][1][-1]
    if "extrapolated beyond" in caption:  # the largest tested PGA in the figure's unit
        unit = "g" if accel_unit == "g" else "m/s²"
        assert f"extrapolated beyond 0.428 {unit}" in caption or f"extrapolated beyond 4.2 {unit}" in caption


def test_the_paper_overturning_figure_has_no_overlapping_text(tmp_path):
    scan = pd.DataFrame(
        {
            "solver": ["housner", "reference"],
            "omega_ratio": [2.0, 3.0],
            "amplitude_ratio": [2.0, 3.0],
            "overturned": [True, True],
        }
    )
    spectrum = pd.DataFrame(
        {"omega_ratio": [2.0, 3.0], "housner_min_ratio": [2.0, 3.0], "reference_min_ratio": [2.1, 3.2]}
    )
    report = Report(tmp_path)
    report.section("Overturning")
    assert overlapping_texts(overturning.draw_figure(report, scan, spectrum).figure_) == []


@pytest.fixture
def drawn(monkeypatch):
    """The figures the commands save, kept (they are still written)."""
    figures: list[Figure] = []
    import rockyade.figures.collapse_mechanism as limit_figures
    import rockyade.figures.histories as histories
    import rockyade.figures.wall_assessment as assess_figures

    for module in (assess_figures, histories, limit_figures):
        original = module.save_figure

        def keep(fig, path, *args, _original=original, **kwargs):
            figures.append(fig)
            return _original(fig, path, *args, **kwargs)

        monkeypatch.setattr(module, "save_figure", keep)
    return figures


@pytest.mark.parametrize(
    "argv",
    [
        ["limit", "assemblies/wall_5_courses.toml", "--no-sliding", "--plot", "OUT/limit.png"],
        ["limit", "assemblies/wall_5_courses.toml", "--plot", "OUT/limit.png"],
        [
            "assess",
            "free_standing_wall.toml",
            *EC8_LC1,
            "--static-only",
            "--out",
            "OUT/wall",
        ],
        ["run", "specimen1_free.toml", "--solver", "housner", "--out", "OUT/free.csv", "--plot", "OUT/free.png"],
    ],
)
@pytest.mark.slow
def test_the_howto_figures_have_no_overlapping_text(tmp_path, drawn, argv):
    args = [str(EXAMPLES / a) if a.endswith(".toml") else a.replace("OUT", str(tmp_path)) for a in argv]
    assert main(args) == 0
    assert drawn, "the command drew no figure"
    for fig in drawn:
        assert overlapping_texts(fig) == []
        assert covered_markers(fig) == []
