"""The Moreau-Jean step of a scene, assembled with numpy and solved by Siconos's numerics.

Runs inside Debian's Python, imported by the Siconos driver (:mod:`rockyade.siconos.driver`,
which passes it Siconos's ``numerics`` module): it imports only numpy (and scipy, whose
sparse matrices are how Siconos's Python takes a sparse one). It is Siconos's own time
stepping, Moreau-Jean's theta-method with Newton's impact law and Coulomb friction, written
out so that the one-step problem is built once per step with numpy instead of by Siconos's
kernel from one Python-visible object per contact (docs/siconos.md, "The one-step problem").

Per step k (step h, theta = 1/2):

* the contact pairs' geometry at q_k, all pairs at once (:mod:`rockyade.siconos.pair_table`): the gap g,
  the normal and tangent, and the rows H_n, H_t of the contact Jacobian (the velocity of the
  vertex relative to the other body's material point at it, along n and t);
* the active set, Siconos's rule (``MoreauJeanOSI::addInteractionInIndexSet``):
  g + h/2 (H_n v_k) <= its activation threshold;
* the free velocity v_free = v_k + h M^-1 F_theta, F_theta = theta F(t_k+1) + (1 - theta) F(t_k)
  (gravity, the base's inertial force -m a_g(t), point loads at q_k);
* the one-step problem of the active contacts, Siconos's ``FrictionContactProblem``:
  u = W r + q with W = H M^-1 H^T (the Delassus operator) and q = H v_free + (e H_n v_k, 0),
  r the impulses, Coulomb's cone |r_t| <= mu r_n, u_n >= 0 complementary to r_n;
* v_k+1 = v_free + M^-1 H^T r, q_k+1 = q_k + h ((1 - theta) v_k + theta v_k+1).

The problem is solved by Siconos: a few contacts (``DIRECT_CONTACTS``) as FrictionContact(2)
by Lemke's pivoting method (``fc2d_lexicolemke``); more as FrictionContact(3) whose
out-of-plane row is decoupled (W's third diagonal entry 1, q's 0: its impulse stays 0, and
the iterates are FrictionContact(2)'s, measured) by Gauss-Seidel on a sparse matrix
(``fc3d_nsgs``, each contact's local problem by a projection on its cone) warm-started from
the last step's impulses of the same pairs. A solution whose residual is above the tolerance
is taken again by the proximal point method (``fc3d_proximal``: a regularised nonsmooth
Newton, which the singular W of redundant contacts does not stop); after Gauss-Seidel fails,
the proximal method goes first for 1, then 8, 64, ... solves (HOLD_GROWTH). Why
FrictionContact(3) for many contacts: Siconos 4.4's 2-D Gauss-Seidel takes only a
sparse-block matrix, whose conversion cost as much as the solve (docs/siconos.md).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # in Debian's Python the driver passes the table (its sibling module's)
    from rockyade.siconos.pair_table import PairTable

#: Up to this many active contacts the problem is FrictionContact(2), dense, solved by Lemke.
DIRECT_CONTACTS = 16
#: Up to this many active contacts Lemke is the last resort after Gauss-Seidel and the
#: proximal method (its cost grows as the cube of the contacts).
LEMKE_CONTACTS = 120
#: Up to this many pairs a step is computed pair by pair in Python floats, beyond it with
#: numpy over all pairs at once (numpy's per-call overhead dominates a block's or a bi-block's
#: step: measured).
SCALAR_PAIRS = 16
#: A contact is active while g + h/2 u_n is at most this fraction of the smallest block
#: dimension (Siconos's constraint activation threshold; 0 there): a contact at rest whose
#: gap drifts by rounding stays active instead of opening and letting its block drop.
ACTIVATION_FRACTION = 1e-5
#: Gauss-Seidel's local solver (each contact's problem with the others' impulses fixed): a
#: projection on the friction cone, Siconos's cheapest; its default, a local nonsmooth Newton,
#: cost 29x more a step on a moving arch for the same solution (docs/siconos.md).
NSGS_LOCAL_SOLVER = "SICONOS_FRICTION_3D_ONECONTACT_ProjectionOnCone"
#: Gauss-Seidel's iteration cap (the proximal point method takes a step it fails: on the
#: t/R 0.08 arch collapsing, 7.0 s with 200 against 16.6 s with 1,000, the same motion).
NSGS_MAX_ITER = 200
#: The proximal point method's iteration cap.
PROX_MAX_ITER = 200
#: A solution whose largest impulse exceeds this many times the moving bodies' momentum scale
#: (their mass x (the largest free speed + g dt)) is refused: on the singular W of redundant
#: contacts the proximal method once returned impulses of 1e16 N s in W's null space, within
#: its relative tolerance, whose rounding then threw a voussoir at 5e14 m/s.
IMPULSE_FACTOR = 1e3
#: After Gauss-Seidel fails, the proximal method goes first for 1 solve, then HOLD_GROWTH
#: times longer at each new failure (a collapsing arch fails it at every step).
HOLD_GROWTH = 8


class MoreauJean:
    """A scene stepped by Moreau-Jean with its one-step problem solved by Siconos (module docstring).

    Parameters
    ----------
    scene
        The payload (:mod:`rockyade.siconos.payload`): bodies, time step, theta, restitution,
        solver tolerance and iteration cap.
    table
        The contact pairs (:class:`rockyade.siconos.pair_table.PairTable`).
    sn
        Siconos's ``numerics`` module.
    forces
        A callable giving the base's force per unit mass (a_x, a_y), m/s^2, at the start and
        the end of step k: ``forces(k) -> ((ax0, ay0), (ax1, ay1))``.
    """

    def __init__(self, scene: dict[str, Any], table: PairTable, sn: Any, forces: Any) -> None:
        bodies = scene["bodies"]
        nb = len(bodies)
        self.scene, self.table, self.sn, self.forces = scene, table, sn, forces
        self.h = float(scene["dt_s"])
        self.theta = float(scene["theta"])
        self.e = float(scene["restitution"])
        self.q = np.zeros((nb + 1, 3))
        self.v = np.zeros((nb + 1, 3))
        for i, b in enumerate(bodies):
            self.q[i] = (b["centroid0_m"][0], b["centroid0_m"][1], b["angle0_rad"])
            self.v[i] = (b["vel0_m_s"][0], b["vel0_m_s"][1], b["angvel0_rad_s"])
        self.moving = np.array([not b["fixed"] for b in bodies] + [False])
        self.mass = np.array([float(b["mass_kg"]) for b in bodies] + [0.0])[self.moving]
        self.minv = np.array(
            [[1.0 / b["mass_kg"], 1.0 / b["mass_kg"], 1.0 / b["inertia_kgm2"]] for b in bodies if not b["fixed"]]
        )
        self.dof = np.full(nb + 1, -1)
        self.dof[self.moving] = np.arange(int(self.moving.sum()))
        self.dof_a, self.dof_b = self.dof[table.a], self.dof[table.b]
        self.loads = [(int(self.dof[i]), b["load"]) for i, b in enumerate(bodies) if not b["fixed"] and b.get("load")]
        self.threshold = ACTIVATION_FRACTION * table.size
        self.total_mass = float(self.mass.sum())
        self.g = float(scene["g"])
        self.impulse_limit = math.inf  # set each step (IMPULSE_FACTOR)
        self.tol = float(scene["solver_tol"])
        self.max_iter = int(scene["solver_max_iter"])
        self.impulse = np.zeros((len(table.pairs), 2))  # the last step's (r_n, r_t) per pair, N s
        self.loaded: list[tuple[int, float, float, float]] = []  # the last step's (pair, r_n, r_t, gap)
        self.scalar = len(table.pairs) <= SCALAR_PAIRS
        self._qs, self._vs = self.q.tolist(), self.v.tolist()  # the scalar path's state
        self.moving_ids = np.flatnonzero(self.moving).tolist()
        self.radius = [float(np.max(np.hypot(*np.asarray(b["vertices_m"], dtype=float).T))) for b in bodies] + [0.0]
        self.minv_list = self.minv.ravel().tolist()
        self.minv_flat = self.minv.ravel()
        self.mass_list = self.mass.tolist()
        self.mu_list = table.mu.tolist()
        self.dof_list = self.dof.tolist()
        self._options: dict[str, Any] = {}
        self._pattern: tuple[bytes, Any, np.ndarray, np.ndarray] | None = None
        self.prox_until = 0  # the proximal method goes first until this solver call
        self.hold = 1
        self._sparse: Any = None
        # diagnostics (the driver's Recorder reads them); fallbacks: the proximal method's calls
        self.calls = self.iterations = self.unconverged = self.fallbacks = 0
        self.residual = 0.0  # of the last call
        self.max_residual = 0.0
        self.names = ["fc2d_lemke", "fc3d_nsgs", "fc3d_prox"]

    def describe(self) -> str:
        """The one-step problem and its solvers, in words (the Result's ``one_step_problem``)."""
        return (
            f"Moreau-Jean assembled with numpy (theta {self.theta:g}, activation threshold {self.threshold:.3g} m); "
            f"up to {DIRECT_CONTACTS} active contacts FrictionContact(2) by Lemke, "
            "more FrictionContact(3) with the out-of-plane row decoupled by Gauss-Seidel warm-started from the "
            "last step's impulses; the proximal point method where they end above the tolerance"
        )

    def options(self, name: str) -> Any:
        """Siconos's solver options of ``name`` (created once, tolerance and cap set)."""
        so = self._options.get(name)
        if so is None:
            sn = self.sn
            ids = {
                "lemke": sn.SICONOS_FRICTION_2D_LEMKE,
                "nsgs": sn.SICONOS_FRICTION_3D_NSGS,
                "prox": sn.SICONOS_FRICTION_3D_PROX,
            }
            so = self._options[name] = sn.SolverOptions(ids[name])
            if name == "nsgs":  # each contact's local problem by one projection on its cone
                sn.solver_options_update_internal(so, 0, getattr(sn, NSGS_LOCAL_SOLVER))
            # Lemke's cap is on its pivots
            so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = (
                min(self.max_iter, PROX_MAX_ITER) if name == "prox" else self.max_iter
            )
            so.dparam[sn.SICONOS_DPARAM_TOL] = self.tol
        return so

    def force(self, k: int) -> np.ndarray:
        """(moving, 3) F_theta of step k: gravity and the base's inertial force, theta-weighted
        between the step's ends, and the point loads at q_k, N and N m."""
        (ax0, ay0), (ax1, ay1) = self.forces(k)
        th = self.theta
        ax, ay = (1.0 - th) * ax0 + th * ax1, (1.0 - th) * ay0 + th * ay1
        F = np.zeros((len(self.mass), 3))
        F[:, 0] = self.mass * ax
        F[:, 1] = self.mass * ay
        for d, load in self.loads:
            phi = float(self.q[self.moving][d, 2])
            fx, fy = load["force_N"]
            m0, qarm = load["arm_Nm"]
            F[d] += (fx, fy, math.cos(phi) * m0 - math.sin(phi) * qarm)
        return F

    def step(self, k: int) -> bool:
        """Take step ``k``; True when it had active contacts."""
        if self.scalar:
            return self._step_scalar(k)
        h, th, mv = self.h, self.theta, self.moving
        t = self.table
        gap, closed, H = t.geometry(self.q)
        va, vb = self.v[t.a], self.v[t.b]
        un = np.einsum("kj,kj->k", H[:, 0, 0], va) + np.einsum("kj,kj->k", H[:, 1, 0], vb)
        active = np.flatnonzero(closed & (gap + 0.5 * h * un <= self.threshold))
        v_free = self.v.copy()
        v_free[mv] += h * self.minv * self.force(k)
        self.impulse_limit = IMPULSE_FACTOR * self.total_mass * (float(np.max(np.abs(v_free))) + self.g * h)
        impulse = np.zeros_like(self.impulse)
        if len(active):
            Ha = H[active]
            q = np.einsum("kij,kj->ki", Ha[:, 0], v_free[t.a[active]]) + np.einsum(
                "kij,kj->ki", Ha[:, 1], v_free[t.b[active]]
            )
            q[:, 0] += self.e * un[active]
            r = self.solve(active, Ha, q)
            impulse[active] = r
            # H^T r summed per body (np.add.at is slower than bincount)
            to = np.concatenate([t.a[active], t.b[active]])
            each = np.concatenate([np.einsum("kij,ki->kj", Ha[:, 0], r), np.einsum("kij,ki->kj", Ha[:, 1], r)])
            push = np.stack([np.bincount(to, weights=each[:, j], minlength=len(self.v)) for j in range(3)], axis=1)
            v_free[mv] += self.minv * push[mv]
        self.q[mv] += h * ((1.0 - th) * self.v[mv] + th * v_free[mv])
        self.v = v_free
        self.impulse = impulse
        self.loaded = list(
            zip(
                active.tolist(),
                impulse[active, 0].tolist(),
                impulse[active, 1].tolist(),
                gap[active].tolist(),
                strict=True,
            )
        )
        return bool(len(active))

    def _step_scalar(self, k: int) -> bool:
        """:meth:`step` for a few pairs: the geometry and the update pair by pair in Python
        floats, the problem dense with numpy (numpy's per-call overhead dominates a few pairs)."""
        h, th = self.h, self.theta
        a_of, b_of, vloc, nl, e0, lo, hi, deep, twin = self.table.lists
        qs, vs = self._qs, self._vs
        trig = [(math.cos(p[2]), math.sin(p[2])) for p in qs]
        dof = self.dof_list
        nd = len(self.minv_flat)
        inside = [False] * len(a_of)
        found = []
        rows = []
        bounce = []
        limit = self.threshold
        ground = len(qs) - 1
        # how far a body's vertex can approach in half a step: |v| + |omega| x its radius
        reach = [0.5 * h * (math.hypot(v[0], v[1]) + abs(v[2]) * r) for v, r in zip(vs, self.radius, strict=True)]
        for i in range(len(a_of)):
            a, b = a_of[i], b_of[i]
            ca, sa = trig[a]
            vx, vy = vloc[i]
            if b == ground and qs[a][1] + sa * vx + ca * vy - reach[a] > limit:
                continue  # a vertex too high to touch the ground in this step
            cb, sb = trig[b]
            rax, ray = ca * vx - sa * vy, sa * vx + ca * vy
            n0, n1 = nl[i]
            nx, ny = cb * n0 - sb * n1, sb * n0 + cb * n1
            ex, ey = e0[i]
            qa, qb = qs[a], qs[b]
            rbx, rby = qa[0] + rax - qb[0], qa[1] + ray - qb[1]
            dx, dy = rbx - (cb * ex - sb * ey), rby - (sb * ex + cb * ey)
            gap = dx * nx + dy * ny
            along = dy * nx - dx * ny
            inside[i] = ok = lo[i] <= along <= hi[i] and gap >= deep[i]
            if not ok or (twin[i] >= 0 and inside[twin[i]]):
                continue
            va, vb = vs[a], vs[b]
            ra, rb = ny * rax - nx * ray, nx * rby - ny * rbx
            un = nx * (va[0] - vb[0]) + ny * (va[1] - vb[1]) + ra * va[2] + rb * vb[2]
            if gap + 0.5 * h * un > limit:
                continue
            row_n, row_t = [0.0] * nd, [0.0] * nd
            da, db = dof[a], dof[b]
            if da >= 0:
                row_n[3 * da : 3 * da + 3] = nx, ny, ra
                row_t[3 * da : 3 * da + 3] = -ny, nx, nx * rax + ny * ray
            if db >= 0:
                row_n[3 * db : 3 * db + 3] = -nx, -ny, rb
                row_t[3 * db : 3 * db + 3] = ny, -nx, -nx * rbx - ny * rby
            rows.append(row_n)
            rows.append(row_t)
            bounce.append(self.e * un)
            bounce.append(0.0)
            found.append((i, gap))
        v0 = [x for body in self.moving_ids for x in vs[body]]
        F = self.force_list(k)
        minv = self.minv_list
        v_new = [v + h * w * f for v, w, f in zip(v0, minv, F, strict=True)]
        self.impulse_limit = IMPULSE_FACTOR * self.total_mass * (max(map(abs, v_new)) + self.g * h)
        self.loaded = []
        if found:
            m = len(found)
            H = np.array(rows)
            HM = H * self.minv_flat
            r = self._direct_dense(m, HM @ H.T, H @ v_new + bounce, [self.mu_list[i] for i, _ in found])
            push = (r @ HM).tolist()
            v_new = [v + p for v, p in zip(v_new, push, strict=True)]
            rl = r.tolist()
            self.loaded = [(i, rl[2 * j], rl[2 * j + 1], gap) for j, (i, gap) in enumerate(found)]
        for j, body in enumerate(self.moving_ids):
            qb, vb = qs[body], vs[body]
            for c in range(3):
                old, new = v0[3 * j + c], v_new[3 * j + c]
                qb[c] += h * ((1.0 - th) * old + th * new)
                vb[c] = new
        return bool(found)

    def force_list(self, k: int) -> list[float]:
        """:meth:`force` as a flat list of floats (the scalar path)."""
        (ax0, ay0), (ax1, ay1) = self.forces(k)
        th = self.theta
        ax, ay = (1.0 - th) * ax0 + th * ax1, (1.0 - th) * ay0 + th * ay1
        F = [c for m in self.mass_list for c in (m * ax, m * ay, 0.0)]
        for d, load in self.loads:
            phi = self._qs[self.moving_ids[d]][2]
            fx, fy = load["force_N"]
            m0, qarm = load["arm_Nm"]
            F[3 * d] += fx
            F[3 * d + 1] += fy
            F[3 * d + 2] += math.cos(phi) * m0 - math.sin(phi) * qarm
        return F

    def runaway(self, max_speed: float, max_spin: float) -> tuple[int, float, float] | None:
        """The first body whose state is not finite or whose speed (m/s) or spin (rad/s) is
        beyond the bounds: (index, speed, spin), or None."""
        if self.scalar:
            for i in self.moving_ids:
                (x, y, p), (vx, vy, w) = self._qs[i], self._vs[i]
                speed = math.hypot(vx, vy)
                if not (speed <= max_speed and abs(w) <= max_spin and math.isfinite(x + y + p)):
                    return i, speed, abs(w)
            return None
        v = self.v[:-1]
        speeds = np.hypot(v[:, 0], v[:, 1])
        ok = np.isfinite(self.q[:-1]).all(axis=1) & (speeds <= max_speed) & (np.abs(v[:, 2]) <= max_spin)
        if ok[self.moving[:-1]].all():
            return None
        i = int(np.flatnonzero(~ok & self.moving[:-1])[0])
        return i, float(speeds[i]), float(abs(v[i, 2]))

    def state(self) -> tuple[np.ndarray, np.ndarray]:
        """(nb, 3) positions (x, y, theta) and (nb, 3) velocities of the bodies, m, rad, m/s, rad/s."""
        if self.scalar:
            return np.array(self._qs[:-1]), np.array(self._vs[:-1])
        return self.q[:-1], self.v[:-1]

    def solve(self, active: np.ndarray, Ha: np.ndarray, q: np.ndarray) -> np.ndarray:
        """The impulses (m, 2) of the active contacts (module docstring)."""
        m = len(active)
        key = active.tobytes()
        if self._pattern is None or self._pattern[0] != key:
            da, db = self.dof_a[active], self.dof_b[active]
            on_a, on_b = np.flatnonzero(da >= 0), np.flatnonzero(db >= 0)
            pattern = self.table.pattern(m, np.concatenate([on_a, on_b]), np.concatenate([da[on_a], db[on_b]]))
            self._pattern = (key, pattern, on_a, on_b)
        _, pattern, on_a, on_b = self._pattern
        blocks = pattern.blocks(np.concatenate([Ha[on_a, 0], Ha[on_b, 1]]), self.minv)
        mu = self.table.mu[active]
        if m <= DIRECT_CONTACTS:
            W = np.zeros((m, 2, m, 2))
            W[pattern.block_row, :, pattern.block_col, :] = blocks
            return self._direct_dense(m, W.reshape(2 * m, 2 * m), q.ravel(), mu).reshape(m, 2)
        return self._iterative(m, pattern, blocks, q, mu, self.impulse[active])

    def _direct_dense(self, m, W, q, mu) -> np.ndarray:
        """The impulses (2m,) of the dense FrictionContact(2) problem (W, q, mu): Lemke's
        solution when its residual (Siconos's ``fc2d_compute_error``, which Lemke leaves in
        the options) is within the tolerance, else Gauss-Seidel's, else the proximal point
        method's (on the problem as FrictionContact(3), its out-of-plane row decoupled).

        Siconos 4.4's ``fc2d_lexicolemke`` reports success whatever its residual (it compares
        the residual with the iteration cap, ``iparam[0]``, instead of the tolerance); on the
        degenerate problems of redundant contacts it can stop on a wrong solution (measured:
        residual 9e-3 on a 4-block stack at rest), hence the check here."""
        sn = self.sn
        self.calls += 1
        so = self.options("lemke")
        r = np.zeros(2 * m)
        sn.fc2d_driver(sn.FrictionContactProblem(2, W, q, mu), r, np.zeros(2 * m), so)
        self.iterations += max(1, int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE]))
        residual = float(so.dparam[sn.SICONOS_DPARAM_RESIDU]) if self._sane(r) else math.inf
        out = r.reshape(m, 2)
        if not residual <= self.tol:
            W3 = np.zeros((m, 3, m, 3))
            W3[:, :2, :, :2] = np.asarray(W).reshape(m, 2, m, 2)
            W3[np.arange(m), 2, np.arange(m), 2] = 1.0
            q3 = np.zeros((m, 3))
            q3[:, :2] = np.asarray(q).reshape(m, 2)
            problem = sn.FrictionContactProblem(3, W3.reshape(3 * m, 3 * m), q3.ravel(), mu)
            self.fallbacks += 1
            for name in ("nsgs", "prox"):
                out, residual = self._fc3(name, problem, m, out, residual)
                if residual <= self.tol:
                    break
        self._count(residual)
        return out.ravel()

    def _sane(self, r: np.ndarray) -> bool:
        """Finite impulses within IMPULSE_FACTOR of the step's momentum scale."""
        limit = self.impulse_limit
        if len(r) <= 3 * DIRECT_CONTACTS:  # a few: in floats (NaN fails the comparison)
            return all(-limit <= x <= limit for x in r.tolist())
        return bool(np.all(np.isfinite(r))) and not float(np.max(np.abs(r), initial=0.0)) > limit

    def _fc3(self, name, problem, m, start, residual) -> tuple[np.ndarray, float]:
        """Siconos's 3-D solver ``name`` on ``problem`` from ``start`` (m, 2; out of plane 0):
        its impulses (m, 2) and residual, or ``start`` and ``residual`` when it does no better."""
        sn = self.sn
        r3 = np.zeros((m, 3))
        r3[:, :2] = np.where(np.isfinite(start), start, 0.0)
        r = r3.ravel()
        so = self.options(name)
        sn.fc3d_driver(problem, r, np.zeros(3 * m), so)
        self.iterations += int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE])
        got = float(so.dparam[sn.SICONOS_DPARAM_RESIDU])
        if self._sane(r) and not got > residual:
            return r.reshape(m, 3)[:, :2], got
        return start, residual

    def _count(self, residual: float) -> None:
        """The last solve's residual in the diagnostics; above the tolerance it is unconverged."""
        self.residual = residual
        self.max_residual = max(self.max_residual, residual)
        if not residual <= self.tol:
            self.unconverged += 1

    def _iterative(self, m, pattern, blocks, q, mu, start) -> np.ndarray:
        """The impulses (m, 2) by Gauss-Seidel on the sparse FrictionContact(3) problem from
        ``start`` (the last step's impulses of the same pairs), by the proximal point method
        where Gauss-Seidel ends above the tolerance (first, for a while, after it did:
        HOLD_GROWTH), and by Lemke where both do (up to LEMKE_CONTACTS)."""
        sn = self.sn
        if self._sparse is None:
            try:
                import scipy.sparse
            except ImportError:
                raise ImportError(
                    "Siconos's Python takes a sparse matrix as a scipy one: apt-get install python3-scipy"
                ) from None
            self._sparse = scipy.sparse
        self.calls += 1
        data, indices, indptr = pattern.fc3(blocks)
        W = self._sparse.csc_matrix((data, indices, indptr), shape=(3 * m, 3 * m))
        W.indices, W.indptr = indices, indptr  # scipy narrows them to int32; Siconos takes int64
        q3 = np.zeros((m, 3))
        q3[:, :2] = q
        problem = sn.FrictionContactProblem(3, W, q3.ravel(), mu)
        out, residual = start, math.inf
        if self.calls < self.prox_until:  # Gauss-Seidel failed lately: the proximal method first
            self.fallbacks += 1
            out, residual = self._fc3("prox", problem, m, start, residual)
            if residual <= self.tol:
                self._count(residual)
                return out
        out, residual = self._fc3("nsgs", problem, m, out, residual)
        if not residual <= self.tol and self.calls >= self.prox_until:
            self.fallbacks += 1
            out, residual = self._fc3("prox", problem, m, out, residual)
            self.prox_until = self.calls + self.hold
            self.hold *= HOLD_GROWTH
        if not residual <= self.tol and m <= LEMKE_CONTACTS:  # the last resort: pivoting
            W2 = np.zeros((m, 2, m, 2))
            W2[pattern.block_row, :, pattern.block_col, :] = blocks
            so = self.options("lemke")
            r = np.zeros(2 * m)
            sn.fc2d_driver(
                sn.FrictionContactProblem(2, W2.reshape(2 * m, 2 * m), q.ravel(), mu), r, np.zeros(2 * m), so
            )
            self.iterations += int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE])
            got = float(so.dparam[sn.SICONOS_DPARAM_RESIDU])
            if self._sane(r) and got < residual:
                out, residual = r.reshape(m, 2), got
        self._count(residual)
        return out
