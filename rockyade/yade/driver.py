"""Run a rockyade DEM scene in YADE and write its time history (executed by YADE's Python).

Usage::

    python3.11 driver.py --serve FD                    # how rockyade runs it: many scenes
    python3.11 driver.py SCENE.json RESULT.npz    # one scene
    yade -x run.py                                     # a `rockyade yade-script` folder:
    yade run.py                                        # scene.json beside run.py, writes
                                                       # result.npz and result.csv there

``--serve FD``: a YADE worker (:mod:`rockyade.io.warm_program` starts it) running the loop
every driver shares (:mod:`rockyade.io.driver_loop`, loaded by its path: this Python cannot
import rockyade; a yade-script folder carries a copy beside ``run.py``): one scene after the
other, the samples so far written every ``flush_s`` seconds (``complete: false``) so that a
worker killed from outside leaves them, and YADE reset between scenes (:func:`reset`). The
output is that module's one dialect (:func:`rockyade.io.driver_loop.output_meta`) with YADE's
own diagnostics.

YADE makes a folder ``/tmp/yade-`` plus six random characters when it is imported (a fixed /tmp, whatever
TMPDIR says) and removes it only at its own exit, which the driver never reaches (it leaves
with ``os._exit``, below); nothing here uses that folder, so the driver removes it, empty,
as soon as YADE is imported (not under the ``yade`` launcher, whose GUI may use it).

Runs inside Debian's /usr/bin/python3.11 with YADE's modules on the path and imports only
the standard library, numpy and YADE. rockyade never uses the ``yade`` launcher, which
opens a Python console and an XMLRPC server on all interfaces; a user may (it also gives
the 3-D view). The scene is data prepared by rockyade (``rockyade.yade.payload``):
every contact decision (sphere places, copies, materials, masks) is in it.

The model, as the reference DEM's:

* each block is one clump: a small sphere at every contact vertex (one copy per joint it
  needs, each with its own material and collision mask), a Polyhedra prism (the contact
  polygon extruded in z) that the other blocks' vertex spheres meet, and a heavy
  non-colliding helper sphere at the centroid so that the clump's centre of mass is the
  block's centroid; the clump's mass and inertia are then set to the block's, the inertia
  isotropic (Izz, Izz, Izz) because with blocked rotations NewtonIntegrator divides the
  global torque by the principal inertia of the clump's own frame;
* planar motion: blockedDOFs = "zXY"; a fixed block is a non-dynamic clump (it moves with
  the base, i.e. not at all in the base frame);
* contacts: sphere-prism (Ig2_Sphere_Polyhedra_ScGeom) and sphere-base
  (Ig2_Box_Sphere_ScGeom) only, Law2_ScGeom_ViscElPhys_Basic with the sphere copy's
  ViscElMat (kn, ks, cn = beta kn, cs = beta ks, friction angle) and zeros on prisms and
  base (Ip2 combines materials in series and skips zeros, so the sphere's values are used
  exactly);
* the base is a fixed Box; the ground motion acts in the base frame as a force -M a_g(t)
  on each moving clump (InterpolatingDirectedForceEngine, linear between samples, zero
  after; one engine per distinct mass and direction);
* NewtonIntegrator with damping 0 (its default is 0.2), gravity -g, O.dt as given;
* the recorder is called *before* the other engines every ``steps_per_sample`` steps, so
  the sample at step n sees x_n and t_n = n dt: rockyade steps the scene itself in the
  driver's thread (:func:`run_stepping`, ``O.step()``: the same steps as YADE's thread runs,
  without a Python command per call), the ``yade`` launcher's console runs it in YADE's
  thread with a PyRunner placed first;
* rotation is continuous from rest, as the reference DEM's: the driver accumulates the
  change of each block's orientation (2 atan2(q_z, q_w) of ori * ori0.conjugate(), taken
  as the smallest angle) at
  every record and, between records, at least every ``track_period`` steps, chosen so that
  MAX_SPIN_RAD_S x track_period x dt stays below ROTATION_STEP_MAX_RAD (< pi): the smallest
  angle is then the true one unless the spin exceeds the blow-up limit (checked at each
  call); an increment above ROTATION_STEP_MAX_RAD fails the run (it cannot be unwrapped);
* at each record, per block, the contact points with a positive normal force (a vertex
  sphere on the base: one point per vertex; between two blocks, the vertex spheres of
  either block on the other's prism, at most 2 per pair: the ends of the reference DEM's
  contact segment) and whether one of them slips: |elastic shear force| >= SLIP_RATIO x
  tan(phi) x normal force (Law2_ScGeom_ViscElPhys_Basic clips it to that limit when
  sliding);
* a block has overturned when |theta| from rest reaches its stop angle (the landing angle
  of rockyade's overturn criterion, given in the data); the run stops there in a column
  scene (``stop_on_overturn``) and goes on in an assembly; it stops when a state is not
  finite (failed).

Same role as :mod:`rockyade.siconos.driver`: each package of an engine that runs in another
Python has a ``payload``, a ``driver`` and a ``backend`` (docs/architecture.md, "How to add a
solver").
"""

import contextlib
import json
import math
import os
import runpy
import sys
import time
import traceback
import types
from typing import Any

YADE_PY = os.environ.get("ROCKYADE_YADE_PY", "/usr/lib/x86_64-linux-gnu/yade-double/py")
if YADE_PY not in sys.path:
    sys.path.insert(1, YADE_PY)


@contextlib.contextmanager
def _ipython_version_only():
    """While YADE loads, ``IPython`` is a module holding only the installed IPython's version.

    ``yade.runtime`` imports IPython at YADE's import only to read ``IPython.__version__`` (for
    YADE's interactive shell, which this driver never starts); the real import costs about 0.4 s
    of CPU, a third of YADE's start (measured with Debian's YADE 2023 and IPython 8.5). The
    version comes from the package's metadata; where that is missing, YADE imports the real
    IPython as before. Afterwards ``import IPython`` gives the real one again."""
    from importlib import metadata

    try:
        version = metadata.version("ipython")
    except metadata.PackageNotFoundError:
        version = None
    if version is None or "IPython" in sys.modules:
        yield
        return
    sys.modules["IPython"] = types.SimpleNamespace(__version__=version)  # type: ignore[assignment]
    try:
        yield
    finally:
        del sys.modules["IPython"]


with _ipython_version_only():
    import yade  # noqa: F401

import numpy as np  # noqa: E402
from yade import (  # noqa: E402
    Bo1_Box_Aabb,
    Bo1_Polyhedra_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Polyhedra_ScGeom,
    InsertionSortCollider,
    InteractionLoop,
    InterpolatingDirectedForceEngine,
    Ip2_ViscElMat_ViscElMat_ViscElPhys,
    Law2_ScGeom_ViscElPhys_Basic,
    NewtonIntegrator,
    O,
    PyRunner,
    Quaternion,
    Vector3,
    ViscElMat,
    utils,
)


def _driver_loop():
    """The loop and output writing every driver shares (``rockyade/io/driver_loop.py``, run from
    its path: this Python cannot import rockyade); beside this script in a yade-script folder."""
    here = os.path.dirname(os.path.abspath(sys.argv[0] if __name__ == "__main__" else __file__))
    beside = os.path.join(here, "driver_loop.py")
    path = beside if os.path.isfile(beside) else os.path.join(here, os.pardir, "io", "driver_loop.py")
    return types.SimpleNamespace(**runpy.run_path(path, run_name="driver_loop"))


LOOP = _driver_loop()

SCENE_FORMAT = "rockyade-yade-scene-2"
BASE_HALF_SIZE = 50.0
HELPER_DENSITY = 1.0e15
LIGHT_DENSITY = 1.0e-3
# beyond these the state is a numerical blow-up, not rocking (as in the reference DEM)
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0
#: Largest rotation of a block between two rotation records, rad (below pi: the smallest
#: angle between two orientations is then the rotation).
ROTATION_STEP_MAX_RAD = 0.9 * math.pi
#: A contact slips when its elastic shear force is at least this fraction of tan(phi) Fn.
SLIP_RATIO = 1.0 - 1e-6


def _remove_yade_temp_folder():
    """Remove the empty folder YADE made at import (module docstring); return its path."""
    try:
        folder = os.path.dirname(O.tmpFilename())
    except Exception:  # nothing to remove
        return None
    with contextlib.suppress(OSError):
        os.rmdir(folder)  # only an empty folder, never a link
    return folder


def _material(values, density):
    if values is None:  # prisms, base, helpers: zeros, skipped by Ip2's series combination
        return ViscElMat(kn=0.0, ks=0.0, cn=0.0, cs=0.0, frictionAngle=math.pi / 2 - 1e-9, density=density)
    return ViscElMat(
        kn=values["kn"],
        ks=values["ks"],
        cn=values["cn"],
        cs=values["cs"],
        frictionAngle=values["friction_angle_rad"],
        density=density,
    )


def _rotate(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _orientation_angle(q):
    """Angle of a rotation about z, rad, in (-2 pi, 2 pi] (q and -q are the same rotation).

    Of the clump's orientation relative to its orientation at build (ori * ori0.conjugate()),
    a rotation about z: the clump's own frame (its principal axes) need not be the block's."""
    return 2.0 * math.atan2(q[2], q[3])


def build(scene):
    """Build the scene in O; return the clumps' bookkeeping."""
    if scene.get("format") != SCENE_FORMAT:
        raise ValueError(f"scene data format {scene.get('format')!r}, expected {SCENE_FORMAT!r}")
    O.reset()
    O.dt = scene["dt_s"]
    inert = O.materials.append(_material(None, LIGHT_DENSITY))
    helper_mat = O.materials.append(_material(None, HELPER_DENSITY))
    sphere_mats = [O.materials.append(_material(m, LIGHT_DENSITY)) for m in scene["materials"]]
    O.bodies.append(
        utils.box(
            center=(0, -0.5, 0),
            extents=(BASE_HALF_SIZE, 0.5, BASE_HALF_SIZE),
            fixed=True,
            material=O.materials[inert],
            mask=scene["base_mask"],
        )
    )
    clumps = []
    for b in scene["bodies"]:
        c0, a0 = b["centroid0_m"], b["angle0_rad"]
        r = b["sphere_radius_m"]
        members: list[Any] = []  # YADE bodies
        vertex_members: list[tuple[int, int]] = []
        for (cx, cy), copies in zip(b["sphere_centers_m"], b["sphere_copies"], strict=True):
            wx, wy = _rotate((cx, cy), a0)
            start = len(members)
            for material, mask in copies:
                members.append(
                    utils.sphere(
                        (c0[0] + wx, c0[1] + wy, 0.0), r, material=O.materials[sphere_mats[material]], mask=mask
                    )
                )
            vertex_members.append((start, len(members)))
        hz = b["prism_half_thickness_m"]
        box = b.get("prism_box")
        prism_at = len(members)
        if box:  # a rectangle: a Box (cheaper contact, robust however deep a sphere goes)
            wx, wy = _rotate(box["center_m"], a0)
            members.append(
                utils.box(
                    center=(c0[0] + wx, c0[1] + wy, 0.0),
                    extents=(box["half_extents_m"][0], box["half_extents_m"][1], hz),
                    orientation=Quaternion(Vector3(0, 0, 1), a0 + box["angle_rad"]),
                    material=O.materials[inert],
                    mask=b["prism_mask"],
                )
            )
        else:
            corners = []
            for vx, vy in b["vertices_m"]:
                wx, wy = _rotate((vx, vy), a0)
                corners += [Vector3(c0[0] + wx, c0[1] + wy, -hz), Vector3(c0[0] + wx, c0[1] + wy, hz)]
            members.append(utils.polyhedron(corners, material=O.materials[inert], mask=b["prism_mask"]))
        members.append(utils.sphere((c0[0], c0[1], 0.0), r, material=O.materials[helper_mat], mask=0))
        load = b.get("load") if not b["fixed"] else None
        if load is not None:  # a massless, non-colliding member at the load point: it turns with the block
            lx, ly = _rotate(load["point_m"], a0)
            members.append(utils.sphere((c0[0] + lx, c0[1] + ly, 0.0), r, material=O.materials[inert], mask=0))
        clump_id, member_ids = O.bodies.appendClumped(members)
        state = O.bodies[clump_id].state
        offset = (state.pos[0] - c0[0], state.pos[1] - c0[1])
        if math.hypot(*offset) > 1e-6 * max(1.0, math.hypot(*c0)):
            raise RuntimeError(f"clump centre {tuple(state.pos)} is not the centroid {c0}")
        state.mass = b["mass_kg"]
        inertia = b["inertia_kgm2"]
        state.inertia = Vector3(inertia, inertia, inertia)
        if b["fixed"]:
            O.bodies[clump_id].dynamic = False
            state.vel = Vector3(0, 0, 0)
            state.angVel = Vector3(0, 0, 0)
        else:
            state.blockedDOFs = "zXY"
            state.vel = Vector3(b["vel0_m_s"][0], b["vel0_m_s"][1], 0.0)
            state.angVel = Vector3(0.0, 0.0, b["angvel0_rad_s"])
        clumps.append(
            {
                "id": clump_id,
                "fixed": b["fixed"],
                "ori0": state.ori.conjugate(),
                "vertex_ids": [member_ids[s:e] for s, e in vertex_members],
                "angle0": a0,
                "rest": b["rest_angle_rad"],
                "stop_angle": b["stop_angle_rad"] if b.get("stop_angle_rad") is not None else math.inf,
                "point": b["accel_point_m"],
                "mass": b["mass_kg"],
                "radius": r,
                "prism": member_ids[prism_at],
                "load_id": member_ids[-1] if load is not None else None,
                "load_force": load["force_N"] if load is not None else None,
                "prism_is_polyhedra": not box,
            }
        )
    return clumps


def ground_engines(scene, clumps):
    """Base motion as forces -M a_g(t) on the moving clumps, one engine per mass and direction."""
    motion = scene["motion"]
    if motion is None:
        return []
    t = list(motion["t_s"])
    engines = []
    # zero after the last sample (the reference DEM's convention), and before the first
    times = [t[0] - 1.0, *t, t[-1] + 1e-09, t[-1] + 1000000000.0]
    by_mass: dict[float, list[int]] = {}
    for c in clumps:
        if not c["fixed"]:
            by_mass.setdefault(c["mass"], []).append(c["id"])
    for key, direction in (("ah_m_s2", Vector3(1, 0, 0)), ("av_m_s2", Vector3(0, 1, 0))):
        values = list(motion[key])
        if not any(values):
            continue
        for mass, ids in by_mass.items():
            mags = [0.0] + [-mass * a for a in values] + [0.0, 0.0]
            engines.append(InterpolatingDirectedForceEngine(ids=ids, times=times, magnitudes=mags, direction=direction))
    return engines


def load_engines(scene, clumps):
    """Point loads: a force on each loaded block's load member (a clump sums its members' forces
    with their current arms, so the torque follows the block's rotation), scaled by the
    apparent gravity (g + a_v) / g as in the reference DEM (rockyade/kernel/point_loads.py)."""
    engines = []
    g = scene["g"]
    motion = scene["motion"]
    for c in clumps:
        if c.get("load_id") is None:
            continue
        fx, fy = c["load_force"]
        mag = math.hypot(fx, fy)
        direction = Vector3(fx / mag, fy / mag, 0.0)
        if motion is None or not any(motion["av_m_s2"]):
            times, mags = [-1.0, 1.0e9], [mag, mag]
        else:
            t = list(motion["t_s"])
            times = [t[0] - 1.0, *t, t[-1] + 1e-09, t[-1] + 1000000000.0]
            mags = [mag] + [mag * (g + a) / g for a in motion["av_m_s2"]] + [mag, mag]
        engines.append(
            InterpolatingDirectedForceEngine(ids=[c["load_id"]], times=times, magnitudes=mags, direction=direction)
        )
    return engines


def _describe(clumps):
    """What was built: for tests of the YADE pitfalls (no simulation is run)."""
    newton = next(e for e in O.engines if type(e).__name__ == "NewtonIntegrator")
    runner = O.engines[0]
    recorder = globals()["rockyade_record"]
    stepping = recorder.runner is None  # called by run_stepping before each step's engines
    out = {
        "engines": [type(e).__name__ for e in O.engines],
        "newton_damping": newton.damping,
        "gravity": list(newton.gravity),
        "dt": O.dt,
        "recorder_first": stepping or type(runner).__name__ == "PyRunner",
        "recorder_period": recorder.sps if stepping else runner.iterPeriod,
        "recorder": "run_stepping" if stepping else "PyRunner",
        "rotation_track_period": recorder.track_period,
        "clumps": [],
    }
    for c in clumps:
        body = O.bodies[c["id"]]
        members = []
        for mid in body.shape.members:
            member = O.bodies[mid]
            mat = member.material
            members.append(
                {
                    "shape": type(member.shape).__name__,
                    "mask": member.groupMask,
                    "kn": mat.kn,
                    "ks": mat.ks,
                    "cn": mat.cn,
                    "cs": mat.cs,
                    "friction_angle": mat.frictionAngle,
                    "pos": list(member.state.pos),
                }
            )
        out["clumps"].append(
            {
                "mass": body.state.mass,
                "inertia": list(body.state.inertia),
                "blocked": body.state.blockedDOFs,
                "dynamic": body.dynamic,
                "pos": list(body.state.pos),
                "members": members,
                "vertex_ids": [list(ids) for ids in c["vertex_ids"]],
            }
        )
    base = O.bodies[0]
    out["base"] = {
        "shape": type(base.shape).__name__,
        "mask": base.groupMask,
        "kn": base.material.kn,
        "dynamic": base.dynamic,
    }
    return out


class Recorder:
    """Samples the state every ``steps_per_sample`` steps; writes the output when done.

    Called before the engines of a step (by :func:`run_stepping`, or by a PyRunner placed
    first when YADE's own thread runs the scene); after each call ``period`` is the number
    of steps to the next call. Samples are kept in Python lists (a float taken from YADE is
    stored as it is: the arrays written are those a per-element write into numpy arrays
    gives) and turned into arrays when the output is written: a numpy scalar update costs
    more than the YADE calls that feed it.

    ``deadline``: a ``time.monotonic()`` value (CLOCK_MONOTONIC, the same clock in every
    process of the machine) at which the run stops with status ``timeout`` and writes what it
    has; ``flush_s``: every so many seconds of wall time the samples so far are written
    (``complete: false``), so that a run killed from outside keeps them.
    """

    def __init__(self, scene, clumps, out_path, csv_path=None):
        nb = len(clumps)
        self.scene, self.clumps, self.ns, self.nb = scene, clumps, scene["n_samples"], nb
        self.maxv = max(len(b["vertices_m"]) for b in scene["bodies"])
        self.out_path, self.csv_path = out_path, csv_path
        # per sample and block: x, y, theta, omega, and the velocity of the acceleration point
        self.kin = []
        # contacts, sparse: flat index (sample, block, vertex) -> normal force and state;
        # (sample, block) -> number of contact points; (sample, block) that slip
        self.fn_at, self.fn_val, self.state_val = [], [], []
        self.ncont_at, self.ncont_val = [], []
        self.slip_at = []
        # continuous rotation: last orientation angle seen and the rotation accumulated since
        self.raw = [0.0] * nb
        self.turned = [0.0] * nb
        self.moving = [i for i, c in enumerate(clumps) if not c["fixed"]]
        # each clump's State, fetched once (YADE updates it in place): a lookup is a
        # boost.python call, and the recorder runs every sample
        self.states = [O.bodies[c["id"]].state for c in clumps]
        self.per_clump = [
            (i, self.states[i], c["angle0"], c["point"], c["fixed"], c["rest"], c["stop_angle"])
            for i, c in enumerate(clumps)
        ]
        self.tracked = [(i, self.states[i], clumps[i]["ori0"]) for i in self.moving]
        self.sps = scene["steps_per_sample"]
        self.track_period = max(1, min(self.sps, int(ROTATION_STEP_MAX_RAD / (MAX_SPIN_RAD_S * scene["dt_s"]))))
        self.period = self.sps
        self.max_rotation_step = 0.0
        self.runner = None
        self.k = 0
        self.status, self.stop_time, self.stop_body = "completed", None, None
        self.stopped = False
        self.overturn_times = {}
        self.stop_on_overturn = scene.get("stop_on_overturn", True)
        self.max_depth_ratio = 0.0
        self.deep_overlap_time = None  # the first sample that saw a sphere a radius deep in a prism
        self.polyhedra = {c["prism"] for c in clumps if c["prism_is_polyhedra"]}
        self.block_of_prism = {c["prism"]: i for i, c in enumerate(clumps)}
        self.vertex_of = {
            sid: (i, v, c["radius"])
            for i, c in enumerate(clumps)
            for v, ids in enumerate(c["vertex_ids"])
            for sid in ids
        }
        self.start = time.perf_counter()
        self.written = False
        self.wait = True
        self.own_time = 0.0  # spent in the recorder, s
        self.deadline = math.inf
        self.flush_s = math.inf
        self.next_flush = math.inf
        self.flushes = 0

    def limit(self, deadline=None, flush_s=None):
        """Stop at ``deadline`` (``time.monotonic()``) and write every ``flush_s`` seconds (None: never)."""
        now = time.monotonic()
        self.deadline = math.inf if deadline is None else float(deadline)
        self.flush_s = math.inf if flush_s is None else float(flush_s)
        self.next_flush = now + self.flush_s

    def __call__(self):
        start = time.perf_counter()
        self.record()
        self.own_time += time.perf_counter() - start

    def record(self):
        """Record the state when this step is a sample (and follow the rotations)."""
        k = self.k
        if k >= self.ns or self.written:
            return
        to_sample = k * self.sps - O.iter
        if not self.track():
            return
        if to_sample > 0:  # a rotation record between samples
            self.period = min(to_sample, self.track_period)
            if self.runner is not None:
                self.runner.iterPeriod = self.period
            return
        turned = self.turned
        row: list[float] = []
        for i, st, angle0, point, fixed, rest, stop_angle in self.per_clump:
            theta = angle0 + turned[i]
            pos, vel = st.pos, st.vel  # one copy of each vector
            x, y = pos[0], pos[1]
            w = st.angVel[2]
            finite = math.isfinite(x) and math.isfinite(y) and math.isfinite(theta)
            if not finite or vel.norm() > MAX_SPEED_M_S or abs(w) > MAX_SPIN_RAD_S:
                self.status, self.stop_time, self.stop_body = "failed", O.time, i
                self.stop()
                return
            px, py = _rotate(point, theta)
            row += (x, y, theta, w, vel[0] - w * py, vel[1] + w * px)
            if not fixed and abs(theta - rest) >= stop_angle and i not in self.overturn_times:
                self.overturn_times[i] = O.time
                if self.stop_on_overturn and self.status == "completed":
                    self.status, self.stop_time, self.stop_body = "overturned", O.time, i
        self.kin += row
        self.contact_forces(k)
        if self.deep_overlap_time is None and self.max_depth_ratio >= 1.0:
            self.deep_overlap_time = O.time
        self.k = k + 1
        self.period = min(self.sps, self.track_period)
        if self.runner is not None:
            self.runner.iterPeriod = self.period
        if self.status != "completed" or self.k >= self.ns:
            self.stop()
            return
        now = time.monotonic()
        if now >= self.deadline:
            self.status, self.stop_time = "timeout", O.time
            self.stop()
        elif now >= self.next_flush:
            self.write_samples(complete=False)
            self.flushes += 1
            self.next_flush = time.monotonic() + self.flush_s

    def track(self):
        """Accumulate each moving block's rotation since the last call (the smallest angle
        between the two orientations); False (the run failed) when a block spins beyond
        MAX_SPIN_RAD_S or turned more than ROTATION_STEP_MAX_RAD: it cannot be unwrapped."""
        raw, turned = self.raw, self.turned
        for i, st, ori0 in self.tracked:
            now = _orientation_angle(st.ori * ori0)
            step = math.remainder(now - raw[i], 2.0 * math.pi)
            raw[i] = now
            turned[i] += step
            step = abs(step)
            if step > self.max_rotation_step:
                self.max_rotation_step = step
            if not step <= ROTATION_STEP_MAX_RAD or abs(st.angVel[2]) > MAX_SPIN_RAD_S:
                self.status, self.stop_time, self.stop_body = "failed", O.time, i
                self.stop()
                return False
        return True

    def contact_forces(self, k):
        """Normal force and state (1 stick, 2 slip) at each vertex: its copies' real contacts;
        per block, its contact points and whether one slips (see the module docstring).

        Also the deepest penetration seen against a Polyhedra prism, in sphere radii: at one
        radius the sphere's centre is inside the prism and YADE's contact loses its normal."""
        vertex_of, polyhedra, block_of_prism = self.vertex_of, self.polyhedra, self.block_of_prism
        fn_of: dict[tuple[int, int], float] = {}  # (block, vertex) -> summed normal force
        state_of: dict[tuple[int, int], int] = {}  # (block, vertex) -> state
        # (block, other block or -1 for the base) -> the (block, vertex) touching
        points: dict[tuple[int, int], set[tuple[int, int]]] = {}
        slipping = set()
        for inter in O.interactions.all(True):  # the real ones, in the container's order
            id1, id2 = inter.id1, inter.id2
            where = vertex_of.get(id1)
            other = id2
            if where is None:
                where, other = vertex_of.get(id2), id1
                if where is None:
                    continue
            i, v, radius = where
            phys = inter.phys
            fn = phys.normalForce.norm()
            if fn <= 0.0:
                continue
            key = (i, v)
            fn_of[key] = fn_of.get(key, 0.0) + fn
            slips = phys.shearForce.norm() >= SLIP_RATIO * fn * phys.tangensOfFrictionAngle
            if slips:
                state_of[key] = 2
            elif key not in state_of:
                state_of[key] = 1
            j = block_of_prism.get(other, -1)
            pair = (i, j) if j < 0 or i < j else (j, i)
            touching = points.get(pair)
            if touching is None:
                points[pair] = {key}
            else:
                touching.add(key)
            if slips:
                slipping.add(i)
                if j >= 0:
                    slipping.add(j)
            if other in polyhedra:
                depth = inter.geom.penetrationDepth / radius
                if depth > self.max_depth_ratio:
                    self.max_depth_ratio = depth
        if not fn_of:
            return
        nb, maxv = self.nb, self.maxv
        base = k * nb
        for (i, v), fn in fn_of.items():
            self.fn_at.append((base + i) * maxv + v)
            self.fn_val.append(fn)
            self.state_val.append(state_of[i, v])
        counts: dict[int, int] = {}
        for (a, b), touching in points.items():
            if b < 0:  # the base: every vertex on it, as the reference DEM
                counts[a] = counts.get(a, 0) + len(touching)
            else:  # two blocks: at most the two ends of their contact segment
                n = min(2, len(touching))
                counts[a] = counts.get(a, 0) + n
                counts[b] = counts.get(b, 0) + n
        for a, n in counts.items():
            self.ncont_at.append(base + a)
            self.ncont_val.append(n)
        for i in slipping:
            self.slip_at.append(base + i)

    def arrays(self, n):
        """The first ``n`` samples as the output's arrays."""
        nb, maxv = self.nb, self.maxv
        kin = np.array(self.kin[: n * nb * 6], dtype=float).reshape(n, nb, 6)
        size = n * nb * maxv
        fn, state = np.zeros(size), np.zeros(size, dtype=np.int8)
        at = np.array(self.fn_at, dtype=np.int64)
        keep = at < size
        fn[at[keep]] = np.array(self.fn_val, dtype=float)[keep]
        state[at[keep]] = np.array(self.state_val, dtype=np.int8)[keep]
        ncont = np.zeros(n * nb, dtype=np.int32)
        at = np.array(self.ncont_at, dtype=np.int64)
        keep = at < n * nb
        ncont[at[keep]] = np.array(self.ncont_val, dtype=np.int32)[keep]
        slip = np.zeros(n * nb, dtype=bool)
        at = np.array(self.slip_at, dtype=np.int64)
        slip[at[at < n * nb]] = True
        return {
            "pos": np.ascontiguousarray(kin[:, :, 0:2]),
            "ang": np.ascontiguousarray(kin[:, :, 2]),
            "angvel": np.ascontiguousarray(kin[:, :, 3]),
            "vpoint": np.ascontiguousarray(kin[:, :, 4:6]),
            "fn": fn.reshape(n, nb, maxv),
            "state": state.reshape(n, nb, maxv),
            "ncont": ncont.reshape(n, nb),
            "slip": slip.reshape(n, nb),
        }

    def stop(self):
        """End of the run seen from inside it: pause, and write now unless the caller waits."""
        self.stopped = True
        O.pause()
        if not self.wait:
            self.write()

    def write(self):
        """Write the output (once)."""
        if self.written:
            return
        self.written = True
        self.write_samples(complete=self.status != "timeout")
        if self.csv_path:
            self.write_csv(self.k)

    def write_samples(self, complete):
        """The samples so far to ``out_path`` (replacing it as one step: a kill leaves the
        previous file); ``complete`` False: a flush while running, or a run stopped at its
        deadline."""
        meta = LOOP.output_meta(
            self,
            complete,
            steps=O.iter,
            version=__import__("yade.config", fromlist=["version"]).version,
            dt_s=O.dt,
            recorder_time_s=self.own_time,
            build_time_s=self.scene.get("_build_time_s"),
            max_polyhedra_penetration_over_radius=self.max_depth_ratio,
            deep_overlap_time_s=self.deep_overlap_time,
            max_rotation_step_rad=self.max_rotation_step,
            rotation_track_period_steps=self.track_period,
        )
        LOOP.write_output(self.out_path, np.savez, self.arrays(self.k), meta)

    def write_csv(self, n):
        """A plain table for hand work: t, and per block x, y (centroid) and theta (from rest)."""
        names = [b["name"] for b in self.scene["bodies"]]
        rest = [b["rest_angle_rad"] for b in self.scene["bodies"]]
        arrays = self.arrays(n)
        header = ["t_s"]
        for name in names:
            header += [f"{name}_x_m", f"{name}_y_m", f"{name}_rotation_rad"]
        t = np.arange(n) * self.scene["dt_s"] * self.scene["steps_per_sample"]
        cols = [t]
        for i in range(len(names)):
            cols += [arrays["pos"][:, i, 0], arrays["pos"][:, i, 1], arrays["ang"][:, i] - rest[i]]
        LOOP.write_replacing(
            self.csv_path,
            lambda fh: np.savetxt(
                fh, np.column_stack(cols), delimiter=",", header=",".join(header), comments="", fmt="%.10g"
            ),
        )


def prepare(scene, out_path, csv_path=None, stepping=False):
    """Build the scene and its engines; return the recorder. ``stepping``: the recorder is
    called by :func:`run_stepping` (no PyRunner: YADE's own thread is not used)."""
    start = time.perf_counter()
    clumps = build(scene)
    recorder = Recorder(scene, clumps, out_path, csv_path)
    globals()["rockyade_record"] = recorder
    if not stepping:
        recorder.runner = PyRunner(command="rockyade_record()", iterPeriod=scene["steps_per_sample"], initRun=True)
    O.engines = [
        *([] if stepping else [recorder.runner]),
        ForceResetter(),
        InsertionSortCollider(
            [Bo1_Sphere_Aabb(), Bo1_Box_Aabb(), Bo1_Polyhedra_Aabb()], verletDist=0.2 * scene["min_sphere_radius_m"]
        ),
        InteractionLoop(
            [Ig2_Sphere_Polyhedra_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
            [Law2_ScGeom_ViscElPhys_Basic()],
        ),
        *ground_engines(scene, clumps),
        *load_engines(scene, clumps),
        NewtonIntegrator(damping=0.0, gravity=Vector3(0.0, -scene["g"], 0.0)),
    ]
    scene["_build_time_s"] = time.perf_counter() - start
    return recorder, clumps


def run_stepping(recorder, n_steps):
    """Run the scene in this thread, one ``O.step()`` at a time, calling the recorder before
    the engines of the steps it asks for, as a PyRunner placed first would (the same steps,
    the same states, bit for bit) without YADE's thread and a Python command per call. The
    step in which the recorder stops the run is completed, as ``O.pause()`` lets it be; at
    most ``n_steps + 1`` steps, as ``O.run(n_steps + 1)``."""
    step = O.step
    last = n_steps + 1
    while O.iter < last:
        recorder()
        if recorder.stopped:
            step()
            return
        for _ in range(min(recorder.period, last - O.iter)):
            step()


def main(scene_path, out_path, csv_path=None, describe=False, wait=True, deadline=None, flush_s=None):
    """Run one scene in this YADE process: read the JSON payload at ``scene_path``, build the
    clumps and contacts, run to the end or the stop rule, and write the samples to ``out_path``
    (``.npz``; ``csv_path``: also as CSV). ``describe``: print the clumps' summary as JSON and
    return without running; ``wait``: run in this thread (:func:`run_stepping`) and write
    (False: leave the run going in YADE's thread, the recorder writes when it stops);
    ``deadline`` and ``flush_s``: :meth:`Recorder.limit`. Returns the run's status."""
    with open(scene_path) as fh:
        scene = json.load(fh)
    recorder, clumps = prepare(scene, out_path, csv_path, stepping=wait)
    if describe:
        print(json.dumps(_describe(clumps)))
        return None
    recorder.wait = wait
    recorder.limit(deadline, flush_s)
    recorder.start = time.perf_counter()
    if not wait:
        O.run(scene["n_steps"] + 1, False)
        return None
    run_stepping(recorder, scene["n_steps"])
    recorder.write()
    if csv_path:
        print(f"{recorder.status}: wrote {out_path} and {csv_path}")
    return recorder.status


def reset():
    """Leave nothing of a scene for the next: stop the run, a new empty scene (bodies,
    interactions, engines, materials, time step, time and iteration count, periodic cell
    are the scene's), not periodic, and no recorder."""
    O.pause()
    O.wait()
    O.reset()
    O.periodic = False
    globals()["rockyade_record"] = None


def serve(fd):
    """Run scenes as they come on socket ``fd`` (the loop of ``driver_loop``, resetting YADE
    between scenes); return the exit code."""

    def run(scene, out, deadline, flush_s):
        return main(scene, out, deadline=deadline, flush_s=flush_s)

    return LOOP.serve(fd, run, hello={"yade_temp_folder": YADE_TEMP_FOLDER}, after_job=reset)


def _interactive_launcher():
    """True under ``yade run.py`` (the launcher's console stays open: do not block it)."""
    runtime = sys.modules.get("yade.runtime")
    opts = getattr(runtime, "opts", None)
    return opts is not None and not getattr(opts, "exitAfter", True)


YADE_TEMP_FOLDER = None

if __name__ == "__main__":
    launcher = "yade.runtime" in sys.modules and hasattr(sys.modules["yade.runtime"], "opts")
    if not launcher:
        YADE_TEMP_FOLDER = _remove_yade_temp_folder()
    try:
        args = sys.argv[1:]
        if args and args[0] == "--serve":
            LOOP.exit_now(serve(int(args[1])))
        elif args and args[0] == "--describe":
            main(args[1], None, describe=True)
        elif len(args) >= 2:
            main(args[0], args[1])
        else:  # a yade-script folder: the data beside this script, the output there too
            here = os.path.dirname(os.path.abspath(sys.argv[0]))
            main(
                os.path.join(here, "scene.json"),
                os.path.join(here, "result.npz"),
                os.path.join(here, "result.csv"),
                wait=not _interactive_launcher(),
            )
    except Exception:
        traceback.print_exc()
        if not launcher:
            LOOP.exit_now(1)
        raise
    if not launcher:
        LOOP.exit_now(0)
