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

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.optimize import linprog

from rockyade.errors import InputError, SolverFailedError
from rockyade.limit.rigid_blocks import RigidBlockModel

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


@dataclass(frozen=True)
class InterfaceArrays:
    """A model's interfaces as arrays (for assembly without a Python loop per joint).

    Attributes
    ----------
    a, b
        (n,) body indices (-1: the base).
    normal, tangent
        (n, 2) unit normal (from b into a) and tangent.
    ends_m
        (n, 2, 2) the two ends, m.
    friction_deg
        (n,) friction angle, degrees (NaN where the joint does not slide).
    has_friction
        (n,) True where the joint has a friction angle.
    """

    a: NDArray[np.int64]
    b: NDArray[np.int64]
    normal: NDArray[np.float64]
    tangent: NDArray[np.float64]
    ends_m: NDArray[np.float64]
    friction_deg: NDArray[np.float64]
    has_friction: NDArray[np.bool_]


def interface_arrays(model: RigidBlockModel) -> InterfaceArrays:
    """The model's interfaces as :class:`InterfaceArrays`."""
    itfs = model.interfaces
    n = len(itfs)
    normal = np.array([itf.normal for itf in itfs], dtype=float).reshape(n, 2)
    friction = np.array([np.nan if itf.friction_angle_deg is None else itf.friction_angle_deg for itf in itfs])
    return InterfaceArrays(
        a=np.array([itf.a for itf in itfs], dtype=np.int64),
        b=np.array([itf.b for itf in itfs], dtype=np.int64),
        normal=normal,
        tangent=np.column_stack([-normal[:, 1], normal[:, 0]]),
        ends_m=np.array([itf.ends_m for itf in itfs], dtype=float).reshape(n, 2, 2),
        friction_deg=friction.reshape(n),
        has_friction=~np.isnan(friction.reshape(n)),
    )


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
    # built as arrays (scipy.sparse coo), not entry by entry: a 10,000-block wall in a second, not a minute.
    # Column 4 k + 2 e + j: interface k, end e, direction j (module docstring).
    n_itf = len(model.interfaces)
    geo = interface_arrays(model)
    normal, tangent, ends = geo.normal, geo.tangent, geo.ends_m
    coulomb = geo.has_friction & (not non_dilatant)  # joints whose two columns span the cone
    mu = np.where(coulomb, np.tan(np.radians(np.where(coulomb, geo.friction_deg, 0.0))), 0.0)[:, None]
    first = np.where(coulomb[:, None], normal + mu * tangent, normal)  # (n_itf, 2)
    second = np.where(coulomb[:, None], normal - mu * tangent, tangent)
    dirs = np.stack([first, second], axis=1)  # (n_itf, j, 2)
    f = np.broadcast_to(dirs[:, None, :, :], (n_itf, 2, 2, 2)).reshape(-1, 2)  # (col, xy)
    p = np.broadcast_to(ends[:, :, None, :], (n_itf, 2, 2, 2)).reshape(-1, 2)
    free = np.broadcast_to(np.stack([np.zeros(n_itf, bool), ~coulomb], axis=1)[:, None, :], (n_itf, 2, 2)).ravel()
    col_ids = np.arange(4 * n_itf)
    rows_l, cols_l, vals_l = [], [], []
    for body, sign in ((geo.a, 1.0), (geo.b, -1.0)):
        body_col = np.repeat(body, 4)
        r = np.where(body_col >= 0, row_of[np.maximum(body_col, 0)], -1)
        keep = r >= 0
        arm = p[keep] - model.centroids_m[body_col[keep]]
        fk = f[keep]
        moment = (arm[:, 0] * fk[:, 1] - arm[:, 1] * fk[:, 0]) / l_ref
        rows_l += [r[keep], r[keep] + 1, r[keep] + 2]
        cols_l += [col_ids[keep]] * 3
        vals_l += [sign * fk[:, 0], sign * fk[:, 1], sign * moment]
    lam_col = 4 * n_itf
    rows_l.append(row_of[moving])
    cols_l.append(np.full(moving.size, lam_col))
    vals_l.append(d * weights[moving] / w_ref)
    rows, cols, vals = np.concatenate(rows_l), np.concatenate(cols_l), np.concatenate(vals_l)
    A = sp.coo_matrix((vals, (rows, cols)), shape=(n_rows, lam_col + 1)).tocsr()
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
    return A, b, lam_col, free.copy(), row_of, (w_ref, l_ref)


#: HiGHS's methods as scipy names them; "highs" is rockyade's choice (:func:`highs_method`).
METHODS = ("highs", "highs-ds", "highs-ipm")
#: Columns between which "highs" takes the interior point method rather than the dual simplex: on a
#: running-bond wall of 999 blocks (11,485 columns) the interior point method (with its crossover to a
#: vertex) takes 2.4 to 2.9 s of CPU against the dual simplex's 11 to 12.5 s, the same multiplier to 5e-7
#: and a vertex mechanism as well; below IPM_COLUMNS both are fast and the dual simplex keeps its
#: bit-for-bit answers; on the 3,015-block wall (35,329 columns) the crossover ends "imprecise" and
#: HiGHS's simplex clean-up from its basis took longer than the dual simplex alone (160 s of CPU
#: against 60 s, both unfinished on a loaded machine), so above IPM_MAX_COLUMNS the dual simplex stays.
IPM_COLUMNS = 4000
IPM_MAX_COLUMNS = 20000


class TimeLimitError(SolverFailedError):
    """A programme stopped at its time limit (``time_limit_s``): no answer."""


def highs_method(method: str, n_columns: int) -> str:
    """The HiGHS method scipy runs for ``method`` on a programme of ``n_columns`` columns: "highs"
    is the interior point method from :data:`IPM_COLUMNS` to :data:`IPM_MAX_COLUMNS` columns, where
    it was measured faster, and the dual simplex elsewhere."""
    if method != "highs":
        return method
    return "highs-ipm" if IPM_COLUMNS < n_columns <= IPM_MAX_COLUMNS else "highs-ds"


def time_options(time_limit_s: float | None) -> dict[str, float]:
    """linprog's options for a time limit (none: {})."""
    if time_limit_s is None:
        return {}
    return {"time_limit": max(float(time_limit_s), 1.0e-3)}


def solve_equilibrium(
    model: RigidBlockModel,
    direction: str = "+x",
    method: str = "highs",
    friction_capacity_N: NDArray[np.float64] | None = None,
    time_limit_s: float | None = None,
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
    time_limit_s
        Wall time HiGHS may take, s (None: no limit); past it :class:`TimeLimitError`.
    """
    if method not in METHODS:
        raise InputError("method", f"must be one of {', '.join(METHODS)}, got {method!r}")
    non_dilatant = friction_capacity_N is not None
    A, b, lam_col, free, row_of, (w_ref, l_ref) = equilibrium_system(model, direction, non_dilatant)
    geo = interface_arrays(model)
    n_cols = lam_col + 1
    c = np.zeros(n_cols)
    c[lam_col] = -1.0
    lower = np.where(np.append(free, False), -np.inf, 0.0)
    upper_t = np.full(n_cols, np.inf)
    if friction_capacity_N is not None:
        cap_n = np.asarray(friction_capacity_N, dtype=float)
        if cap_n.shape != (len(model.interfaces), 2) or not np.all(np.isfinite(cap_n)) or cap_n.min(initial=0.0) < 0:
            raise InputError("friction_capacity_N", "must be (n_interfaces, 2) finite capacities >= 0 N")
        k, e = np.nonzero(np.broadcast_to(geo.has_friction[:, None], (len(model.interfaces), 2)))
        col_t = 4 * k + 2 * e + 1  # columns: (N, T) at end 0, then at end 1
        lower[col_t] = -cap_n[k, e] / w_ref
        upper_t[col_t] = cap_n[k, e] / w_ref
    t0 = time.perf_counter()
    res = None
    for cap in (LAMBDA_CAP, None):
        upper = upper_t.copy()
        upper[lam_col] = np.inf if cap is None else cap
        left = None if time_limit_s is None else time_limit_s - (time.perf_counter() - t0)
        res = linprog(
            c,
            A_eq=A,
            b_eq=b,
            bounds=np.column_stack([lower, upper]),
            method=highs_method(method, n_cols),
            options=time_options(left),
        )
        if res.status != 0 or cap is None or res.x[lam_col] < 0.999 * cap:
            break
    elapsed = time.perf_counter() - t0
    assert res is not None  # the loop above runs at least once
    if res.status == 1 and time_limit_s is not None:
        raise TimeLimitError(
            f"the equilibrium programme ({A.shape[0]} rows, {n_cols} columns) stopped at its time limit of "
            f"{time_limit_s:g} s without an answer"
        )
    if res.status == 2:
        return LPSolution("unstable", None, direction, None, None, None, elapsed, res.message, friction_capacity_N)
    if res.status == 3:
        return LPSolution("no_mechanism", None, direction, None, None, None, elapsed, res.message, friction_capacity_N)
    if res.status != 0:
        raise SolverFailedError(f"HiGHS could not solve the equilibrium programme: {res.message}")
    x = res.x
    forces = x[:lam_col].reshape(len(model.interfaces), 2, 2) * w_ref  # (interface, end, column)
    cone = (geo.has_friction & (not non_dilatant))[:, None]  # (f1, f2) columns; else (N, T)
    mu = np.tan(np.radians(np.where(geo.has_friction, geo.friction_deg, 0.0)))[:, None]
    normal = np.where(cone, forces[:, :, 0] + forces[:, :, 1], forces[:, :, 0])
    tangential = np.where(cone, mu * (forces[:, :, 0] - forces[:, :, 1]), forces[:, :, 1])
    y = -np.asarray(res.eqlin.marginals)  # d(lambda)/d(b): the virtual velocities, scaled
    velocities = np.zeros((model.n_blocks, 3))
    r = row_of[model.moving]
    velocities[model.moving] = np.column_stack([y[r], y[r + 1], y[r + 2] / l_ref])
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
