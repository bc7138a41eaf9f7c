"""The assembly at rest as a linear spring system: stability limit of the time step and
static settlement.

At rest every joint is a segment whose two ends carry a normal spring K and a shear spring
Ks of the joint (the contact points both DEMs create there). With M = diag(m, m, I) of the
moving bodies (fixed bodies and the base do not move) this gives a sparse stiffness K.

* Stability: the explicit central-difference scheme is stable for
  dt <= (2 / w_max) (sqrt(1 + xi^2) - xi), w_max the highest natural frequency of K, M and
  xi its damping ratio with the stiffness-proportional dashpots (beta w / 2) and the
  mass-proportional one (a / 2w): the default time step stays below it.
* Settlement: K u = f (gravity and the point loads, forces without mass) gives the static
  penetration of every contact point; it must stay small against the blocks (the paper's
  stiffness read as N/m sinks a block into its base, see the stiffness scale).

And the rigid column's own statics: :func:`column_uplift`, the smallest horizontal base
acceleration that lifts one of its blocks.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.linalg import eigh
from scipy.sparse.linalg import ArpackNoConvergence, MatrixRankWarning, eigsh, spsolve

from rockyade.constants import G
from rockyade.dem.joints import JointTable
from rockyade.scene.placement import RestContact

if TYPE_CHECKING:
    from rockyade.scene import Scene

#: Below this number of degrees of freedom the eigenproblem is solved densely.
DENSE_DOF = 300


@dataclass(frozen=True)
class RestSprings:
    """The contact springs at rest, as rows of a sparse compatibility matrix.

    Attributes
    ----------
    B
        (n_springs, 3 n_moving) sparse: relative displacement of each spring (normal or
        shear, at a joint end) in terms of the moving bodies' (x, y, rotation).
    k
        (n_springs,) spring stiffness, N/m.
    beta
        (n_springs,) stiffness-proportional damping of the spring's joint, s.
    normal
        (n_springs,) True for normal springs.
    contact
        (n_springs,) index of the rest contact the spring belongs to.
    dof_of
        (nb,) first degree of freedom of each body, -1 for fixed bodies.
    """

    B: sp.csr_matrix
    k: NDArray[np.float64]
    beta: NDArray[np.float64]
    normal: NDArray[np.bool_]
    contact: NDArray[np.int64]
    dof_of: NDArray[np.int64]

    @property
    def stiffness(self) -> sp.csr_matrix:
        """K = B^T diag(k) B."""
        return (self.B.T @ sp.diags(self.k) @ self.B).tocsr()


def rest_springs(
    centroids: NDArray[np.float64], fixed: Sequence[bool], contacts: Sequence[RestContact], joints: JointTable
) -> RestSprings:
    """Springs of the rest contacts (see module docstring).

    Parameters
    ----------
    centroids
        (nb, 2) body centroids at rest, base frame, m.
    fixed
        Fixed flag per body.
    contacts
        Rest contacts (with their end points).
    joints
        The model's joint table.
    """
    nb = len(fixed)
    dof_of = np.full(nb, -1, dtype=np.int64)
    n_dof = 0
    for i in range(nb):
        if not fixed[i]:
            dof_of[i] = n_dof
            n_dof += 3
    rows, cols, vals, ks, betas, normals, owners = [], [], [], [], [], [], []
    r = 0
    for c_index, c in enumerate(contacts):
        joint = joints.params[joints.joint_for(c.a, c.b)]
        n = np.array(c.normal)
        t = np.array([-n[1], n[0]])
        for end in c.ends_m:
            point = np.array(end)
            for direction, k, is_normal in ((n, joint.K_N_per_m, True), (t, joint.Ks_N_per_m, False)):
                for body, sign in ((c.a, 1.0), (c.b, -1.0)):
                    if body < 0 or dof_of[body] < 0:
                        continue
                    arm = point - centroids[body]
                    d = dof_of[body]
                    for col, v in zip(
                        (d, d + 1, d + 2),
                        (direction[0], direction[1], arm[0] * direction[1] - arm[1] * direction[0]),
                        strict=True,
                    ):
                        rows.append(r)
                        cols.append(col)
                        vals.append(sign * v)
                ks.append(k)
                betas.append(joint.beta_s)
                normals.append(is_normal)
                owners.append(c_index)
                r += 1
    B = sp.csr_matrix((vals, (rows, cols)), shape=(r, n_dof))
    return RestSprings(
        B,
        np.array(ks, dtype=float),
        np.array(betas, dtype=float),
        np.array(normals, dtype=bool),
        np.array(owners, dtype=np.int64),
        dof_of,
    )


def mass_vector(masses: Sequence[float], inertias: Sequence[float], fixed: Sequence[bool]) -> NDArray[np.float64]:
    """diag(M) over the moving bodies' (x, y, rotation) degrees of freedom."""
    out = []
    for m, inertia, f in zip(masses, inertias, fixed, strict=True):
        if not f:
            out += [m, m, inertia]
    return np.array(out, dtype=float)


def highest_frequency(springs: RestSprings, mass: NDArray[np.float64]) -> float:
    """w_max of the rest spring system, rad/s (dense below DENSE_DOF dof, else ARPACK)."""
    K = springs.stiffness
    n = K.shape[0]
    if n == 0 or springs.k.size == 0:
        return 0.0
    scale = 1.0 / np.sqrt(mass)
    A = sp.diags(scale) @ K @ sp.diags(scale)  # M^-1/2 K M^-1/2: same eigenvalues
    if n <= DENSE_DOF:
        w2 = float(eigh(A.toarray(), eigvals_only=True).max())
    else:
        try:
            w2 = float(eigsh(A, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0])
        except ArpackNoConvergence:
            # Gershgorin's bound: never below the true w_max^2, so the step stays stable
            absA = abs(A)
            w2 = float(np.max(absA.sum(axis=1)))
    return math.sqrt(max(w2, 0.0))


def stability_limit(springs: RestSprings, mass: NDArray[np.float64], mass_damping_1_s: float) -> tuple[float, float]:
    """Largest stable time step of the explicit scheme at rest (s), and w_max (rad/s).

    With no spring at rest (every block in the air) the limit is infinite.
    """
    w_max = highest_frequency(springs, mass)
    if w_max <= 0.0:
        return math.inf, 0.0
    beta_max = float(springs.beta.max()) if springs.beta.size else 0.0
    xi = 0.5 * beta_max * w_max + 0.5 * mass_damping_1_s / w_max
    return (2.0 / w_max) * (math.sqrt(1.0 + xi * xi) - xi), w_max


def rest_load_wrenches(
    nb: int, centroids: NDArray[np.float64], loads: Sequence[tuple[int, Sequence[float], Sequence[float]]]
) -> NDArray[np.float64]:
    """(nb, 3) resultant of the point loads on each body at rest: Fx, Fy (N) and the moment
    about the body's centroid, (p - c) x F (N m, counter-clockwise).

    Parameters
    ----------
    nb
        Number of bodies.
    centroids
        (nb, 2) centroids at rest, base frame, m.
    loads
        (body index, point of application at rest (x, y) in m, force (Fx, Fy) in N) per load.
    """
    out = np.zeros((nb, 3))
    for i, point, force in loads:
        rx, ry = point[0] - centroids[i][0], point[1] - centroids[i][1]
        out[i] += (force[0], force[1], rx * force[1] - ry * force[0])
    return out


def static_displacement(
    springs: RestSprings,
    masses: Sequence[float],
    fixed: Sequence[bool],
    g: float,
    loads: NDArray[np.float64] | None = None,
) -> NDArray[np.float64] | None:
    """(nb, 3) static displacement (x, y, rotation) of every body under gravity and the point
    loads, m and rad (zeros for fixed bodies); None when K is singular (a body with no support,
    a mechanism).

    Parameters
    ----------
    springs, masses, fixed
        The rest springs, body masses (kg) and fixed flags.
    g
        Gravity, m/s^2.
    loads
        (nb, 3) point loads on each body (:func:`rest_load_wrenches`: Fx, Fy in N, moment in
        N m); a load is a force without mass, added to the weights. None: gravity alone.
    """
    K = springs.stiffness.tocsc()
    if K.shape[0] == 0 or springs.k.size == 0:
        return None
    f = np.zeros(K.shape[0])
    for i, (m, fx) in enumerate(zip(masses, fixed, strict=True)):
        if not fx:
            d = springs.dof_of[i]
            f[d + 1] = -m * g
            if loads is not None:
                f[d : d + 3] += loads[i]
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", MatrixRankWarning)  # a mechanism: answered below
            u = spsolve(K, f)
    except (RuntimeError, ValueError):
        return None
    if not np.all(np.isfinite(u)):
        return None
    residual = np.linalg.norm(K @ u - f) / max(float(np.linalg.norm(f)), 1e-300)
    if residual > 1e-6:
        return None
    out = np.zeros((len(fixed), 3))
    for i, d in enumerate(springs.dof_of):
        if d >= 0:
            out[i] = u[d : d + 3]
    return out


def static_penetration(
    springs: RestSprings,
    masses: Sequence[float],
    fixed: Sequence[bool],
    g: float,
    loads: NDArray[np.float64] | None = None,
) -> NDArray[np.float64] | None:
    """Static compression of every normal spring under gravity and the point loads (``loads``
    as in :func:`static_displacement`), m (None for a mechanism)."""
    disp = static_displacement(springs, masses, fixed, g, loads)
    if disp is None:
        return None
    u = np.concatenate([disp[i] for i, d in enumerate(springs.dof_of) if d >= 0])
    elongation = springs.B @ u
    return -elongation[springs.normal]


@dataclass(frozen=True)
class Uplift:
    """The smallest horizontal base acceleration that lifts a block of a column (statics).

    Attributes
    ----------
    accel_m_s2
        Uplift acceleration of the weakest mechanism, m/s^2.
    mechanism
        Which blocks rock, as one body, on which joint.
    """

    accel_m_s2: float
    mechanism: str


def column_uplift(scene: Scene) -> Uplift:
    """The uplift acceleration of a column of blocks (bottom to top): its weakest mechanism.

    Each mechanism is blocks k..n rocking as one rigid body about a corner of block k's
    base: a_up = g (b_k - |x_c - x_k|) / h_c, with b_k = h_k tan(alpha_k) the half base of
    block k (its alpha, overrides included: paper Eq 11's equivalent base), x_k its
    centroid, and (x_c, h_c) the centroid of blocks k..n above that base. For one block
    this is Housner's g tan(alpha). A rigid column subject to a smaller acceleration does
    not rock; a sequence of mechanisms of two moving bodies needs at least the smaller of
    its two single-body values (the ratio of work terms is smallest on an extreme ray).
    """
    blocks = list(scene.blocks)
    best = Uplift(math.inf, "")
    base_y = np.cumsum([0.0] + [b.block().height_m for b in blocks])
    for k, spec in enumerate(blocks):
        params = spec.classical()
        cx_k = spec.block().centroid_m[0] + spec.x_offset_m
        half_base = params.centroid_height_m * math.tan(params.alpha_rad)
        masses, xs, ys = [], [], []
        for j in range(k, len(blocks)):
            geo = blocks[j].block()
            masses.append(geo.mass_kg)
            xs.append(geo.centroid_m[0] + blocks[j].x_offset_m)
            ys.append(base_y[j] - base_y[k] + geo.centroid_m[1] - geo.vertices_m[:, 1].min())
        m = np.asarray(masses)
        x_c, h_c = float(np.dot(m, xs) / m.sum()), float(np.dot(m, ys) / m.sum())
        accel = G * (half_base - abs(x_c - cx_k)) / h_c
        if accel < best.accel_m_s2:
            names = [b.name for b in blocks[k:]]
            on = "the base" if k == 0 else blocks[k - 1].name
            who = names[0] if len(names) == 1 else " + ".join(names) + " as one body"
            best = Uplift(accel, f"{who} rocking on {on}")
    return best
