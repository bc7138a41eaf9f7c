"""Run a rockyade scene in Siconos and write its time history (executed by Debian's Python).

Usage::

    python3 driver.py --serve FD              # how rockyade runs it: many scenes
    python3 driver.py SCENE.json RESULT.npz   # one scene

``--serve FD``: a Siconos worker (:mod:`rockyade.io.warm_program` starts it) running the loop
every driver shares (:mod:`rockyade.io.driver_loop`, loaded by its path: this Python cannot
import rockyade): one scene after the other, the samples so far written every ``flush_s``
seconds (``complete: false``) so that a worker killed from outside leaves them. The output
is that module's one dialect (:func:`rockyade.io.driver_loop.output_meta`) with Siconos's
own diagnostics.

Runs inside Debian's /usr/bin/python3 and imports only the standard library, numpy,
Siconos (``python3-siconos``) and, from its own folder, :mod:`rockyade.siconos.moreau_jean`
(which takes scipy's sparse matrices to Siconos). The scene is data prepared by rockyade
(``rockyade.siconos.payload``): the blocks' contact polygons (the DEMs' own: base corners at
the equivalent base b_eq), masses and inertias (I_O = M g R / p^2), the ground acceleration
samples, the loads, the time step and ``integrator``, which chooses the engine:

* contacts are rockyade's own vertex-to-edge pairs (``contact_pairs``: the reference DEM's),
  found once from the starting geometry; a corner lifted at the start pairs with the seat it
  will land on (``pair_reach_fraction``); of two pairs at coinciding corners only one is
  active at a time (``twins``: their rows are equal);
* ``numerics`` (the default, :class:`NumericsEngine`): every vertex of a moving block is also
  paired with the ground (a block that starts above it, or falls, lands); Moreau-Jean's
  one-step problem is assembled with numpy and solved by Siconos's numerics
  (:mod:`rockyade.siconos.moreau_jean`: Lemke for a few contacts, Gauss-Seidel warm-started
  for many, the proximal point method where they stop above the tolerance); the base force
  theta-weighted between each step's ends;
* ``kernel`` (:class:`KernelEngine`, the path before): each moving block a
  ``RigidBody2dDS``, each pair a ``LagrangianLinearTIR`` whose C and e are set before every
  step (``Contacts``) with ``NewtonImpactFrictionNSL(e, 0, mu, 3)``, ``MoreauJeanOSI(theta)``
  and ``TimeStepping``; the one-step problem ``FrictionContact(3)`` by the nonsmooth Newton,
  a step it fails taken again by NSGS, then ADMM (``Stepper``); the base force at the middle
  of each step, set with ``setFExtPtr``;
* either way the ground motion enters in the base frame as an inertial force -m a_g(t) on
  every moving block (exact for a rigid base: the base frame translates without rotating),
  with the vertical -m (g + a_v(t)); a point load is a constant force at its point of the
  block, its torque cos(phi) M0 - sin(phi) Q at world angle phi; a step no solver can take, or
  that leaves a body non-finite or running away, ends the run ``failed`` with the reason and
  the samples so far;
* every ``steps_per_sample`` steps the state is recorded (:class:`Recorder`) with, per vertex,
  the normal force (reaction impulse / dt) and whether the contact slips (|tangential| >=
  SLIP_RATIO x mu x normal); per step the solver's iterations and residual are counted (a
  step left above the tolerance is "unconverged"); at every sample the deepest penetration
  of a vertex below the ground: beyond ``max_penetration_m`` the run fails (the block went
  through the ground).

Same role as :mod:`rockyade.yade.driver`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

import json
import math
import os
import runpy
import sys
import time
import traceback
import types

import numpy as np

SCENE_FORMAT = "rockyade-siconos-scene-1"
#: The friction-contact solvers by name (of Siconos's 3-D problem: a 2-D contact is a 3-D one
#: whose second tangent sees only a small fictitious arm on the rotation, TWIST_ARM):
#: Alart-Curnier nonsmooth Newton (a few iterations on a stack, measured) and Gauss-Seidel
#: (thousands of iterations on a stack: two contacts per joint make it hyperstatic).
SOLVERS = {
    "nsn": "SICONOS_FRICTION_3D_NSN_AC",
    "nsgs": "SICONOS_FRICTION_3D_NSGS",
    "admm": "SICONOS_FRICTION_3D_ADMM",
}
#: The second tangent's arm on the rotation, m (it keeps the local 3x3 problem regular; its
#: friction torque is at most TWIST_ARM x mu x N).
TWIST_ARM = 1e-4
#: A contact's gap is read this much smaller, m, so that a contact closed at the start
#: (gap 0 up to rounding) is active from the first step.
GAP_OFFSET_M = 1e-8
#: A pair whose vertex has left its edge (by this fraction of the edge's length) is open.
EDGE_SLACK = 1e-3
#: A pair whose vertex lies deeper behind the edge than this fraction of the smaller block's
#: smallest dimension is open (the vertex crossed the edge's line elsewhere).
DEEP_FRACTION = 0.25
#: Up to this many pairs the contact geometry is computed pair by pair in Python floats,
#: beyond it with numpy over all pairs at once (numpy's per-call overhead: measured).
SCALAR_PAIRS = 12
#: A vertex pairs with another block's edge only when its block lies on the edge's outer
#: side: neither of the vertex's own edges dips into the inner side by more than this cosine
#: (30 deg: a block tilted at the start, its lifted corner still over the seat it will land
#: on; a block beside another, whose corner touches the other's bottom edge's end, dips 90 deg).
SIDE_COS = 0.5
#: Two pairs of the same two bodies are twins when their vertices start this close, as a
#: fraction of the smallest block dimension (coinciding corners).
TWIN_FRACTION = 1e-6
#: Beyond these the state is a numerical blow-up, not rocking (as in the DEMs).
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0
#: The nonsmooth Newton's iteration cap when a fallback solver follows it (it converges in a
#: few iterations or not at all: on redundant contacts each iteration's LU factorisation fails).
NSN_MAX_ITER = 100
#: A step whose residual is above the tolerance but within this factor of it is accepted
#: (counted as ``loose_steps``) rather than taken again with the next solver.
ACCEPT_FACTOR = 100.0
#: A fallback solver that took a step the first solver failed is kept for 1 step, then
#: HOLD_GROWTH times longer at each new failure of the first solver (a scene whose contacts
#: are redundant fails it every time, and each failure costs up to solver_max_iter iterations).
HOLD_GROWTH = 8
#: A contact slips when |tangential| >= SLIP_RATIO x mu x normal.
SLIP_RATIO = 0.999


#: The loop and output writing every driver shares (``rockyade/io/driver_loop.py``, run from its
#: path: this Python cannot import rockyade).
LOOP = types.SimpleNamespace(
    **runpy.run_path(
        os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "io", "driver_loop.py"),
        run_name="driver_loop",
    )
)


def _siconos():
    """Siconos's modules (imported on first use: the worker says it is ready only once they load)."""
    import siconos
    import siconos.kernel as sk
    import siconos.numerics as sn
    from siconos.mechanics.collision import RigidBody2dDS

    return {
        "version": getattr(siconos, "__version__", None) or _version(),
        "sk": sk,
        "sn": sn,
        "RigidBody2dDS": RigidBody2dDS,
    }


def _version():
    try:
        from importlib.metadata import version

        return version("siconos")
    except Exception:
        return "unknown"


def _world(vertices, centroid, angle):
    c, s = math.cos(angle), math.sin(angle)
    return [[centroid[0] + c * x - s * y, centroid[1] + s * x + c * y] for x, y in vertices]


def _rot(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def contact_pairs(scene, ground_all=False):
    """The vertex-to-edge contact pairs of a scene, found once from the starting geometry.

    Returns a list of dicts: ``a`` (the body of the vertex), ``v`` (its index), ``b`` (the
    body of the edge, -1 for the ground), and for a block's edge its start point ``e0``,
    unit direction ``t`` and outward normal ``n`` in that block's frame and its length ``L``;
    ``mu`` the pair's friction coefficient. A vertex of a moving block pairs with the ground
    when it starts below ``ground_pair_fraction`` of its block's height, or always with
    ``ground_all`` (the numerics path: a block that starts above the ground, or a voussoir
    that falls, lands on it; whether the pair is a contact is decided every step by its
    gap); a vertex pairs with another block's edge when it lies at most
    ``pair_gap_fraction`` of the smaller block's smallest dimension inside the edge's line
    and at most ``pair_reach_fraction`` of the smaller block's largest dimension outside it
    (a corner lifted at the start, as a free-rocking block's, pairs with the seat it will land
    on), its foot within the edge up to ``pair_gap_fraction``, and its own block lies on the
    edge's outer side (neither of its edges dips into the inner side by more than SIDE_COS):
    the reference DEM's contacts.
    """
    bodies = scene["bodies"]
    mu = {}
    for f in scene["friction_pairs"]:
        mu[(int(f["a"]), int(f["b"]))] = float(f["mu"])
        mu[(int(f["b"]), int(f["a"]))] = float(f["mu"])
    local = [np.asarray(b["vertices_m"], dtype=float) for b in bodies]
    size = [float(np.min(np.ptp(v, axis=0))) for v in local]
    span = [float(np.max(np.ptp(v, axis=0))) for v in local]
    world = [
        np.asarray(b["centroid0_m"], dtype=float) + local[i] @ _rot(b["angle0_rad"]).T for i, b in enumerate(bodies)
    ]
    centre = [w.mean(axis=0) for w in world]
    radius = [float(np.max(np.hypot(*(w - c).T))) for w, c in zip(world, centre, strict=True)]
    pairs = []
    for a, ba in enumerate(bodies):
        va = world[a]
        na = len(va)
        low = float(np.min(va[:, 1]))
        for k in range(na):
            low_enough = va[k, 1] - low <= scene["ground_pair_fraction"] * np.ptp(va[:, 1]) and low < size[a]
            if not ba["fixed"] and (ground_all or low_enough):
                pairs.append({"a": a, "v": k, "b": -1, "mu": mu[(a, -1)]})
        for b, bb in enumerate(bodies):
            if b == a or (ba["fixed"] and bb["fixed"]) or (a, b) not in mu:
                continue
            tol = scene["pair_gap_fraction"] * min(size[a], size[b])
            reach = max(tol, scene.get("pair_reach_fraction", 0.0) * min(span[a], span[b]))
            if float(np.hypot(*(centre[a] - centre[b]))) > radius[a] + radius[b] + reach:
                continue  # too far apart for any pair
            vb = world[b]
            nv = len(vb)
            rb = _rot(-bb["angle0_rad"])
            for e in range(nv):
                p0, p1 = vb[e], vb[(e + 1) % nv]
                length = float(np.hypot(*(p1 - p0)))
                t = (p1 - p0) / length
                n = np.array([t[1], -t[0]])  # outward: vertices are counter-clockwise
                for k in range(na):
                    p = va[k]
                    g, sp = float((p - p0) @ n), float((p - p0) @ t)
                    if not (-tol <= g <= reach and -tol <= sp <= length + tol):
                        continue
                    side = [va[k - 1] - p, va[(k + 1) % na] - p]
                    if any(float(d @ n) < -SIDE_COS * float(np.hypot(*d)) - 1e-9 * length for d in side):
                        continue
                    pairs.append(
                        {
                            "a": a,
                            "v": k,
                            "b": b,
                            "e0": rb @ (p0 - np.asarray(bb["centroid0_m"], dtype=float)),
                            "t": rb @ t,
                            "n": rb @ n,
                            "L": length,
                            "mu": mu[(a, b)],
                        }
                    )
    return pairs


class Contacts:
    """The contact pairs as Siconos interactions: each a ``LagrangianLinearTIR`` y = C q + e,
    (normal gap, tangential, twist) with C and e set before each step from the bodies'
    positions (the gap and its Jacobian at the step's start: the linearised vertex-to-edge
    distance, exact to first order), and ``NewtonImpactFrictionNSL(e, 0, mu, 3)``.

    The geometry of all pairs is computed at once with numpy (``update``); only the copy into
    each interaction's C and e is a loop. A pair is open (y far positive) when its vertex has
    left its edge by EDGE_SLACK of the edge's length, when it lies deeper than
    DEEP_FRACTION of the smaller block's smallest dimension behind the edge (a vertex that
    crossed the edge's line elsewhere, as voussoirs tumble: not this contact), and when it
    is the twin of an earlier pair still on its edge: two blocks whose corners coincide
    (a head joint, the ends of a bed joint, the joints of an arch) give two pairs at one
    point with one normal, whose rows make the one-step problem singular; one is kept while
    it holds, the other takes over once the blocks slide apart.
    """

    def __init__(self, scene, sk, nsds, ds_of, pairs):
        self.pairs = pairs
        self.ds_of = ds_of
        bodies = scene["bodies"]
        nb = len(bodies)
        m = len(pairs)
        self.q = np.zeros((nb + 1, 3))  # the bodies' (x, y, theta); row nb: the ground
        for i, b in enumerate(bodies):
            self.q[i] = (b["centroid0_m"][0], b["centroid0_m"][1], b["angle0_rad"])
        self.moving_ids = [i for i, ds in enumerate(ds_of) if ds is not None]
        self.twin = twins(scene, pairs)
        # the pairs' geometry: the numerics path's (its gap, open rule and Jacobian rows)
        self.table = _sibling("pair_table").PairTable(bodies, pairs, self.twin, EDGE_SLACK, DEEP_FRACTION)
        movable = np.array([ds is not None for ds in ds_of] + [False])
        self.mov_a = movable[self.table.a].astype(float)
        self.mov_b = movable[self.table.b].astype(float)
        self.inside = np.zeros(m, dtype=bool)
        self.mova_list, self.movb_list = self.mov_a.tolist(), self.mov_b.tolist()
        self.inters, self.views, self.cols = [], [], []
        laws = {}
        for pair in pairs:
            a, b = pair["a"], pair["b"]
            moving = [x for x in (a, b) if x >= 0 and ds_of[x] is not None]
            nsl = laws.get(pair["mu"])
            if nsl is None:
                nsl = laws[pair["mu"]] = sk.NewtonImpactFrictionNSL(float(scene["restitution"]), 0.0, pair["mu"], 3)
            rel = sk.LagrangianLinearTIR(np.zeros((3, 3 * len(moving))), np.zeros(3))
            inter = sk.Interaction(nsl, rel)
            if len(moving) == 2:
                nsds.link(inter, ds_of[moving[0]], ds_of[moving[1]])
            else:
                nsds.link(inter, ds_of[moving[0]])
            self.inters.append(inter)
            self.views.append((rel.C(), rel.e()))
            # the columns of the (3, 6) Jacobian [body a | body b] this pair's C keeps
            self.cols.append(slice(0, 6) if len(moving) == 2 else slice(0, 3) if moving[0] == a else slice(3, 6))
        self.gaps = np.zeros(m)
        self.jac = np.zeros((m, 3, 6))
        self.off = np.zeros((m, 3))
        self.q_floats = [tuple(row) for row in self.q.tolist()]
        # the scalar path writes each pair's C row by row: (row, column of C, column of [a | b])
        self.col_lists = [list(range(6))[c] for c in self.cols]

    def read_state(self):
        """The moving bodies' (x, y, theta) from Siconos into ``self.q``."""
        q, ds_of = self.q, self.ds_of
        for i in self.moving_ids:
            q[i] = ds_of[i].q()

    def read_state_floats(self):
        """The bodies' (x, y, theta) as tuples of floats (the ground's and fixed bodies' kept
        from the start): the scalar path's state, without numpy's per-element cost."""
        qf, ds_of = self.q_floats, self.ds_of
        for i in self.moving_ids:
            x, y, phi = ds_of[i].q().tolist()
            qf[i] = (x, y, phi)
        return qf

    def geometry(self):
        """Gaps, open flags, Jacobians and offsets of every pair at ``self.q`` (numpy, all pairs:
        the pair table's geometry, with the twist row and the moving sides only)."""
        q, t = self.q, self.table
        gap, closed, H = t.geometry(q)
        J = self.jac
        ma, mb = self.mov_a[:, None, None], self.mov_b[:, None, None]
        J[:, :2, :3] = H[:, 0] * ma
        J[:, :2, 3:] = H[:, 1] * mb
        J[:, 2, 2] = TWIST_ARM * self.mov_a
        J[:, 2, 5] = -TWIST_ARM * self.mov_b
        cq = np.einsum("kij,kj->ki", J[:, :, :3], q[t.a]) + np.einsum("kij,kj->ki", J[:, :, 3:], q[t.b])
        self.off[:] = -cq
        self.off[:, 0] += np.where(closed, gap - GAP_OFFSET_M, 1.0)
        self.gaps[:] = np.where(closed, gap, math.inf)

    def geometry_scalar(self):
        """As :meth:`geometry` followed by the copy into C and e, pair by pair in plain Python
        floats: faster than numpy's per-call overhead for the few pairs of a block or a small
        stack (SCALAR_PAIRS). Writes each pair's C and e directly (not ``jac`` and ``off``)."""
        q, gaps, inside_flags = self.read_state_floats(), self.gaps, self.inside
        a_of, b_of, vloc, nl, e0, lo, hi, deep, twin_of = self.table.lists
        gap_list = [0.0] * len(self.pairs)
        for k in range(len(self.pairs)):
            a, b = a_of[k], b_of[k]
            xa, ya, pa = q[a]
            xb, yb, pb = q[b]
            ca, sa = math.cos(pa), math.sin(pa)
            vx, vy = vloc[k]
            rax, ray = ca * vx - sa * vy, sa * vx + ca * vy
            px, py = xa + rax, ya + ray
            cb, sb = math.cos(pb), math.sin(pb)
            n0, n1 = nl[k]
            nx, ny = cb * n0 - sb * n1, sb * n0 + cb * n1
            tx, ty = -ny, nx
            ex, ey = e0[k]
            dx, dy = px - (xb + cb * ex - sb * ey), py - (yb + sb * ex + cb * ey)
            gap = dx * nx + dy * ny
            sp = dx * tx + dy * ty
            inside = lo[k] <= sp <= hi[k] and gap >= deep[k]
            inside_flags[k] = inside
            twin = twin_of[k]
            closed = inside and not (twin >= 0 and inside_flags[twin])
            rbx, rby = px - xb, py - yb
            ma, mb = self.mova_list[k], self.movb_list[k]
            row0 = (nx * ma, ny * ma, (ny * rax - nx * ray) * ma, -nx * mb, -ny * mb, -(ny * rbx - nx * rby) * mb)
            row1 = (tx * ma, ty * ma, (ty * rax - tx * ray) * ma, -tx * mb, -ty * mb, -(ty * rbx - tx * rby) * mb)
            row2 = (0.0, 0.0, TWIST_ARM * ma, 0.0, 0.0, -TWIST_ARM * mb)
            C, e = self.views[k]
            cols = self.col_lists[k]
            for j, col in enumerate(cols):
                C[0, j] = row0[col]
                C[1, j] = row1[col]
                C[2, j] = row2[col]
            e[0] = (gap - GAP_OFFSET_M if closed else 1.0) - (
                row0[0] * xa + row0[1] * ya + row0[2] * pa + row0[3] * xb + row0[4] * yb + row0[5] * pb
            )
            e[1] = -(row1[0] * xa + row1[1] * ya + row1[2] * pa + row1[3] * xb + row1[4] * yb + row1[5] * pb)
            e[2] = -(row2[2] * pa + row2[5] * pb)
            gap_list[k] = gap if closed else math.inf
        gaps[:] = gap_list

    def update(self):
        """C and e of every pair at the bodies' current positions; the gaps (m) kept."""
        if len(self.pairs) <= SCALAR_PAIRS:
            self.geometry_scalar()
            return
        self.read_state()
        self.geometry()
        J, off = self.jac, self.off
        for k, (C, e) in enumerate(self.views):
            C[:] = J[k, :, self.cols[k]]
            e[:] = off[k]


def twins(scene, pairs):
    """For each pair, the index of an earlier pair at the same point of the same two bodies
    with the opposite normal (a vertex of each on the other's edge, the corners coinciding),
    else -1 (:class:`Contacts`)."""
    bodies = scene["bodies"]
    world = []
    for b in bodies:
        v = np.asarray(b["vertices_m"], dtype=float)
        world.append(np.asarray(b["centroid0_m"], dtype=float) + v @ _rot(b["angle0_rad"]).T)
    size = min(float(np.min(np.ptp(w, axis=0))) for w in world)
    tol = TWIN_FRACTION * size
    seen = {}
    out = np.full(len(pairs), -1, dtype=int)
    for k, p in enumerate(pairs):
        if p["b"] < 0:
            continue
        point = world[p["a"]][p["v"]]
        key = (min(p["a"], p["b"]), max(p["a"], p["b"]))
        for j, other in seen.get(key, []):
            if pairs[j]["a"] != p["a"] and float(np.hypot(*(other - point))) <= tol:
                out[k] = j
                break
        seen.setdefault(key, []).append((k, point))
    return out


def build(scene, S):
    """The Siconos simulation of a scene: returns a dict of what the stepping needs."""
    sk = S["sk"]
    t_end = scene["n_steps"] * scene["dt_s"]
    nsds = sk.NonSmoothDynamicalSystem(0.0, t_end)
    bodies = []
    for i, b in enumerate(scene["bodies"]):
        if b["fixed"]:
            bodies.append(None)
            continue
        x, y = b["centroid0_m"]
        vx, vy = b["vel0_m_s"]
        ds = S["RigidBody2dDS"](
            [float(x), float(y), float(b["angle0_rad"])],
            [float(vx), float(vy), float(b["angvel0_rad_s"])],
            float(b["mass_kg"]),
            float(b["inertia_kgm2"]),
        )
        ds.setNumber(i + 1)
        ds.setFExtPtr([0.0, -float(b["mass_kg"]) * scene["g"], 0.0])
        nsds.insertDynamicalSystem(ds)
        bodies.append(ds)
    contacts = Contacts(scene, sk, nsds, bodies, contact_pairs(scene))
    contacts.update()
    osi = sk.MoreauJeanOSI(float(scene["theta"]))
    timedisc = sk.TimeDiscretisation(0.0, float(scene["dt_s"]))
    stepper = Stepper(scene, S, contacts, bodies)
    problem = sk.FrictionContact(3, stepper.options(stepper.names[0]))
    problem.setKeepLambdaAndYState(True)
    sim = sk.TimeStepping(nsds, timedisc, osi, problem)
    sim.setNewtonMaxIteration(int(scene["newton_max_iter"]))
    sim.setNewtonTolerance(float(scene["newton_tol"]))
    stepper.attach(sim, problem)
    return {"sim": sim, "nsds": nsds, "bodies": bodies, "contacts": contacts, "problem": problem, "stepper": stepper}


class StepError(Exception):
    """A step no friction-contact solver could take (the run ends ``failed`` with this reason)."""


class Stepper:
    """One Moreau-Jean step, retried when the friction-contact solver fails.

    A step fails when Siconos raises, when the solver's residual stays above the tolerance,
    or when the state comes out non-finite or beyond MAX_SPEED_M_S / MAX_SPIN_RAD_S. A failed
    step is taken again from the state before it (positions, velocities and the contacts'
    impulses restored, their C and e recomputed) with each fallback solver in turn (``fallback_solvers``;
    NSGS: slow on a hyperstatic stack but unaffected by redundant contacts, on which the
    nonsmooth Newton's LU factorisation is singular). A fallback that succeeds is kept for
    1, 8, 64, ... steps (HOLD_GROWTH) before the first
    solver is tried again. A step every solver fails ends the run when it raised or left a
    non-finite or runaway state (StepError); a step that merely stayed above the
    tolerance is kept and counted (``unconverged_steps``), as before.
    """

    def __init__(self, scene, S, contacts, bodies):
        self.S, self.sk, self.sn = S, S["sk"], S["sn"]
        self.scene = scene
        self.contacts = contacts
        self.moving = [ds for ds in bodies if ds is not None]
        first = scene["friction_solver"]
        self.names = [first] + [f for f in scene.get("fallback_solvers", ["nsgs", "admm"]) if f != first]
        self.tol = float(scene["solver_tol"])
        self.active = 0
        self.back_at = 0
        self.hold = 1
        self.retries = 0  # steps taken again with a fallback solver
        self.retried_ok = 0  # ... of which a fallback converged
        self.fallback_steps = 0  # steps solved by a fallback solver
        self.loose = 0  # steps accepted between solver_tol and ACCEPT_FACTOR x solver_tol
        self.sim = self.problem = None

    def options(self, name):
        """Numerics options of solver ``name`` (SOLVERS) with the scene's tolerance and cap."""
        sn = self.sn
        so = self.sk.solver_options_create(getattr(sn, SOLVERS[name]))
        self._set(so, name)
        return so

    def _set(self, so, name):
        sn = self.sn
        cap = int(self.scene["solver_max_iter"])
        if name == "nsn" and len(self.names) > 1:
            cap = min(cap, NSN_MAX_ITER)
        so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = cap
        so.dparam[sn.SICONOS_DPARAM_TOL] = self.tol

    def attach(self, sim, problem):
        self.sim, self.problem = sim, problem
        self.so = problem.numericsSolverOptions()

    def _use(self, index):
        if index != self.active:
            self.problem.setSolverId(getattr(self.sn, SOLVERS[self.names[index]]))
            self.so = self.problem.numericsSolverOptions()
            self._set(self.so, self.names[index])
            self.active = index

    def _attempt(self):
        """computeOneStep; (ok, why) with why None, "unconverged" or a fatal reason."""
        sn = self.sn
        so = self.so
        so.iparam[sn.SICONOS_IPARAM_ITER_DONE] = 0
        so.dparam[sn.SICONOS_DPARAM_RESIDU] = 0.0
        try:
            self.sim.computeOneStep()
        except Exception as exc:  # Siconos raises std::exception when its solver fails
            return False, f"Siconos raised {type(exc).__name__}: {exc} ({self.names[self.active]})"
        for ds in self.moving:
            q, v = ds.q(), ds.velocity()
            vx, vy, w = float(v[0]), float(v[1]), float(v[2])
            if not math.isfinite(float(q[0]) + float(q[1]) + float(q[2]) + vx + vy + w):
                return False, "non-finite state"
            if math.hypot(vx, vy) > MAX_SPEED_M_S or abs(w) > MAX_SPIN_RAD_S:
                return False, "runaway speed"
        if self.problem.getSizeOutput() > 0:
            res = float(so.dparam[sn.SICONOS_DPARAM_RESIDU])
            if not (res <= self.tol):
                if res <= ACCEPT_FACTOR * self.tol:
                    return True, "loose"
                return False, "unconverged"
        return True, None

    def step(self, index):
        """Take step ``index`` (0-based); returns True when the friction-contact problem had
        contacts. Raises StepError when no solver could take it."""
        first = 0 if index >= self.back_at else self.active
        order = [first] + [k for k in range(len(self.names)) if k != first]
        saved = (
            [(ds, ds.q().tolist(), ds.velocity().tolist()) for ds in self.moving],
            [inter.lambda_(1).tolist() for inter in self.contacts.inters],
        )
        finite = None  # the first solver whose step stayed finite, unconverged
        why = None
        for n, k in enumerate(order):
            if n:
                self._restore(saved)
            self._use(k)
            ok, why = self._attempt()
            if ok:
                if n:
                    self.retried_ok += 1
                    if first == 0:
                        self.back_at = index + 1 + self.hold
                        self.hold *= HOLD_GROWTH
                if why == "loose":
                    self.loose += 1
                break
            if n == 0:
                self.retries += 1
            if why == "unconverged" and finite is None:
                finite = k
        else:
            if finite is None:
                names = ", ".join(self.names[k] for k in order)
                t = (index + 1) * self.scene["dt_s"]
                raise StepError(f"no friction-contact solver could take the step to t = {t:.6g} s ({names}: {why})")
            if finite != order[-1] or why != "unconverged":
                self._restore(saved)
                self._use(finite)
                self._attempt()
        if self.active != 0:
            self.fallback_steps += 1
        return self.problem.getSizeOutput() > 0

    def _restore(self, saved):
        """The positions, velocities and contact impulses before the step (the impulses start
        the next solver: a failed Newton leaves them non-finite), and the contacts' C and e."""
        states, impulses = saved
        for ds, q, v in states:
            ds.setQ(q)
            ds.setVelocity(v)
        for inter, lam in zip(self.contacts.inters, impulses, strict=True):
            inter.lambda_(1)[:] = lam
        self.contacts.update()


class Recorder:
    """The samples of a run, its diagnostics and its output file (module docstring).

    It reads the state and the contacts' impulses from the run's engine (:class:`KernelEngine`
    or :class:`NumericsEngine`): ``state()`` gives the bodies' (x, y, theta) and velocities,
    ``contact_impulses()`` each loaded pair's impulses and gap, ``solve_report()`` the last
    step's iterations, residual and whether it converged.
    """

    def __init__(self, scene, engine, S, out_path):
        self.scene, self.engine, self.S, self.out_path = scene, engine, S, out_path
        nb = len(scene["bodies"])
        self.nb = nb
        self.ns = scene["n_samples"]
        self.maxv = max(len(b["vertices_m"]) for b in scene["bodies"])
        self.pos = np.zeros((self.ns, nb, 2))
        self.ang = np.zeros((self.ns, nb))
        self.angvel = np.zeros((self.ns, nb))
        self.vpoint = np.zeros((self.ns, nb, 2))
        self.fn = np.zeros((self.ns, nb, self.maxv))
        self.state = np.zeros((self.ns, nb, self.maxv), dtype=np.int8)
        self.ncont = np.zeros((self.ns, nb), dtype=np.int32)
        self.slip = np.zeros((self.ns, nb), dtype=bool)
        self.verts = [np.asarray(b["vertices_m"], dtype=float) for b in scene["bodies"]]
        self.k = 0
        self.status, self.stop_time, self.stop_body = "completed", None, None
        self.failure_reason = None
        self.overturn_times = {}
        self.max_penetration = 0.0  # of a vertex below the ground, m (geometric)
        self.penetration_bound = scene.get("max_penetration_m")  # beyond it the run fails, m
        self.max_overlap = 0.0  # the deepest vertex-to-edge overlap of a loaded pair, m
        self.iterations = 0
        self.solver_calls = 0
        self.unconverged = 0
        self.max_residual = 0.0
        self.first_unconverged_s = None
        self.start = time.perf_counter()
        self.flushes = 0
        self.steps = 0

    def record(self, t):
        """Record sample ``k`` at time ``t``; False when the run must stop."""
        k = self.k
        if k >= self.ns:
            return False
        q, v = self.engine.state()
        deepest = None
        for i, b in enumerate(self.scene["bodies"]):
            if b["fixed"]:
                self.pos[k, i] = b["centroid0_m"]
                self.ang[k, i] = b["angle0_rad"]
                continue
            x, y, phi = (float(c) for c in q[i])
            vx, vy, w = (float(c) for c in v[i])
            if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(phi) and math.isfinite(w)):
                return self._fail(t, i, "non-finite state")
            if math.hypot(vx, vy) > MAX_SPEED_M_S or abs(w) > MAX_SPIN_RAD_S:
                return self._fail(t, i, "runaway speed")
            self.pos[k, i] = (x, y)
            self.ang[k, i] = phi
            self.angvel[k, i] = w
            px, py = b["accel_point_m"]
            c, s = math.cos(phi), math.sin(phi)
            rx, ry = c * px - s * py, s * px + c * py
            self.vpoint[k, i] = (vx - w * ry, vy + w * rx)
            low = min(y + s * vxb + c * vyb for vxb, vyb in self.verts[i])
            if -low > self.max_penetration:
                self.max_penetration = -low
                deepest = i
            stop = b["stop_angle_rad"]
            if stop is not None and abs(phi - b["rest_angle_rad"]) >= stop and i not in self.overturn_times:
                self.overturn_times[i] = t
                if self.scene["stop_on_overturn"] and self.status == "completed":
                    self.status, self.stop_time, self.stop_body = "overturned", t, i
        self._contacts(k)
        self.k = k + 1
        bound = self.penetration_bound
        if deepest is not None and bound is not None and self.max_penetration > bound:
            self._fail(
                t,
                deepest,
                f"a vertex {self.max_penetration:.3g} m below the ground, beyond the bound of {bound:.3g} m "
                "(the block went through the ground)",
            )
        return self.status == "completed"

    def _fail(self, t, i, why):
        self.status, self.stop_time, self.stop_body = "failed", t, i
        self.failure_reason = f"{why} of body {i} at t = {t:.6g} s"
        return False

    def _contacts(self, k):
        """Normal force and state per vertex, contact points and slip per block (module docstring)."""
        dt = self.scene["dt_s"]
        points = {}
        for pair, lam_n, lam_t, gap in self.engine.contact_impulses():
            rn = lam_n / dt
            if rn <= 0.0:
                continue
            if -gap > self.max_overlap:
                self.max_overlap = -gap
            body, v, other = pair["a"], pair["v"], pair["b"]
            slips = abs(lam_t) >= SLIP_RATIO * pair["mu"] * lam_n
            self.fn[k, body, v] += rn
            if slips:
                self.state[k, body, v] = 2
            elif self.state[k, body, v] == 0:
                self.state[k, body, v] = 1
            key = (body, other) if other < 0 or body < other else (other, body)
            points.setdefault(key, set()).add((body, v))
            if slips:
                self.slip[k, body] = True
                if other >= 0:
                    self.slip[k, other] = True
        for (a, b), touching in points.items():
            if b < 0:
                self.ncont[k, a] += len(touching)
            else:
                n = min(2, len(touching))
                self.ncont[k, a] += n
                self.ncont[k, b] += n

    def step_diagnostics(self, t, had_contacts):
        """The numerics solver's iterations and residual after a step (when it ran)."""
        if not had_contacts:
            return
        it, res, converged = self.engine.solve_report()
        self.solver_calls += 1
        self.iterations += it
        if res > self.max_residual:
            self.max_residual = res
        if not converged:
            self.unconverged += 1
            if self.first_unconverged_s is None:
                self.first_unconverged_s = t

    def write(self, complete):
        n = self.k
        stepper = self.engine.diagnostics()
        meta = LOOP.output_meta(
            self,
            complete,
            steps=self.steps,
            version=self.S["version"],
            dt_s=self.scene["dt_s"],
            solver_calls=self.solver_calls,
            solver_iterations=self.iterations,
            unconverged_steps=self.unconverged,
            first_unconverged_s=self.first_unconverged_s,
            max_residual=self.max_residual,
            failure_reason=self.failure_reason,
            retried_steps=stepper["retried_steps"],
            retried_steps_converged=stepper["retried_steps_converged"],
            fallback_steps=stepper["fallback_steps"],
            loose_steps=stepper["loose_steps"],
            friction_solvers=stepper["friction_solvers"],
            integrator=self.scene.get("integrator", "kernel"),
            one_step_problem=stepper["one_step_problem"],
            penetration_bound_m=self.penetration_bound,
            max_penetration_m=self.max_penetration,
            max_bullet_overlap_m=self.max_overlap,
        )
        arrays = {
            "pos": self.pos[:n],
            "ang": self.ang[:n],
            "angvel": self.angvel[:n],
            "vpoint": self.vpoint[:n],
            "fn": self.fn[:n],
            "state": self.state[:n],
            "ncont": self.ncont[:n],
            "slip": self.slip[:n],
        }
        LOOP.write_output(self.out_path, np.savez, arrays, meta)


#: Steps whose base forces are computed at a time (base_force_steps).
FORCE_CHUNK = 4096


def base_forces(scene, start=0, stop=None, offset=0.5):
    """(stop - start, 2) the inertial force per unit mass at ``offset`` of steps ``start`` to
    ``stop`` (default: the last; offset 0.5: their middle, 0: their start), m/s^2:
    (-a_h, -(g + a_v)), the samples linear between, zero outside the record."""
    dt, g = scene["dt_s"], scene["g"]
    stop = scene["n_steps"] if stop is None else stop
    t = (np.arange(start, stop) + offset) * dt
    n = len(t)
    out = np.zeros((n, 2))
    out[:, 1] = -g
    motion = scene["motion"]
    if motion is not None:
        ts = np.asarray(motion["t_s"], dtype=float)
        out[:, 0] -= np.interp(t, ts, np.asarray(motion["ah_m_s2"], dtype=float), left=0.0, right=0.0)
        out[:, 1] -= np.interp(t, ts, np.asarray(motion["av_m_s2"], dtype=float), left=0.0, right=0.0)
    return out


def base_force_steps(scene):
    """The base forces step by step as (a_x, a_y) float pairs, m/s^2, computed FORCE_CHUNK steps
    at a time (a long run's whole array as Python floats would take gigabytes)."""
    for start in range(0, scene["n_steps"], FORCE_CHUNK):
        yield from base_forces(scene, start, min(start + FORCE_CHUNK, scene["n_steps"])).tolist()


class StepForces:
    """The base's force per unit mass at the start and the end of each step, m/s^2
    (:func:`base_forces` at the steps' boundaries, FORCE_CHUNK steps at a time): ``self(k)``
    gives ((a_x, a_y) at t_k, (a_x, a_y) at t_k+1), steps taken in order."""

    def __init__(self, scene):
        self.scene = scene
        self.start = 0
        self.values = base_forces(scene, 0, min(FORCE_CHUNK, scene["n_steps"]) + 1, offset=0.0).tolist()

    def __call__(self, k):
        i = k - self.start
        if i + 1 >= len(self.values):
            self.start = k
            stop = min(k + FORCE_CHUNK, self.scene["n_steps"]) + 1
            self.values = base_forces(self.scene, k, stop, offset=0.0).tolist()
            i = 0
        return self.values[i], self.values[i + 1]


class KernelEngine:
    """The scene in Siconos's kernel (``integrator = "kernel"``, the path before the numerics
    one): one ``RigidBody2dDS`` per moving block, one interaction per pair, ``TimeStepping``
    with ``MoreauJeanOSI`` and ``FrictionContact(3)`` (:func:`build`, :class:`Stepper`). The
    base force is set at the middle of each step with ``setFExtPtr``."""

    def __init__(self, scene, S):
        self.scene = scene
        self.built = build(scene, S)
        self.sn = S["sn"]
        self.moving = [
            (ds, float(scene["bodies"][i]["mass_kg"]), scene["bodies"][i].get("load"))
            for i, ds in enumerate(self.built["bodies"])
            if ds is not None
        ]
        self.forces = base_force_steps(scene)
        self.stepper = self.built["stepper"]
        self.contacts = self.built["contacts"]
        nb = len(scene["bodies"])
        self.q0 = np.array([[*b["centroid0_m"], b["angle0_rad"]] for b in scene["bodies"]]).reshape(nb, 3)

    def step(self, index):
        """Take step ``index``; True when it had contacts (StepError when none could take it)."""
        ax, ay = next(self.forces)
        for ds, m, load in self.moving:
            if load is None:
                ds.setFExtPtr([m * ax, m * ay, 0.0])
            else:
                phi = float(ds.q()[2])
                fx, fy = load["force_N"]
                m0, q = load["arm_Nm"]
                ds.setFExtPtr([m * ax + fx, m * ay + fy, math.cos(phi) * m0 - math.sin(phi) * q])
        self.contacts.update()
        return self.stepper.step(index)

    def advance(self):
        """After the step's sample: Siconos's next step (its memories swapped)."""
        self.built["sim"].nextStep()

    def state(self):
        """(nb, 3) positions (x, y, theta) and (nb, 3) velocities; a fixed body at its start."""
        q, v = self.q0.copy(), np.zeros_like(self.q0)
        for i, ds in enumerate(self.built["bodies"]):
            if ds is not None:
                q[i] = ds.q()
                v[i] = ds.velocity()
        return q, v

    def contact_impulses(self):
        """(pair, normal impulse, tangential impulse, gap) of every closed pair, N s and m."""
        for pair, inter, gap in zip(self.contacts.pairs, self.contacts.inters, self.contacts.gaps, strict=True):
            if math.isfinite(gap):
                lam = inter.lambda_(1)
                yield pair, float(lam[0]), float(lam[1]), gap

    def solve_report(self):
        """The last step's solver iterations, residual, and whether it is within ACCEPT_FACTOR
        x the tolerance."""
        so, sn = self.stepper.so, self.sn
        res = float(so.dparam[sn.SICONOS_DPARAM_RESIDU])
        ok = res <= ACCEPT_FACTOR * self.scene["solver_tol"] and math.isfinite(res)
        return int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE]), res, ok

    def diagnostics(self):
        st = self.stepper
        return {
            "retried_steps": st.retries,
            "retried_steps_converged": st.retried_ok,
            "fallback_steps": st.fallback_steps,
            "loose_steps": st.loose,
            "friction_solvers": st.names,
            "one_step_problem": "FrictionContact(3) assembled by Siconos's kernel (TimeStepping)",
        }


def _sibling(name):
    """A module of the driver's own folder (Debian's Python runs the driver as a script, so its
    folder is on ``sys.path``; the modules there import nothing from rockyade)."""
    import importlib

    folder = os.path.dirname(os.path.abspath(__file__))
    if folder not in sys.path:
        sys.path.insert(0, folder)
    return importlib.import_module(name)


class NumericsEngine:
    """The scene stepped by Moreau-Jean with the one-step problem assembled with numpy and
    solved by Siconos's numerics (``integrator = "numerics"``, the default:
    :mod:`rockyade.siconos.moreau_jean`). Every vertex of a moving block is paired with the
    ground (:func:`contact_pairs` with ``ground_all``)."""

    def __init__(self, scene, S):
        self.scene = scene
        pairs = contact_pairs(scene, ground_all=True)
        table = _sibling("pair_table").PairTable(scene["bodies"], pairs, twins(scene, pairs), EDGE_SLACK, DEEP_FRACTION)
        self.mj = _sibling("moreau_jean").MoreauJean(scene, table, S["sn"], StepForces(scene))
        self.pairs = pairs
        self._calls = self._iterations = self._unconverged = 0

    def step(self, index):
        """Take step ``index``; True when it had active contacts."""
        mj = self.mj
        self._calls, self._iterations, self._unconverged = mj.calls, mj.iterations, mj.unconverged
        had = mj.step(index)
        bad = mj.runaway(MAX_SPEED_M_S, MAX_SPIN_RAD_S)
        if bad is not None:
            i, speed, spin = bad
            t = (index + 1) * self.scene["dt_s"]
            raise StepError(
                f"the step to t = {t:.6g} s left body {i} with a non-finite state or a runaway speed "
                f"(|v| = {speed:.3g} m/s, |omega| = {spin:.3g} rad/s; limits {MAX_SPEED_M_S:g} m/s, "
                f"{MAX_SPIN_RAD_S:g} rad/s)"
            )
        return had

    def advance(self):
        """Nothing to do after the step's sample."""

    def state(self):
        """(nb, 3) positions (x, y, theta) and (nb, 3) velocities."""
        return self.mj.state()

    def contact_impulses(self):
        """(pair, normal impulse, tangential impulse, gap) of every active pair, N s and m."""
        for k, rn, rt, gap in self.mj.loaded:
            yield self.pairs[k], rn, rt, gap

    def solve_report(self):
        """The last step's solver iterations, residual, and whether its solver converged."""
        mj = self.mj
        return mj.iterations - self._iterations, mj.residual, mj.unconverged == self._unconverged

    def diagnostics(self):
        mj = self.mj
        return {
            "retried_steps": mj.fallbacks,
            "retried_steps_converged": mj.fallbacks - mj.unconverged,
            "fallback_steps": mj.fallbacks,
            "loose_steps": 0,
            "friction_solvers": list(mj.names),
            "one_step_problem": mj.describe(),
        }


def engine(scene, S):
    """The run's engine: :class:`NumericsEngine` (the default) or :class:`KernelEngine`."""
    return KernelEngine(scene, S) if scene.get("integrator", "kernel") == "kernel" else NumericsEngine(scene, S)


def main(scene_path, out_path, deadline=None, flush_s=None):
    """Run one scene: read the payload, build, step to the end or the stop rule, write the
    samples to ``out_path`` (``.npz``). Returns the run's status."""
    with open(scene_path) as fh:
        scene = json.load(fh)
    if scene.get("format") != SCENE_FORMAT:
        raise ValueError(f"scene format {scene.get('format')!r}, expected {SCENE_FORMAT!r}")
    S = _siconos()
    run = engine(scene, S)
    rec = Recorder(scene, run, S, out_path)
    dt, sps, n_steps = scene["dt_s"], scene["steps_per_sample"], scene["n_steps"]
    deadline = math.inf if deadline is None else float(deadline)
    flush_s = math.inf if flush_s is None else float(flush_s)
    next_flush = time.monotonic() + flush_s
    go = rec.record(0.0)
    step = 0
    while go and step < n_steps:
        try:
            had = run.step(step)
        except StepError as exc:
            rec.status, rec.stop_time, rec.failure_reason = "failed", step * dt, str(exc)
            break
        step += 1
        t = step * dt
        rec.step_diagnostics(t, had)
        rec.steps = step
        if step % sps == 0:
            go = rec.record(t)
            if go:
                now = time.monotonic()
                if now >= deadline:
                    rec.status, rec.stop_time = "timeout", t
                    go = False
                elif now >= next_flush:
                    rec.write(complete=False)
                    rec.flushes += 1
                    next_flush = time.monotonic() + flush_s
        run.advance()
    rec.write(complete=rec.status != "timeout")
    return rec.status


def serve(fd):
    """Run scenes as they come on socket ``fd`` (the loop of ``driver_loop``); return the exit code."""
    _siconos()  # loaded before saying ready: a missing Siconos fails the start, not a scene
    return LOOP.serve(fd, main)


if __name__ == "__main__":
    try:
        args = sys.argv[1:]
        if args and args[0] == "--serve":
            LOOP.exit_now(serve(int(args[1])))
        elif len(args) >= 2:
            print(main(args[0], args[1]))
        else:
            print(__doc__)
            LOOP.exit_now(2)
    except Exception:
        traceback.print_exc()
        LOOP.exit_now(1)
    LOOP.exit_now(0)
