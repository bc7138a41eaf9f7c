"""The site's spectrum of an assessment (``rockyade assess --report``): the elastic spectrum Se(T)
at 5 % (NTC 2018 3.2.3.2.1, or EN 1998-1 3.2.2.2) with its corner periods, at the damping of the
nonlinear check where it takes another (Circolare 2019 C8.7.1.2.1.8: 8 %), at height the floor's
spectrum SeZ(T) of Circolare 2019 C7.2.3 at both dampings, and the periods the checks take
marked on the curve they read (T_SLV, Ts, T1, T0)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes

from rockyade.assess.assessment import Assessment
from rockyade.assess.floor_spectra import SLD_DAMPING
from rockyade.figures.canvas import other_accel_axis, save_figure, single_axes

GROUND = "#1f4e79"
FLOOR = "#b35806"
MARK = "#b2182b"


def plot_site_spectrum(a: Assessment, ax: Axes | None = None, path: str | Path | None = None) -> tuple[Any, Axes]:
    """Draw the spectra and the checks' periods (module docstring); written to ``path`` when given.

    Parameters
    ----------
    a
        An assessment.
    ax
        Axes to draw into (default: a new figure).
    path
        PNG to write.
    """
    fig, ax = single_axes(ax, path, (7.6, 5.0))
    spectrum = a.site.spectrum
    periods = np.linspace(0.0, 4.0, 801)
    ax.plot(periods, spectrum.psa(periods), color=GROUND, lw=2.0, label="Se(T), 5 % (the site's elastic spectrum)")
    xi = None if a.position.method == "circolare2009" else a.position.xi_slv
    if xi is not None and not a.position.at_height:
        damped = dataclasses.replace(spectrum, damping=xi)
        ax.plot(
            periods,
            damped.psa(periods),
            color=GROUND,
            lw=1.3,
            ls="--",
            label=f"Se(T), {100 * xi:g} % (the nonlinear check's)",
        )
    if a.position.at_height and xi is not None:
        floor = a.position.floor(spectrum)
        ax.plot(
            periods, floor.psa(periods, SLD_DAMPING), color=FLOOR, lw=2.0, label="SeZ(T), 5 % (the floor's, C7.2.3)"
        )
        ax.plot(periods, floor.psa(periods, xi), color=FLOOR, lw=1.3, ls="--", label=f"SeZ(T), {100 * xi:g} %")
        ax.axvline(floor.T1_s, color=FLOOR, ls=":", lw=1.0)
        ax.annotate(
            f"T1 = {floor.T1_s:.3g} s",
            (floor.T1_s, 0),
            xytext=(2, 60),
            textcoords="offset points",
            rotation=90,
            fontsize=7,
        )
    for name, value in (("TB", spectrum.TB_s), ("TC", spectrum.TC_s), ("TD", spectrum.TD_s)):
        ax.axvline(value, color="0.6", ls=":", lw=0.9)
        ax.annotate(
            f"{name} = {value:.3g} s",
            (value, 0),
            xytext=(2, 4),
            textcoords="offset points",
            rotation=90,
            fontsize=7,
            color="0.35",
            va="bottom",
        )
    for c in a.checks:
        if not c.applies:
            continue
        t = c.terms
        if "T_SLV_s" in t:
            se = t.get("Se_TSLV_m_s2", t.get("SeZ_TSLV_m_s2"))
            _mark(ax, t["T_SLV_s"], se, f"{c.name}: T_SLV = {t['T_SLV_s']:.3g} s")
        elif "Ts_s" in t:
            _mark(ax, t["Ts_s"], t["Se_Ts_m_s2"], f"{c.name}: Ts = {t['Ts_s']:.3g} s")
        elif "SeZ_T0_m_s2" in t:
            _mark(ax, t["T0_s"], t["SeZ_T0_m_s2"], f"{c.name}: T0 = {t['T0_s']:.3g} s")
    ax.set_xlim(0.0, 4.0)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("period T (s)")
    ax.set_ylabel("pseudo-acceleration (m/s$^2$)")
    other_accel_axis(ax, "m/s2", "y", "PSA")
    ax.grid(alpha=0.3)
    ax.set_title(spectrum.label, fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    if path is not None:
        save_figure(fig, path)
    return fig, ax


def _mark(ax: Axes, period: float, se: float | None, label: str) -> None:
    if se is None:
        return
    ax.plot([period], [se], "D", color=MARK, ms=6, zorder=6, label=label)


__all__ = ["plot_site_spectrum"]
