"""Agreement between solvers on one scene.

For every block and every solver, against a reference solver (by default the reference
DEM): the first peak amplitudes and times, the effective restitution (free rocking), max
|theta|, the overturn verdict and time, and the RMS difference of theta(t) over the common
time window. One long table (CSV) with the value, the reference value and the difference;
the reference solver is not compared with itself (its values are the ``reference_value``
column). :func:`verdict` sums it up in one line: the outcome agreement, the largest peak
difference between solvers (max |theta| under a base motion; in free rocking, where max
|theta| is the release angle for every solver, the first peaks after the release) and, given
runs at half the time step, whether halving the step changed the peaks more than the solvers
differ (then the difference says nothing).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rockyade.analysis.collapse import ROCK_FRACTION, ROCK_MIN_RAD
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
    overturned = result.status == "overturned" and result.meta.overturned_block == block
    out["overturned"] = float(overturned)
    when = result.meta.overturn_time_s
    out["overturn_time_s"] = float(when) if overturned and when is not None else math.nan
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
            if solver == reference and len(results) > 1:
                continue  # a solver is never compared with itself
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


#: Free rocking: the verdict compares this many peaks after the release (those of mu_eff).
FREE_PEAKS = MU_EFF_IMPACTS

#: A relative change below this (0.1 %) is no change: a step change and a solver gap both
#: under it do not make the difference "say nothing" (0 >= 0 is agreement, not doubt).
CONVERGED_TOL = 1e-3


def _peaks(scene: Scene, result: Result) -> dict[str, tuple[float, ...]]:
    """Block -> the peaks the verdict compares (rad); empty for a failed result.

    Under a base motion: (max |theta|,). In free rocking max |theta| is the release angle
    theta0, the same for every solver, so the peaks compared are the first
    :data:`FREE_PEAKS` amplitudes after the release (the response to the impacts; those
    :func:`~rockyade.blocks.restitution.effective_restitution` uses), or (max |theta|,) when
    the block has none (it overturned or never rocked back).
    """
    if not result.ok:
        return {}
    out: dict[str, tuple[float, ...]] = {}
    for spec in scene.blocks:
        if spec.fixed or spec.name not in result.blocks:
            continue
        theta = result.series("theta_rad", spec.name)
        largest = (float(np.nanmax(np.abs(theta))),)
        if scene.motion.type == "free":
            alpha = spec.classical().alpha_rad
            amplitudes = find_peaks(result.t, theta, min_peak_rad=max(1e-5, 1e-3 * alpha)).amplitude_rad
            after = tuple(float(abs(a)) for a in amplitudes[:FREE_PEAKS])
            out[spec.name] = after or largest
        else:
            out[spec.name] = largest
    return out


def _still(scene: Scene, result: Result) -> set[str]:
    """The blocks that never rock in ``result``: max |theta| at most ``ROCK_FRACTION`` of the
    block's alpha (and ``ROCK_MIN_RAD``), the threshold of
    :func:`~rockyade.analysis.collapse.block_states`. Their theta is the contacts' elastic tilt
    (the DEMs) or a micro-uplift (a lower block thrown open by the landing of the one above): a
    relative difference of two such tilts is large and says nothing about the rocking."""
    if not result.ok:
        return set()
    out = set()
    for spec in scene.blocks:
        if spec.fixed or spec.name not in result.blocks:
            continue
        largest = float(np.nanmax(np.abs(result.series("theta_rad", spec.name))))
        if largest <= max(ROCK_MIN_RAD, ROCK_FRACTION * spec.classical().alpha_rad):
            out.add(spec.name)
    return out


def _relative(va: tuple[float, ...], vb: tuple[float, ...]) -> float:
    """The largest |a - b| / max(a, b) over the peaks both have (NaN: none comparable); when
    one has no peak after the release and the other has, their first values (max |theta| and
    the first peak) are compared."""
    worst = math.nan
    for a, b in zip(va, vb, strict=False):
        if math.isfinite(a) and math.isfinite(b) and max(a, b) > 0:
            d = abs(a - b) / max(a, b)
            worst = d if not math.isfinite(worst) else max(worst, d)
    return worst


def _largest_difference(
    a: dict[str, tuple[float, ...]], b: dict[str, tuple[float, ...]], still: set[str] | frozenset[str] = frozenset()
) -> tuple[float, str]:
    """The largest relative difference |a - b| / max(a, b) over the blocks both have and their
    peaks (symmetric: a solver's change with dt and two solvers' gap are measured alike), and
    its block; the blocks in ``still`` (at rest in both runs: :func:`_still`) are left out."""
    worst, where = 0.0, ""
    for block, vb in b.items():
        if block in still:
            continue
        d = _relative(a.get(block, ()), vb)
        if math.isfinite(d) and (d > worst or not where):
            worst, where = d, block
    return (worst, where) if where else (math.nan, "")


def verdict(scene: Scene, results: dict[str, Result], reference: str, finer: dict[str, Result] | None = None) -> str:
    """One line: do the solvers give the same outcome (overturned or not), how far apart are
    their peaks (the largest relative difference from ``reference``, over blocks, of the
    larger of the two: max |theta| under a base motion, the first :data:`FREE_PEAKS` peaks
    after the release in free rocking), and, with ``finer`` (solver -> its run at half the
    time step), did halving the step change a solver's peaks more than the solvers differ
    (then the difference says nothing; changes and gaps both below :data:`CONVERGED_TOL`
    are agreement to the step's accuracy).

    Parameters
    ----------
    scene
        The scene all results come from.
    results
        Solver name -> Result at the step compared.
    reference
        The solver the others are compared with.
    finer
        Solver name -> Result of the same solver at half that step (absent: not run).
    """
    outcomes = {s: (r.status if r.ok else "failed") for s, r in results.items()}
    kinds = set(outcomes.values())
    if len(kinds) == 1:
        outcome = f"same outcome ({kinds.pop()})"
    else:
        outcome = "outcomes differ (" + ", ".join(f"{s} {o}" for s, o in outcomes.items()) + ")"
    what = f"the first {FREE_PEAKS} peaks after release" if scene.motion.type == "free" else "peak |theta|"
    ref = _peaks(scene, results[reference])
    still = {s: _still(scene, r) for s, r in results.items()}
    diffs = {
        s: _largest_difference(_peaks(scene, r), ref, still[s] & still[reference])
        for s, r in results.items()
        if s != reference
    }
    diffs = {s: d for s, d in diffs.items() if math.isfinite(d[0])}
    resting = sorted(set.intersection(*still.values()), key=[b.name for b in scene.blocks].index)
    named = ", ".join(resting[:4]) + (f" and {len(resting) - 4} more" if len(resting) > 4 else "")
    at_rest = (
        f" ({named} at rest in every solver, below {100 * ROCK_FRACTION:g} % of its alpha: not compared)"
        if resting
        else ""
    )
    if diffs:
        solver = max(diffs, key=lambda s: diffs[s][0])
        gap, block = diffs[solver]
        peak = f"{what} within {100 * gap:.1f} % of {reference} (largest: {solver}, {block}){at_rest}"
    else:
        gap, peak = math.nan, f"no peaks to compare{at_rest}"
    if not finer:
        return f"{outcome}; {peak}; the time step not checked"
    changes = {
        s: _largest_difference(
            _peaks(scene, finer[s]), _peaks(scene, results[s]), _still(scene, finer[s]) & still.get(s, set())
        )[0]
        for s in finer
        if s in results
    }
    changes = {s: c for s, c in changes.items() if math.isfinite(c)}
    flips = [s for s in finer if s in results and finer[s].status != results[s].status]
    if not changes:
        return f"{outcome}; {peak}; halving the step gave no peaks to compare"
    moved = max(changes, key=lambda s: changes[s])
    change = changes[moved]
    step = f"halving the step changed {moved}'s peaks by {100 * change:.1f} %"
    if flips:
        step += f" and the outcome of {', '.join(flips)}"
    if math.isfinite(gap) and (flips or (change >= gap and change >= CONVERGED_TOL)):
        step += ", not less than the difference between solvers: that difference says nothing"
    elif math.isfinite(gap) and gap < CONVERGED_TOL:
        step += f", and the solvers differ by less than {100 * CONVERGED_TOL:g} %: they agree to the step's accuracy"
    elif math.isfinite(gap):
        step += ", less than the difference between solvers"
    return f"{outcome}; {peak}; {step}"
