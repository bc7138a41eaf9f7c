"""Running the numba kernel on a DEM model: the model as arrays, the compiled kernel warmed
up before it is timed, and the raw sampled outputs.

Both the reference DEM solver and the matched calibration run models through here.
"""

from __future__ import annotations

import math
import time
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from rockyade.dem.model import DemModel
from rockyade.kernel import simulation as kernel
from rockyade.kernel.broadphase import MARGIN_REL
from rockyade.kernel.single import simulate_single, single_body
from rockyade.kernel.state import pack

#: A contact point keeps its shear spring when last step's point of the same pair lies within
#: this fraction of the shortest edge of the two polygons.
FEATURE_TOL_REL = 0.25


class KernelOutput(NamedTuple):
    """Raw outputs of :func:`rockyade.kernel.simulation.simulate` (the fields of
    :class:`rockyade.kernel.recording.Output`).

    The first ten fields keep the order of earlier versions, so positional unpacking of
    ``pos, ang, ...`` keeps working.
    """

    pos: NDArray[np.float64]
    ang: NDArray[np.float64]
    angvel: NDArray[np.float64]
    vpoint: NDArray[np.float64] | None  # None: a batched run (rockyade.kernel.runs) keeps no history of it
    corner_states: NDArray[np.int8] | None
    energy: NDArray[np.float64] | None
    status: int
    n_filled: int
    t_stop: float
    stop_body: int
    n_contacts: NDArray[np.int32] | None
    slipping: NDArray[np.bool_] | None
    overturn_time: NDArray[np.float64]
    n_builds: int
    max_pairs: int
    n_tests: int


def polygon_arrays(polygons: list[NDArray[np.float64]]) -> dict[str, NDArray]:
    """Padded vertex, normal and edge-length arrays and the per-body tolerances.

    Parameters
    ----------
    polygons
        Convex polygons relative to their centroids, counter-clockwise, m.
    """
    nb = len(polygons)
    maxv = max(len(p) for p in polygons)
    verts = np.zeros((nb, maxv, 2))
    normals = np.zeros((nb, maxv, 2))
    edge_len = np.ones((nb, maxv))
    nverts = np.zeros(nb, dtype=np.int64)
    radius = np.zeros(nb)
    scale = np.zeros(nb)
    feature_tol = np.zeros(nb)
    for i, poly in enumerate(polygons):
        p = np.asarray(poly, dtype=float)
        n = len(p)
        edges = np.roll(p, -1, axis=0) - p
        length = np.hypot(edges[:, 0], edges[:, 1])
        out = np.column_stack([edges[:, 1], -edges[:, 0]]) / length[:, None]  # outward for CCW
        verts[i, :n] = p
        normals[i, :n] = out
        edge_len[i, :n] = length
        nverts[i] = n
        radius[i] = float(np.max(np.hypot(p[:, 0], p[:, 1]))) * (1 + 1e-9)
        # smallest width of a convex polygon: over its edges, the depth of the farthest vertex
        depth = np.einsum("evk,ek->ev", p[None, :, :] - p[:, None, :], out)  # (v - p_e) . n_e <= 0
        scale[i] = float(np.min(-depth.min(axis=1)))
        feature_tol[i] = FEATURE_TOL_REL * float(length.min())
    return {
        "verts": verts,
        "normals": normals,
        "edge_len": edge_len,
        "nverts": nverts,
        "radius": radius,
        "scale": scale,
        "feature_tol": feature_tol,
        "margin": MARGIN_REL * scale,
    }


def model_arrays(model: DemModel, stop_angle_rad: NDArray[np.float64] | None = None) -> dict[str, object]:
    """The kernel's inputs for a model, as flat arrays (:func:`rockyade.kernel.state.pack`
    makes the kernel's records of them).

    Parameters
    ----------
    stop_angle_rad
        (nb,) |theta| at which each body counts as overturned; default the model's landing
        angles (:mod:`rockyade.dem.overturn`), or pi/2 for a model without them.
    """
    bodies = model.bodies
    nb = len(bodies)
    table = model.joints
    params = table.params
    if stop_angle_rad is None:
        stop_angle_rad = model.stop_angle_rad if model.stop_angle_rad is not None else np.full(nb, 0.5 * math.pi)
    stop = np.asarray(stop_angle_rad, dtype=float)
    moving = np.array([not b.fixed for b in bodies], dtype=bool)
    stop = np.where(moving, stop, math.inf)
    motion = model.motion
    return {
        "mass": np.array([b.mass_kg for b in bodies], dtype=float),
        "inertia": np.array([b.inertia_kgm2 for b in bodies], dtype=float),
        "moving": moving,
        **polygon_arrays([b.contact_vertices_m for b in bodies]),
        "kn": np.array([j.K_N_per_m for j in params], dtype=float),
        "ks": np.array([j.Ks_N_per_m for j in params], dtype=float),
        "cn": np.array([j.beta_s * j.K_N_per_m for j in params], dtype=float),
        "cs": np.array([j.beta_s * j.Ks_N_per_m for j in params], dtype=float),
        "tanphi": np.array([math.tan(math.radians(j.friction_angle_deg)) for j in params], dtype=float),
        "base_joint": np.asarray(table.base_joint, dtype=np.int64),
        "own_joint": np.asarray(table.own_joint, dtype=np.int64),
        "pair_keys": np.asarray(table.pair_a, dtype=np.int64) * (nb + 1) + np.asarray(table.pair_b, dtype=np.int64),
        "pair_joint": np.asarray(table.pair_joint, dtype=np.int64),
        "mass_damping": float(model.mass_damping_1_s),
        "pos0": model.pos0_m.astype(float),
        "ang0": model.ang0_rad.astype(float),
        "vel0": model.vel0_m_s.astype(float),
        "angvel0": model.angvel0_rad_s.astype(float),
        "rest_ang": np.array([b.rest_angle_rad for b in bodies], dtype=float),
        "stop_angle": stop,
        "mt": np.zeros(0) if motion is None else np.asarray(motion.t_s, dtype=float),
        "mah": np.zeros(0) if motion is None else np.asarray(motion.ah_m_s2, dtype=float),
        "mav": np.zeros(0) if motion is None else np.asarray(motion.av_m_s2, dtype=float),
        "g": float(model.g),
        "dt": float(model.dt_s),
        "n_steps": int(model.n_steps),
        "steps_per_sample": int(model.steps_per_sample),
        "accel_points": np.array([b.accel_point_m for b in bodies], dtype=float),
        "load_force": np.zeros((nb, 2)) if model.load_force_N is None else np.asarray(model.load_force_N, dtype=float),
        "load_arm": np.zeros((nb, 2)) if model.load_arm_Nm is None else np.asarray(model.load_arm_Nm, dtype=float),
    }


def simulate_model(
    model: DemModel,
    record_energy: bool = True,
    *,
    record_corners: bool = False,
    stop_on_overturn: bool = True,
    stop_angle_rad: NDArray[np.float64] | None = None,
    coherent: bool = True,
) -> tuple[KernelOutput, float]:
    """Run the kernel on a model; return its raw outputs and the kernel's wall time (s).

    Parameters
    ----------
    record_energy
        Record the energy terms.
    record_corners
        Record the contact state of every vertex (open, stick, slip).
    stop_on_overturn
        End the run when a moving body reaches its stop angle (column scenes); else only
        record when each body first did (assemblies: a falling block does not end a wall's run).
    stop_angle_rad
        (nb,) stop angles, rad; default the model's (landing angles, :mod:`rockyade.dem.overturn`).
    coherent
        Keep each pair's separating-axis answer while the pair has not moved enough to
        change it (False: test every candidate pair every step; same results, slower).

    One moving body without energy terms takes the single-body path (:mod:`rockyade.kernel.single`,
    the same results bit for bit). The compiled kernel is loaded (or compiled) before the timer starts.
    """
    records = pack(
        model_arrays(model, stop_angle_rad),
        stop_on_overturn=stop_on_overturn,
        record_energy=record_energy,
        record_corners=record_corners,
        coherent=coherent,
    )
    single = single_body(records[0], records[1], record_energy)
    warm_up(single)
    start = time.perf_counter()
    out = simulate_single(*records) if single else kernel.simulate(*records)
    return KernelOutput(*out), time.perf_counter() - start


_WARM: set[str] = set()


def warm_up(single: bool = False, runs: bool = False) -> None:
    """Run the kernel (``single``: the single-body path, :mod:`rockyade.kernel.single`;
    ``runs``: many runs at once, :mod:`rockyade.kernel.runs`) once on a tiny problem so that
    its loading is not timed."""
    key = "runs" if runs else "single" if single else "general"
    if key in _WARM:
        return
    _WARM.add(key)
    if runs:
        from rockyade.kernel.runs import simulate_runs

        b, j, _, s, i = pack(
            tiny_problem(), stop_on_overturn=True, record_energy=False, record_corners=False, coherent=True
        )
        empty = np.zeros(0)
        simulate_runs(b, j, s, i, empty, empty, empty, np.zeros(2, dtype=np.int64), 1e-3, 1e-4)
        return
    if single:
        simulate_single(
            *pack(tiny_problem(), stop_on_overturn=True, record_energy=False, record_corners=True, coherent=True)
        )
        return
    flags = {"stop_on_overturn": True, "record_energy": True, "record_corners": True, "coherent": True}
    kernel.simulate(*pack(tiny_problem(), **flags))


def tiny_problem() -> dict[str, object]:
    """The flat arrays of a 0.2 m square resting on the base, two steps of 0.1 ms (the
    kernel's warm-up)."""
    square = np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]])
    one = np.ones(1)
    zero = np.zeros(1)
    return {
        "mass": one,
        "inertia": one,
        "moving": np.ones(1, dtype=bool),
        **polygon_arrays([square]),
        "kn": one * 1e6,
        "ks": one * 1e6,
        "cn": zero,
        "cs": zero,
        "tanphi": one,
        "base_joint": np.zeros(1, dtype=np.int64),
        "own_joint": np.zeros(1, dtype=np.int64),
        "pair_keys": np.zeros(0, dtype=np.int64),
        "pair_joint": np.zeros(0, dtype=np.int64),
        "mass_damping": 0.0,
        "pos0": np.array([[0.0, 0.1]]),
        "ang0": zero,
        "vel0": np.zeros((1, 2)),
        "angvel0": zero,
        "rest_ang": zero,
        "stop_angle": one,
        "mt": np.zeros(0),
        "mah": np.zeros(0),
        "mav": np.zeros(0),
        "g": 9.81,
        "dt": 1e-4,
        "n_steps": 2,
        "steps_per_sample": 1,
        "accel_points": np.zeros((1, 2)),
        "load_force": np.zeros((1, 2)),
        "load_arm": np.zeros((1, 2)),
    }
