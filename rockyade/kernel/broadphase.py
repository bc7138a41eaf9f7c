"""Broad phase of the reference DEM: candidate pairs by sort and sweep over AABBs grown by a
margin, rebuilt only when a body has moved by more than its margin (a Verlet list).

Each body's axis-aligned bounding box is grown by its margin ``m_i``; two bodies are a
candidate pair when their grown boxes overlap. No point of a body moves farther than
``|dx| + |dy| + |d theta| r_i`` (r_i its largest vertex distance from the centroid) since
the list was built, so while that bound stays below ``m_i`` for every body, no pair outside
the list can touch, and the list stays valid (the "Verlet distance" of YADE's
``InsertionSortCollider``; Baraff's sort and sweep, D. Baraff, "Dynamic simulation of
non-penetrating rigid bodies", PhD thesis, Cornell 1992, ch. 6). A rebuild sorts the bodies
along the sweep axis by insertion sort from the last order (linear for slowly moving
blocks), sweeps, and keeps the state of the pairs that persist.

The sweep axis is the one along which the bodies' centres spread most (x for a wall, y for
a column), so that few boxes overlap along it.
"""

from __future__ import annotations

import numba
import numpy as np

#: A body's box is grown by this fraction of its smallest extent.
MARGIN_REL = 0.05


@numba.njit(cache=True, nogil=True)
def sweep_axis(lo, hi) -> int:
    """0 (x) or 1 (y): the axis along which the box centres spread most."""
    nb = lo.shape[0]
    spread = np.zeros(2)
    for k in range(2):
        cmin = np.inf
        cmax = -np.inf
        for i in range(nb):
            c = 0.5 * (lo[i, k] + hi[i, k])
            cmin = min(cmin, c)
            cmax = max(cmax, c)
        spread[k] = cmax - cmin
    return 0 if spread[0] >= spread[1] else 1


@numba.njit(cache=True, nogil=True, inline="always")
def initial_order(lo, hi):
    """The sweep axis (:func:`sweep_axis`) and the bodies sorted by their box centres along it
    ((nb,) int64), the starting order of :func:`candidate_pairs`."""
    order = np.argsort(lo[:, 0] + hi[:, 0]).astype(np.int64)
    axis = sweep_axis(lo, hi)
    if axis == 1:
        order = np.argsort(lo[:, 1] + hi[:, 1]).astype(np.int64)
    return axis, order


@numba.njit(cache=True, nogil=True)
def insertion_sort(order, key) -> None:
    """Sort ``order`` in place by ``key[order]`` (linear when nearly sorted)."""
    for i in range(1, order.size):
        item = order[i]
        k = key[item]
        j = i - 1
        while j >= 0 and key[order[j]] > k:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = item


@numba.njit(cache=True, nogil=True)
def candidate_pairs(lo, hi, margin, fixed, axis: int, order):
    """Pairs (a < b) whose grown boxes overlap, sorted by key a * (nb + 1) + b.

    Parameters
    ----------
    lo, hi
        (nb, 2) tight boxes, m.
    margin
        (nb,) growth of each box, m.
    fixed
        (nb,) bool: pairs of two fixed bodies are left out.
    axis
        Sweep axis.
    order
        (nb,) int64 body order along the axis from the last build, sorted in place.

    Returns
    -------
    keys : (np,) int64 sorted pair keys; pa, pb : (np,) int64
    """
    nb = lo.shape[0]
    other = 1 - axis
    glo = np.empty(nb)
    ghi = np.empty(nb)
    for i in range(nb):
        glo[i] = lo[i, axis] - margin[i]
        ghi[i] = hi[i, axis] + margin[i]
    insertion_sort(order, glo)
    cap = 4 * nb + 16
    keys = np.empty(cap, dtype=np.int64)
    n = 0
    for ii in range(nb):
        i = order[ii]
        for jj in range(ii + 1, nb):
            j = order[jj]
            if glo[j] > ghi[i]:
                break
            if fixed[i] and fixed[j]:
                continue
            if lo[i, other] - margin[i] > hi[j, other] + margin[j]:
                continue
            if lo[j, other] - margin[j] > hi[i, other] + margin[i]:
                continue
            if n == cap:
                grown = np.empty(2 * cap, dtype=np.int64)
                grown[:cap] = keys
                keys = grown
                cap *= 2
            a = i if i < j else j
            b = j if i < j else i
            keys[n] = a * (nb + 1) + b
            n += 1
    keys = np.sort(keys[:n])
    pa = keys // (nb + 1)
    pb = keys - pa * (nb + 1)
    return keys, pa, pb


@numba.njit(cache=True, nogil=True, inline="always")
def moved_beyond_margin(pos, ang, ref_pos, ref_ang, radius, margin, moving) -> bool:
    """True when some moving body may have moved a point farther than its margin."""
    for i in range(pos.shape[0]):
        if not moving[i]:
            continue
        d = abs(pos[i, 0] - ref_pos[i, 0]) + abs(pos[i, 1] - ref_pos[i, 1]) + abs(ang[i] - ref_ang[i]) * radius[i]
        if d > margin[i]:
            return True
    return False
