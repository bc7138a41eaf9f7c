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
        ``uplift_time_s`` (first |theta| > 1e-4 alpha), ``overturned`` (bool: in an assembly,
        it fell by the collapse table's rule, :mod:`rockyade.analysis.collapse`).
    """
    out: dict[str, dict[str, float]] = {}
    t = result.t
    free = scene.motion.type == "free"
    fell: dict[str, bool] = {}
    if scene.positioned and result.ok:
        from rockyade.analysis.collapse import collapse_report

        report = collapse_report(scene, result)
        fell = dict(zip(report["block"], report["fell"], strict=True))
    for spec in scene.blocks:
        if spec.fixed:
            continue
        alpha = spec.classical().alpha_rad
        theta = result.series("theta_rad", spec.name)
        finite = theta[np.isfinite(theta)]
        peaks = find_peaks(t, theta, min_peak_rad=max(1e-5, 1e-3 * alpha))
        lifted = np.nonzero(np.abs(theta) > 1e-4 * alpha)[0]
        out[spec.name] = {
            "max_abs_theta_rad": float(np.max(np.abs(finite))) if finite.size else math.nan,
            "max_theta_over_alpha": float(np.max(np.abs(finite)) / alpha) if finite.size else math.nan,
            "n_peaks": len(peaks),
            "first_peak_rad": float(peaks.theta_rad[0]) if len(peaks) else math.nan,
            "first_peak_time_s": float(peaks.t_s[0]) if len(peaks) else math.nan,
            "mu_eff": effective_restitution(peaks, alpha, n_impacts) if free else math.nan,
            "residual_theta_rad": float(finite[-1]) if finite.size else math.nan,
            "uplift_time_s": float(t[lifted[0]]) if lifted.size else math.nan,
            "overturned": fell[spec.name]
            if spec.name in fell
            else result.meta.get("overturned_block") == spec.name
            or spec.name in (result.meta.get("overturn_times_s") or {}),
        }
    return out


#: Assemblies with more blocks than this get aggregate metrics only (batch rows, CLI summary).
PER_BLOCK_LIMIT = 10


def assembly_metrics(scene: Scene, result: Result) -> dict[str, float | int | str]:
    """Aggregate collapse metrics of an assembly's run (:mod:`rockyade.analysis.collapse`):
    ``n_blocks``, ``n_fallen`` (blocks that came down within the run), ``fallen_fraction``,
    ``first_fall_time_s``, ``first_fallen_block``, ``n_falling_at_end`` (blocks still falling
    when the run ended: not counted as fallen), ``max_abs_theta_rad`` and its block,
    ``max_residual_displacement_m`` (at the end of the run) and its block, ``n_moving_at_end``
    (blocks whose final state is not rest or fallen: their "residual" values are where they
    were when the run ended, not where they stopped). Times in s, angles in rad,
    displacements in m. The run's status is ``overturned`` exactly when ``n_fallen`` > 0
    (both DEMs decide it by the same rule, :func:`rockyade.dem.overturn.run_outcome`).

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
    first = fallen.sort_values("fall_time_s", kind="stable").iloc[0] if len(fallen) else None
    k_theta = int(np.nanargmax(report["max_abs_theta_rad"])) if len(report) else -1
    k_disp = int(np.nanargmax(residual)) if len(report) else -1
    return {
        "n_blocks": len(report),
        "n_fallen": len(fallen),
        "fallen_fraction": float(len(fallen) / max(len(report), 1)),
        "first_fall_time_s": float(first["fall_time_s"]) if first is not None else math.nan,
        "first_fallen_block": str(first["block"]) if first is not None else "",
        "n_falling_at_end": int(report["falling_at_end"].sum()) if len(report) else 0,
        "max_abs_theta_rad": float(report["max_abs_theta_rad"].iloc[k_theta]) if k_theta >= 0 else math.nan,
        "max_theta_block": str(report["block"].iloc[k_theta]) if k_theta >= 0 else "",
        "max_residual_displacement_m": float(residual.iloc[k_disp]) if k_disp >= 0 else math.nan,
        "max_residual_block": str(report["block"].iloc[k_disp]) if k_disp >= 0 else "",
        "n_moving_at_end": int((~report["final_state"].isin(["rest", "fallen"])).sum()),
    }
