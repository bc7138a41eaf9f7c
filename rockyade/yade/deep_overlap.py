"""YADE's deep overlaps: a run stopped by one is a failure, unless an assembly was already collapsing.

YADE's sphere-polyhedron contact loses its normal when a vertex sphere goes deeper into a
non-rectangular block than its own radius (the driver records the deepest such ratio and when
it first reached 1). Such a run fails (:data:`DEEP_OVERLAP`), unless by then the assembly had
started to collapse without creating energy (:func:`collapse_before_overlap`, docs/yade.md):
its history up to the overlap is then kept, status ``overturned`` (:func:`collapsed_meta`).
The backend (:mod:`rockyade.yade.backend`) asks both through its ``rescue`` hook.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from rockyade.dem.model import DemModel
from rockyade.dem.overturn import DROP_FRACTION
from rockyade.dem.result_frames import energy_gain
from rockyade.dem.worker_output import WorkerOutput

#: Why a run with a deep sphere-polyhedron overlap fails (when it is not part of a collapse).
DEEP_OVERLAP = (
    "a vertex sphere went deeper into a non-rectangular block than its own radius (YADE's sphere-polyhedron "
    "contact then loses its normal): the impact is too hard for these contact spheres"
)


def collapse_before_overlap(model: DemModel, meta: WorkerOutput, arrays: dict[str, np.ndarray]) -> int | None:
    """The samples to keep when a deep overlap is part of a collapse, or None (a blow-up).

    The rule (docs/yade.md): at the last sample before the overlap (``deep_overlap_time_s``
    of the driver; the end of the output when an older driver does not say), some moving block
    has reached its landing angle, dropped by more than DROP_FRACTION of its height (the
    collapse table's rule, :data:`rockyade.dem.overturn.DROP_FRACTION`), or passed
    its tipping angle alpha, and the energy has not grown up to then (no blow-up by
    :func:`rockyade.dem.result_frames.energy_gain`).
    """
    n = meta.n_filled
    when = meta.deep_overlap_time_s
    # the depth is measured at the samples: keep those before the one that saw it
    keep = n if when is None else min(n, math.floor(float(when) / model.sample_dt_s + 1e-9))
    if keep < 3:
        return None
    pos, ang, angvel = arrays["pos"][:keep], arrays["ang"][:keep], arrays["angvel"][:keep]
    if not (np.all(np.isfinite(pos)) and np.all(np.isfinite(ang))):
        return None
    _, t_blowup = energy_gain(model, pos, ang, angvel)
    if t_blowup is not None:
        return None
    stop = model.stop_angle_rad if model.stop_angle_rad is not None else np.full(len(model.bodies), 0.5 * math.pi)
    for i, body in enumerate(model.bodies):
        if body.fixed:
            continue
        theta = np.abs(ang[:, i] - body.rest_angle_rad)
        height = float(np.ptp(body.contact_vertices_m[:, 1]))
        dropped = body.rest_centroid_m[1] - pos[:, i, 1] > DROP_FRACTION * height
        alpha = body.alpha_rad if math.isfinite(body.alpha_rad) else stop[i]
        if np.any(theta >= stop[i]) or np.any(dropped) or np.any(theta > alpha):
            return keep
    return None


def collapsed_meta(
    model: DemModel,
    meta: WorkerOutput,
    arrays: dict[str, np.ndarray],
    run_meta: Callable[[WorkerOutput], dict[str, object]],
) -> dict[str, object]:
    """The Result's metadata of an assembly collapsing up to a deep overlap, ``arrays`` its
    samples up to there (``run_meta``: the backend's metadata of a run): status
    ``overturned``, the first block that landed, else the first past its tipping angle."""
    names = model.names
    ang = arrays["ang"]
    t_cut = (ang.shape[0] - 1) * model.sample_dt_s
    meta = dataclasses.replace(
        meta,
        overturn_times_s={i: t for i, t in meta.overturn_times_s.items() if t <= t_cut + 1e-12},
        status="completed",  # re-decided from the blocks' falls up to the cut
    )
    out = run_meta(meta)
    if out["status"] != "overturned":
        first, block = math.inf, None
        for i, body in enumerate(model.bodies):
            if body.fixed:
                continue
            over = np.flatnonzero(np.abs(ang[:, i] - body.rest_angle_rad) > body.alpha_rad)
            if over.size and over[0] * model.sample_dt_s < first:
                first, block = over[0] * model.sample_dt_s, names[i]
        out.update(status="overturned", overturn_time_s=first if block else t_cut, overturned_block=block)
    out["stopped_at_deep_overlap_s"] = t_cut
    out["deep_overlap_note"] = (
        "the run stopped at a deep sphere-polyhedron overlap after the assembly had started to collapse "
        "(docs/yade.md): its history up to there is kept"
    )
    return out
