"""The reference DEM: a standalone rigid-polygon DEM (numpy + numba) with the paper's joint.

It reads the same :class:`~rockyade.dem_model.DemModel` as the YADE backend and returns the
common Result schema, plus contact states per corner (``<block>_c<i>_state``: open, stick
or slip; corners numbered counter-clockwise from the bottom left) and energy terms
(``energy_*_J``, ``work_base_J`` and ``energy_balance_error_J``).

Accelerations (``ax_m_s2``, ``ay_m_s2``) are absolute, at the output point, and are the
mean over +/- one sample interval (central difference of the point velocity), which
keeps the impact spikes from aliasing; ``[output] accel_lowpass_hz`` adds a zero-phase
low-pass (paper Section 6.1).
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
import pandas as pd

from rockyade import __version__
from rockyade.dem_model import DemModel, build_dem_model
from rockyade.dem_result import dem_frame, energy_gain
from rockyade.result import Result, failed_result
from rockyade.scene import Scene
from rockyade.solvers.reference import kernel


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
    joint = [b.joint for b in model.bodies]
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


def run_model(
    model: DemModel,
    *,
    record_energy: bool = True,
    record_contacts: bool = True,
    accel_lowpass_hz: float | None = None,
) -> Result:
    """Run a DEM model and return a Result (see module docstring)."""
    out, wall = simulate_model(model, record_energy)
    pos_s, ang_s, angvel_s, vpoint_s, state_s, energy_s, status, n_filled, t_stop, stop_body = out
    n = int(n_filled)
    names = model.names
    frame = dem_frame(
        model,
        pos_s[:n],
        ang_s[:n],
        angvel_s[:n],
        vpoint_s[:n],
        state_s[:n] if record_contacts else None,
        accel_lowpass_hz,
    )
    meta_energy: dict[str, float] = {}
    if record_energy and n:
        e = energy_s[:n]
        e_pot_rest = sum(b.mass_kg * model.g * b.rest_centroid_m[1] for b in model.bodies)
        total = (
            e[:, kernel.E_KIN]
            + e[:, kernel.E_POT]
            + e[:, kernel.E_EL]
            + e[:, kernel.E_DASH]
            + e[:, kernel.E_FRIC]
            - e[:, kernel.W_BASE]
        )
        error = total - total[0]
        energy = pd.DataFrame(
            {
                "energy_kinetic_J": e[:, kernel.E_KIN],
                "energy_potential_J": e[:, kernel.E_POT] - e_pot_rest,
                "energy_elastic_J": e[:, kernel.E_EL],
                "energy_dashpot_J": e[:, kernel.E_DASH],
                "energy_friction_J": e[:, kernel.E_FRIC],
                "work_base_J": e[:, kernel.W_BASE],
                "energy_balance_error_J": error,
            }
        )
        frame = pd.concat([frame, energy], axis=1)
        initial_pe = float(e[0, kernel.E_POT] - e_pot_rest)
        meta_energy = {
            "energy_balance_max_error_J": float(np.max(np.abs(error))),
            "initial_potential_energy_J": initial_pe,
        }
    gain, t_blowup = energy_gain(model, pos_s[:n], ang_s[:n], angvel_s[:n])
    status_name = {
        kernel.STATUS_COMPLETED: "completed",
        kernel.STATUS_OVERTURNED: "overturned",
        kernel.STATUS_FAILED: "failed",
    }[int(status)]
    if t_blowup is not None and status_name != "failed":
        status_name, t_stop = "failed", t_blowup
    meta = {
        "solver": "reference",
        "version": f"rockyade {__version__} reference DEM (numba {numba.__version__})",
        "scene_hash": model.scene_hash,
        "wall_time_s": wall,
        "status": status_name,
        "overturn_time_s": float(t_stop) if status_name == "overturned" else None,
        "overturned_block": names[int(stop_body)] if status_name == "overturned" else None,
        "overturn_criterion": "|theta| reached pi/2",
        "failure_reason": (
            f"numerical instability at t = {t_stop:.6g} s (energy created: {gain:.3g} x weight x height; or a "
            f"non-finite state, speed > {kernel.MAX_SPEED_M_S:g} m/s or spin > {kernel.MAX_SPIN_RAD_S:g} rad/s)"
            if status_name == "failed"
            else None
        ),
        "blocks": names,
        "sample_dt_s": model.sample_dt_s,
        "duration_s": model.duration_s,
        "dt_s": model.dt_s,
        "dt_source": model.dt_source,
        "dt_eq7_s": model.dt_eq7_s,
        "dt_stability_limit_s": model.dt_stable_s,
        "n_steps": model.n_steps,
        "ns_per_step": 1e9 * wall / max(1, model.n_steps),
        "calibration": model.calibration,
        "contact": model.joint_summary(),
        "bodies": model.body_summary(),
        "motion": model.motion.label if model.motion is not None else "free",
        "accel_definition": "absolute, mean over +/- one sample interval"
        + (f", zero-phase low-pass {accel_lowpass_hz:g} Hz" if accel_lowpass_hz else ""),
        **meta_energy,
    }
    return Result(frame, meta)


def run_scene(scene: Scene, *, record_energy: bool = True, record_contacts: bool = True) -> Result:
    """Run a scene with the reference DEM.

    The returned ``wall_time_s`` is the kernel's; ``setup_time_s`` is the model build
    (including a matched calibration when asked for).
    """
    start = time.perf_counter()
    model = build_dem_model(scene)
    setup = time.perf_counter() - start
    result = run_model(
        model,
        record_energy=record_energy,
        record_contacts=record_contacts,
        accel_lowpass_hz=scene.output.accel_lowpass_hz,
    )
    result.meta["setup_time_s"] = setup
    return result


def _run_quiet(scene: Scene, record_energy: bool, record_contacts: bool) -> Result:
    try:
        return run_scene(scene, record_energy=record_energy, record_contacts=record_contacts)
    except Exception as exc:  # one failed scene must not stop a batch
        return failed_result("reference", scene.scene_hash, f"{type(exc).__name__}: {exc}")


def run_many(
    scenes: Iterable[Scene],
    workers: int = 2,
    *,
    record_energy: bool = False,
    record_contacts: bool = False,
) -> list[Result]:
    """Run many scenes in one call on ``workers`` threads (the kernel releases the GIL).

    A scene that fails gives a Result with status ``failed`` and the reason; the others
    are unaffected. Results come back in the order of ``scenes``.
    """
    scene_list: Sequence[Scene] = list(scenes)
    if workers <= 1:
        return [_run_quiet(s, record_energy, record_contacts) for s in scene_list]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(lambda s: _run_quiet(s, record_energy, record_contacts), scene_list))
