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
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from rockyade.errors import InputError, SolverFailedError
from rockyade.limit.highs import Programme, solve_programme
from rockyade.limit.highs_child import solve_in_child
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


#: The methods of :func:`solve_equilibrium`: "highs" is rockyade's choice (:func:`choose_solver`),
#: "highs-ds" HiGHS's dual simplex, "highs-ipm" its interior point method IPX with the crossover to a
#: vertex, "highs-hipo" its interior point method HiPO without crossover (:mod:`rockyade.limit.highs`).
METHODS = ("highs", "highs-ds", "highs-ipm", "highs-hipo")
_SOLVER_OF = {"highs-ds": "simplex", "highs-ipm": "ipx", "highs-hipo": "hipo"}
#: Columns from which "highs" takes HiPO rather than the dual simplex. Measured on running-bond walls of
#: ``rockyade build wall`` (CPU s, a loaded 2-core machine; docs/limit.md, "Cost"): 999 blocks (11,625
#: columns) dual simplex 6.6, IPX with crossover 3.1, HiPO 1.0; 3,025 blocks (35,661 columns) dual
#: simplex unfinished at 130, IPX without crossover 37, HiPO 5.8; 10,050 blocks (119,401 columns) HiPO 34.
#: Below, the dual simplex is as fast and keeps its vertex (the mechanism of the tests' walls, to the bit).
HIPO_COLUMNS = 4000
#: Columns from which a programme is solved in a child process (Ctrl-C ends it at once, progress every
#: 10 s: :mod:`rockyade.limit.highs_child`): about 1,700 blocks of running bond, 2.5 s of HiPO's CPU or
#: more, against the child's start (about 1 s of CPU). Smaller programmes run here: a Ctrl-C waits for
#: the programme under way (HiGHS does not return to Python before), a second or two.
CHILD_COLUMNS = 20000


class TimeLimitError(SolverFailedError):
    """A programme stopped at its time limit (``time_limit_s``): no answer."""


def highs_method(method: str, n_columns: int) -> str:
    """The method scipy's ``linprog`` runs for ``method`` (the callers that use ``linprog``:
    :mod:`rockyade.limit.standing`, :func:`rockyade.limit.coulomb.certified`): "highs" is the
    interior point method with crossover from 4,000 to 20,000 columns and the dual simplex elsewhere."""
    if method != "highs":
        return method
    return "highs-ipm" if 4000 < n_columns <= 20000 else "highs-ds"


def choose_solver(method: str, n_columns: int) -> str:
    """HiGHS's solver (:data:`rockyade.limit.highs.SOLVERS`) for ``method`` on ``n_columns`` columns:
    "highs" is HiPO from :data:`HIPO_COLUMNS` columns and the dual simplex below."""
    if method not in METHODS:
        raise InputError("method", f"must be one of {', '.join(METHODS)}, got {method!r}")
    if method == "highs":
        return "hipo" if n_columns >= HIPO_COLUMNS else "simplex"
    return _SOLVER_OF[method]


def time_options(time_limit_s: float | None) -> dict[str, float]:
    """linprog's options for a time limit (none: {})."""
    if time_limit_s is None:
        return {}
    return {"time_limit": max(float(time_limit_s), 1.0e-3)}


def _programme(A, b, lam_col: int, lower, upper, chained: bool) -> Programme:
    """maximise lambda, A x = b, as HiGHS's :class:`Programme`. ``chained``: lambda's column, the one
    dense column (every moving block's x row), becomes one lambda_i per block with lambda_i = lambda_(i+1)
    (rows of two entries): the normal equations of an interior point method stay sparse (HiPO's
    factorisation of the 10,050-block wall: 34 s of CPU against 79 s with the dense column). Lambda is
    then column ``lam_col`` still, the first lambda_i; the extra rows follow the equilibrium rows."""
    n_rows = A.shape[0]
    if not chained:
        c = np.zeros(A.shape[1])
        c[lam_col] = -1.0
        return Programme(c, sp.csc_matrix(A), b, b, lower, upper)
    g = A[:, lam_col].tocoo()
    blocks = np.arange(g.nnz)
    lam_cols = sp.csc_matrix((g.data, (g.row, blocks)), shape=(n_rows, g.nnz))
    ones = np.ones(g.nnz - 1)
    chain = sp.coo_matrix(
        (np.concatenate([ones, -ones]), (np.tile(np.arange(g.nnz - 1), 2), np.concatenate([blocks[:-1], blocks[1:]]))),
        shape=(g.nnz - 1, g.nnz),
    )
    matrix = sp.vstack([sp.hstack([A[:, :lam_col], lam_cols]), sp.hstack([sp.csc_matrix((g.nnz - 1, lam_col)), chain])])
    matrix = matrix.tocsc()
    c = np.zeros(lam_col + g.nnz)
    c[lam_col] = -1.0
    rhs = np.concatenate([b, np.zeros(g.nnz - 1)])
    lo = np.concatenate([lower[:lam_col], np.full(g.nnz, lower[lam_col])])
    up = np.concatenate([upper[:lam_col], np.full(g.nnz, upper[lam_col])])
    return Programme(c, matrix, rhs, rhs, lo, up)


def solve_equilibrium(
    model: RigidBlockModel,
    direction: str = "+x",
    method: str = "highs",
    friction_capacity_N: NDArray[np.float64] | None = None,
    time_limit_s: float | None = None,
    on_progress: Callable[[float, str], None] | None = None,
) -> LPSolution:
    """Maximise lambda subject to every moving block's equilibrium (module docstring).

    Parameters
    ----------
    model
        The rigid-block model.
    direction
        "+x" or "-x": the sense of the horizontal force lambda m g.
    method
        HiGHS's method, one of :data:`METHODS`: the simplex and IPX with its crossover give a vertex
        (the mechanism is a vertex of the kinematic programme); HiPO a point inside the optimal face,
        the same multiplier to its tolerance (where several mechanisms share it, a blend of them,
        each as admissible).
    friction_capacity_N
        (n_interfaces, 2) fixed friction capacities c >= 0 at the interface ends, N: with them every
        joint with friction carries |t| <= c whatever its normal force (a non-dilatant, Tresca-like
        joint: one step of :func:`rockyade.limit.coulomb.solve_coulomb`); None: Coulomb's cone
        |t| <= tan(phi) n with its associated flow.
    time_limit_s
        Wall time HiGHS may take, s (None: no limit); past it :class:`TimeLimitError`.
    on_progress
        A programme solved in a child process (from :data:`CHILD_COLUMNS` columns) calls it every 10 s
        with (seconds so far, HiGHS's latest iteration in words).
    """
    non_dilatant = friction_capacity_N is not None
    A, b, lam_col, free, row_of, (w_ref, l_ref) = equilibrium_system(model, direction, non_dilatant)
    geo = interface_arrays(model)
    n_cols = lam_col + 1
    solver = choose_solver(method, n_cols)
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
        programme = _programme(A, b, lam_col, lower, upper, chained=solver == "hipo")
        if n_cols >= CHILD_COLUMNS:
            res = solve_in_child(programme, solver, left, on_progress)
        else:
            res = solve_programme(programme, solver, left)
        if res.status != 0 or cap is None or res.x is None or res.x[lam_col] < 0.999 * cap:
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
    if res.status != 0 or res.x is None or res.marginals is None:
        raise SolverFailedError(f"HiGHS could not solve the equilibrium programme: {res.message}")
    x = res.x[: lam_col + 1]
    forces = x[:lam_col].reshape(len(model.interfaces), 2, 2) * w_ref  # (interface, end, column)
    cone = (geo.has_friction & (not non_dilatant))[:, None]  # (f1, f2) columns; else (N, T)
    mu = np.tan(np.radians(np.where(geo.has_friction, geo.friction_deg, 0.0)))[:, None]
    normal = np.where(cone, forces[:, :, 0] + forces[:, :, 1], forces[:, :, 0])
    tangential = np.where(cone, mu * (forces[:, :, 0] - forces[:, :, 1]), forces[:, :, 1])
    y = -res.marginals[: A.shape[0]]  # d(lambda)/d(b): the virtual velocities, scaled
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
