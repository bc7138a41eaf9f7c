"""The plotting API works in a notebook: no backend switch on import, (fig, ax) returned,
``ax=`` honoured, files written without pyplot, a Result drawn by ``plot_result`` and
``HistoryDisplay``."""

from __future__ import annotations

import subprocess
import sys

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure

from rockyade.errors import InputError
from rockyade.figures import HistoryDisplay, plot_accelerogram, plot_result, plot_results, plot_spectra
from rockyade.scene import scene_from_dict
from rockyade.solvers import run

from .conftest import free_scene_dict


@pytest.fixture(scope="module")
def housner_result():
    return run(scene_from_dict(free_scene_dict(duration=1.0)), solver="housner")


@pytest.mark.slow
def test_importing_figures_and_studies_keeps_the_users_backend():
    code = (
        "import matplotlib; matplotlib.use('svg');"
        "import rockyade.figures, rockyade.studies.paper, rockyade.studies.free_rocking, rockyade.studies.harmonic;"
        "print(matplotlib.get_backend())"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "svg"


def test_writing_a_file_leaves_pyplot_alone(tmp_path, housner_result):
    """A figure for a file is not a pyplot figure: nothing is shown, nothing leaks."""
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    backend = matplotlib.get_backend()
    fig, ax = plot_results({"housner": housner_result}, tmp_path / "r.png", title="t")
    assert isinstance(fig, Figure) and ax.figure is fig
    assert plt.get_fignums() == before and matplotlib.get_backend() == backend
    assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_result_draws_into_the_axes_it_is_given(housner_result):
    fig = Figure()
    ax = fig.subplots()
    out_fig, out_ax = plot_result(housner_result, ax=ax, label="exact")
    plot_result(housner_result, ax=ax, quantity="omega_rad_s", label="rate")
    assert out_fig is fig and out_ax is ax
    assert [line.get_label() for line in ax.lines if not line.get_label().startswith("_")] == ["exact", "rate"]
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), housner_result.series("theta_rad"))


def test_plot_result_without_axes_returns_a_pyplot_figure(housner_result):
    """In a notebook (no ax, no file) the figure comes from pyplot, so it shows inline."""
    import matplotlib.pyplot as plt

    fig, ax = plot_result(housner_result)
    try:
        assert fig.number in plt.get_fignums() and ax.get_ylabel() == "specimen1: theta (rad)"
    finally:
        plt.close(fig)


def test_history_display_keeps_what_it_drew_and_draws_again(housner_result, tmp_path):
    """As scikit-learn's displays: built from a result it draws at once (``figure_``,
    ``ax_``); ``plot`` draws the same curves elsewhere, and a path writes a PNG."""
    first = Figure().subplots()
    display = HistoryDisplay.from_result(housner_result, quantity="omega_rad_s", label="exact", ax=first)
    assert display.ax_ is first and display.figure_ is first.figure
    np.testing.assert_array_equal(first.lines[0].get_ydata(), housner_result.series("omega_rad_s"))
    second = Figure().subplots()
    assert display.plot(second, path=tmp_path / "h.png") is display
    assert display.ax_ is second and second.get_ylabel() == "specimen1: omega_rad_s"
    assert [line.get_label() for line in second.lines if not line.get_label().startswith("_")] == ["exact"]
    assert (tmp_path / "h.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_motion_plots_accept_axes_and_return_them(tmp_path):
    fig = Figure()
    axes = fig.subplots(2, 2)
    t = np.linspace(0, 1, 101)
    out_fig, out_axes = plot_accelerogram(t, np.sin(t), np.cos(t), t, ax=[axes[0, 0], axes[0, 1], axes[1, 0]])
    assert out_fig is fig and out_axes[2] is axes[1, 0] and axes[1, 0].get_xlabel() == "time t (s)"
    periods = np.geomspace(0.1, 2, 10)
    out_fig, out_ax = plot_spectra(periods, np.ones(10), 1.1 * np.ones(10), ax=axes[1, 1], damping=0.02)
    assert out_ax is axes[1, 1] and "2 % damping" in out_ax.get_ylabel()
    fig2, _ = plot_spectra(periods, None, np.ones(10), tmp_path / "s.png")
    assert isinstance(fig2, Figure) and (tmp_path / "s.png").is_file()


def test_wrong_number_of_axes_is_an_input_error(housner_result):
    fig = Figure()
    with pytest.raises(InputError, match="ax: must be 3 matplotlib Axes"):
        plot_accelerogram([0, 1], [0, 1], [0, 1], [0, 1], ax=fig.subplots(1, 2))
    with pytest.raises(InputError, match="ax: must be 1 matplotlib Axes"):
        plot_result(housner_result, ax=fig.subplots(1, 2))


# ------------------------------------------------------------------ every plot function (issue "What users hit" 9)


def _synthetic_frame_result(scene):
    """A made-up run of a scene: every moving block turns by 0.01 sin(pi t) about its centroid."""
    import pandas as pd

    from rockyade.result import Result
    from rockyade.run_meta import RunMeta

    t = np.linspace(0.0, 1.0, 21)
    data = {"t_s": t, "ag_m_s2": np.zeros_like(t)}
    names = [b.name for b in scene.blocks]
    for name in names:
        data[f"{name}_theta_rad"] = 0.01 * np.sin(np.pi * t)
        data[f"{name}_x_m"] = data[f"{name}_y_m"] = np.zeros_like(t)
    return Result(pd.DataFrame(data), RunMeta(status="completed", blocks=tuple(names), solver="synthetic"))


_ANIMATIONS: list = []


def _kept(fig_ax_anim):
    """(fig, ax) of animate, its animation kept alive (matplotlib warns when one is dropped unseen)."""
    _ANIMATIONS.append(fig_ax_anim[2])
    return fig_ax_anim[:2]


@pytest.mark.slow
def test_every_plot_function_returns_fig_and_ax_and_draws_into_given_axes(tmp_path, housner_result):
    """draw_assembly, draw_snapshots and animate wrote files only and returned a count or paths;
    every plot function of rockyade.figures now returns its figure and Axes, takes ``ax=``,
    writes nothing without a path and leaves pyplot alone when it draws into given Axes."""
    import types

    import matplotlib.pyplot as plt
    import pandas as pd

    from rockyade.figures.assembly import animate, draw_assembly, draw_snapshots
    from rockyade.figures.collapse_mechanism import draw_mechanism
    from rockyade.figures.identification_fit import plot_error_surface, plot_fit
    from rockyade.figures.uncertainty_bands import plot_uncertainty
    from rockyade.figures.verification_histories import plot_check
    from rockyade.identification.fit import identify
    from rockyade.identification.measurement import read_measurement
    from rockyade.limit.analysis import limit_analysis
    from rockyade.probability.exceedance import level_column
    from rockyade.scene.generators import frame, stack

    from .conftest import EXAMPLES

    scene = scene_from_dict(frame())
    result = _synthetic_frame_result(scene)
    limit = limit_analysis(scene_from_dict(stack(widths_m=[0.4, 0.3], heights_m=0.8)))
    ident = identify(read_measurement(EXAMPLES / "measured" / "specimen1_free_rocking.csv"))
    study = types.SimpleNamespace(measures=["pga_m_s2"], levels=[0.5], name="s", samples=2)
    probabilities = pd.DataFrame(
        {
            "solver": ["housner"] * 2,
            "load_factor": [0.5, 1.0],
            "p_overturn": [0.1, 0.6],
            "p_overturn_lo": [0.0, 0.3],
            "p_overturn_hi": [0.4, 0.8],
            level_column(0.5): [0.3, 0.9],
        }
    )
    runs = pd.DataFrame(
        {
            "solver": ["housner"] * 4,
            "status": ["completed", "overturned", "completed", "overturned"],
            "pga_m_s2": [1.0, 4.0, 2.0, 5.0],
            "load_factor": [0.5, 1.0, 0.5, 1.0],
            "max_theta_over_alpha": [0.2, 3.0, 0.4, 3.0],
        }
    )
    fragility = pd.DataFrame(
        {"solver": ["housner"], "measure": ["pga_m_s2"], "status": ["fitted"], "median": [2.9], "beta": [0.4]}
    ).assign(n_runs=4)
    calls = {
        "draw_assembly": (lambda ax, path=None: draw_assembly(scene, path, ax=ax), 1),
        "draw_snapshots": (lambda ax, path=None: draw_snapshots(scene, result, [0.5], path, ax=ax), 1),
        "animate": (lambda ax, path=None: _kept(animate(scene, result, path, fps=5.0, ax=ax)), 1),
        "draw_mechanism": (lambda ax, path=None: draw_mechanism(limit, path, ax=ax), 1),
        "plot_fit": (lambda ax, path=None: plot_fit(ident, path, ax=ax), 2),
        "plot_error_surface": (lambda ax, path=None: plot_error_surface(ident, path, n=7, ax=ax), 1),
        "plot_uncertainty": (
            lambda ax, path=None: plot_uncertainty(study, probabilities, runs, fragility, None, path, ax=ax),
            3,
        ),
        "plot_check": (lambda ax, path=None: plot_check("pad", {"housner": housner_result}, path, ax=ax), 1),
    }
    before = plt.get_fignums()
    for name, (call, n_axes) in calls.items():
        mine = Figure()
        axes = mine.subplots(1, n_axes, squeeze=False)[0].tolist()
        fig, ax = call(axes[0] if n_axes == 1 else axes)
        assert fig is mine, name
        drawn = [ax] if n_axes == 1 else list(ax)
        assert drawn == axes and any(a.has_data() or a.images or a.collections for a in drawn), name
        assert not list(tmp_path.iterdir()), name  # no path: no file
    assert plt.get_fignums() == before  # into given Axes: pyplot never saw a figure
    # with a path (and no Axes) each writes its file; an animation needs .gif or .mp4
    for name, (call, _) in calls.items():
        path = tmp_path / (f"{name}.gif" if name == "animate" else f"{name}.png")
        fig, _ = call(None, path)
        assert path.stat().st_size > 0 and isinstance(fig, Figure), name
    assert plt.get_fignums() == before  # figures for files are drawn outside pyplot


def test_no_module_selects_a_backend_or_shows_a_figure():
    """Notebook-first: no call of ``matplotlib.use``, ``switch_backend`` or ``.show()`` anywhere in the package."""
    import ast
    import re
    from pathlib import Path

    import rockyade

    for path in Path(rockyade.__file__).parent.rglob("*.py"):
        text = path.read_text()
        # only a module that names show or switch_backend, or matplotlib and use, can hold such a
        # call (an identifier is a whole word of the text): the others need not be parsed
        if not (
            re.search(r"\b(show|switch_backend)\b", text) or ("matplotlib" in text and re.search(r"\buse\b", text))
        ):
            continue
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
                called = node.func.attr
                owner = ast.unparse(node.func.value)
                assert called not in ("show", "switch_backend"), f"{path}: {owner}.{called}()"
                assert not (called == "use" and owner.endswith("matplotlib")), f"{path}: {owner}.use()"


def test_study_displays_draw_into_given_axes_and_keep_what_they_drew(tmp_path, housner_result):
    """The paper study's figures are display objects in figures/: computed data in, ``plot(ax=)``,
    ``figure_`` and ``ax_`` kept; a failed run is a legend entry, never a curve."""
    import pandas as pd

    from rockyade.figures.parameter_sensitivity import SensitivityDisplay
    from rockyade.figures.rocking_patterns import PatternMapDisplay
    from rockyade.figures.solver_panels import Curve, Panel, SolverPanelsDisplay

    r = housner_result
    panel = Panel(curves=[Curve("housner", "Housner", r.t, r.series("theta_rad")), Curve("yade", "YADE: FAILED")])
    fig = Figure()
    axes = fig.subplots(1, 2)
    shown = SolverPanelsDisplay([[panel, Panel(note="not reachable")]]).plot(list(axes))
    assert shown.figure_ is fig and shown.ax_ == [list(axes)]
    assert len(axes[0].lines) == 3  # the curve, the failed entry (no points) and the zero line
    assert [len(line.get_xdata()) for line in axes[0].lines][1] == 0
    assert "not reachable" in axes[1].texts[0].get_text()
    written = SolverPanelsDisplay([[panel]], title="t").plot(path=tmp_path / "panels.png")
    assert (tmp_path / "panels.png").stat().st_size > 5_000 and written.figure_ is not fig

    rows = [
        {"response": resp, "solver": s, "parameter": p, "change_pct": c, "relative_change_pct": 2.0 * c}
        for resp in ("peak", "mu_eff")
        for s in ("housner", "reference")
        for p in ("alpha_rad", "p_rad_s", "mu")
        for c in (-5, 5)
    ]
    fig2 = Figure()
    bars = SensitivityDisplay(pd.DataFrame(rows)).plot(list(fig2.subplots(1, 2)))
    assert bars.figure_ is fig2 and len(bars.ax_[0].patches) == 12

    cells = pd.DataFrame(
        {
            "frequency_hz": [1.0],
            "amplitude_mm": [0.5],
            "pattern_dem": ["rest"],
            "pattern_paper": [None],
            "agree": [None],
        }
    )
    fig3 = Figure()
    ax3 = fig3.subplots()
    grid = PatternMapDisplay(cells, (1.0, 2.0), (0.5, 1.0)).plot(ax3)
    assert grid.ax_ is ax3 and ax3.texts[0].get_text() == "rest"


def test_the_fragility_display_draws_stripes_and_a_curve_solid_where_tested(tmp_path):
    """One drawing of a fragility curve with its stripes (the paper study's panels and assess's
    figure): points at the stripes, the curve solid up to the largest tested level and dotted
    beyond, an extrapolated median marked; a missing curve is a red legend entry."""
    from rockyade.figures.fragility_panels import MISSING_COLOUR, FragilityCurve, FragilityDisplay, Mark
    from rockyade.probability.fragility_curves import Fragility

    levels = np.array([0.1, 0.2, 0.3])
    curve = FragilityCurve(
        levels,
        np.array([0.0, 0.2, 0.4]),
        "stripes",
        fragility=Fragility(0.35, 0.3, 3),
        mark_median=True,
        fraction_lo=np.array([0.0, 0.05, 0.2]),
        fraction_hi=np.array([0.2, 0.5, 0.6]),
    )
    fig = Figure()
    ax = fig.subplots()
    display = FragilityDisplay(
        [curve], 0.5, "PGA (g)", beyond=0.3, marks=[Mark(0.25, "demand")], missing=["YADE: no curve"]
    ).plot(ax)
    assert display.figure_ is fig and display.ax_ is ax
    solid, dotted = ax.lines[0], ax.lines[1]
    assert solid.get_linestyle() == "-" and max(solid.get_xdata()) <= 0.3 < min(dotted.get_xdata())
    assert dotted.get_linestyle() == ":"
    median = ax.lines[2]  # beyond the tested levels: a diamond at P = 0.5
    assert median.get_marker() == "D" and list(median.get_xydata()[0]) == pytest.approx([0.35, 0.5])
    assert ax.get_xlabel() == "PGA (g)" and ax.get_xlim() == (0.0, 0.5)
    texts = {t.get_text(): t.get_color() for t in ax.get_legend().get_texts()}
    assert texts["YADE: no curve"] == MISSING_COLOUR and "stripes" in texts and "demand" in texts
    written = FragilityDisplay([curve], 0.5).plot(path=tmp_path / "fragility.png")
    assert (tmp_path / "fragility.png").stat().st_size > 5_000 and written.figure_ is not fig
