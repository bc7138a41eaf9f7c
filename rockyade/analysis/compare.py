"""Agreement between solvers on one scene.

For every block and every solver, against a reference solver (by default the reference
DEM): the first peak amplitudes and times, the effective restitution (free rocking), max
|theta|, the overturn verdict and time, and the RMS difference of theta(t) over the common
time window. One long table (CSV) with the value, the reference value and the difference.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.result import Result
from rockyade.scene import Scene

N_PEAKS = 5
COLUMNS = ["block", "solver", "reference", "metric", "value", "reference_value", "difference", "relative_difference"]


def _metrics(scene: Scene, result: Result, block: str, alpha: float) -> dict[str, float]:
    out: dict[str, float] = {}
    if not result.ok or block not in result.blocks:
        return out
    theta = result.series("theta_rad", block)
    peaks = find_peaks(result.t, theta, min_peak_rad=max(1e-5, 1e-3 * alpha))
    for k in range(N_PEAKS):
        out[f"peak{k + 1}_amplitude_rad"] = float(peaks.amplitude_rad[k]) if k < len(peaks) else math.nan
        out[f"peak{k + 1}_time_s"] = float(peaks.t_s[k]) if k < len(peaks) else math.nan
    out["mu_eff"] = effective_restitution(peaks, alpha, MU_EFF_IMPACTS) if scene.motion.type == "free" else math.nan
    out["max_abs_theta_rad"] = float(np.nanmax(np.abs(theta))) if theta.size else math.nan
    overturned = result.status == "overturned" and result.meta.get("overturned_block") == block
    out["overturned"] = float(overturned)
    out["overturn_time_s"] = float(result.meta["overturn_time_s"]) if overturned else math.nan
    return out


def rms_difference(a: Result, b: Result, block: str) -> float:
    """RMS of theta_a - theta_b over the samples both results have, rad.

    Parameters
    ----------
    a, b
        The two results (sampled alike).
    block
        The block compared; NaN when either result lacks it.
    """
    n = min(len(a.frame), len(b.frame))
    if n == 0 or block not in a.blocks or block not in b.blocks:
        return math.nan
    d = a.series("theta_rad", block)[:n] - b.series("theta_rad", block)[:n]
    return float(np.sqrt(np.nanmean(d * d)))


def compare(scene: Scene, results: dict[str, Result], reference: str | None = None) -> pd.DataFrame:
    """Agreement metrics of several solvers' results on ``scene``.

    Parameters
    ----------
    scene
        The scene all results come from.
    results
        solver name -> Result.
    reference
        Solver to compare against (default: "reference" if present, else the first).
    """
    if reference is None:
        reference = "reference" if "reference" in results else next(iter(results))
    rows = []
    for spec in scene.blocks:
        alpha = spec.classical().alpha_rad
        ref_metrics = _metrics(scene, results[reference], spec.name, alpha)
        for solver, result in results.items():
            metrics = _metrics(scene, result, spec.name, alpha)
            if not metrics:
                rows.append([spec.name, solver, reference, "status", math.nan, math.nan, math.nan, math.nan])
                continue
            metrics["rms_theta_difference_rad"] = rms_difference(result, results[reference], spec.name)
            for name, value in metrics.items():
                ref_value = 0.0 if name == "rms_theta_difference_rad" else ref_metrics.get(name, math.nan)
                diff = value - ref_value
                rel = diff / ref_value if ref_value not in (0.0,) and math.isfinite(ref_value) else math.nan
                rows.append([spec.name, solver, reference, name, value, ref_value, diff, rel])
    return pd.DataFrame(rows, columns=COLUMNS)
