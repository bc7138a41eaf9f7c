"""Run a rockyade scene in Siconos and write its time history (executed by Debian's Python).

Usage::

    python3 driver.py --serve FD              # how rockyade runs it: many scenes
    python3 driver.py SCENE.json RESULT.npz   # one scene

``--serve FD``: a Siconos worker (:mod:`rockyade.io.worker` starts it). FD is its end of a
socket pair (AF_UNIX, SOCK_SEQPACKET: no address, no port). It says ``{"ready": true}``,
then takes jobs ``{"scene": path, "out": path, "deadline": t, "flush_s": s}``, each with the
descriptor of the job's log file (SCM_RIGHTS) onto which its stdout and stderr go while the
job runs, and answers each with ``{"ok": ...}`` (``"timeout": true`` when the scene was
stopped at its deadline, a ``time.monotonic()`` value, with its samples written; every
``flush_s`` seconds the samples so far are written, ``complete: false``, so that a worker
killed from outside leaves them). After a job that raised it answers and exits (code 1).
It stops on ``{"quit": true}`` or when its end of the socket closes.

Runs inside Debian's /usr/bin/python3 and imports only the standard library, numpy and
Siconos (``python3-siconos``). The scene is data prepared by rockyade
(``rockyade.siconos.payload``): the blocks' contact polygons (the DEMs' own: base corners at
the equivalent base b_eq), masses and inertias (I_O = M g R / p^2), the ground acceleration
samples, the loads and the time step.

The model (nonsmooth contact dynamics, Moreau-Jean time stepping):

* each moving block is a ``RigidBody2dDS`` (x, y, theta) with a ``SiconosConvexHull2d``
  contactor (its contact polygon, margins 0) and a small ``SiconosDisk`` inside each vertex,
  tangent to its two edges; a fixed block and the ground are static contactor sets (they
  move with the base: not at all in the base frame);
* contacts are found by Bullet (``SiconosBulletCollisionManager``, 2-D) between a block's
  vertex disks and the other blocks' hulls or the ground only (the DEMs' vertex-to-edge
  contacts: a hull-on-hull contact of two flat faces gets a single point in the middle, on
  which a stack cannot stand), and obey a Newton impact law with Coulomb friction
  (``NewtonImpactFrictionNSL(e, 0, mu, 2)``) per pair of contactor groups; the one-step
  problem is ``FrictionContact(2)`` solved by NSGS to the tolerance given;
* ``MoreauJeanOSI(theta)``; the ground motion enters in the base frame as an inertial
  force -m a_g(t) on every moving block (exact for a rigid base: the base frame translates
  without rotating), with the vertical -m (g + a_v(t)), both evaluated at the middle of each
  step (t_k + dt/2) and set with ``setFExtPtr`` before the step; a point load is a constant
  force at its point of the block, its torque cos(phi) M0 - sin(phi) Q at world angle phi;
* every ``steps_per_sample`` steps the state is recorded with, per vertex, the normal force
  (reaction impulse / dt) and whether the contact slips (|tangential| >= SLIP_RATIO x mu x
  normal); per step the numerics solver's iterations and residual are counted (a step whose
  residual stays above the tolerance is "unconverged"); at every sample the deepest
  penetration (-gap) of the contacts.

Same role as :mod:`rockyade.yade.driver`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

import contextlib
import json
import math
import os
import socket
import sys
import time
import traceback

import numpy as np

SCENE_FORMAT = "rockyade-siconos-scene-1"
#: The friction-contact solvers by name (of Siconos's 3-D problem: a 2-D contact is a 3-D one
#: whose second tangent sees only a small fictitious arm on the rotation, TWIST_ARM):
#: Alart-Curnier nonsmooth Newton (a few iterations on a stack, measured) and Gauss-Seidel
#: (thousands of iterations on a stack: two contacts per joint make it hyperstatic).
SOLVERS = {
    "nsn": "SICONOS_FRICTION_3D_NSN_AC",
    "nsgs": "SICONOS_FRICTION_3D_NSGS",
}
#: The second tangent's arm on the rotation, m (it keeps the local 3x3 problem regular; its
#: friction torque is at most TWIST_ARM x mu x N).
TWIST_ARM = 1e-4
#: A contact's gap is read this much smaller, m, so that a contact closed at the start
#: (gap 0 up to rounding) is active from the first step.
GAP_OFFSET_M = 1e-8
#: A pair whose vertex has left its edge (by this fraction of the edge's length) is open.
EDGE_SLACK = 1e-3
#: Beyond these the state is a numerical blow-up, not rocking (as in the DEMs).
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0
#: A contact slips when |tangential| >= SLIP_RATIO x mu x normal.
SLIP_RATIO = 0.999


class OutputError(Exception):
    """The output could not be written (its partial file is removed)."""

    def __init__(self, path, exc):
        super().__init__(f"cannot write {path}: {exc.strerror or exc}")
        self.path = path
        self.errno = exc.errno
        self.strerror = exc.strerror or str(exc)


def _write_replacing(path, write):
    """``write(tmp)`` to ``path + ".part"``, then rename it onto ``path``; on failure the
    partial file is removed and OutputError names ``path``."""
    tmp = path + ".part"
    try:
        write(tmp)
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise OutputError(path, exc) from None


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


def contact_pairs(scene):
    """The vertex-to-edge contact pairs of a scene, found once from the starting geometry.

    Returns a list of dicts: ``a`` (the body of the vertex), ``v`` (its index), ``b`` (the
    body of the edge, -1 for the ground), and for a block's edge its start point ``e0``,
    unit direction ``t`` and outward normal ``n`` in that block's frame and its length ``L``;
    ``mu`` the pair's friction coefficient. A vertex pairs with the ground when it starts
    below ``ground_pair_fraction`` of its block's height, and with another block's edge when
    it is within ``pair_gap_fraction`` of the smaller block's smallest dimension of the edge,
    its foot within the edge by as much, and its own block lies on the edge's outer side
    (both of its edges leave the vertex on that side): the reference DEM's contacts.
    """
    bodies = scene["bodies"]
    mu = {}
    for f in scene["friction_pairs"]:
        mu[(int(f["a"]), int(f["b"]))] = float(f["mu"])
        mu[(int(f["b"]), int(f["a"]))] = float(f["mu"])
    local = [np.asarray(b["vertices_m"], dtype=float) for b in bodies]
    size = [float(np.min(np.ptp(v, axis=0))) for v in local]
    world = [
        np.asarray(b["centroid0_m"], dtype=float) + local[i] @ _rot(b["angle0_rad"]).T for i, b in enumerate(bodies)
    ]
    pairs = []
    for a, ba in enumerate(bodies):
        va = world[a]
        na = len(va)
        low = float(np.min(va[:, 1]))
        for k in range(na):
            if not ba["fixed"] and va[k, 1] - low <= scene["ground_pair_fraction"] * np.ptp(va[:, 1]) and low < size[a]:
                pairs.append({"a": a, "v": k, "b": -1, "mu": mu[(a, -1)]})
        for b, bb in enumerate(bodies):
            if b == a or (ba["fixed"] and bb["fixed"]) or (a, b) not in mu:
                continue
            tol = scene["pair_gap_fraction"] * min(size[a], size[b])
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
                    if not (-tol <= g <= tol and -tol <= sp <= length + tol):
                        continue
                    side = [va[k - 1] - p, va[(k + 1) % na] - p]
                    if any(float(d @ n) < -1e-9 * length for d in side):
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
    distance, exact to first order), and ``NewtonImpactFrictionNSL(e, 0, mu, 3)``."""

    def __init__(self, scene, sk, nsds, ds_of, pairs):
        self.pairs = pairs
        self.ds_of = ds_of
        self.local = [np.asarray(b["vertices_m"], dtype=float) for b in scene["bodies"]]
        self.static = [(np.asarray(b["centroid0_m"], dtype=float), float(b["angle0_rad"])) for b in scene["bodies"]]
        self.inters, self.views, self.moving = [], [], []
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
            self.moving.append(moving)
        self.gaps = np.zeros(len(pairs))

    def _state(self, i):
        ds = self.ds_of[i]
        if ds is None:
            c, a = self.static[i]
            return np.array([c[0], c[1], a])
        return np.asarray(ds.q(), dtype=float)

    def update(self):
        """C and e of every pair at the bodies' current positions; the gaps (m) kept."""
        q = {}
        for k, pair in enumerate(self.pairs):
            a, b = pair["a"], pair["b"]
            qa = q.get(a)
            if qa is None:
                qa = q[a] = self._state(a)
            ra = _rot(qa[2]) @ self.local[a][pair["v"]]
            point = qa[:2] + ra
            inside = True
            if b < 0:
                n = np.array([0.0, 1.0])
                gap = point[1]
                rb = None
            else:
                qb = q.get(b)
                if qb is None:
                    qb = q[b] = self._state(b)
                rot = _rot(qb[2])
                n = rot @ pair["n"]
                t = rot @ pair["t"]
                p0 = qb[:2] + rot @ pair["e0"]
                gap = float((point - p0) @ n)
                sp = float((point - p0) @ t)
                slack = EDGE_SLACK * pair["L"]
                inside = -slack <= sp <= pair["L"] + slack
                rb = point - qb[:2]
            tx, ty = -n[1], n[0]
            C, e = self.views[k]
            col = 0
            qq = []
            for body, sign, r in ((a, 1.0, ra), (b, -1.0, rb)):
                if body < 0 or self.ds_of[body] is None:
                    continue
                C[0, col : col + 3] = (sign * n[0], sign * n[1], sign * (n[1] * r[0] - n[0] * r[1]))
                C[1, col : col + 3] = (sign * tx, sign * ty, sign * (ty * r[0] - tx * r[1]))
                C[2, col : col + 3] = (0.0, 0.0, sign * TWIST_ARM)
                qq.append(q[body])
                col += 3
            qv = np.concatenate(qq)
            self.gaps[k] = gap if inside else math.inf
            e[0] = (gap - GAP_OFFSET_M if inside else 1.0) - float(C[0] @ qv)
            e[1] = -float(C[1] @ qv)
            e[2] = -float(C[2] @ qv)


def build(scene, S):
    """The Siconos simulation of a scene: returns a dict of what the stepping needs."""
    sk, sn = S["sk"], S["sn"]
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
    so = sk.solver_options_create(getattr(sn, SOLVERS[scene["friction_solver"]]))
    so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = int(scene["solver_max_iter"])
    so.dparam[sn.SICONOS_DPARAM_TOL] = float(scene["solver_tol"])
    problem = sk.FrictionContact(3, so)
    problem.setKeepLambdaAndYState(True)
    sim = sk.TimeStepping(nsds, timedisc, osi, problem)
    sim.setNewtonMaxIteration(int(scene["newton_max_iter"]))
    sim.setNewtonTolerance(float(scene["newton_tol"]))
    return {"sim": sim, "nsds": nsds, "bodies": bodies, "so": so, "contacts": contacts, "problem": problem}


class Recorder:
    """The samples of a run, its diagnostics and its output file (module docstring)."""

    def __init__(self, scene, built, S, out_path):
        self.scene, self.built, self.S, self.out_path = scene, built, S, out_path
        self.sn = S["sn"]
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
        self.overturn_times = {}
        self.max_penetration = 0.0  # of a vertex below the ground, m (geometric)
        self.max_overlap = 0.0  # Bullet's -gap, m (a disk's includes about 0.44 of its radius)
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
        for i, b in enumerate(self.scene["bodies"]):
            ds = self.built["bodies"][i]
            if ds is None:
                self.pos[k, i] = b["centroid0_m"]
                self.ang[k, i] = b["angle0_rad"]
                continue
            q, v = ds.q(), ds.velocity()
            x, y, phi = float(q[0]), float(q[1]), float(q[2])
            vx, vy, w = float(v[0]), float(v[1]), float(v[2])
            if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(phi) and math.isfinite(w)):
                return self._fail(t, i)
            if math.hypot(vx, vy) > MAX_SPEED_M_S or abs(w) > MAX_SPIN_RAD_S:
                return self._fail(t, i)
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
            stop = b["stop_angle_rad"]
            if stop is not None and abs(phi - b["rest_angle_rad"]) >= stop and i not in self.overturn_times:
                self.overturn_times[i] = t
                if self.scene["stop_on_overturn"] and self.status == "completed":
                    self.status, self.stop_time, self.stop_body = "overturned", t, i
        self._contacts(k)
        self.k = k + 1
        return self.status == "completed"

    def _fail(self, t, i):
        self.status, self.stop_time, self.stop_body = "failed", t, i
        return False

    def _contacts(self, k):
        """Normal force and state per vertex, contact points and slip per block (module docstring)."""
        contacts = self.built["contacts"]
        dt = self.scene["dt_s"]
        points = {}
        for pair, inter, gap in zip(contacts.pairs, contacts.inters, contacts.gaps, strict=True):
            if not math.isfinite(gap):
                continue
            lam = inter.lambda_(1)
            rn = float(lam[0]) / dt
            if rn <= 0.0:
                continue
            if -gap > self.max_overlap:
                self.max_overlap = -gap
            body, v, other = pair["a"], pair["v"], pair["b"]
            slips = abs(float(lam[1])) >= SLIP_RATIO * pair["mu"] * float(lam[0])
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
        sn, so = self.sn, self.built["so"]
        it = int(so.iparam[sn.SICONOS_IPARAM_ITER_DONE])
        res = float(so.dparam[sn.SICONOS_DPARAM_RESIDU])
        self.solver_calls += 1
        self.iterations += it
        if res > self.max_residual:
            self.max_residual = res
        if res > self.scene["solver_tol"] or not math.isfinite(res):
            self.unconverged += 1
            if self.first_unconverged_s is None:
                self.first_unconverged_s = t

    def write(self, complete):
        n = self.k
        meta = {
            "status": self.status if complete or self.status == "timeout" else "running",
            "stop_time_s": self.stop_time,
            "overturn_times_s": {str(i): t for i, t in self.overturn_times.items()},
            "stop_body": self.stop_body,
            "n_filled": n,
            "steps": self.steps,
            "wall_time_s": time.perf_counter() - self.start,
            "siconos_version": self.S["version"],
            "dt_s": self.scene["dt_s"],
            "solver_calls": self.solver_calls,
            "solver_iterations": self.iterations,
            "unconverged_steps": self.unconverged,
            "first_unconverged_s": self.first_unconverged_s,
            "max_residual": self.max_residual,
            "max_penetration_m": self.max_penetration,
            "max_bullet_overlap_m": self.max_overlap,
            "complete": complete,
            "flushes": self.flushes,
            "process_cpu_s": time.process_time(),
        }
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

        def write(tmp):
            with open(tmp, "wb") as fh:
                np.savez(fh, **arrays, meta=np.array(json.dumps(meta)))
                fh.flush()
                os.fsync(fh.fileno())

        _write_replacing(self.out_path, write)


def base_forces(scene):
    """(n_steps, 2) the inertial force per unit mass at each step's middle, m/s^2:
    (-a_h, -(g + a_v)), the samples linear between, zero outside the record."""
    n, dt, g = scene["n_steps"], scene["dt_s"], scene["g"]
    t = (np.arange(n) + 0.5) * dt
    out = np.zeros((n, 2))
    out[:, 1] = -g
    motion = scene["motion"]
    if motion is not None:
        ts = np.asarray(motion["t_s"], dtype=float)
        out[:, 0] -= np.interp(t, ts, np.asarray(motion["ah_m_s2"], dtype=float), left=0.0, right=0.0)
        out[:, 1] -= np.interp(t, ts, np.asarray(motion["av_m_s2"], dtype=float), left=0.0, right=0.0)
    return out


def main(scene_path, out_path, deadline=None, flush_s=None):
    """Run one scene: read the payload, build, step to the end or the stop rule, write the
    samples to ``out_path`` (``.npz``). Returns the run's status."""
    with open(scene_path) as fh:
        scene = json.load(fh)
    if scene.get("format") != SCENE_FORMAT:
        raise ValueError(f"scene format {scene.get('format')!r}, expected {SCENE_FORMAT!r}")
    S = _siconos()
    built = build(scene, S)
    rec = Recorder(scene, built, S, out_path)
    sim = built["sim"]
    moving = [
        (i, ds, float(scene["bodies"][i]["mass_kg"]), scene["bodies"][i].get("load"))
        for i, ds in enumerate(built["bodies"])
        if ds is not None
    ]
    forces = base_forces(scene)
    dt, sps, n_steps = scene["dt_s"], scene["steps_per_sample"], scene["n_steps"]
    deadline = math.inf if deadline is None else float(deadline)
    flush_s = math.inf if flush_s is None else float(flush_s)
    next_flush = time.monotonic() + flush_s
    so, sn = built["so"], S["sn"]
    problem = built["problem"]
    contacts = built["contacts"]
    go = rec.record(0.0)
    step = 0
    while go and step < n_steps:
        ax, ay = forces[step]
        for _i, ds, m, load in moving:
            if load is None:
                ds.setFExtPtr([m * ax, m * ay, 0.0])
            else:
                phi = float(ds.q()[2])
                fx, fy = load["force_N"]
                m0, q = load["arm_Nm"]
                ds.setFExtPtr([m * ax + fx, m * ay + fy, math.cos(phi) * m0 - math.sin(phi) * q])
        contacts.update()
        so.iparam[sn.SICONOS_IPARAM_ITER_DONE] = 0
        sim.computeOneStep()
        step += 1
        t = step * dt
        had = problem.getSizeOutput() > 0
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
        sim.nextStep()
    rec.write(complete=rec.status != "timeout")
    return rec.status


def _send(sock, message):
    sock.send(json.dumps(message).encode())


def serve(fd):
    """Run scenes as they come on socket ``fd`` (module docstring); return the exit code."""
    sock = socket.socket(fileno=fd)
    keep_out, keep_err = os.dup(1), os.dup(2)
    _siconos()  # loaded before saying ready: a missing Siconos fails the start, not a scene
    _send(sock, {"ready": True, "pid": os.getpid()})
    while True:
        try:
            data, fds, _flags, _addr = socket.recv_fds(sock, 1 << 16, 1)
        except OSError:
            return 0
        if not data:
            for extra in fds:
                os.close(extra)
            return 0
        job = json.loads(data)
        if job.get("quit"):
            return 0
        sys.stdout.flush()
        sys.stderr.flush()
        for log in fds:
            os.dup2(log, 1)
            os.dup2(log, 2)
            os.close(log)
        reply = {"ok": True}
        try:
            status = main(job["scene"], job["out"], deadline=job.get("deadline"), flush_s=job.get("flush_s"))
            if status == "timeout":
                reply["timeout"] = True
        except OutputError as exc:
            reply = {"ok": False, "path": exc.path, "errno": exc.errno, "strerror": exc.strerror}
        except Exception as exc:  # reported, then this worker ends
            traceback.print_exc()
            reply = {"ok": False, "error": f"{type(exc).__name__}: {exc}"}
        sys.stdout.flush()
        sys.stderr.flush()
        os.dup2(keep_out, 1)
        os.dup2(keep_err, 2)
        if not reply["ok"] and "errno" not in reply:
            _send(sock, reply)
            return 1
        _send(sock, reply)


def _exit(code):
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    try:
        args = sys.argv[1:]
        if args and args[0] == "--serve":
            _exit(serve(int(args[1])))
        elif len(args) >= 2:
            print(main(args[0], args[1]))
        else:
            print(__doc__)
            _exit(2)
    except Exception:
        traceback.print_exc()
        _exit(1)
    _exit(0)
