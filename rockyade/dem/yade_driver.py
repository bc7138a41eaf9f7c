"""Run a rockyade DEM scene in YADE and write its time history (executed by YADE's Python).

Usage: python3.11 run_scene.py SCENE.json RESULT.npz

Runs inside Debian's /usr/bin/python3.11 with YADE's modules on the path; imports only the
standard library, numpy and YADE (never the ``yade`` launcher, which opens a Python console
and an XMLRPC server on all interfaces). The scene is data prepared by rockyade
(``rockyade.solvers.yade.scene_payload``).

The model, as the reference DEM's:

* each block is one clump: a small sphere at every contact vertex (tangent to the base
  line at a base corner, to the top line at a top corner), thin Box slabs where another
  block rests on it or it rests on another block, and a heavy non-colliding helper
  sphere at the centroid so that the clump's centre of mass is the block's centroid; the
  clump's mass and inertia are then set to the block's, with the inertia isotropic
  (Izz, Izz, Izz) because with blocked rotations NewtonIntegrator divides the global torque
  by the principal inertia of the clump's own frame;
* planar motion: blockedDOFs = "zXY";
* contacts: Law2_ScGeom_ViscElPhys_Basic with ViscElMat giving kn, ks, cn = beta kn,
  cs = beta ks and the friction angle on the spheres, and all zeros on the base and the
  slabs (Ip2 combines materials in series and skips zeros, so the sphere's values are
  used exactly); collision masks keep spheres of different blocks apart;
* the base is a fixed Box; the ground motion acts in the base frame as a force -M a_g(t)
  on each clump (InterpolatingDirectedForceEngine, linear between samples, zero after);
* NewtonIntegrator with damping 0 (its default is 0.2), gravity -g, O.dt as given;
* a PyRunner *before* the other engines records every ``steps_per_sample`` steps, so the
  sample at step n sees x_n and t_n = n dt; rotation is measured as the z component of
  the axis-angle of ori * ori0.conjugate() (State.rot() can flip sign);
* the run stops when any block reaches |theta| >= pi/2 (overturned) or a state is not
  finite (failed).
"""

import json
import math
import os
import sys
import time
import traceback

YADE_PY = os.environ.get("ROCKYADE_YADE_PY", "/usr/lib/x86_64-linux-gnu/yade-double/py")
sys.path.insert(1, YADE_PY)

import numpy as np  # noqa: E402
from yade import (  # noqa: E402
    Bo1_Box_Aabb,
    Bo1_Sphere_Aabb,
    ForceResetter,
    Ig2_Box_Sphere_ScGeom,
    Ig2_Sphere_Sphere_ScGeom,
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

BASE_HALF_SIZE = 50.0
HELPER_DENSITY = 1.0e15
# beyond these the state is a numerical blow-up, not rocking (as in the reference DEM)
MAX_SPEED_M_S = 100.0
MAX_SPIN_RAD_S = 1000.0
LIGHT_DENSITY = 1.0e-3


def _material(joint, density):
    if joint is None:
        return ViscElMat(kn=0.0, ks=0.0, cn=0.0, cs=0.0, frictionAngle=math.pi / 2 - 1e-9, density=density)
    return ViscElMat(
        kn=joint["kn"],
        ks=joint["ks"],
        cn=joint["cn"],
        cs=joint["cs"],
        frictionAngle=joint["friction_angle_rad"],
        density=density,
    )


def _rotate(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def build(scene):
    O.reset()
    O.dt = scene["dt_s"]
    bodies = scene["bodies"]
    nb = len(bodies)
    r = scene["sphere_radius_m"]
    sphere_bit = [1 << (i + 1) for i in range(nb)]
    all_spheres = sum(sphere_bit)
    zero_mat = O.materials.append(_material(None, LIGHT_DENSITY))
    helper_mat = O.materials.append(_material(None, HELPER_DENSITY))
    base_id = O.bodies.append(
        utils.box(
            center=(0, -0.5, 0),
            extents=(BASE_HALF_SIZE, 0.5, BASE_HALF_SIZE),
            fixed=True,
            material=O.materials[zero_mat],
            mask=all_spheres,
        )
    )
    clumps = []
    for i, b in enumerate(bodies):
        c0 = b["centroid0_m"]
        a0 = b["angle0_rad"]
        mat_below = O.materials.append(_material(b["joint_below"], LIGHT_DENSITY))
        mat_above = O.materials.append(_material(b["joint_above"], LIGHT_DENSITY)) if b["joint_above"] else mat_below
        members = []
        vertex_ids = []
        for (vx, vy), role in zip(b["vertices_m"], b["vertex_roles"], strict=False):
            if role == "base":
                cx, cy = vx, vy + r
            elif role == "top":
                cx, cy = vx, vy - r
            else:
                norm = math.hypot(vx, vy)
                cx, cy = vx - r * vx / norm, vy - r * vy / norm
            wx, wy = _rotate((cx, cy), a0)
            sph = utils.sphere(
                (c0[0] + wx, c0[1] + wy, 0.0),
                r,
                material=O.materials[mat_above if role == "top" else mat_below],
                mask=sphere_bit[i],
            )
            members.append(sph)
        helper = utils.sphere((c0[0], c0[1], 0.0), r, material=O.materials[helper_mat], mask=0)
        members.append(helper)
        thickness = b["thickness_m"]
        for slab in b["slabs"]:
            (sx, sy), (hx, hy) = slab["center_m"], slab["half_extents_m"]
            wx, wy = _rotate((sx, sy), a0)
            box = utils.box(
                center=(c0[0] + wx, c0[1] + wy, 0.0),
                extents=(hx, hy, 0.5 * thickness),
                orientation=Quaternion(Vector3(0, 0, 1), a0),
                material=O.materials[zero_mat],
                mask=slab["mask_bits"] and sum(sphere_bit[j] for j in slab["mask_bits"]),
            )
            members.append(box)
        clump_id, member_ids = O.bodies.appendClumped(members)
        vertex_ids = member_ids[: len(b["vertices_m"])]
        state = O.bodies[clump_id].state
        offset = (state.pos[0] - c0[0], state.pos[1] - c0[1])
        if math.hypot(*offset) > 1e-6 * max(1.0, math.hypot(*c0)):
            raise RuntimeError(f"clump centre {tuple(state.pos)} is not the centroid {c0}")
        state.mass = b["mass_kg"]
        inertia = b["inertia_kgm2"]
        state.inertia = Vector3(inertia, inertia, inertia)
        state.blockedDOFs = "zXY"
        state.vel = Vector3(b["vel0_m_s"][0], b["vel0_m_s"][1], 0.0)
        state.angVel = Vector3(0.0, 0.0, b["angvel0_rad_s"])
        clumps.append(
            {
                "id": clump_id,
                "vertex_ids": vertex_ids,
                "ori0": Quaternion(state.ori),
                "angle0": a0,
                "rest": b["rest_centroid_m"],
                "point": b["accel_point_m"],
                "mass": b["mass_kg"],
                "tanphi": math.tan(b["joint_below"]["friction_angle_rad"]),
            }
        )
    return base_id, clumps


def ground_engines(scene, clumps):
    motion = scene["motion"]
    if motion is None:
        return []
    t = list(motion["t_s"])
    engines = []
    # zero after the last sample (the reference DEM's convention), and before the first
    times = [t[0] - 1.0, *t, t[-1] + 1e-09, t[-1] + 1000000000.0]
    for key, direction in (("ah_m_s2", Vector3(1, 0, 0)), ("av_m_s2", Vector3(0, 1, 0))):
        values = list(motion[key])
        if not any(values):
            continue
        for c in clumps:
            mags = [0.0] + [-c["mass"] * a for a in values] + [0.0, 0.0]
            engines.append(
                InterpolatingDirectedForceEngine(ids=[c["id"]], times=times, magnitudes=mags, direction=direction)
            )
    return engines


def _describe(scene, clumps):
    """What was built: for tests of the YADE pitfalls (no simulation is run)."""
    newton = next(e for e in O.engines if type(e).__name__ == "NewtonIntegrator")
    runner = O.engines[0]
    out = {
        "engines": [type(e).__name__ for e in O.engines],
        "newton_damping": newton.damping,
        "gravity": list(newton.gravity),
        "dt": O.dt,
        "recorder_first": type(runner).__name__ == "PyRunner",
        "recorder_period": runner.iterPeriod,
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
                "pos": list(body.state.pos),
                "members": members,
                "vertex_ids": list(c["vertex_ids"]),
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


def main(scene_path, out_path, describe=False):
    with open(scene_path) as fh:
        scene = json.load(fh)
    start_build = time.perf_counter()
    _base_id, clumps = build(scene)
    nb = len(clumps)
    ns = scene["n_samples"]
    maxv = max(len(b["vertices_m"]) for b in scene["bodies"])
    rec = {
        "pos": np.full((ns, nb, 2), np.nan),
        "ang": np.full((ns, nb), np.nan),
        "angvel": np.full((ns, nb), np.nan),
        "vpoint": np.full((ns, nb, 2), np.nan),
        "fn": np.zeros((ns, nb, maxv)),
        "state": np.zeros((ns, nb, maxv), dtype=np.int8),
    }
    info = {"k": 0, "status": "completed", "stop_time": None, "stop_body": None}
    half_pi = 0.5 * math.pi

    def record():
        k = info["k"]
        if k >= ns:
            return
        for i, c in enumerate(clumps):
            st = O.bodies[c["id"]].state
            q = st.ori * c["ori0"].conjugate()
            axis, angle = q.toAxisAngle()
            theta = c["angle0"] + angle * axis[2]
            x, y = st.pos[0], st.pos[1]
            w = st.angVel[2]
            finite = math.isfinite(x) and math.isfinite(y) and math.isfinite(theta)
            if not finite or st.vel.norm() > MAX_SPEED_M_S or abs(w) > MAX_SPIN_RAD_S:
                info["status"], info["stop_time"], info["stop_body"] = "failed", O.time, i
                O.pause()
                return
            rec["pos"][k, i] = (x, y)
            rec["ang"][k, i] = theta
            rec["angvel"][k, i] = w
            px, py = _rotate(c["point"], theta)
            rec["vpoint"][k, i] = (st.vel[0] - w * py, st.vel[1] + w * px)
            for v, sid in enumerate(c["vertex_ids"]):
                total_fn, state = 0.0, 0
                for inter in O.interactions.withBody(sid):
                    if not inter.isReal:
                        continue
                    fn = inter.phys.normalForce.norm()
                    fs = inter.phys.shearForce.norm()
                    total_fn += fn
                    s = 2 if fn > 0 and fs >= 0.9999 * fn * c["tanphi"] else 1
                    state = max(state, s)
                rec["fn"][k, i, v] = total_fn
                rec["state"][k, i, v] = state
            if abs(theta) >= half_pi and info["status"] == "completed":
                info["status"], info["stop_time"], info["stop_body"] = "overturned", O.time, i
        info["k"] = k + 1
        if info["status"] != "completed" or info["k"] >= ns:
            O.pause()

    recorder = PyRunner(command="record_hook()", iterPeriod=scene["steps_per_sample"], initRun=True)
    globals()["record_hook"] = record
    O.engines = [
        recorder,
        ForceResetter(),
        InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Box_Aabb()], verletDist=0.2 * scene["sphere_radius_m"]),
        InteractionLoop(
            [Ig2_Sphere_Sphere_ScGeom(), Ig2_Box_Sphere_ScGeom()],
            [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
            [Law2_ScGeom_ViscElPhys_Basic()],
        ),
        *ground_engines(scene, clumps),
        NewtonIntegrator(damping=0.0, gravity=Vector3(0.0, -scene["g"], 0.0)),
    ]
    build_time = time.perf_counter() - start_build
    if describe:
        print(json.dumps(_describe(scene, clumps)))
        return
    start = time.perf_counter()
    O.run(scene["n_steps"] + 1, True)
    wall = time.perf_counter() - start
    n = info["k"]
    meta = {
        "status": info["status"],
        "stop_time_s": info["stop_time"],
        "stop_body": info["stop_body"],
        "n_filled": n,
        "iterations": O.iter,
        "wall_time_s": wall,
        "build_time_s": build_time,
        "yade_version": __import__("yade.config", fromlist=["version"]).version,
        "dt_s": O.dt,
        "complete": True,
    }
    tmp = out_path + ".part"
    with open(tmp, "wb") as fh:
        np.savez(fh, **{k: v[:n] for k, v in rec.items()}, meta=np.array(json.dumps(meta)))
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, out_path)


if __name__ == "__main__":
    try:
        if sys.argv[1] == "--describe":
            main(sys.argv[2], None, describe=True)
        else:
            main(sys.argv[1], sys.argv[2])
    except Exception:
        traceback.print_exc()
        sys.exit(1)
