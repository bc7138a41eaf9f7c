"""The equilibrium linear programme of a rigid-block model and its solution by HiGHS.

Unknowns: the contact forces at the two ends of every interface and the load multiplier
lambda. Each moving block i is in equilibrium (3 equations: forces along x and y, moment
about its centroid at rest) under its weight (0, -m_i g), the horizontal force
lambda m_i g d (d = +1 towards +x, -1 towards -x), the external loads on it and the
contact forces. Maximise lambda.

At an interface end with friction angle phi the force is f1 (n + mu t) + f2 (n - mu t),
f1, f2 >= 0, mu = tan(phi): every such force has a normal part >= 0 (no tension) and
|t| <= mu n (Coulomb), and every force in that cone is one of them; without sliding it is
N n + T t with N >= 0 and T free. The programme has equality constraints and sign bounds
only, which HiGHS solves fast (a wall of 1,000 blocks in about a second).

This is the lower-bound (static) theorem of limit analysis for rigid blocks with
no-tension joints (Livesley 1978, "Limit analysis of structures formed from rigid blocks",
Int. J. Numer. Meth. Eng. 12, 1853-1871; Gilbert & Melbourne 1994 for arches). With
finite friction the programme's dual is the upper-bound mechanism with an associated flow
rule (a sliding joint dilates at tan(phi)): real Coulomb friction does not dilate, and the
multiplier of a mechanism in which joints slide can be above the true one (Gilbert,
Casapulla & Ahmed 2006, Comput. Struct. 84, 873-887; Ferris & Tin-Loi 2001, Int. J. Mech.
Sci. 43, 209-224). With ``sliding=False`` (no joint end moves along its joint) the
multiplier is exact (to the solver's tolerance). With finite friction it is exact for
associated friction; for Coulomb friction it is an upper bound even when the mechanism found
has no sliding joint, because a lower mechanism may need a joint end to slide without
opening, which the associated rule forbids: a slender running-bond panel's whole-panel
rocking (L / H = 0.5) against its heel mechanism (0.434; docs/assemblies.md). With fixed
friction capacities (``friction_capacity_N``) the programme is one step of the non-associated
iteration of :mod:`rockyade.limit.coulomb`.

The dual variables of the equilibrium equations are the mechanism: a virtual velocity
(vx, vy, omega) of every moving block for which the load lambda m g d does unit work and
every contact force does none (:mod:`rockyade.limit.mechanism`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.optimize import linprog

from rockyade.errors import InputError, SolverFailedError
from rockyade.limit.model import RigidBlockModel

#: The multiplier is first sought below this (a horizontal acceleration of 1,000 g); a
#: solution at the cap is re-solved without it to tell a large multiplier from no mechanism.
LAMBDA_CAP = 1.0e3
DIRECTIONS = {"+x": 1.0, "-x": -1.0}


@dataclass(frozen=True)
class LPSolution:
    """What the programme gives (raw; :func:`rockyade.limit.analysis.limit_analysis` reads it).

    Attributes
    ----------
    status
        "collapse" (a multiplier), "unstable" (no equilibrium under gravity and the loads
        alone) or "no_mechanism" (lambda unbounded).
    load_multiplier
        lambda, None unless status is "collapse".
    direction
        "+x" or "-x".
    normal_N, tangential_N
        (n_interfaces, 2) contact forces at the two ends at collapse, N: normal (>= 0,
        compression, on body ``a`` along the interface normal) and tangential (on ``a``
        along the interface tangent). None unless "collapse".
    velocities
        (nb, 3) dual variables as velocities (vx, vy, omega) of every block (zeros for fixed
        blocks), unnormalised; None unless "collapse".
    solve_time_s
        Wall time of the HiGHS calls, s.
    message
        HiGHS's message for the last call.
    friction_capacity_N
        (n_interfaces, 2) the fixed friction capacities |t| <= c of the non-dilatant programme
        (:func:`rockyade.limit.coulomb.solve_coulomb`), N; None for the associated rule.
    """

    status: str
    load_multiplier: float | None
    direction: str
    normal_N: NDArray[np.float64] | None
    tangential_N: NDArray[np.float64] | None
    velocities: NDArray[np.float64] | None
    solve_time_s: float
    message: str
    friction_capacity_N: NDArray[np.float64] | None = None


def _cross(r: NDArray[np.float64], f: NDArray[np.float64]) -> float:
    return float(r[0] * f[1] - r[1] * f[0])


def equilibrium_system(model: RigidBlockModel, direction: str, non_dilatant: bool = False):
    """The scaled programme: (A, b, lambda column, column kinds, row of each moving block, scales).

    Rows: 3 per moving block (x force / W, y force / W, moment / (W L)); columns: 2 per
    interface end (f1, f2 with friction; N, T without, and with friction when ``non_dilatant``:
    then the caller bounds T by a fixed capacity), then lambda. W is the largest block
    weight, L the assembly's size.
    """
    if direction not in DIRECTIONS:
        raise InputError("direction", f"must be +x or -x, got {direction!r}")
    d = DIRECTIONS[direction]
    moving = model.moving
    row_of = np.full(model.n_blocks, -1, dtype=np.int64)
    row_of[moving] = 3 * np.arange(moving.size)
    weights = model.masses_kg * model.g
    w_ref = float(weights[moving].max())
    l_ref = model.size_m
    n_rows = 3 * moving.size
    rows: list[int] = []
    cols: list[int] = []
    vals: list[float] = []
    free: list[bool] = []  # tangential columns without friction are free
    col = 0
    for itf in model.interfaces:
        n, t = itf.normal, itf.tangent
        if itf.friction_angle_deg is None or non_dilatant:
            directions = ((n, False), (t, True))
        else:
            mu = math.tan(math.radians(itf.friction_angle_deg))
            directions = ((n + mu * t, False), (n - mu * t, False))
        for p in itf.ends_m:
            for f, is_free in directions:
                for body, sign in ((itf.a, 1.0), (itf.b, -1.0)):
                    r = row_of[body] if body >= 0 else -1
                    if r < 0:
                        continue
                    arm = p - model.centroids_m[body]
                    rows += [r, r + 1, r + 2]
                    cols += [col, col, col]
                    vals += [sign * f[0], sign * f[1], sign * _cross(arm, f) / l_ref]
                free.append(is_free)
                col += 1
    lam_col = col
    for i in moving:
        rows.append(row_of[i])
        cols.append(lam_col)
        vals.append(d * weights[i] / w_ref)
    A = sp.csr_matrix((vals, (rows, cols)), shape=(n_rows, lam_col + 1))
    b = np.zeros(n_rows)
    b[row_of[moving] + 1] = weights[moving] / w_ref  # contact + lambda terms balance the weight
    for load in model.loads:
        r = row_of[int(load.block)]
        if r < 0:
            continue  # a load on a fixed block goes straight to the base
        f = np.asarray(load.force_N, dtype=float)
        arm = np.asarray(load.point_m, dtype=float) - model.centroids_m[int(load.block)]
        b[r] -= f[0] / w_ref
        b[r + 1] -= f[1] / w_ref
        b[r + 2] -= _cross(arm, f) / (w_ref * l_ref)
    return A, b, lam_col, np.array(free, dtype=bool), row_of, (w_ref, l_ref)


#: HiGHS's methods as scipy names them ("highs" lets HiGHS choose; it picks the dual simplex).
METHODS = ("highs", "highs-ds", "highs-ipm")


def solve_equilibrium(
    model: RigidBlockModel,
    direction: str = "+x",
    method: str = "highs",
    friction_capacity_N: NDArray[np.float64] | None = None,
) -> LPSolution:
    """Maximise lambda subject to every moving block's equilibrium (module docstring).

    Parameters
    ----------
    model
        The rigid-block model.
    direction
        "+x" or "-x": the sense of the horizontal force lambda m g.
    method
        HiGHS's method, one of :data:`METHODS` (the interior point method runs a crossover, so
        its answer is a vertex as the simplex's: same multiplier, same kind of mechanism).
    friction_capacity_N
        (n_interfaces, 2) fixed friction capacities c >= 0 at the interface ends, N: with them every
        joint with friction carries |t| <= c whatever its normal force (a non-dilatant, Tresca-like
        joint: one step of :func:`rockyade.limit.coulomb.solve_coulomb`); None: Coulomb's cone
        |t| <= tan(phi) n with its associated flow.
    """
    if method not in METHODS:
        raise InputError("method", f"must be one of {', '.join(METHODS)}, got {method!r}")
    non_dilatant = friction_capacity_N is not None
    A, b, lam_col, free, row_of, (w_ref, l_ref) = equilibrium_system(model, direction, non_dilatant)
    n_cols = lam_col + 1
    c = np.zeros(n_cols)
    c[lam_col] = -1.0
    lower = np.where(np.append(free, False), -np.inf, 0.0)
    upper_t = np.full(n_cols, np.inf)
    if friction_capacity_N is not None:
        cap_n = np.asarray(friction_capacity_N, dtype=float)
        if cap_n.shape != (len(model.interfaces), 2) or not np.all(np.isfinite(cap_n)) or cap_n.min(initial=0.0) < 0:
            raise InputError("friction_capacity_N", "must be (n_interfaces, 2) finite capacities >= 0 N")
        for k, itf in enumerate(model.interfaces):
            if itf.friction_angle_deg is not None:
                for e in range(2):
                    col_t = 4 * k + 2 * e + 1  # columns: (N, T) at end 0, then at end 1
                    lower[col_t] = -cap_n[k, e] / w_ref
                    upper_t[col_t] = cap_n[k, e] / w_ref
    t0 = time.perf_counter()
    res = None
    for cap in (LAMBDA_CAP, None):
        upper = upper_t.copy()
        upper[lam_col] = np.inf if cap is None else cap
        res = linprog(c, A_eq=A, b_eq=b, bounds=np.column_stack([lower, upper]), method=method)
        if res.status != 0 or cap is None or res.x[lam_col] < 0.999 * cap:
            break
    elapsed = time.perf_counter() - t0
    assert res is not None  # the loop above runs at least once
    if res.status == 2:
        return LPSolution("unstable", None, direction, None, None, None, elapsed, res.message, friction_capacity_N)
    if res.status == 3:
        return LPSolution("no_mechanism", None, direction, None, None, None, elapsed, res.message, friction_capacity_N)
    if res.status != 0:
        raise SolverFailedError(f"HiGHS could not solve the equilibrium programme: {res.message}")
    x = res.x
    forces = x[:lam_col].reshape(len(model.interfaces), 2, 2) * w_ref  # (interface, end, column)
    normal = np.empty((len(model.interfaces), 2))
    tangential = np.empty_like(normal)
    for k, itf in enumerate(model.interfaces):
        if itf.friction_angle_deg is None or non_dilatant:
            normal[k], tangential[k] = forces[k, :, 0], forces[k, :, 1]
        else:
            mu = math.tan(math.radians(itf.friction_angle_deg))
            normal[k] = forces[k, :, 0] + forces[k, :, 1]
            tangential[k] = mu * (forces[k, :, 0] - forces[k, :, 1])
    y = -np.asarray(res.eqlin.marginals)  # d(lambda)/d(b): the virtual velocities, scaled
    velocities = np.zeros((model.n_blocks, 3))
    for i in model.moving:
        r = row_of[i]
        velocities[i] = (y[r], y[r + 1], y[r + 2] / l_ref)
    return LPSolution(
        "collapse",
        float(x[lam_col]),
        direction,
        normal,
        tangential,
        velocities,
        elapsed,
        res.message,
        None if friction_capacity_N is None else np.asarray(friction_capacity_N, dtype=float),
    )
