"""Summary metrics of a run (the rows of batch summaries and CLI reports): per block, per
assembly (collapse), and of a stack as one body (:func:`structure_rotation`)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from rockyade.analysis.collapse_verdict import collapse_verdict
from rockyade.blocks.classical import ClassicalParameters
from rockyade.blocks.restitution import MU_EFF_IMPACTS, effective_restitution, find_peaks
from rockyade.constants import G
from rockyade.result import Result
from rockyade.runner.rows import Cell, Verdict
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical

if TYPE_CHECKING:
    import pandas as pd


def run_metrics(
    scene: Scene,
    result: Result,
    n_impacts: int = MU_EFF_IMPACTS,
    report: pd.DataFrame | None = None,
    verdict: Verdict | None = None,
) -> dict[str, dict[str, float]]:
    """Per-block summary of a run: peaks, max |theta|, effective mu, overturn.

    Parameters
    ----------
    scene
        The Scene that produced ``result``.
    result
        The Result.
    n_impacts
        Impacts used for the effective restitution (free rocking).
    report
        The run's :func:`rockyade.analysis.collapse.collapse_report`, when the caller has it.
    verdict
        The run's :func:`rockyade.analysis.collapse_verdict.collapse_verdict`, when the caller
        has it.

    Returns
    -------
    dict
        block name -> ``max_abs_theta_rad``, ``max_theta_over_alpha``, ``n_peaks``,
        ``first_peak_rad``, ``mu_eff`` (free rocking only; NaN otherwise or without two
        peaks), ``residual_theta_rad``,
        ``uplift_time_s`` (first |theta| > 1e-4 alpha), ``overturned`` (bool: it fell, by the
        one rule of :mod:`rockyade.analysis.collapse_verdict`).
    """
    out: dict[str, dict[str, float]] = {}
    t = result.t
    free = scene.motion.type == "free"
    fell: tuple[str, ...] = ()
    if result.ok:
        fell = (verdict or collapse_verdict(scene, result, report=report)).fallen
    classical = loaded_classical(scene, G)
    for spec in scene.blocks:
        if spec.fixed:
            continue
        cp = classical[spec.name]
        theta = result.series("theta_rad", spec.name)
        overturned = spec.name in fell
        values = theta_metrics(t, theta, cp.alpha_rad, cp)
        out[spec.name] = block_summary(values, t, theta, cp.alpha_rad, free, overturned, n_impacts, cp)
    return out


#: The keys of a block's summary (:func:`block_summary`), in the order of earlier versions.
SUMMARY_KEYS = (
    "max_abs_theta_rad",
    "max_theta_over_alpha",
    "n_peaks",
    "first_peak_rad",
    "first_peak_time_s",
    "mu_eff",
    "residual_theta_rad",
    "uplift_time_s",
    "overturned",
)


def block_summary(
    theta_values: Mapping[str, float],
    t: np.ndarray,
    theta: np.ndarray,
    alpha_rad: float,
    free: bool,
    overturned: bool,
    n_impacts: int = MU_EFF_IMPACTS,
    classical: ClassicalParameters | None = None,
) -> dict[str, float]:
    """One block's summary row (:data:`SUMMARY_KEYS`): of a Result (:func:`run_metrics`) and of
    a grouped run (:class:`rockyade.solvers.base.GroupRun`, whose solver computed the rotation's
    metrics).

    Parameters
    ----------
    theta_values
        ``max_abs_theta_rad``, ``residual_theta_rad`` (rad) and ``uplift_time_s`` (s) of the
        rotation (:func:`theta_metrics`, or the solver's).
    t, theta
        The sampled rotation: s and rad.
    alpha_rad
        The block's slenderness, rad (the governing side's when it has two).
    free
        Free rocking (``mu_eff`` is computed for it only).
    overturned
        Whether the block fell (:func:`rockyade.analysis.collapse_verdict.collapse_verdict`).
    n_impacts
        Impacts used for the effective restitution.
    classical
        The classical parameters of the body that rocks (a loaded block's:
        :func:`rockyade.scene.carried.loaded_classical`): ``max_theta_over_alpha`` is then each
        side's rotation over that side's alpha (:meth:`ClassicalParameters.theta_over_alpha`);
        None: the peak over ``alpha_rad``.
    """
    peak = theta_values["max_abs_theta_rad"]
    values = {
        **theta_values,
        "max_theta_over_alpha": peak / alpha_rad if classical is None else classical.theta_over_alpha(theta),
        **peak_metrics(t, theta, alpha_rad, free, n_impacts),
        "overturned": overturned,
    }
    return {k: values[k] for k in SUMMARY_KEYS}


def uplift_threshold_rad(alpha_rad: float) -> float:
    """|theta| above which a block of slenderness ``alpha_rad`` counts as lifted off, rad."""
    return 1e-4 * alpha_rad


def theta_metrics(
    t: np.ndarray, theta: np.ndarray, alpha_rad: float, classical: ClassicalParameters | None = None
) -> dict[str, float]:
    """``max_abs_theta_rad``, ``max_theta_over_alpha``, ``residual_theta_rad`` and
    ``uplift_time_s`` of one block's sampled rotation (``t`` in s, ``theta`` in rad; NaN
    samples ignored). :func:`rockyade.kernel.runs.simulate_runs` computes the same in the kernel.
    With ``classical`` (the body's parameters, each side its own alpha) the ratio is taken
    against the alpha of the side the block turns to (:meth:`ClassicalParameters.theta_over_alpha`)."""
    finite = theta[np.isfinite(theta)]
    lifted = np.nonzero(np.abs(theta) > uplift_threshold_rad(alpha_rad))[0]
    peak = float(np.max(np.abs(finite))) if finite.size else math.nan
    return {
        "max_abs_theta_rad": peak,
        "max_theta_over_alpha": peak / alpha_rad if classical is None else classical.theta_over_alpha(theta),
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


def assembly_metrics(scene: Scene, result: Result, report: pd.DataFrame | None = None) -> dict[str, float | int | str]:
    """Aggregate collapse metrics of an assembly's run (:mod:`rockyade.analysis.collapse`):
    ``n_blocks``, ``n_fallen`` (blocks that came down within the run), ``fallen_fraction``,
    ``first_fall_time_s``, ``first_fallen_block``, ``n_falling_at_end`` (blocks still falling
    when the run ended: not counted as fallen), ``max_abs_theta_rad`` and its block,
    ``max_residual_displacement_m`` (at the end of the run) and its block, ``n_moving_at_end``
    (blocks whose final state is not rest or fallen: their "residual" values are where they
    were when the run ended, not where they stopped), and the whole's own measure
    (:func:`structure_rotation`: ``structure``, ``structure_alpha_rad``,
    ``structure_max_theta_rad``, ``structure_max_theta_over_alpha``, ``structure_note``).
    Times in s, angles in rad, displacements in m. The run's status is ``overturned`` exactly when ``n_fallen`` > 0
    (both DEMs decide it by the same rule, :func:`rockyade.dem.overturn.run_outcome`).

    Parameters
    ----------
    scene
        The scene that produced ``result`` (its blocks, bottom to top).
    result
        The run's Result (any solver).
    report
        The run's :func:`rockyade.analysis.collapse.collapse_report`, when the caller has it."""
    if report is None:
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
        **structure_rotation(scene, result),
    }


def summary_metrics(
    scene: Scene, result: Result, report: pd.DataFrame | None = None, verdict: Verdict | None = None
) -> dict[str, Cell]:
    """The metrics of a run as one flat summary row (a batch summary's, after its status
    columns): the assembly's (:func:`assembly_metrics`, positioned scenes), each block's
    (:func:`run_metrics`; prefixed with the block's name unless the scene has one block;
    none for an assembly of more than :data:`PER_BLOCK_LIMIT` blocks) and, for two blocks,
    the dominant rocking pattern and its time fractions (JSON;
    :func:`rockyade.analysis.patterns.classify_result`).

    Parameters
    ----------
    scene
        The Scene that produced ``result``.
    result
        The run's Result (completed or overturned).
    report, verdict
        The run's collapse table and verdict, when the caller has them (computed once).
    """
    row: dict[str, Cell] = {}
    if report is None and scene.positioned and len(scene.blocks) > 1:
        from rockyade.analysis.collapse import collapse_report

        report = collapse_report(scene, result)
    if scene.positioned:
        row.update(assembly_metrics(scene, result, report))
    if not scene.positioned or len(scene.blocks) <= PER_BLOCK_LIMIT:
        single = len(scene.blocks) == 1
        for block, values in run_metrics(scene, result, report=report, verdict=verdict).items():
            for key, value in values.items():
                row[key if single else f"{block}_{key}"] = value
    if len(scene.blocks) == 2:
        from rockyade.analysis.patterns import classify_result

        pattern = classify_result(scene, result)
        row["pattern"] = pattern.dominant
        row["pattern_fractions"] = json.dumps(pattern.fractions, sort_keys=True)
    return row


#: Why an assembly that is not a stack has no whole-body rotation measure (docs/assemblies.md).
NO_WHOLE_ROTATION = (
    "not a single stack: a wall, an arch or a frame fails by a mechanism of some of its blocks, not by "
    "rocking as one body, so it has no whole-body alpha"
)


def stack_order(scene: Scene) -> list[str] | None:
    """The moving blocks bottom to top when they form one stack (the bottom one on the base,
    each other on the one below it alone, no fixed block, no head joint); else None.

    Parameters
    ----------
    scene
        Any scene (a column scene is a stack by construction)."""
    from rockyade.scene.placement import placed_blocks, scene_rest_contacts

    if any(spec.fixed for spec in scene.blocks):
        return None
    if not scene.positioned:
        return [spec.name for spec in scene.blocks]
    placed = placed_blocks(scene)
    below: dict[int, list[int]] = {}
    for c in scene_rest_contacts(scene):
        if c.kind != "bed":
            return None
        lower = -1 if c.b < 0 else (c.b if c.upper == c.a else c.a)
        below.setdefault(c.upper, []).append(lower)
    order, current = [], -1
    for _ in placed:
        above = [k for k, lows in below.items() if lows == [current]]
        if len(above) != 1:
            return None
        current = above[0]
        order.append(current)
    if sorted(order) != list(range(len(placed))):
        return None
    return [placed[k].name for k in order]


def structure_rotation(scene: Scene, result: Result) -> dict[str, float | str]:
    """A stack's rotation as one body: the turn of the line from its base corner to the
    centroid of all its blocks, against that line's angle from the vertical at rest (the
    whole's alpha: a rigid stack turned by it has its centroid over the corner).

    For one block this is its theta against its alpha; for drums that rock as one body, each
    drum's theta against the column's alpha, whereas each drum's own alpha is much larger
    (a drum 0.8 m wide and 1 m tall has alpha = 0.675 rad; six of them, 0.133 rad).

    Parameters
    ----------
    scene
        The scene that produced ``result``.
    result
        The run's Result (any solver).

    Returns
    -------
    dict
        ``structure``: "stack of N" or "none"; ``structure_alpha_rad`` (of the side the stack
        turns to at its peak: the largest rotation over its side's alpha; one block: each side's
        alpha with its loads' masses), ``structure_max_theta_rad`` (signed: counter-clockwise about
        the left corner > 0), ``structure_max_theta_over_alpha``; NaN and ``structure_note`` saying why
        for an assembly that is not a stack (:data:`NO_WHOLE_ROTATION`). Angles in rad.
    """
    nan: dict[str, float | str] = {
        "structure": "none",
        "structure_alpha_rad": math.nan,
        "structure_max_theta_rad": math.nan,
        "structure_max_theta_over_alpha": math.nan,
        "structure_note": "",
    }
    order = stack_order(scene)
    if order is None:
        return {**nan, "structure_note": NO_WHOLE_ROTATION}
    if not result.ok or result.t.size == 0:
        return {**nan, "structure": f"stack of {len(order)}", "structure_note": "the run failed"}
    from rockyade.scene.placement import placed_blocks

    placed = {b.name: b for b in placed_blocks(scene)}
    bodies = result.meta.bodies or {}
    specs = {spec.name: spec for spec in scene.blocks}
    mass = np.array([float(bodies[n]["mass_kg"]) if n in bodies else specs[n].block().mass_kg for n in order])
    rest = np.array([placed[n].centroid_m for n in order])
    g0 = mass @ rest / mass.sum()
    moved = np.stack(
        [rest[k] + np.column_stack([result.series("x_m", n), result.series("y_m", n)]) for k, n in enumerate(order)]
    )
    g = np.einsum("k,knd->nd", mass, moved) / mass.sum()
    left, right = _base_corners(placed[order[0]], bodies.get(order[0]))
    alpha_left = math.atan2(g0[0] - left[0], g0[1] - left[1])
    alpha_right = math.atan2(right[0] - g0[0], g0[1] - right[1])
    about_left = np.arctan2(-(g[:, 0] - left[0]), g[:, 1] - left[1]) + alpha_left  # > 0: CCW, towards -x
    about_right = np.arctan2(-(g[:, 0] - right[0]), g[:, 1] - right[1]) - alpha_right  # < 0: CW
    theta = np.where(g[:, 0] <= g0[0], about_left, about_right)
    if len(order) == 1:  # one block: each side's alpha as it rocks (the loads' masses in; an overridden
        # alpha's equivalent base, as the DEMs' contact polygon)
        cp = loaded_classical(scene, G)[order[0]]
        alpha_left, alpha_right = cp.left.alpha_rad, cp.right.alpha_rad
    finite = np.isfinite(theta)
    if not finite.any():
        return {**nan, "structure": f"stack of {len(order)}", "structure_note": "no finite sample"}
    ratio = np.where(theta >= 0, theta / alpha_left, -theta / alpha_right)  # each side over its own alpha
    k = int(np.nanargmax(ratio))
    alpha = alpha_left if theta[k] >= 0 else alpha_right
    return {
        "structure": f"stack of {len(order)}",
        "structure_alpha_rad": float(alpha),
        "structure_max_theta_rad": float(theta[k]),
        "structure_max_theta_over_alpha": float(ratio[k]),
        "structure_note": "",
    }


def _base_corners(block, body: dict | None) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Left and right base corners of the bottom block at rest, base frame, m: the DEM's (its
    base corners may sit at the equivalent base b_eq, paper Eq 11) when the result has them."""
    if body is not None:
        poly = np.asarray(body["contact_vertices_m"], dtype=float)
        c, s = math.cos(body["rest_angle_rad"]), math.sin(body["rest_angle_rad"])
        poly = poly @ np.array([[c, s], [-s, c]]) + np.asarray(body["rest_centroid_m"], dtype=float)
    else:
        poly = np.asarray(block.vertices_m, dtype=float)
    low = poly[:, 1] <= poly[:, 1].min() + 1e-9 * max(float(np.ptp(poly[:, 1])), 1.0)
    base = poly[low]
    return base[np.argmin(base[:, 0])], base[np.argmax(base[:, 0])]
