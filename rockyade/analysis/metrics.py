"""Per-block summary metrics of a run (the rows of batch summaries and CLI reports)."""

from __future__ import annotations

import math

import numpy as np

from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.result import Result
from rockyade.scene import Scene


def run_metrics(scene: Scene, result: Result, n_impacts: int = MU_EFF_IMPACTS) -> dict[str, dict[str, float]]:
    """Per-block summary of a run: peaks, max |theta|, effective mu, overturn.

    Parameters
    ----------
    scene
        The Scene that produced ``result``.
    result
        The Result.
    n_impacts
        Impacts used for the effective restitution (free rocking).

    Returns
    -------
    dict
        block name -> ``max_abs_theta_rad``, ``max_theta_over_alpha``, ``n_peaks``,
        ``first_peak_rad``, ``mu_eff`` (free rocking only; NaN otherwise or without two
        peaks), ``residual_theta_rad``,
        ``uplift_time_s`` (first |theta| > 1e-4 alpha), ``overturned`` (bool).
    """
    out: dict[str, dict[str, float]] = {}
    t = result.t
    free = scene.motion.type == "free"
    for spec in scene.blocks:
        if spec.fixed:
            continue
        alpha = spec.classical().alpha_rad
        theta = result.series("theta_rad", spec.name)
        overturned = result.meta.get("overturned_block") == spec.name or spec.name in (
            result.meta.get("overturn_times_s") or {}
        )
        out[spec.name] = {**theta_metrics(t, theta, alpha), **peak_metrics(t, theta, alpha, free, n_impacts),
                          "overturned": overturned}
    # the keys in the order of earlier versions
    order = ("max_abs_theta_rad", "max_theta_over_alpha", "n_peaks", "first_peak_rad", "first_peak_time_s", "mu_eff",
             "residual_theta_rad", "uplift_time_s", "overturned")
    return {name: {k: values[k] for k in order} for name, values in out.items()}


def uplift_threshold_rad(alpha_rad: float) -> float:
    """|theta| above which a block of slenderness ``alpha_rad`` counts as lifted off, rad."""
    return 1e-4 * alpha_rad


def theta_metrics(t: np.ndarray, theta: np.ndarray, alpha_rad: float) -> dict[str, float]:
    """``max_abs_theta_rad``, ``max_theta_over_alpha``, ``residual_theta_rad`` and
    ``uplift_time_s`` of one block's sampled rotation (``t`` in s, ``theta`` in rad; NaN
    samples ignored). :func:`rockyade.kernel.runs.simulate_runs` computes the same in the kernel."""
    finite = theta[np.isfinite(theta)]
    lifted = np.nonzero(np.abs(theta) > uplift_threshold_rad(alpha_rad))[0]
    peak = float(np.max(np.abs(finite))) if finite.size else math.nan
    return {
        "max_abs_theta_rad": peak,
        "max_theta_over_alpha": peak / alpha_rad,
        "residual_theta_rad": float(finite[-1]) if finite.size else math.nan,
        "uplift_time_s": float(t[lifted[0]]) if lifted.size else math.nan,
    }


def peak_metrics(
    t: np.ndarray, theta: np.ndarray, alpha_rad: float, free: bool, n_impacts: int = MU_EFF_IMPACTS
) -> dict[str, float]:
    """``n_peaks``, ``first_peak_rad`` (rad), ``first_peak_time_s`` (s) and ``mu_eff`` (free
    rocking only, else NaN) of one block's sampled rotation (``t`` in s, ``theta`` in rad)."""
    peaks = find_peaks(t, theta, min_peak_rad=max(1e-5, 1e-3 * alpha_rad))
    return {
        "n_peaks": len(peaks),
        "first_peak_rad": float(peaks.theta_rad[0]) if len(peaks) else math.nan,
        "first_peak_time_s": float(peaks.t_s[0]) if len(peaks) else math.nan,
        "mu_eff": effective_restitution(peaks, alpha_rad, n_impacts) if free else math.nan,
    }


#: Assemblies with more blocks than this get aggregate metrics only (batch rows, CLI summary).
PER_BLOCK_LIMIT = 10


def assembly_metrics(scene: Scene, result: Result) -> dict[str, float | int | str]:
    """Aggregate collapse metrics of an assembly's run (:mod:`rockyade.analysis.collapse`):
    ``n_blocks``, ``n_fallen``, ``fallen_fraction``, ``first_fall_time_s``, ``first_fallen_block``,
    ``max_abs_theta_rad`` and its block, ``max_residual_displacement_m`` (at the end of the
    run) and its block, ``n_moving_at_end`` (blocks whose final state is not rest or fallen:
    their "residual" values are where they were when the run ended, not where they stopped).
    Times in s, angles in rad, displacements in m.

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver)."""
    from rockyade.analysis.collapse import collapse_report

    report = collapse_report(scene, result)
    fallen = report[report["fell"]]
    residual = np.hypot(report["residual_x_m"], report["residual_y_m"])
    first = fallen.sort_values("fall_time_s").iloc[0] if len(fallen) else None
    k_theta = int(np.nanargmax(report["max_abs_theta_rad"])) if len(report) else -1
    k_disp = int(np.nanargmax(residual)) if len(report) else -1
    return {
        "n_blocks": len(report),
        "n_fallen": len(fallen),
        "fallen_fraction": float(len(fallen) / max(len(report), 1)),
        "first_fall_time_s": float(first["fall_time_s"]) if first is not None else math.nan,
        "first_fallen_block": str(first["block"]) if first is not None else "",
        "max_abs_theta_rad": float(report["max_abs_theta_rad"].iloc[k_theta]) if k_theta >= 0 else math.nan,
        "max_theta_block": str(report["block"].iloc[k_theta]) if k_theta >= 0 else "",
        "max_residual_displacement_m": float(residual.iloc[k_disp]) if k_disp >= 0 else math.nan,
        "max_residual_block": str(report["block"].iloc[k_disp]) if k_disp >= 0 else "",
        "n_moving_at_end": int((~report["final_state"].isin(["rest", "fallen"])).sum()),
    }
