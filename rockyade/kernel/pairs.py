"""The candidate pairs of the broad phase and the state each pair carries from step to step.

A pair's state: the reference face of its last separating-axis test (side and face, for
the test's hysteresis), the incident edge, the test's slack and the relative position at
it (temporal coherence, :func:`rockyade.kernel.narrowphase.separating_axis_test`), and last
step's contact points with their shear springs (as vectors, :mod:`.pair_contacts`).

A rebuild (:func:`build_pairs`) places the moving bodies, sweeps for the new list
(:func:`rockyade.kernel.broadphase.candidate_pairs`), and lets the pairs that persist keep
their faces and points; every pair is tested again after a rebuild. A pair leaves the list
only when its grown boxes are apart, so its contact had opened before.
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np
from numpy.typing import NDArray

from rockyade.kernel.broadphase import candidate_pairs
from rockyade.kernel.narrowphase import NO_FACE, joint_for
from rockyade.kernel.world import place_bodies


class PairState(NamedTuple):
    """The candidate pairs (a < b) and what each keeps between steps."""

    keys: NDArray[np.int64]  #: (np,) a * (nb + 1) + b, sorted
    a: NDArray[np.int64]  #: (np,) lower body
    b: NDArray[np.int64]  #: (np,) upper body
    joint: NDArray[np.int64]  #: (np,) the pair's joint
    side: NDArray[np.int64]  #: (np,) reference side of the last test: 0 (a), 1 (b), NO_FACE
    face: NDArray[np.int64]  #: (np,) reference face of the last contact (NO_FACE: none)
    edge: NDArray[np.int64]  #: (np,) incident edge of the last test
    n: NDArray[np.int64]  #: (np,) contact points of the last step (0, 1, 2)
    pt: NDArray[np.float64]  #: (np, 2, 2) their positions, m
    shear: NDArray[np.float64]  #: (np, 2, 2) their shear spring force vectors, N
    slack: NDArray[np.float64]  #: (np,) the last test holds while the pair moves less, m
    at: NDArray[np.float64]  #: (np, 4) at the test: centroid b - centroid a (x, y), angles of a and b
    pos_at_build: NDArray[np.float64]  #: (nb, 2) centroids when the list was built, m
    ang_at_build: NDArray[np.float64]  #: (nb,) angles when the list was built, rad


@numba.njit(cache=True, nogil=True, inline="always")
def carry_pairs(old: PairState, keys, pa, pb, joints, bodies, kin) -> PairState:
    """State of the new pair list ``keys`` (sorted, as ``old.keys``) built at the bodies'
    positions in ``kin``: the pairs that persist keep their faces and points; the coherence
    data start afresh."""
    n = keys.size
    side = np.full(n, NO_FACE, dtype=np.int64)
    face = np.full(n, NO_FACE, dtype=np.int64)
    npt = np.zeros(n, dtype=np.int64)
    pt = np.zeros((n, 2, 2))
    sh = np.zeros((n, 2, 2))
    i = 0
    for k in range(n):
        while i < old.keys.size and old.keys[i] < keys[k]:
            i += 1
        if i < old.keys.size and old.keys[i] == keys[k]:
            side[k] = old.side[i]
            face[k] = old.face[i]
            npt[k] = old.n[i]
            pt[k] = old.pt[i]
            sh[k] = old.shear[i]
    nb = bodies.mass.shape[0]
    pj = np.empty(n, dtype=np.int64)
    for k in range(n):
        pj[k] = joint_for(
            pa[k],
            pb[k],
            nb,
            joints.base_joint,
            joints.own_joint,
            joints.pair_keys,
            joints.pair_joint,
            bodies.fixed,
            joints.kn,
        )
    return PairState(
        keys,
        pa,
        pb,
        pj,
        side,
        face,
        np.zeros(n, dtype=np.int64),
        npt,
        pt,
        sh,
        np.zeros(n),
        np.zeros((n, 4)),
        kin.pos.copy(),
        kin.ang.copy(),
    )


@numba.njit(cache=True, nogil=True, inline="always")
def no_pairs() -> PairState:
    """An empty pair list."""
    e = np.zeros(0, dtype=np.int64)
    return PairState(
        e,
        e,
        e,
        e,
        e,
        e,
        e,
        e,
        np.zeros((0, 2, 2)),
        np.zeros((0, 2, 2)),
        np.zeros(0),
        np.zeros((0, 4)),
        np.zeros((0, 2)),
        np.zeros(0),
    )


@numba.njit(cache=True, nogil=True)
def build_pairs(old: PairState, bodies, joints, kin, world, axis: int, order) -> PairState:
    """Place the moving bodies, sweep for the candidate pairs along ``axis`` (``order``: the
    bodies' order from the last build, sorted in place) and carry the state of ``old``."""
    place_bodies(kin, bodies, world, True)
    keys, pa, pb = candidate_pairs(world.lo, world.hi, bodies.margin, bodies.fixed, axis, order)
    return carry_pairs(old, keys, pa, pb, joints, bodies, kin)
