"""Engineers' units (issue "What users hit" 11): PGA in g by default where a command is about
it, m/s^2 beside it, and every "load factor" says what it multiplies."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.constants import STANDARD_GRAVITY
from rockyade.studies import fragility_study
from rockyade.studies.report import Report

from .conftest import EXAMPLES

RECORD = str(EXAMPLES / "records" / "ec8_type2_D_record21.AT2")


def test_motion_info_gives_the_pga_in_g_first_and_m_s2_beside_it(capsys):
    assert main(["motion", "info", RECORD]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "PGA" in x)
    assert line.strip().startswith("PGA = 0.3714 g (3.642 m/s^2)")
    assert main(["motion", "info", RECORD, "--accel-units", "m/s2"]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if "PGA" in x)
    assert line.strip().startswith("PGA = 3.642 m/s^2 (0.3714 g)")
    assert main(["motion", "info", RECORD, "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["pga_g"] == pytest.approx(info["pga_m_s2"] / STANDARD_GRAVITY)


def test_motion_spectrum_writes_psa_in_g_and_m_s2(tmp_path, capsys):
    out = tmp_path / "spectrum.csv"
    assert main(["motion", "spectrum", RECORD, "-n", "5", "--out", str(out), "--plot", str(tmp_path / "s.png")]) == 0
    table = pd.read_csv(out)
    assert list(table.columns) == ["period_s", "psa_g", "psa_m_s2"]
    np.testing.assert_allclose(table["psa_g"], table["psa_m_s2"] / STANDARD_GRAVITY, rtol=1e-7)


def _fits():
    rows = []
    for lf in fragility_study.LOAD_FACTORS:
        for k in range(10):
            rows.append(
                {
                    "specimen": "specimen2",
                    "solver": "reference",
                    "load_factor": lf,
                    "record": k + 1,
                    "status": "overturned" if k < round(10 * min(1.0, lf / 0.8) ** 3) else "completed",
                    "collapsed": k < round(10 * min(1.0, lf / 0.8) ** 3),
                    "failure_reason": None,
                }
            )
    return fragility_study.fit_table(pd.DataFrame(rows))


@pytest.mark.parametrize(("unit", "scale", "other"), [("g", STANDARD_GRAVITY, "m/s"), ("m/s2", 1.0, "(g)")])
def test_the_paper_fragility_figure_is_in_g_by_default_with_the_other_unit_on_top(tmp_path, unit, scale, other):
    stripes, fits = _fits()
    report = Report(tmp_path)
    report.section("Fragility")
    fig = fragility_study.draw_figure(report, stripes, fits, unit) if unit != "g" else None
    fig = fig or fragility_study.draw_figure(report, stripes, fits)
    ax = fig.axes[0]
    points = next(line for line in ax.get_lines() if line.get_marker() == "o")
    expected = stripes[stripes.solver == "reference"].pga_m_s2.to_numpy() / scale
    np.testing.assert_allclose(np.sort(points.get_xdata()), np.sort(expected))
    xlabel = fig.axes[2].get_xlabel()
    assert ("(g)" if unit == "g" else "(m/s$^2$)") in xlabel
    # what the load factor multiplies is said in the caption (the x label stays short: no overlap)
    assert any("accelerations as read" in str(item) for item in report.sections[-1][1])
    assert any(other in child.get_xlabel() for child in ax.child_axes)  # the other unit, on top


@pytest.mark.parametrize(
    ("argv", "words"),
    [
        (["build", "wall", "--help"], "multiplies the record's accelerations as read"),
        (["uncertainty", "--help"], "accelerations as read"),
        (["uncertainty", "--help"], "--accel-units {g,m/s2}"),
        (["paper", "--help"], "--accel-units {g,m/s2}"),
        (["motion", "spectrum", "--help"], "--accel-units {g,m/s2}"),
    ],
)
def test_help_says_what_a_load_factor_multiplies_and_offers_g(capsys, argv, words):
    with pytest.raises(SystemExit):
        main(argv)
    assert words in " ".join(capsys.readouterr().out.split())
