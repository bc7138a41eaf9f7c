"""Figures of an identification: the fit over the measurement, and the error surface."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from scipy import interpolate, stats

from rockyade.figures.canvas import axes_list, figure_of, new_figure, save_figure
from rockyade.identification.fit import CONFIDENCE, Identification, error_surface

#: Points along each axis of the grid the error surface's contours are drawn on.
DRAWN_GRID = 81


def _value_text(result: Identification, name: str, unit: str, digits: int) -> str:
    if name in result.unidentifiable:
        return f"{name.split('_')[0]} unidentifiable"
    v = getattr(result.fit, name)
    lo, hi = result.ci[name]
    return f"{name.split('_')[0]} = {v:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]{unit}"


def plot_fit(
    result: Identification, path: str | Path | None = None, *, ax: Sequence[Axes] | None = None
) -> tuple[Figure, tuple[Axes, Axes]]:
    """Measured rotation (rad), the fitted Housner history and the residuals against time (s).

    Parameters
    ----------
    result
        The identification.
    path
        PNG to write (atomically); None writes nothing.
    ax
        Two Axes to draw into (the histories, the residuals); None: a new figure (pyplot's
        without ``path``).

    Returns
    -------
    fig, (ax, ax_residual)
        The figure and its two Axes.
    """
    h = result.history
    modelled = result.modelled()
    resid = h.theta_rad - modelled
    if ax is None:
        fig, (axh, axr) = new_figure(
            path, 2, 1, figsize=(10, 6.2), sharex=True, gridspec_kw={"height_ratios": [3, 1.3]}
        )
    else:
        axh, axr = axes_list(ax, 2)
        fig = figure_of(axh)
    axh.plot(h.t_s, h.theta_rad, ".", ms=2.0, color="0.45", label=f"measured ({h.rate_hz:.4g} Hz)")
    axh.plot(h.t_s, modelled, "-", lw=1.1, color="C3", label="Housner, identified parameters")
    axh.axhline(result.fit.offset_rad, color="0.6", lw=0.6, ls="--", label=f"offset {result.fit.offset_rad:.3g} rad")
    axh.axvline(
        result.fit.release_time_s, color="C0", lw=0.8, ls=":", label=f"release t = {result.fit.release_time_s:.4g} s"
    )
    axh.set_ylabel("theta (rad)")
    axh.grid(alpha=0.3)
    axh.legend(loc="upper right", fontsize=8)
    pct = round(100 * CONFIDENCE)
    lines = [
        _value_text(result, "alpha_rad", " rad", 4),
        _value_text(result, "p_rad_s", " 1/s", 3),
        _value_text(result, "mu", "", 4),
    ]
    axh.set_title(
        f"{Path(h.source).name or 'measurement'}: " + ";  ".join(lines) + f"  ({pct} % intervals)", fontsize=9
    )
    axr.plot(h.t_s, resid, lw=0.6, color="0.3")
    axr.axhline(0.0, color="C3", lw=0.6)
    axr.set_ylabel("measured - model (rad)")
    axr.set_xlabel("time t (s)")
    axr.grid(alpha=0.3)
    axr.set_title(
        f"rms residual {result.rms_residual_rad:.3g} rad, lag-1 correlation {result.residual_lag1_correlation:.2f}, "
        f"{result.n_impacts} impacts above the noise",
        fontsize=8,
    )
    if result.unidentifiable:
        fig.text(
            0.01,
            0.005,
            "unidentifiable: " + "; ".join(f"{k}: {v}" for k, v in result.unidentifiable.items()),
            fontsize=7,
            color="C3",
            wrap=True,
        )
    if path is not None:
        save_figure(fig, path)
    return fig, (axh, axr)


def plot_error_surface(
    result: Identification, path: str | Path | None = None, n: int = 15, *, ax: Axes | None = None
) -> tuple[Figure, Axes]:
    """RMS misfit (rad) over the alpha (rad) - p (1/s) plane (other unknowns at the optimum),
    with the optimum and the joint 95 % confidence ellipse of (alpha, p).

    Parameters
    ----------
    result
        The identification.
    path
        PNG to write (atomically); None writes nothing.
    n
        Grid points along each axis where the misfit is computed (one Housner solution
        each). The contours are drawn on a :data:`DRAWN_GRID` square grid from a bicubic
        spline of the mean square misfit through them (a smooth function of alpha and p): on
        the shipped example, 15 x 15 computed points give the misfit computed on 41 x 41
        within 0.02 %, where contours drawn straight from 41 x 41 points would interpolate it
        linearly (1.4 % off between the points).
    ax
        Axes to draw into; None: a new figure (pyplot's without ``path``).

    Returns
    -------
    fig, ax
        The figure and its Axes.
    """
    fit = result.fit
    cov = result.covariance[:2, :2]
    sa, sp = (math.sqrt(max(cov[i, i], 0.0)) for i in range(2))
    half_a = max(4.0 * sa, 0.01 * fit.alpha_rad)
    half_p = max(4.0 * sp, 0.01 * fit.p_rad_s)
    a_lo = max(fit.alpha_rad - half_a, 1.001 * abs(fit.theta0_rad))
    alphas, ps, rms = _drawn_surface(
        *error_surface(result, (a_lo, fit.alpha_rad + half_a), (fit.p_rad_s - half_p, fit.p_rad_s + half_p), n)
    )
    if ax is None:
        fig, ax = new_figure(path, figsize=(7.4, 5.8))
    else:
        ax = axes_list(ax, 1)[0]
        fig = figure_of(ax)
    levels = np.geomspace(rms.min(), rms.max(), 16)
    cs = ax.contourf(alphas, ps, rms, levels=levels, cmap="viridis_r", norm=_log_norm(levels))
    ax.contour(alphas, ps, rms, levels=levels, colors="k", linewidths=0.3)
    cbar = fig.colorbar(cs, ax=ax, format="%.2g")
    cbar.set_label("rms of measured - modelled rotation (rad)")
    ax.plot(fit.alpha_rad, fit.p_rad_s, "r*", ms=12, label="optimum")
    ex, ey = _ellipse(np.array([fit.alpha_rad, fit.p_rad_s]), cov, CONFIDENCE)
    ax.plot(ex, ey, "r-", lw=1.2, label=f"joint {round(100 * CONFIDENCE)} % confidence region (all unknowns free)")
    ax.set_xlabel("alpha (rad)")
    ax.set_ylabel("p (1/s)")
    ax.set_title(
        f"Error surface: mu = {fit.mu:.4f}, release and offset at the optimum\n"
        "(the misfit with mu, release and offset held; the ellipse lets them adjust)",
        fontsize=9,
    )
    ax.legend(loc="upper right", fontsize=8)
    if path is not None:
        save_figure(fig, path)
    return fig, ax


def _drawn_surface(alphas: np.ndarray, ps: np.ndarray, rms: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rms misfit on the drawing grid, from a bicubic spline of its square through the
    computed points (``scipy.interpolate.RectBivariateSpline``, interpolating)."""
    k = min(3, alphas.size - 1, ps.size - 1)
    spline = interpolate.RectBivariateSpline(ps, alphas, rms**2, kx=k, ky=k)
    fine_a = np.linspace(alphas[0], alphas[-1], DRAWN_GRID)
    fine_p = np.linspace(ps[0], ps[-1], DRAWN_GRID)
    mean_square = np.maximum(spline(fine_p, fine_a), 0.25 * float(rms.min()) ** 2)
    return fine_a, fine_p, np.sqrt(mean_square)


def _log_norm(levels: np.ndarray):
    from matplotlib.colors import LogNorm

    return LogNorm(vmin=levels[0], vmax=levels[-1])


def _ellipse(centre: np.ndarray, cov: np.ndarray, level: float, n: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """Points of the confidence ellipse {x : (x - c)^T C^-1 (x - c) = chi2_2(level)}."""
    radius = math.sqrt(stats.chi2.ppf(level, 2))
    vals, vecs = np.linalg.eigh(cov)
    angles = np.linspace(0.0, 2.0 * math.pi, n)
    circle = np.stack([np.cos(angles), np.sin(angles)])
    pts = centre[:, None] + vecs @ (np.sqrt(np.maximum(vals, 0.0))[:, None] * circle) * radius
    return pts[0], pts[1]
