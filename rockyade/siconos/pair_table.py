"""The contact pairs of a scene as arrays: their geometry at a state, and where the blocks of
the one-step problem's W = H M^-1 H^T are.

Runs inside Debian's Python beside the Siconos driver (:mod:`rockyade.siconos.driver`), which
builds a :class:`PairTable` for either of its engines: :mod:`rockyade.siconos.moreau_jean`
(the numerics path) steps with it, the kernel path sets its interactions from it. Imports only
numpy.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


class PairTable:
    """The contact pairs of a scene as arrays, and their geometry at a state (numpy).

    Parameters
    ----------
    bodies
        The scene's bodies (``vertices_m`` in the body frame, ``fixed``).
    pairs
        The vertex-to-edge pairs (:func:`rockyade.siconos.driver.contact_pairs`): ``a`` the
        vertex's body, ``v`` its index, ``b`` the edge's body (-1: the ground), and for a
        block's edge ``e0``, ``n`` (outward normal), ``L`` in that block's frame; ``mu``.
    twin
        For each pair the index of an earlier pair at the same point (coinciding corners), or
        -1 (:func:`rockyade.siconos.driver.twins`): while the earlier one is on its edge the
        later one is open.
    edge_slack, deep_fraction
        A pair is open when its vertex has left its edge by ``edge_slack`` of the edge's
        length, or lies deeper behind it than ``deep_fraction`` of the smaller block's
        smallest dimension.
    """

    def __init__(
        self,
        bodies: list[dict[str, Any]],
        pairs: list[dict[str, Any]],
        twin: np.ndarray,
        edge_slack: float,
        deep_fraction: float,
    ) -> None:
        nb = len(bodies)
        m = len(pairs)
        local = [np.asarray(b["vertices_m"], dtype=float) for b in bodies]
        size = [float(np.min(np.ptp(v, axis=0))) for v in local]
        self.pairs = pairs
        self.a = np.array([p["a"] for p in pairs], dtype=int)
        self.b = np.array([p["b"] if p["b"] >= 0 else nb for p in pairs], dtype=int)
        self.ground = np.array([p["b"] < 0 for p in pairs], dtype=bool)
        self.vloc = np.array([local[p["a"]][p["v"]] for p in pairs], dtype=float).reshape(m, 2)
        self.e0 = np.array([p["e0"] if p["b"] >= 0 else (0.0, 0.0) for p in pairs], dtype=float).reshape(m, 2)
        self.nl = np.array([p["n"] if p["b"] >= 0 else (0.0, 1.0) for p in pairs], dtype=float).reshape(m, 2)
        length = np.array([p["L"] if p["b"] >= 0 else math.inf for p in pairs], dtype=float)
        self.lo = -edge_slack * np.where(self.ground, 0.0, length)
        self.lo[self.ground] = -math.inf
        self.hi = np.where(self.ground, math.inf, length * (1.0 + edge_slack))
        self.deep = -np.array(
            [deep_fraction * min(size[p["a"]], size[p["b"]] if p["b"] >= 0 else size[p["a"]]) for p in pairs]
        )
        self.mu = np.array([p["mu"] for p in pairs], dtype=float)
        self.twin = np.asarray(twin, dtype=int)
        self.has_twin = np.flatnonzero(self.twin >= 0)
        self.twin_of = self.twin[self.has_twin]
        self.size = min(size)
        self.lists = (
            self.a.tolist(),
            self.b.tolist(),
            self.vloc.tolist(),
            self.nl.tolist(),
            self.e0.tolist(),
            self.lo.tolist(),
            self.hi.tolist(),
            self.deep.tolist(),
            self.twin.tolist(),
        )

    def pattern(self, m: int, contacts: np.ndarray, dofs: np.ndarray) -> DelassusPattern:
        """The :class:`DelassusPattern` of ``m`` active contacts (incidences ``contacts``, ``dofs``)."""
        return DelassusPattern(m, contacts, dofs)

    def geometry(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The pairs at positions ``q`` ((nb + 1, 3): x, y, theta per body, the ground last).

        Returns
        -------
        gap
            (m,) the vertex's distance from the edge's line along its normal, m.
        closed
            (m,) the pair is a contact: its vertex on its edge, not too deep, not a twin's
            shadow.
        H
            (m, 2, 2, 3) the contact Jacobian: [pair, side (a: the vertex's body, b: the
            edge's), row (normal, tangent), dof (x, y, theta)]; u = H_a v_a + H_b v_b.
        """
        qa, qb = q[self.a], q[self.b]
        ca, sa = np.cos(qa[:, 2]), np.sin(qa[:, 2])
        cb, sb = np.cos(qb[:, 2]), np.sin(qb[:, 2])
        vx, vy = self.vloc[:, 0], self.vloc[:, 1]
        rax, ray = ca * vx - sa * vy, sa * vx + ca * vy
        px, py = qa[:, 0] + rax, qa[:, 1] + ray
        nx = cb * self.nl[:, 0] - sb * self.nl[:, 1]
        ny = sb * self.nl[:, 0] + cb * self.nl[:, 1]
        ex, ey = self.e0[:, 0], self.e0[:, 1]
        rbx, rby = px - qb[:, 0], py - qb[:, 1]
        dx, dy = rbx - (cb * ex - sb * ey), rby - (sb * ex + cb * ey)
        gap = dx * nx + dy * ny
        along = dy * nx - dx * ny  # tangent t = (-n_y, n_x)
        closed = (along >= self.lo) & (along <= self.hi) & (gap >= self.deep)
        if len(self.has_twin):
            closed[self.has_twin] &= ~closed[self.twin_of]
        H = np.empty((len(gap), 2, 2, 3))
        H[:, 0, 0, 0], H[:, 0, 0, 1], H[:, 0, 0, 2] = nx, ny, ny * rax - nx * ray
        H[:, 0, 1, 0], H[:, 0, 1, 1], H[:, 0, 1, 2] = -ny, nx, nx * rax + ny * ray
        H[:, 1, 0, 0], H[:, 1, 0, 1], H[:, 1, 0, 2] = -nx, -ny, nx * rby - ny * rbx
        H[:, 1, 1, 0], H[:, 1, 1, 1], H[:, 1, 1, 2] = ny, -nx, -nx * rbx - ny * rby
        return gap, closed, H


class DelassusPattern:
    """Where the blocks of W = H M^-1 H^T of an active set are, and how they are summed: found
    once and kept while the active set stays (most steps), so that a step computes only the
    values.

    Parameters
    ----------
    m
        The active contacts.
    contacts, dofs
        One entry per (contact, moving body) incidence: the contact's index among the active
        ones and the body's index among the moving bodies.
    """

    def __init__(self, m: int, contacts: np.ndarray, dofs: np.ndarray) -> None:
        self.m = m
        self.order = np.argsort(dofs, kind="stable")
        c, d = contacts[self.order], dofs[self.order]
        self.dofs = d
        counts = np.bincount(d)
        group = counts[d]
        start = (np.cumsum(counts) - counts)[d]
        # every pair (x, y) of incidences on the same body: a product J_x M^-1 J_y^T
        self.x = np.repeat(np.arange(len(d)), group)
        self.y = np.arange(len(self.x)) - np.repeat(np.cumsum(group) - group, group) + np.repeat(start, group)
        keys, where = np.unique(c[self.y] * m + c[self.x], return_inverse=True)
        self.perm = np.argsort(where, kind="stable")  # the products of one block together
        self.starts = np.flatnonzero(np.r_[True, np.diff(where[self.perm]) != 0])
        self.block_row, self.block_col = keys % m, keys // m
        self._fc3: tuple[np.ndarray, ...] | None = None

    def blocks(self, rows: np.ndarray, minv: np.ndarray) -> np.ndarray:
        """(n, 2, 2) the blocks, sorted by column then row, from the incidences' (2, 3) Jacobian
        rows and the moving bodies' inverse mass diagonals (1/m, 1/m, 1/I)."""
        Jr = rows[self.order]
        a, b = (Jr * minv[self.dofs][:, None, :])[self.x], Jr[self.y]
        products = np.empty((len(a), 4))
        for i in range(2):  # written out: 6x faster than einsum on a wall's 4,600 products
            for j in range(2):
                products[:, 2 * i + j] = a[:, i, 0] * b[:, j, 0] + a[:, i, 1] * b[:, j, 1] + a[:, i, 2] * b[:, j, 2]
        return np.add.reduceat(products[self.perm], self.starts, axis=0).reshape(-1, 2, 2)

    def fc3(self, blocks: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The CSC arrays (data, indices, indptr) of the 3m x 3m FrictionContact(3) matrix with
        these in-plane ``blocks`` and its out-of-plane rows decoupled (diagonal 1)."""
        if self._fc3 is None:
            m, block_row, block_col = self.m, self.block_row, self.block_col
            per_col = np.bincount(block_col, minlength=m)
            counts = np.empty(3 * m, dtype=np.int64)
            counts[0::3] = 2 * per_col
            counts[1::3] = 2 * per_col
            counts[2::3] = 1
            indptr = np.zeros(3 * m + 1, dtype=np.int64)
            np.cumsum(counts, out=indptr[1:])
            indices = np.empty(int(indptr[-1]), dtype=np.int64)
            at = np.empty((len(block_row), 2, 2), dtype=np.int64)  # where each block entry goes
            rank = np.arange(len(block_row)) - (np.cumsum(per_col) - per_col)[block_col]
            for k in (0, 1):
                first = indptr[3 * block_col + k] + 2 * rank
                indices[first] = 3 * block_row
                indices[first + 1] = 3 * block_row + 1
                at[:, 0, k], at[:, 1, k] = first, first + 1
            third = indptr[3 * np.arange(m) + 2]
            indices[third] = 3 * np.arange(m) + 2
            self._fc3 = (indices, indptr, at, third)
        indices, indptr, at, third = self._fc3
        data = np.empty(len(indices))
        data[at] = blocks
        data[third] = 1.0
        return data, indices, indptr


def delassus_blocks(
    m: int, contacts: np.ndarray, dofs: np.ndarray, rows: np.ndarray, minv: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The non-zero 2x2 blocks of W = H M^-1 H^T for ``m`` contacts (:class:`DelassusPattern`).

    Parameters
    ----------
    contacts, dofs, rows
        One entry per (contact, moving body) incidence: the contact's index, the body's
        index among the moving bodies, and the contact's (2, 3) Jacobian rows on that body.
    minv
        (moving bodies, 3) the inverse mass matrix's diagonal (1/m, 1/m, 1/I), 1/kg, 1/(kg m^2).

    Returns
    -------
    block_row, block_col, blocks
        The blocks (n, 2, 2) and their block indices, each block once, sorted by column then row.
    """
    pattern = DelassusPattern(m, contacts, dofs)
    return pattern.block_row, pattern.block_col, pattern.blocks(rows, minv)


def sparse_fc3(m: int, block_row: np.ndarray, block_col: np.ndarray, blocks: np.ndarray) -> tuple[np.ndarray, ...]:
    """The CSC arrays (data, indices, indptr) of the 3m x 3m FrictionContact(3) matrix whose 2x2
    in-plane blocks are ``blocks`` (sorted by column then row) and whose out-of-plane rows are
    decoupled (diagonal 1): :meth:`DelassusPattern.fc3` for a pattern of these blocks."""
    pattern = DelassusPattern.__new__(DelassusPattern)
    pattern.m, pattern.block_row, pattern.block_col, pattern._fc3 = m, block_row, block_col, None
    return pattern.fc3(blocks)
