"""Figures of :mod:`rockyade.assess`: a fragility curve, and an assessment (the code's capacity
curve with the demand beside the fragility in ag).

* :func:`plot_fragility` (:func:`fragility_display`, a
  :class:`rockyade.figures.fragility_panels.FragilityDisplay`): the fraction of records that
  collapse at each stripe (points, 95 % Wilson bars), the lognormal fit (solid over the
  tested levels, dotted beyond), its 90 % bootstrap band, the median marked;
* :func:`plot_capacity`: the code's capacity curve a*(d*) of the equivalent system, a0*,
  du* and the secant point of T_SLV (of Ts in the 2009 form), the linear demand (ag S / q, or
  the floor's at height) and the nonlinear one: the site's elastic spectrum (the floor's at
  height) at the check's damping in acceleration-displacement form (Se(T) against SDe(T)) and
  its point at T_SLV (Ts);
* with ``--pushover``, the reference DEM's pushover curve at the mechanism's control point
  in the same a*-d* coordinates over the code's curve;
* :func:`draw_fragility` and :func:`draw_assessment` write them as PNG files.
"""

from __future__ import annotations

import dataclasses
import math
import re
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes

from rockyade.assess.assessment import Assessment
from rockyade.assess.code import VERIFIED
from rockyade.assess.fragility_analysis import FragilityResult
from rockyade.constants import CODE_GRAVITY as G
from rockyade.figures.canvas import new_figure, save_figure, single_axes
from rockyade.figures.fragility_panels import FragilityCurve, FragilityDisplay, Mark
from rockyade.probability.fragility_curves import Fragility

CURVE = "#1f4e79"
BAND = "#9ecae1"
POINTS = "#08306b"
DEMAND = "#b2182b"
CODE = "#e08214"
OK = "#1b7837"
PUSH = "#762a83"
#: Characters of the 10-point heading one 6.4-inch panel holds (wider, the PNG grows to fit it).
TITLE_CHARACTERS_PER_PANEL = 88


def plot_fragility(
    result: FragilityResult, ax: Axes | None = None, marks: list[tuple[float, str, str, str]] | None = None
) -> tuple[Any, Axes]:
    """The stripes and the fit (module docstring) in the measure's shown unit
    (:func:`fragility_display`, drawn).

    Parameters
    ----------
    result
        A fragility analysis.
    ax
        Axes to draw into (default: a new figure).
    marks
        Vertical lines: (value in SI, label, colour, line style).
    """
    display = fragility_display(result, marks).plot(ax)
    assert display.ax_ is not None  # set by plot
    return display.figure_, display.ax_


def fragility_display(
    result: FragilityResult, marks: list[tuple[float, str, str, str]] | None = None
) -> FragilityDisplay:
    """The display of a fragility analysis: the fraction of records that collapse at each
    stripe with its 95 % Wilson interval, the lognormal fit (solid over the tested levels,
    dotted beyond, its median marked) and its 90 % bootstrap band, in the measure's shown
    unit; ``marks`` as for :func:`plot_fragility`."""
    m, fit = result.measure, result.fit
    s = result.stripes
    x = s[m.si_column].to_numpy() / m.scale
    top = 1.25 * max([float(x.max()), *(v / m.scale for v, *_ in marks or [])])
    f = fit.fragility
    shown = Fragility(f.median / m.scale, f.beta, f.n_points, f.status, f.fraction)
    if f.status == "fitted":
        curve_label = f"lognormal fit: median {m.shown(f.median):.3g} {m.unit}, beta {f.beta:.2f}"
    elif f.status == "separated":
        curve_label = f"threshold near {m.shown(f.median):.3g} {m.unit}"
    else:
        curve_label = ""
    n = int(s["n_runs"].max()) if len(s) else 0
    curve = FragilityCurve(
        x,
        s["fraction"].to_numpy(),
        f"fraction of {n} records that collapse (95 % Wilson)",
        colour=CURVE,
        point_colour=POINTS,
        marker="s",
        filled=True,
        fraction_lo=s["fraction_lo"].to_numpy(),
        fraction_hi=s["fraction_hi"].to_numpy(),
        fragility=shown,
        curve_label=curve_label,
        tested_max=float(x.max()),
        mark_median=True,
        band=(fit.grid_si / m.scale, fit.band_lo, fit.band_hi),
        band_label="90 % bootstrap band",
        band_colour=BAND,
        lw=1.8,
    )
    lines = [
        # the first mark (the site's ag in an assessment) wide and below: a capacity at the same value,
        # drawn thin over it, leaves it showing on both sides
        Mark(
            value / m.scale,
            label,
            colour,
            style,
            3.2 if k == 0 else 1.3,
            0.75 if k == 0 else 1.0,
            1.5 if k == 0 else 2.5,
        )
        for k, (value, label, colour, style) in enumerate(marks or [])
    ]
    return FragilityDisplay([curve], top, m.label, "P(collapse)", marks=lines, legend="below")


def _legend_below(ax: Axes, fontsize: float) -> None:
    """The legend under the axes, outside them: it never covers a point, an error bar or a line."""
    ax.legend(fontsize=fontsize, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncol=1, frameon=False)


def plot_capacity(a: Assessment, ax: Axes | None = None) -> tuple[Any, Axes]:
    """The code's capacity curve and demand (module docstring)."""
    fig, ax = single_axes(ax, None, (6.4, 4.2))
    kin = a.limit.kinematic
    if kin is None:
        ax.text(0.5, 0.5, f"no mechanism ({a.limit.status})", ha="center", va="center", transform=ax.transAxes)
        ax.set_axis_off()
        return fig, ax
    curve = kin.spectral()
    ymax = kin.a0_star_m_s2
    xmax = 0.0
    if curve is not None:
        d, acc = curve
        keep = acc >= 0
        ax.plot(d[keep] * 1e3, acc[keep], color="black", lw=1.8, label="capacity a*(d*) of the mechanism")
        xmax = float(d[keep].max())
    ax.plot([0.0], [kin.a0_star_m_s2], "o", color="black", ms=5, zorder=5)
    push = a.pushover
    if push is not None and push.d_star_m.size:
        # force-controlled: flat past the onset; cut where the code's curve ends (the run overturns)
        reach = xmax if xmax > 0 else float(push.d_star_m.max())
        inside = push.d_star_m <= 1.15 * reach
        ax.plot(
            push.d_star_m[inside] * 1e3,
            push.a_star_m_s2[inside],
            color=PUSH,
            lw=1.6,
            ls="-",
            label=f"reference DEM pushover, force-controlled (held levels): {_onset_label(push)}",
        )
    ax.annotate(
        f"a0* = {kin.a0_star_m_s2:.3g}", (0, kin.a0_star_m_s2), xytext=(6, 4), textcoords="offset points", fontsize=8
    )
    for c in a.checks:
        if not c.applies:
            continue
        colour = OK if c.status == VERIFIED else DEMAND
        if c.quantity == "a0*":
            ax.axhline(
                c.demand, color=colour, ls="--", lw=1.3, label=f"{c.name}: demand {c.demand:.3g} m/s$^2$ ({c.status})"
            )
            ymax = max(ymax, c.demand)
        else:
            periods = np.linspace(0.02, 4.0, 400)
            if "T_SLV_s" in c.terms and a.position.at_height:  # the floor's spectrum (Circolare 2019 C7.2.3)
                ts, xi = c.terms["T_SLV_s"], c.terms["xi"]
                floor = a.position.floor(a.site.spectrum)
                spectrum, sd = floor.psa(periods, xi), floor.sde(periods, xi)
                what = f"the floor's spectrum at Z, {100 * xi:g} % (ADRS)"
                se = c.demand * (2 * math.pi / ts) ** 2
                label = f"{c.name}: demand at T_SLV = {ts:.2f} s: {c.demand * 1e3:.3g} mm ({c.status})"
            elif "T_SLV_s" in c.terms:  # at ground level, 2019: the site's spectrum at the mechanism's damping
                ts, xi, se = c.terms["T_SLV_s"], c.terms["xi"], c.terms["Se_TSLV_m_s2"]
                spectrum = dataclasses.replace(a.site.spectrum, damping=xi).psa(periods)
                sd = spectrum * (periods / (2 * math.pi)) ** 2
                what = f"site's elastic spectrum at {100 * xi:g} % (ADRS)"
                label = f"{c.name}: demand SDe(T_SLV = {ts:.2f} s) = {c.demand * 1e3:.3g} mm ({c.status})"
            else:
                ts, se = c.terms["Ts_s"], c.terms["Se_Ts_m_s2"]
                spectrum = a.site.spectrum.psa(periods)
                sd = spectrum * (periods / (2 * math.pi)) ** 2
                what = "site's elastic spectrum, 5 % (ADRS)"
                label = f"{c.name}: demand SDe(Ts = {ts:.2f} s) = {c.demand * 1e3:.3g} mm ({c.status})"
            ax.plot(sd * 1e3, spectrum, color="0.55", lw=1.0, label=what)
            ax.plot([0, c.demand * 1e3], [0, se], color="0.55", lw=0.8, ls=":")
            ax.plot([c.demand * 1e3], [se], "D", color=colour, ms=6, zorder=6, label=label)
            if kin.du_star_m is not None:  # None when the mechanism has no ultimate displacement
                ax.axvline(
                    kin.du_star_m * 1e3, color=CURVE, ls="--", lw=1.2, label=f"du* = {kin.du_star_m * 1e3:.3g} mm"
                )
            if "T_SLV_s" in c.terms and kin.du_star_m is not None:  # the secant point of T_SLV (C8.7.1.10)
                ax.plot([kin.du_star_m * 1e3], [c.terms["a_SLV_m_s2"]], "s", color=CURVE, ms=4)
            elif kin.ds_star_m is not None and kin.as_star_m_s2 is not None:
                ax.plot([kin.ds_star_m * 1e3], [kin.as_star_m_s2], "s", color=CURVE, ms=4)
            ymax = max(ymax, se)
            xmax = max(xmax, c.demand)
    ax.set_xlim(0, 1.15 * xmax * 1e3 if xmax > 0 else 1.0)
    ax.set_ylim(0, 1.2 * ymax)
    ax.set_xlabel("d* (mm)")
    ax.set_ylabel("a* (m/s$^2$)")
    ax.set_title(f"the code's check (e* = {kin.e_star:.3f}, FC = {kin.FC:g}; {a.verdict})", fontsize=9)
    ax.grid(alpha=0.3)
    _legend_below(ax, 7)
    return fig, ax


def assessment_marks(a: Assessment) -> list[tuple[float, str, str, str]]:
    """The code's demand and capacity on the fragility's axis (ag, SI)."""
    marks = [(a.site.ag_m_s2, f"the site's ag = {a.site.ag_m_s2 / G:.3g} g (the code's demand)", DEMAND, "-")]
    styles = iter(("--", "-.", ":"))
    for c in a.checks:
        if c.applies:
            marks.append(
                (
                    c.ag_capacity_m_s2,
                    f"code capacity, {c.name}: ag = {c.ag_capacity_m_s2 / G:.3g} g",
                    CODE,
                    next(styles),
                )
            )
    return marks


def draw_fragility(result: FragilityResult, path: str | Path, title: str | None = None) -> Path:
    """Write :func:`plot_fragility` as a PNG."""
    fig, ax = new_figure(path, figsize=(6.8, 5.8), layout="constrained")
    static = result.plan.static_acceleration_m_s2
    marks = []
    if result.measure.kind == "pga" and math.isfinite(static):
        marks.append((static, f"static collapse, alpha0 g = {static / G:.3g} g (limit analysis)", "0.45", "--"))
    plot_fragility(result, ax, marks=marks)
    if title:
        ax.set_title(title, fontsize=10)
    return save_figure(fig, path)


def draw_assessment(a: Assessment, path: str | Path, title: str | None = None) -> Path:
    """The capacity curve and demand (left) and, when the dynamics ran, the fragility in ag
    with the code's demand and capacity marked (right); a PNG."""
    panels = 2 if a.dynamic is not None else 1
    fig, axes = new_figure(path, 1, panels, figsize=(6.4 * panels, 6.2), layout="constrained", squeeze=False)
    plot_capacity(a, axes[0, 0])
    if a.dynamic is not None:
        plot_fragility(a.dynamic, axes[0, 1], marks=assessment_marks(a))
        ratio = a.median_over_code
        axes[0, 1].set_title(
            f"dynamics: {a.dynamic.plan.stripes.solver.name}, {a.dynamic.plan.stripes.motions.count} records"
            + (f"; median / code capacity = {ratio:.2f}" if not math.isnan(ratio) else ""),
            fontsize=9,
        )
    if title:  # the site's line wrapped to the panels' width (an NTC 2018 site's is ~180 characters)
        heading = f"{title}: {a.site.describe().replace('m/s^2', 'm/s²')}"
        unbroken = re.sub(r" (?==)|(?<==) |(?<=\d) (?=[a-zA-Z%(])", "\u00a0", heading)  # "TC = 0.42 s" whole
        fig.suptitle(textwrap.fill(unbroken, width=TITLE_CHARACTERS_PER_PANEL * panels), fontsize=10)
    return save_figure(fig, path)


def _onset_label(push: Any) -> str:
    """The pushover's onset for a legend: a percentage only where two held levels bracket it."""
    if push.bound == "measured":
        return f"onset λ {push.onset.multiplier:.4g}, {100 * push.difference:+.1f} % on alpha0"
    if push.bound == "below":
        return f"onset below λ {push.onset.multiplier:.4g} (the first level)"
    if push.bound == "above":
        return f"held at every level up to λ {push.onset.below:.4g}"
    return "no onset measured"
