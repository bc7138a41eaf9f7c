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
