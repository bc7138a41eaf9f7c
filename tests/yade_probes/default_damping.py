"""YADE probe: NewtonIntegrator's default damping is 0.2, not 0.

A free clump under a steady torque about z, spinning the same way: with damping 0 its
angular acceleration is torque / I; YADE's default (non-viscous) damping of 0.2 reduces
it to 0.8 torque / I. Prints JSON: the default value and both accelerations.
"""

import json
import sys

sys.path.insert(1, "/usr/lib/x86_64-linux-gnu/yade-double/py")
from yade import ForceResetter, NewtonIntegrator, O, Vector3, utils

TORQUE = 1.0
out = {"default_damping": NewtonIntegrator().damping}
for label, newton in (
    ("default", NewtonIntegrator(gravity=(0, 0, 0))),
    ("zero", NewtonIntegrator(damping=0.0, gravity=(0, 0, 0))),
):
    O.reset()
    O.dt = 1e-4
    cid, _ = O.bodies.appendClumped([utils.sphere((0, 0, 0), 0.1), utils.sphere((0.3, 0, 0), 0.1)])
    st = O.bodies[cid].state
    inertia = st.inertia[2]
    st.inertia = Vector3(inertia, inertia, inertia)
    st.blockedDOFs = "zXY"
    st.angVel = Vector3(0, 0, 1.0)
    O.engines = [ForceResetter(), newton]
    O.forces.setPermT(cid, Vector3(0, 0, TORQUE))
    O.run(100, True)
    out[label] = (st.angVel[2] - 1.0) / (100 * O.dt)
    out["expected"] = TORQUE / inertia
print(json.dumps(out))
