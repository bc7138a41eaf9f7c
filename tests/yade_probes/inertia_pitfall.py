"""YADE probe: angular acceleration of a planar clump under a known torque about z.

A clump's orientation is its principal frame. With rotations blocked except about global
z (blockedDOFs "zXY"), NewtonIntegrator divides the global torque by inertia[i] of that
principal frame. For a clump whose principal axes are tilted, the default principal
inertia gives the wrong angular acceleration; an isotropic inertia (Izz, Izz, Izz) gives
the right one. Prints JSON: expected and measured angular accelerations for both.
"""

import json
import sys

sys.path.insert(1, "/usr/lib/x86_64-linux-gnu/yade-double/py")
from yade import ForceResetter, NewtonIntegrator, O, Vector3, utils

TORQUE = 10.0
out = {}
for mode in ("principal", "isotropic"):
    O.reset()
    O.dt = 1e-4
    # members: an L-shaped layout whose principal axes are tilted in the x-y plane
    members = [utils.sphere(c, 0.05) for c in ((0, 0, 0), (0.4, 0, 0), (0.8, 0, 0), (0, 0.3, 0), (0.1, 0.9, 0.2))]
    cid, _ = O.bodies.appendClumped(members)
    st = O.bodies[cid].state
    # the true inertia about global z through the centre of mass
    izz = sum(
        O.bodies[m].state.mass
        * ((O.bodies[m].state.pos[0] - st.pos[0]) ** 2 + (O.bodies[m].state.pos[1] - st.pos[1]) ** 2)
        + 0.4 * O.bodies[m].state.mass * 0.05**2
        for m in _
    )
    out["principal_inertia"] = list(st.inertia)
    out["izz"] = izz
    if mode == "isotropic":
        st.inertia = Vector3(izz, izz, izz)
    st.blockedDOFs = "zXY"
    O.engines = [ForceResetter(), NewtonIntegrator(damping=0.0, gravity=(0, 0, 0))]
    O.forces.setPermT(cid, Vector3(0, 0, TORQUE))
    O.run(1, True)
    out[mode] = st.angVel[2] / O.dt
out["expected"] = TORQUE / out["izz"]
print(json.dumps(out))
