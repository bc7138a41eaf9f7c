"""Limit analysis with non-associated (Coulomb, non-dilatant) friction by iterated linear programmes.

The equilibrium programme of :mod:`rockyade.limit.lp` bounds the tangential force of every
joint end by Coulomb's cone |t| <= tan(phi) n; its dual mechanism then follows the associated
flow rule, in which a sliding joint opens by tan(phi) times its slip. Real joints slide without
opening. Gilbert, Casapulla & Ahmed (2006, "Limit analysis of masonry block structures with
non-associative frictional joints using linear programming", Comput. Struct. 84, 873-887)
replace, at each joint, Coulomb's cone by a failure surface whose shear capacity does not depend
on the normal force of the programme being solved, but on the normal force of the previous
solution: at iteration k every end carries

    n >= 0 (no tension),   |t| <= c_k = tan(phi) n_bar_k   (a fixed, Tresca-like capacity),

whose normal flow is sliding without dilatancy (the capacity is flat in n). The iteration starts
from the associated solution, n_bar_1 = its normal forces, and sets n_bar_(k+1) to the normal
forces n_k of solution k, relaxed as n_bar_(k+1) = n_bar_k + beta (n_k - n_bar_k) with beta
halved each time lambda turns back (an oscillation). At a fixed point (n_k = n_bar_k) the forces
meet Coulomb's |t| <= tan(phi) n and the mechanism slides without opening: a solution of the
non-associated problem.

It is a heuristic, as the paper says: the non-associated problem has no extremum principle, a
fixed point need not be the lowest collapse load, and the iteration need not converge (the
answer then says so and carries no multiplier).

Convergence (this module's tolerances): lambda changes by at most ``LAMBDA_RTOL`` (relative)
between two successive solutions and every end's normal force by at most ``FORCE_RTOL`` times the
largest block weight (a fixed point); or lambda stays the same over ``SETTLED_STEPS`` successive
solutions and the last one is a non-associated solution, which :func:`certify` checks by a
programme of its own: with lambda fixed at the last value and the
mechanism of the last solution, there are contact forces in equilibrium with n >= 0 and
|t| <= tan(phi) n (Coulomb's cone, on the real normal force) that vanish at the ends that open
and lie on the cone's edge against the slip (t = -tan(phi) n sign(slip)) at the ends that slide.
That is the normal forces settling where they matter: where the rigid parts are statically
indeterminate the programme's vertex may hop from one equilibrium to another from iteration to
iteration (the same lambda) and those forces need not settle.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.optimize import linprog

from rockyade.limit.lp import LPSolution, TimeLimitError, equilibrium_system, highs_method, solve_equilibrium
from rockyade.limit.rigid_blocks import RigidBlockModel

#: Relative change of lambda between successive programmes below which it has settled.
LAMBDA_RTOL = 1.0e-6
#: Change of an end's normal force (in units of the largest block weight) below which it has settled.
FORCE_RTOL = 1.0e-6
#: Programmes solved at most after the associated one.
MAX_ITERATIONS = 100
#: Successive programmes with the same lambda (to ``LAMBDA_RTOL``) after which a solution whose normal
#: forces still move is checked by :func:`certify`.
SETTLED_STEPS = 3
#: Iterations with the plain update (beta = 1) before an oscillation of lambda relaxes it.
PLAIN_ITERATIONS = 20
#: Relative velocities below this (in units of the largest centroid velocity) are zero in :func:`certify`.
VELOCITY_TOL = 1.0e-6


@dataclass(frozen=True)
class CoulombSolution:
    """The outcome of :func:`solve_coulomb`.

    Attributes
    ----------
    solution
        The last programme's solution (its ``friction_capacity_N`` the capacities it was solved with), or,
        converged by :func:`certified`, the same lambda and mechanism with the certificate's forces.
    iterations
        Programmes solved with fixed capacities (the associated start not counted).
    converged
        True when lambda and the normal forces settled within the tolerances.
    history
        lambda of the associated start and of every iteration.
    solve_time_s
        Wall time of all the HiGHS calls, s.
    reason
        Why it stopped without converging ("" when it converged).
    """

    solution: LPSolution
    iterations: int
    converged: bool
    history: tuple[float, ...]
    solve_time_s: float
    reason: str


def friction_coefficients(model: RigidBlockModel) -> NDArray[np.float64]:
    """(n_interfaces,) tan(phi) of every joint, 0 where it has no friction angle (no sliding)."""
    angles = [itf.friction_angle_deg for itf in model.interfaces]
    return np.array([0.0 if a is None else math.tan(math.radians(a)) for a in angles])


def solve_coulomb(
    model: RigidBlockModel,
    start: LPSolution,
    method: str = "highs",
    max_iterations: int = MAX_ITERATIONS,
    time_limit_s: float | None = None,
    on_iteration: Callable[[int, float, float], None] | None = None,
    on_progress: Callable[[float, str], None] | None = None,
) -> CoulombSolution:
    """The non-associated (non-dilatant Coulomb) collapse by the iteration of the module docstring.

    Parameters
    ----------
    model
        The rigid-block model (joints with a friction angle).
    start
        The associated solution (:func:`rockyade.limit.lp.solve_equilibrium`), status "collapse".
    method
        HiGHS's method (:data:`rockyade.limit.lp.METHODS`).
    max_iterations
        Programmes solved at most.
    time_limit_s
        Wall time the iteration may take, s, counted from its call (None: no limit): past it the
        iteration stops, not converged, and its reason says so.
    on_iteration
        Called after every programme with (iteration, lambda, seconds since the call): progress.
    on_progress
        Passed to :func:`~rockyade.limit.lp.solve_equilibrium` (progress within one large programme).

    Convergence, relaxation and what "converged" means: module docstring.
    """
    if start.status != "collapse" or start.normal_N is None or start.load_multiplier is None:
        raise ValueError("the iteration starts from an associated collapse solution")
    mu = friction_coefficients(model)[:, None]
    w_ref = float((model.masses_kg[model.moving] * model.g).max())
    n_bar = np.maximum(start.normal_N, 0.0)
    lam_prev = start.load_multiplier
    history = [lam_prev]
    step_prev = 0.0
    beta = 1.0
    settled_for = 0
    elapsed = start.solve_time_s
    t0 = time.perf_counter()
    sol = start
    for k in range(1, max_iterations + 1):
        left = None if time_limit_s is None else time_limit_s - (time.perf_counter() - t0)
        try:
            if left is not None and left <= 0.0:
                raise TimeLimitError("no time left")
            sol = solve_equilibrium(
                model, start.direction, method, mu * n_bar, time_limit_s=left, on_progress=on_progress
            )
        except TimeLimitError:
            reason = f"the time limit of {time_limit_s:g} s was reached after {k - 1} iterations"
            return CoulombSolution(sol, k - 1, False, tuple(history), elapsed + time.perf_counter() - t0, reason)
        if on_iteration is not None and sol.load_multiplier is not None:
            on_iteration(k, sol.load_multiplier, time.perf_counter() - t0)
        if sol.status != "collapse" or sol.normal_N is None or sol.load_multiplier is None:
            reason = f"iteration {k} found no collapse multiplier (status {sol.status})"
            return CoulombSolution(sol, k, False, tuple(history), elapsed + time.perf_counter() - t0, reason)
        lam = sol.load_multiplier
        history.append(lam)
        n_new = np.maximum(sol.normal_N, 0.0)
        d_lam = lam - lam_prev
        d_n = float(np.max(np.abs(n_new - n_bar), initial=0.0))
        settled_for = settled_for + 1 if abs(d_lam) <= LAMBDA_RTOL * max(abs(lam), 1e-12) else 0
        fixed_point = settled_for > 0 and d_n <= FORCE_RTOL * w_ref
        if fixed_point:
            return CoulombSolution(sol, k, True, tuple(history), elapsed + time.perf_counter() - t0, "")
        found = certified(model, sol) if settled_for >= SETTLED_STEPS else None
        if found is not None:
            return CoulombSolution(found, k, True, tuple(history), elapsed + time.perf_counter() - t0, "")
        if k > PLAIN_ITERATIONS and d_lam * step_prev < 0.0 and abs(d_lam) > 0.5 * abs(step_prev):
            beta = max(0.5 * beta, 1.0 / 16.0)  # lambda oscillates without shrinking: relax the update
        step_prev = d_lam if d_lam != 0.0 else step_prev
        n_bar = n_bar + beta * (n_new - n_bar)
        lam_prev = lam
    reason = f"lambda and the normal forces did not settle in {max_iterations} iterations"
    return CoulombSolution(sol, max_iterations, False, tuple(history), elapsed + time.perf_counter() - t0, reason)


def end_motions(model: RigidBlockModel, velocities: NDArray[np.float64]) -> NDArray[np.float64]:
    """(n_interfaces, 2, 2) relative velocity (normal, tangential) of body a on body b at every
    interface end, the velocities normalised to a largest centroid velocity of 1."""
    vel = velocities / max(float(np.max(np.abs(velocities[:, :2]))), 1e-300)
    out = np.zeros((len(model.interfaces), 2, 2))
    for k, itf in enumerate(model.interfaces):
        for e, p in enumerate(itf.ends_m):
            dv = np.zeros(2)
            for body, sign in ((itf.a, 1.0), (itf.b, -1.0)):
                if body >= 0:
                    r = p - model.centroids_m[body]
                    v = vel[body]
                    dv += sign * np.array([v[0] - v[2] * r[1], v[1] + v[2] * r[0]])
            out[k, e] = (dv @ itf.normal, dv @ itf.tangent)
    return out


def certify(model: RigidBlockModel, solution: LPSolution) -> bool:
    """True when ``solution`` (lambda and mechanism) is a non-associated solution (:func:`certified`)."""
    return certified(model, solution) is not None


def certified(model: RigidBlockModel, solution: LPSolution) -> LPSolution | None:
    """``solution`` with the contact forces of a feasibility programme that finds them in equilibrium
    at its lambda with n >= 0 and |t| <= tan(phi) n at every end, n = t = 0 where the mechanism opens
    the end and t = -tan(phi) n sign(slip) where it slides along the joint without opening (module
    docstring), and with friction capacities tan(phi) n; None when there are no such forces."""
    if solution.velocities is None or solution.load_multiplier is None:
        return None
    A, b, lam_col, free, _, (w_ref, l_ref) = equilibrium_system(model, solution.direction, non_dilatant=True)
    scale = max(
        1.0,
        float(np.max(np.abs(solution.velocities[:, 2])))
        * l_ref
        / max(float(np.max(np.abs(solution.velocities[:, :2]))), 1e-300),
    )
    tol = VELOCITY_TOL * scale
    motion = end_motions(model, solution.velocities)
    n_cols = lam_col
    lower = np.where(free, -np.inf, 0.0)
    upper = np.full(n_cols, np.inf)
    # extra rows as (row, column, value) triplets: slip rows (equalities), cone rows (<= 0)
    eq: list[tuple[int, int, float]] = []
    ub: list[tuple[int, int, float]] = []
    mu = friction_coefficients(model)
    for k, itf in enumerate(model.interfaces):
        for e in range(2):
            cn, ct = 4 * k + 2 * e, 4 * k + 2 * e + 1
            dn, dt = motion[k, e]
            if dn > tol:  # the end opens: no force
                lower[cn] = upper[cn] = lower[ct] = upper[ct] = 0.0
                continue
            if itf.friction_angle_deg is None:
                continue  # locked or sliding freely along a joint without friction: n >= 0, t free
            if abs(dt) > tol:  # slides without opening: t + tan(phi) n sign(slip) = 0
                r = len(eq) // 2
                eq += [(r, ct, 1.0), (r, cn, float(mu[k] * np.sign(dt)))]
            else:  # locked: t - tan(phi) n <= 0 and -t - tan(phi) n <= 0
                r = len(ub) // 2
                ub += [(r, ct, 1.0), (r, cn, -float(mu[k])), (r + 1, ct, -1.0), (r + 1, cn, -float(mu[k]))]

    def rows(triplets: list[tuple[int, int, float]], n_rows: int) -> sp.csr_matrix:
        r, c, v = zip(*triplets, strict=True) if triplets else ((), (), ())
        return sp.csr_matrix((v, (r, c)), shape=(n_rows, n_cols))

    n_eq, n_ub = len(eq) // 2, len(ub) // 2
    A_eq = sp.vstack([A[:, :lam_col], rows(eq, n_eq)], format="csr")
    b_eq = np.concatenate([b - A[:, lam_col].toarray().ravel() * solution.load_multiplier, np.zeros(n_eq)])
    res = linprog(
        np.zeros(n_cols),
        A_ub=rows(ub, n_ub) if n_ub else None,
        b_ub=np.zeros(n_ub) if n_ub else None,
        A_eq=A_eq,
        b_eq=b_eq,
        bounds=np.column_stack([lower, upper]),
        method=highs_method("highs", n_cols),
    )
    if res.status != 0:
        return None
    forces = res.x.reshape(len(model.interfaces), 2, 2) * w_ref  # (interface, end, (N, T))
    normal, tangential = forces[:, :, 0], forces[:, :, 1]
    capacity = mu[:, None] * np.maximum(normal, 0.0)
    return replace(solution, normal_N=normal, tangential_N=tangential, friction_capacity_N=capacity)
