"""A mechanism followed at finite displacement, and its multiplier alpha(dk) by virtual work.

The blocks that take part in a mechanism move as rigid bodies; blocks joined by a locked
joint (neither end opens nor slips at rest) move together as one rigid group. Group g's
material point X (rest position, base frame) is at C_g + t_g + R(theta_g) (X - C_g), C_g its
centre of mass at rest, t_g its displacement and theta_g its rotation. The hinges (an
interface end where the two bodies turn relative to each other without opening or
slipping) stay joined: x_a(X) = x_b(X), a body not taking part (or the base, a fixed block)
staying where it is. The velocities (vx, vy, omega) compatible with those joints
form the null space of the constraints' Jacobian C(s) in the displaced configuration s;
a one-degree-of-freedom mechanism has a one-dimensional null space (where it has more, the
velocity nearest the last one is followed).

The hinges are unilateral: where keeping them all would lock the mechanism (they can be
compatible at rest to first order only, as in walls whose hinges line up), the velocity is
the one that keeps every hinge from slipping and from closing and minimises alpha (a
small linear programme over the hinges, HiGHS), and the hinges it opens are released
for good (how far their points later pass into each other is reported).

The configuration is advanced by the midpoint rule in steps of the control displacement
dk (the control point's horizontal displacement along the load), each step projected back
onto the joints by Gauss-Newton, and at every configuration

    alpha = (sum m_i g vy_i - sum F . v(p)) / (d sum m_i g vx_i)

(the virtual work of gravity, the loads F at their points p and alpha m g d, zero), down to
alpha = 0. This is the nonlinear kinematic analysis of NTC 2018 / Circolare 2019 C8.7.1
(the multiplier of the mechanism at finite displacement). The joints are kept as they
are at rest. A frictionless joint that slides (a wall's top on a frictionless restraint: the
three-hinge mechanism) is followed: the corner that slides stays on the line of the face it
slides along (a bilateral constraint; no work is dissipated, so alpha is still the ratio below).
A joint that slides with friction is not followed (the code's nonlinear analysis is for rocking
mechanisms; friction's dissipation is not in the ratio). A new contact is not followed either:
where a moving block meets a fixed block it did not touch at rest (a restrained wall's top
closing its gap), the curve stops there and says so (the mechanism changes: the wall bears on its
restraint, and its capacity beyond is another mechanism's, which a limit analysis of the scene with
the gap closed gives).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from rockyade.limit.lp import DIRECTIONS
from rockyade.limit.mechanism import VELOCITY_TOL, Mechanism, relative_velocity
from rockyade.limit.rigid_blocks import RigidBlockModel, _outside
from rockyade.scene.placement import candidate_pairs, edge_normals, penetration_depth

#: Largest rotation of any block in one step, rad.
MAX_STEP_ROTATION_RAD = 2.0e-3
#: Largest change of alpha in one step, as a fraction of alpha at rest.
MAX_STEP_ALPHA = 5.0e-3
MAX_STEPS = 20_000


@dataclass(frozen=True)
class CapacityCurve:
    """alpha against the control point's displacement, from rest down to alpha = 0.

    Attributes
    ----------
    dk_m
        Horizontal displacement of the control point along the load, m (first 0).
    alpha
        Multiplier of the mechanism in each configuration (first: alpha0).
    d0_m
        dk at alpha = 0 (interpolated), m; None when the curve stops before (``stopped``).
    stopped
        Why the curve ended before alpha = 0, else None.
    max_joint_gap_m
        Largest distance apart of two joined points over the curve (the drift of the
        integration), m.
    opened
        (interface, end) of the hinges that opened on the way (the mechanism's hinges are
        unilateral: kept while they bear, released where keeping them all would lock it).
    max_overlap_m
        Largest distance by which the two points of a released hinge passed into each other
        along its normal, m.
    closed_dk_m
        Where a gap closed (a moving block met a fixed block it did not touch at rest), the
        control displacement dk at which it did, m (the curve stops there); else None.
    """

    dk_m: NDArray[np.float64]
    alpha: NDArray[np.float64]
    d0_m: float | None
    stopped: str | None
    max_joint_gap_m: float
    opened: tuple[tuple[int, int], ...] = ()
    max_overlap_m: float = 0.0
    closed_dk_m: float | None = None


_T = TypeVar("_T")
#: How many configurations' constraints and null spaces are kept (a step visits three).
_REMEMBERED = 4


def _remembered(memo: dict[bytes, _T], key: bytes, compute: Callable[[], _T]) -> _T:
    """``memo[key]``, computed by ``compute`` where missing; the oldest entry dropped beyond
    ``_REMEMBERED``."""
    if key not in memo:
        if len(memo) >= _REMEMBERED:
            del memo[next(iter(memo))]
        memo[key] = compute()
    return memo[key]


class _Kinematics:
    """Positions, joint constraints and compatible velocities of the moving rigid groups.

    Blocks joined by a locked interface (both ends active) move as one rigid group; a
    group's state is the displacement (tx, ty) of its reference point (the members' centre
    of mass) and its rotation theta. Only active points between different groups, or
    between a group and the ground, constrain the motion.
    """

    def __init__(self, model: RigidBlockModel, mechanism: Mechanism, direction: str) -> None:
        self.model = model
        self.direction = direction
        members = [int(b) for b in np.flatnonzero(mechanism.moving)]
        parent = {b: b for b in members}

        def root(b: int) -> int:
            while parent[b] != b:
                parent[b] = parent[parent[b]]
                b = parent[b]
            return b

        ends: dict[int, list[int]] = {}
        for k, e in mechanism.active_points:
            ends.setdefault(k, []).append(e)
        for k, es in ends.items():
            itf = model.interfaces[k]
            if len(es) == 2 and itf.a in parent and itf.b in parent:
                parent[root(itf.a)] = root(itf.b)
        roots = sorted({root(b) for b in members})
        self.group_of = {b: roots.index(root(b)) for b in members}
        self.members = [np.array([b for b in members if self.group_of[b] == g]) for g in range(len(roots))]
        masses = model.masses_kg
        self.group_mass = np.array([masses[m].sum() for m in self.members])
        self.refs = np.array(
            [np.average(model.centroids_m[m], axis=0, weights=masses[m]) for m in self.members]
        ).reshape(-1, 2)
        self.points = []  # (rest point, group of a or -1, group of b or -1, rest normal b -> a)
        self.hinge_of = []  # (interface, end) of each point
        for k, es in ends.items():
            itf = model.interfaces[k]
            ga = self.group_of.get(itf.a, -1)
            gb = self.group_of.get(itf.b, -1) if itf.b >= 0 else -1
            if ga == gb:
                continue  # inside a group (or between two bodies at rest)
            for e in es:
                self.points.append((itf.ends_m[e].copy(), ga, gb, itf.normal.copy()))
                self.hinge_of.append((k, e))
        self.active = np.ones(len(self.points), dtype=bool)
        self.ever_opened: set[int] = set()
        self.slides = self._slides(mechanism)
        # what does not change along a curve: each group's reference point and each point's rest
        # position, groups and arms X - ref (ref_a, ref_b)
        self._refs = [(float(x), float(y)) for x, y in self.refs]
        self._static = []
        for rest, ga, gb, _ in self.points:
            arms = tuple((rest - self.refs[g]).tolist() if g >= 0 else [0.0, 0.0] for g in (ga, gb))
            self._static.append((float(rest[0]), float(rest[1]), ga, gb, arms))
        self._frame_at: tuple[bytes, list[tuple[float, float, float, float]]] | None = None
        self.scale = np.ones(self.n_dof)
        self.scale[2::3] = model.size_m  # rotations to lengths: comparable columns
        # the last few configurations' (gap, Jacobian) and null spaces: a step asks for the same twice,
        # and a step tried again with half the length starts again from the same configuration
        self._constraints_at: dict[bytes, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}
        self._null_space_at: dict[bytes, NDArray[np.float64]] = {}

    def _slides(self, mechanism: Mechanism):
        """The ends of frictionless joints that slide without opening, as (point at rest, group of the
        body whose face the joint keeps, its outward normal at rest, group of the body whose corner
        follows that face): the corner stays on the face's line (module docstring)."""
        model = self.model
        out = []
        vel = mechanism.velocities
        scale = max(1.0, float(np.max(np.abs(vel[:, 2]))) * model.size_m)
        for slide in mechanism.sliding:
            itf = model.interfaces[slide.interface]
            ga = self.group_of.get(itf.a, -1)
            gb = self.group_of.get(itf.b, -1) if itf.b >= 0 else -1
            for p in itf.ends_m:
                dn, dt = relative_velocity(model, vel, itf, p)
                if abs(dn) > VELOCITY_TOL * scale or abs(dt) <= VELOCITY_TOL * scale:
                    continue
                # a's face past b's corner, if a's face goes on where a's points come from; else a's corner
                # along b's face
                back = p - np.sign(dt) * itf.tangent * 1e-6 * model.size_m
                face = self.members[ga] if ga >= 0 else [itf.a]  # a's face goes on in its group's blocks
                on_a = min(_outside(model.polygons_m[int(i)], back) for i in face) <= 1e-9 * model.size_m
                if on_a:
                    out.append((p.copy(), ga, -itf.normal, gb))
                else:
                    out.append((p.copy(), gb, itf.normal.copy(), ga))
        return out

    def _slide_row(self, s: NDArray[np.float64], k: int):
        """(distance of the corner from the face's line, its 1 x n Jacobian) of slide ``k``."""
        rest, g_face, normal, g_corner = self.slides[k]
        x_face, arm_f = self.place(s, g_face, rest)
        x_corner, arm_c = self.place(s, g_corner, rest)
        n = normal
        if g_face >= 0:
            c, sn = np.cos(s[3 * g_face + 2]), np.sin(s[3 * g_face + 2])
            n = np.array([c * normal[0] - sn * normal[1], sn * normal[0] + c * normal[1]])
        gap = x_corner - x_face
        J = np.zeros(self.n_dof)
        for group, arm, sign in ((g_corner, arm_c, 1.0), (g_face, arm_f, -1.0)):
            if group < 0:
                continue
            J[3 * group : 3 * group + 2] += sign * n
            J[3 * group + 2] += sign * (n @ np.array([-arm[1], arm[0]]))
        if g_face >= 0:
            J[3 * g_face + 2] += gap @ np.array([-n[1], n[0]])
        return float(gap @ n), J

    @property
    def n_dof(self) -> int:
        return 3 * len(self.members)

    def _frame(self, s: NDArray[np.float64]) -> list[tuple[float, float, float, float]]:
        """Each group's (ref_x + t_x, ref_y + t_y, cos theta, sin theta) in configuration ``s`` (the
        last configuration's kept: a configuration places many points)."""
        key = s.tobytes()
        if self._frame_at is None or self._frame_at[0] != key:
            state = s.tolist()
            frame = []
            for g, (x, y) in enumerate(self._refs):
                theta = s[3 * g + 2]
                frame.append((x + state[3 * g], y + state[3 * g + 1], float(np.cos(theta)), float(np.sin(theta))))
            self._frame_at = key, frame
        return self._frame_at[1]

    def place(self, s: NDArray[np.float64], group: int, rest: NDArray[np.float64]):
        """Position of a group's material point and its arm R(theta)(X - ref) (None for the ground)."""
        if group < 0:
            return rest, None
        x, y, c, sn = self._frame(s)[group]
        r = rest - self.refs[group]
        arm = np.array([c * r[0] - sn * r[1], sn * r[0] + c * r[1]])
        return np.array([x + arm[0], y + arm[1]]), arm

    def place_polygon(self, s: NDArray[np.float64], group: int, rest: NDArray[np.float64]) -> NDArray[np.float64]:
        """Positions of a group's material points ``rest`` (n x 2): ``place`` of each, element by element."""
        x, y, c, sn = self._frame(s)[group]
        r = rest - self.refs[group]
        out = np.empty_like(r)
        out[:, 0] = x + (c * r[:, 0] - sn * r[:, 1])
        out[:, 1] = y + (sn * r[:, 0] + c * r[:, 1])
        return out

    def point_velocity(self, s, q, group: int, rest) -> NDArray[np.float64]:
        """Velocity of a group's material point (rest position ``rest``)."""
        _, arm = self.place(s, group, rest)
        omega = q[3 * group + 2]
        return q[3 * group : 3 * group + 2] + omega * np.array([-arm[1], arm[0]])

    def initial_velocity(self, velocities: NDArray[np.float64]) -> NDArray[np.float64]:
        """The mechanism's block velocities as group velocities (of the reference points)."""
        q = np.zeros(self.n_dof)
        for g, members in enumerate(self.members):
            i = int(members[0])
            v = velocities[i]
            r = self.refs[g] - self.model.centroids_m[i]
            q[3 * g : 3 * g + 3] = (v[0] - v[2] * r[1], v[1] + v[2] * r[0], v[2])
        return q

    def _point(self, frame: list[tuple[float, float, float, float]], k: int):
        """(x_a - x_b as 2 floats, the two rows of its Jacobian as lists) of point ``k`` in the
        configuration whose ``_frame`` is ``frame``."""
        rest_x, rest_y, ga, gb, arms = self._static[k]
        rows = ([0.0] * self.n_dof, [0.0] * self.n_dof)
        xs = []
        for group, (rx, ry), sign in ((ga, arms[0], 1.0), (gb, arms[1], -1.0)):
            if group < 0:
                xs.append((rest_x, rest_y))
                continue
            x, y, c, sn = frame[group]
            arm_x, arm_y = c * rx - sn * ry, sn * rx + c * ry
            xs.append((x + arm_x, y + arm_y))
            rows[0][3 * group] += sign
            rows[1][3 * group + 1] += sign
            rows[0][3 * group + 2] += -sign * arm_y
            rows[1][3 * group + 2] += sign * arm_x
        (xa, ya), (xb, yb) = xs
        return (xa - xb, ya - yb), rows

    def _rows(self, s: NDArray[np.float64], k: int):
        """(x_a - x_b, its 2 x n Jacobian, the current normal) of point ``k``; the normal turns
        with body b (the face a bears on)."""
        frame = self._frame(s)
        gap, rows = self._point(frame, k)
        _, gb, normal = self.points[k][1:]
        if gb >= 0:
            _, _, c, sn = frame[gb]
            normal = np.array([c * normal[0] - sn * normal[1], sn * normal[0] + c * normal[1]])
        return np.array(gap), np.array(rows), normal

    def _key(self, s: NDArray[np.float64]) -> bytes:
        """What the constraints depend on that changes along a curve: the configuration and the
        hinges still active."""
        return s.tobytes() + self.active.tobytes()

    def constraints(self, s: NDArray[np.float64]):
        """(gap vector g, Jacobian C): x_a - x_b at every active point and its derivative (the
        last configuration's kept: the caller must not write into them)."""
        return _remembered(self._constraints_at, self._key(s), lambda: self._constraints(s))

    def _constraints(self, s: NDArray[np.float64]):
        frame = self._frame(s)
        gaps: list[float] = []
        rows: list[list[float]] = []
        for k in np.flatnonzero(self.active).tolist():
            gap, jac = self._point(frame, k)
            gaps += gap
            rows += jac
        for k in range(len(self.slides)):
            v, J = self._slide_row(s, k)
            gaps.append(v)
            rows.append(J.tolist())
        if not rows:
            return np.zeros(0), np.zeros((0, self.n_dof))
        return np.array(gaps), np.array(rows)

    def normal_gaps(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """(x_a - x_b) . n at every point (> 0: open), m."""
        out = np.empty(len(self.points))
        for k in range(len(self.points)):
            gap, _, normal = self._rows(s, k)
            out[k] = gap @ normal
        return out

    def _null_space(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        """Orthonormal basis of the compatible velocities, in (vx, vy, omega x size) (the last
        configuration's kept: the caller must not write into it)."""
        return _remembered(self._null_space_at, self._key(s), lambda: self._basis(s))

    def _basis(self, s: NDArray[np.float64]) -> NDArray[np.float64]:
        _, C = self.constraints(s)
        if C.shape[0] == 0:
            return np.eye(self.n_dof)
        _, sv, vt = np.linalg.svd(C / self.scale, full_matrices=True)
        rank = int(np.sum(sv > 1e-9 * max(sv.max(), 1.0))) if sv.size else 0
        return vt[rank:].T

    def release(self, s: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """When the hinges kept lock the mechanism (they are compatible at rest only to first
        order), let them open: a hinge is unilateral. The velocity that keeps every active hinge
        from slipping and from closing (its opening rate >= 0) and minimises alpha (the virtual
        work ratio, by HiGHS); the hinges it opens are released. None when there is none."""
        from scipy.optimize import linprog

        d = DIRECTIONS[self.direction]
        eq, ub = [], []
        index = np.flatnonzero(self.active)
        rows = [self._rows(s, int(k)) for k in index]
        for _, J, n in rows:
            t = np.array([-n[1], n[0]])
            eq.append(t @ J)
            ub.append(-(n @ J))
        eq += [J for _, J in (self._slide_row(s, k) for k in range(len(self.slides)))]
        g = self.model.g
        pushed = np.zeros(self.n_dof)
        pushed[0::3] = d * g * self.group_mass
        c = np.zeros(self.n_dof)
        c[1::3] = g * self.group_mass
        for load in self.model.loads:
            group = self.group_of.get(int(load.block), -1)
            if group < 0:
                continue
            _, arm = self.place(s, group, np.asarray(load.point_m, dtype=float))
            fx, fy = load.force_N
            c[3 * group] -= fx
            c[3 * group + 1] -= fy
            c[3 * group + 2] -= -fx * arm[1] + fy * arm[0]
        A_eq = np.vstack([*eq, pushed]) if eq else pushed[None, :]
        b_eq = np.zeros(A_eq.shape[0])
        b_eq[-1] = 1.0
        A_ub = np.vstack(ub) if ub else None
        b_ub = np.zeros(len(ub)) if ub else None
        res = linprog(c, A_ub=A_ub, b_ub=b_ub, A_eq=A_eq, b_eq=b_eq, bounds=(None, None), method="highs")
        if res.status != 0:
            return None
        q = res.x
        speed = max(float(np.max(np.abs(q * self.scale))), 1e-300)
        for k, (_, J, n) in zip(index, rows, strict=True):
            if n @ J @ q > 1e-7 * speed:
                self.active[k] = False
                self.ever_opened.add(int(k))
        return q

    def velocity(self, s: NDArray[np.float64], previous: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The compatible velocity nearest ``previous`` (unit norm), None when the joints lock."""
        basis = self._null_space(s)
        if basis.shape[1] == 0:
            target = self.release(s)
            if target is None:
                return None
            basis = self._null_space(s)
            if basis.shape[1] == 0:
                return None
            previous = target
        q = (basis @ (basis.T @ (previous * self.scale))) / self.scale
        norm = np.linalg.norm(q)
        if norm < 1e-12 * max(float(np.linalg.norm(previous)), 1e-300):
            return None
        return q / norm

    def project(self, s: NDArray[np.float64], iterations: int = 4) -> tuple[NDArray[np.float64], float]:
        """``s`` moved back onto the active hinges (least-norm Gauss-Newton); and the gap left, m."""
        for _ in range(iterations):
            g, C = self.constraints(s)
            if g.size == 0 or np.max(np.abs(g)) < 1e-13 * self.model.size_m:
                break
            s = s - np.linalg.lstsq(C, g, rcond=None)[0]
        g, _ = self.constraints(s)
        return s, float(np.max(np.abs(g))) if g.size else 0.0

    def released_overlap(self, s: NDArray[np.float64]) -> float:
        """How far the points of released hinges have passed into each other (0 if none), m."""
        if self.active.all():
            return 0.0
        gaps = self.normal_gaps(s)[~self.active]
        return float(max(0.0, -gaps.min()))


def _watched_pairs(model: RigidBlockModel, kin: _Kinematics) -> list[tuple[int, int, NDArray[np.float64]]]:
    """(moving block, fixed block, the fixed block's edge normals) of the pairs that do not touch at
    rest and lie within a quarter of the assembly's size of each other: where a gap can close
    (module docstring)."""
    touching = {frozenset((itf.a, itf.b)) for itf in model.interfaces}
    touching |= {frozenset((c.a, c.b)) for c in model.corners}
    fixed = [j for j in range(model.n_blocks) if model.fixed[j]]
    if not fixed:
        return []
    moving = sorted(kin.group_of)
    bodies = moving + fixed
    polys = [model.polygons_m[b] for b in bodies]
    out = []
    for i, j in candidate_pairs(polys, margin=0.25 * model.size_m):
        a, b = bodies[i], bodies[j]
        if model.fixed[a] == model.fixed[b] or frozenset((a, b)) in touching:
            continue
        moved, still = (a, b) if not model.fixed[a] else (b, a)
        out.append((moved, still, edge_normals(model.polygons_m[still])))
    return out


def _closed(model: RigidBlockModel, kin: _Kinematics, s, pairs) -> tuple[int, int] | None:
    """The first watched pair whose blocks overlap in configuration ``s``, else None."""
    tol = 1e-9 * model.size_m
    for a, b, normals_b in pairs:
        moved = kin.place_polygon(s, kin.group_of[a], model.polygons_m[a])
        if penetration_depth(moved, model.polygons_m[b], (edge_normals(moved), normals_b)) > tol:
            return a, b
    return None


def _alpha(model: RigidBlockModel, kin: _Kinematics, s, q, direction: str) -> float:
    """alpha by virtual work in configuration ``s`` with velocity ``q`` (module docstring).

    A group's reference point is its centre of mass, so the work of its weight and of its
    horizontal load are those of its mass M_g moving with the reference point's velocity.
    """
    d = DIRECTIONS[direction]
    lifted = model.g * float(np.dot(kin.group_mass, q[1::3]))
    pushed = d * model.g * float(np.dot(kin.group_mass, q[0::3]))
    loads = 0.0
    for load in model.loads:
        group = kin.group_of.get(int(load.block), -1)
        if group >= 0:
            v = kin.point_velocity(s, q, group, np.asarray(load.point_m, dtype=float))
            loads += float(np.dot(load.force_N, v))
    return (lifted - loads) / pushed if pushed > 0.0 else math.nan


def capacity_curve(model: RigidBlockModel, mechanism: Mechanism, direction: str, control_block: int) -> CapacityCurve:
    """Follow ``mechanism`` from rest until alpha = 0 (module docstring).

    Parameters
    ----------
    model, mechanism
        The rigid-block model and a mechanism of it without sliding joints.
    direction
        "+x" or "-x", the load's sense (dk is measured along it).
    control_block
        Index of the block whose centroid is the control point k.
    """
    kin = _Kinematics(model, mechanism, direction)
    d = DIRECTIONS[direction]
    group_k = kin.group_of[control_block]
    c_k = model.centroids_m[control_block]
    s = np.zeros(kin.n_dof)
    q0 = kin.initial_velocity(mechanism.velocities)
    dks, alphas = [0.0], []
    q = kin.velocity(s, q0)
    if q is None:
        return CapacityCurve(np.array([0.0]), np.array([np.nan]), None, "the joints lock the mechanism", 0.0)

    def field(state, previous):
        v = kin.velocity(state, previous)
        if v is None:
            return None
        rate = d * kin.point_velocity(state, v, group_k, c_k)[0]
        return None if rate <= 0 else v / rate  # per unit of dk

    q = field(s, q)
    if q is None:
        return CapacityCurve(
            np.array([0.0]), np.array([np.nan]), None, "the control point does not move along the load", 0.0
        )
    alpha0 = _alpha(model, kin, s, q, direction)
    alphas.append(alpha0)
    omega_max = max(float(np.max(np.abs(q[2::3]))), 1e-12)
    h = MAX_STEP_ROTATION_RAD / omega_max
    gap = overlap = 0.0
    stopped = None
    closed_dk = None
    watched = _watched_pairs(model, kin)
    while len(dks) < MAX_STEPS:
        q1 = field(s, q)
        if q1 is None:
            stopped = "the joints lock the mechanism or the control point turns back"
            break
        q2 = field(s + 0.5 * h * q1, q1)
        if q2 is None:
            stopped = "the joints lock the mechanism or the control point turns back"
            break
        trial, trial_gap = kin.project(s + h * q2)
        q_new = field(trial, q2)
        if q_new is None:
            stopped = "the joints lock the mechanism or the control point turns back"
            break
        a_new = _alpha(model, kin, trial, q_new, direction)
        if not math.isfinite(a_new):
            stopped = "the load lambda m g no longer does work on the mechanism"
            break
        if abs(a_new - alphas[-1]) > MAX_STEP_ALPHA * abs(alpha0) and h > 1e-9 * model.size_m:
            h *= 0.5
            continue
        met = _closed(model, kin, trial, watched)
        if met is not None and h > 1e-6 * model.size_m:
            h *= 0.5  # find where the gap closes
            continue
        if met is not None:
            a, b = (model.names[x] for x in met)
            dk_met = d * float(kin.place(trial, group_k, c_k)[0][0] - c_k[0])
            closed_dk = 0.5 * (dks[-1] + dk_met)
            stopped = (
                f"{a} meets {b} between dk = {dks[-1]:.4g} and {dk_met:.4g} m (alpha = {alphas[-1]:.4g}): a gap "
                "closes and a new contact forms, which this mechanism does not follow (the capacity beyond is "
                "another mechanism's: a limit analysis with the gap closed)"
            )
            break
        s, q, gap = trial, q_new, max(gap, trial_gap)
        overlap = max(overlap, kin.released_overlap(s))
        dks.append(d * float(kin.place(s, group_k, c_k)[0][0] - c_k[0]))
        alphas.append(a_new)
        if a_new <= 0.0:
            break
        rot = MAX_STEP_ROTATION_RAD / max(float(np.max(np.abs(q[2::3]))), 1e-12)
        h = min(2.0 * h, rot)
    else:
        stopped = f"alpha did not reach 0 in {MAX_STEPS} steps"
    dk_arr, a_arr = np.array(dks), np.array(alphas)
    d0 = None
    if stopped is None and a_arr[-1] <= 0.0:
        a1, a2 = a_arr[-2], a_arr[-1]
        d1, d2 = dk_arr[-2], dk_arr[-1]
        d0 = float(d1 + (d2 - d1) * a1 / (a1 - a2)) if a1 != a2 else float(d2)
    opened = tuple(kin.hinge_of[k] for k in sorted(kin.ever_opened))
    return CapacityCurve(dk_arr, a_arr, d0, stopped, gap, opened, overlap, closed_dk)
