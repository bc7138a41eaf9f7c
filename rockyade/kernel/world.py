"""Placement: every body's polygon in the base frame at the current positions.

For body a at centroid x_a and angle theta_a, with R(theta) the rotation by theta:

* vertex v:       p_v = x_a + R(theta_a) v_v            (the body-frame vertex v_v)
* edge normal e:  n_e = R(theta_a) n_e^body
* edge line e:    d_e = n_e . p_e                        (the line is n_e . p = d_e)
* tight box:      lo, hi = min, max of p_v over the vertices.

The separating-axis test, the clipping and the base contacts read these; the broad phase
reads the boxes.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.step import world_x, world_y


class World(NamedTuple):
    """The bodies placed in the base frame (filled by :func:`place_body`)."""

    wv: NDArray[np.float64]  #: (nb, maxv, 2) vertices, m
    wn: NDArray[np.float64]  #: (nb, maxv, 2) outward unit edge normals
    wd: NDArray[np.float64]  #: (nb, maxv) edge-line offsets n_e . p_e, m
    lo: NDArray[np.float64]  #: (nb, 2) lower corner of the tight box, m
    hi: NDArray[np.float64]  #: (nb, 2) upper corner of the tight box, m


@numba.njit(cache=True, nogil=True, inline="always")
def new_world(nb: int, maxv: int) -> World:
    """Zeroed placement arrays for nb bodies of at most maxv vertices."""
    return World(
        np.zeros((nb, maxv, 2)), np.zeros((nb, maxv, 2)), np.zeros((nb, maxv)), np.zeros((nb, 2)), np.zeros((nb, 2))
    )


@numba.njit(cache=True, nogil=True, inline="always")
def place_body(a: int, kin, bodies, world) -> None:
    """World vertices, edge normals, edge-line offsets and tight box of body ``a``.

    Parameters
    ----------
    kin
        :class:`rockyade.kernel.integration.Motion` (``pos``, m, and ``ang``, rad).
    bodies
        :class:`rockyade.kernel.state.Bodies` (``verts``, ``normals``, ``nverts``).
    world
        :class:`World`, written for body ``a``.
    """
    pos, ang = kin.pos, kin.ang
    verts, normals = bodies.verts, bodies.normals
    wv, wn, wd, lo, hi = world.wv, world.wn, world.wd, world.lo, world.hi
    c = math.cos(ang[a])
    s = math.sin(ang[a])
    lox = math.inf
    loy = math.inf
    hix = -math.inf
    hiy = -math.inf
    for v in range(bodies.nverts[a]):
        x = verts[a, v, 0]
        y = verts[a, v, 1]
        px = world_x(pos[a, 0], c, s, x, y)
        py = world_y(pos[a, 1], c, s, x, y)
        wv[a, v, 0] = px
        wv[a, v, 1] = py
        nx = normals[a, v, 0]
        ny = normals[a, v, 1]
        wn[a, v, 0] = c * nx - s * ny
        wn[a, v, 1] = s * nx + c * ny
        wd[a, v] = wn[a, v, 0] * px + wn[a, v, 1] * py
        lox = min(lox, px)
        hix = max(hix, px)
        loy = min(loy, py)
        hiy = max(hiy, py)
    lo[a, 0] = lox
    lo[a, 1] = loy
    hi[a, 0] = hix
    hi[a, 1] = hiy


@numba.njit(cache=True, nogil=True, inline="always")
def place_bodies(kin, bodies, world, moving_only: bool) -> None:
    """:func:`place_body` for every body (``moving_only``: the moving ones; fixed bodies
    never move in the base frame)."""
    moving = bodies.moving
    for a in range(moving.size):
        if moving[a] or not moving_only:
            place_body(a, kin, bodies, world)
