"""Which way the wall can go: the side each load bears on, and whether the governing mechanism
turns towards it (``rockyade assess``'s verdict line and its floor note; docs/howto/is-this-wall-safe.md,
"Which way can the wall go").

A load on a moving block bears on the side of the block's axis its point lies on (``+x`` or
``-x``, or ``axis`` within 1e-6 of the block's width), its offset measured from the block's own
centroid. A floor or a roof bearing on the side the mechanism turns to may hold the wall's top
that way, which the scene does not model unless it has a restraint there.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rockyade.limit import LimitResult


def load_sides(limit: LimitResult) -> list[dict[str, Any]]:
    """Each load on a moving block with the side of the block's axis it bears on: ``+x``, ``-x`` or
    ``axis`` (within 1e-6 of the block's width), with its offset from the block's own centroid, m."""
    model = limit.model
    own = model.centroids_m if model.block_centroids_m is None else model.block_centroids_m
    out = []
    for k, q in enumerate(model.given_loads):
        i = int(q.block)
        if model.fixed[i]:
            continue
        width = float(np.ptp(model.polygons_m[i][:, 0]))
        offset = float(q.point_m[0]) - float(own[i][0])
        side = "axis" if abs(offset) <= 1e-6 * width else ("+x" if offset > 0 else "-x")
        out.append({"load": k, "block": model.names[i], "offset_m": offset, "side": side, "force_N": list(q.force_N)})
    return out


def toward_loaded_side(limit: LimitResult) -> list[int]:
    """The loads (their index) on the side the governing mechanism turns to (:func:`load_sides`)."""
    return [q["load"] for q in load_sides(limit) if q["side"] == limit.direction]
