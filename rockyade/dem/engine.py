"""Running the numba kernel on a DEM model: the model as arrays, the compiled kernel warmed
up before it is timed, and the raw sampled outputs.

Both the reference DEM solver and the matched calibration run models through here.
"""

from __future__ import annotations

import math
import time

import numpy as np

from rockyade.dem import kernel
from rockyade.dem.model import DemModel
from rockyade.errors import InputError


def model_arrays(model: DemModel) -> dict[str, object]:
    """The kernel's inputs for a model."""
    nb = len(model.bodies)
    maxv = max(len(b.contact_vertices_m) for b in model.bodies)
    verts = np.zeros((nb, maxv, 2))
    nverts = np.zeros(nb, dtype=np.int64)
    for i, b in enumerate(model.bodies):
        n = len(b.contact_vertices_m)
        verts[i, :n] = b.contact_vertices_m
        nverts[i] = n
    radius = np.array([np.max(np.hypot(*b.contact_vertices_m.T)) for b in model.bodies]) * (1 + 1e-9)
    if any(b.fixed for b in model.bodies):
        raise InputError("blocks.fixed", "fixed blocks are not supported by this reference DEM kernel yet")
    joint = [model.joints.params[int(j)] for j in model.joints.base_joint]
    motion = model.motion
    return {
        "mass": np.array([b.mass_kg for b in model.bodies]),
        "inertia": np.array([b.inertia_kgm2 for b in model.bodies]),
        "verts": verts,
        "nverts": nverts,
        "radius": radius,
        "kn": np.array([j.K_N_per_m for j in joint]),
        "ks": np.array([j.Ks_N_per_m for j in joint]),
        "cn": np.array([j.beta_s * j.K_N_per_m for j in joint]),
        "cs": np.array([j.beta_s * j.Ks_N_per_m for j in joint]),
        "tanphi": np.array([math.tan(math.radians(j.friction_angle_deg)) for j in joint]),
        "mass_damping": float(model.mass_damping_1_s),
        "pos0": model.pos0_m.astype(float),
        "ang0": model.ang0_rad.astype(float),
        "vel0": model.vel0_m_s.astype(float),
        "angvel0": model.angvel0_rad_s.astype(float),
        "mt": np.zeros(0) if motion is None else motion.t_s,
        "mah": np.zeros(0) if motion is None else motion.ah_m_s2,
        "mav": np.zeros(0) if motion is None else motion.av_m_s2,
        "g": float(model.g),
        "dt": float(model.dt_s),
        "n_steps": int(model.n_steps),
        "steps_per_sample": int(model.steps_per_sample),
        "accel_points": np.array([b.accel_point_m for b in model.bodies], dtype=float),
    }


def simulate_model(model: DemModel, record_energy: bool = True) -> tuple[tuple, float]:
    """Run the kernel on a model; return its raw outputs and the kernel's wall time (s).

    The compiled kernel is loaded (or compiled) before the timer starts.
    """
    args = model_arrays(model)
    _warm_up(record_energy)
    start = time.perf_counter()
    out = kernel.simulate(**args, record_energy=record_energy)
    return out, time.perf_counter() - start


_WARM: set[bool] = set()


def _warm_up(record_energy: bool) -> None:
    """Run the kernel once on a tiny problem so that its loading is not timed."""
    if record_energy in _WARM:
        return
    _WARM.add(record_energy)
    one = np.ones(1)
    verts = np.array([[[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]])
    kernel.simulate(
        one,
        one,
        verts,
        np.array([4]),
        one * 0.2,
        one * 1e6,
        one * 1e6,
        one * 0.0,
        one * 0.0,
        one,
        0.0,
        np.array([[0.0, 0.1]]),
        np.zeros(1),
        np.zeros((1, 2)),
        np.zeros(1),
        np.zeros(0),
        np.zeros(0),
        np.zeros(0),
        9.81,
        1e-4,
        2,
        1,
        np.zeros((1, 2)),
        record_energy,
    )
