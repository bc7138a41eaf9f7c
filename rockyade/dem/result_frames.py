"""Time histories of a DEM run as a Result frame (shared by the reference DEM and YADE).

From sampled centroid positions, rotations, angular velocities, velocities of the output
point and corner states, both DEM solvers build the same columns: ``t_s``, ``ag_m_s2``,
per block ``theta_rad``, ``omega_rad_s``, ``x_m``, ``y_m`` (centroid displacement from
rest), ``ax_m_s2``, ``ay_m_s2`` (absolute acceleration of the output point: mean over
+/- one sample interval, the central difference of its velocity, plus the base
acceleration; optionally low-passed); optionally per block ``n_contacts`` (contact points on
the block) and ``slipping`` (one of them slips), and per corner ``c<i>_state`` (open /
stick / slip).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from rockyade.dem.model import DemModel
from rockyade.result import column

STATE_NAMES = np.array(["open", "stick", "slip"])


def dem_frame(
    model: DemModel,
    pos: np.ndarray,
    ang: np.ndarray,
    angvel: np.ndarray,
    vpoint: np.ndarray,
    states: np.ndarray | None,
    accel_lowpass_hz: float | None = None,
    *,
    n_contacts: np.ndarray | None = None,
    slipping: np.ndarray | None = None,
) -> pd.DataFrame:
    """Result frame from sampled arrays.

    Parameters
    ----------
    model
        The DEM model run.
    pos, vpoint
        (n, nb, 2) centroid positions (base frame) and output-point velocities, m, m/s.
    ang, angvel
        (n, nb) rotations from rest (rad) and angular velocities (rad/s).
    states
        (n, nb, maxv) corner states 0 open, 1 stick, 2 slip; None to leave them out.
    accel_lowpass_hz
        Optional zero-phase low-pass of the accelerations.
    n_contacts, slipping
        (n, nb) contact points on each block and whether one of them slips; None to leave
        them out.
    """
    n = pos.shape[0]
    names = model.names
    t = np.arange(n) * model.sample_dt_s
    motion = model.motion
    ah = motion.horizontal(t) if motion is not None else np.zeros(n)
    av = motion.vertical(t) if motion is not None else np.zeros(n)
    data: dict[str, object] = {"t_s": t, "ag_m_s2": ah}
    for i, body in enumerate(model.bodies):
        rest = np.asarray(body.rest_centroid_m)
        data[column(body.name, "theta_rad", names)] = ang[:, i] - body.rest_angle_rad
        data[column(body.name, "omega_rad_s", names)] = angvel[:, i]
        data[column(body.name, "x_m", names)] = pos[:, i, 0] - rest[0]
        data[column(body.name, "y_m", names)] = pos[:, i, 1] - rest[1]
        for axis, q, base in ((0, "ax_m_s2", ah), (1, "ay_m_s2", av)):
            v = vpoint[:, i, axis]
            acc = (np.gradient(v, model.sample_dt_s) if n >= 2 else np.zeros(n)) + base
            if accel_lowpass_hz:
                from rockyade.motion.processing import lowpass_zero_phase

                acc = lowpass_zero_phase(acc, model.sample_dt_s, accel_lowpass_hz)
            data[column(body.name, q, names)] = acc
    if n_contacts is not None and slipping is not None:
        for i, body in enumerate(model.bodies):
            data[column(body.name, "n_contacts", names)] = n_contacts[:, i].astype(np.int32)
            data[column(body.name, "slipping", names)] = slipping[:, i].astype(bool)
    if states is not None:
        for i, body in enumerate(model.bodies):
            prefix = f"{body.name}_" if len(names) > 1 else ""
            for corner in range(len(body.contact_vertices_m)):
                data[f"{prefix}c{corner}_state"] = pd.Categorical(
                    STATE_NAMES[states[:, i, corner]], categories=STATE_NAMES
                )
    return pd.DataFrame(data)


#: A run whose mechanical energy exceeds its initial energy plus the work of the base by
#: more than this fraction of the blocks' weight times their centroid height is a numerical
#: blow-up (the DEM cannot create energy), whatever its rotation says.
ENERGY_GROWTH_LIMIT = 0.5


def energy_gain(model: DemModel, pos: np.ndarray, ang: np.ndarray, angvel: np.ndarray) -> tuple[float, float | None]:
    """Largest gain of mechanical energy over the base's work, as a fraction of the blocks'
    weight times centroid height, and the time it first exceeds ``ENERGY_GROWTH_LIMIT``.

    Velocities of the centroids come from the sampled positions (central differences), so
    this is a coarse physical check for blow-ups, not an energy balance.
    """
    n = pos.shape[0]
    if n < 3:
        return 0.0, None
    dt = model.sample_dt_s
    t = np.arange(n) * dt
    motion = model.motion
    ah = motion.horizontal(t) if motion is not None else np.zeros(n)
    av = motion.vertical(t) if motion is not None else np.zeros(n)
    energy = np.zeros(n)
    work = np.zeros(n)
    scale = 0.0
    for i, body in enumerate(model.bodies):
        if body.fixed:
            continue
        v = np.gradient(pos[:, i, :], dt, axis=0)
        rest_y = body.rest_centroid_m[1]
        energy += 0.5 * body.mass_kg * (v**2).sum(axis=1) + 0.5 * body.inertia_kgm2 * angvel[:, i] ** 2
        energy += body.mass_kg * model.g * (pos[:, i, 1] - rest_y)
        power = -body.mass_kg * (ah * v[:, 0] + av * v[:, 1])
        work += np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * dt)])
        scale += body.mass_kg * model.g * rest_y  # weight times centroid height above the base
    work += load_work(model, pos, ang)
    if scale <= 0.0:
        return 0.0, None
    gain = (energy - energy[0] - work) / scale
    bad = np.nonzero(gain > ENERGY_GROWTH_LIMIT)[0]
    return float(np.nanmax(gain)), (float(t[bad[0]]) if bad.size else None)


def load_work(model: DemModel, pos: np.ndarray, ang: np.ndarray) -> np.ndarray:
    """Work done by the point loads from the first sample, J (zeros without loads).

    A dead load F at a body point moving from x_i to x_{i+1} does the work F . (x_{i+1} - x_i);
    its scale s = (g + a_v) / g (:mod:`rockyade.kernel.point_loads`) is taken as the mean of
    the two samples' (exact when s is constant).

    Parameters
    ----------
    pos, ang
        (n, nb, 2) sampled centroids, m, and (n, nb) angles, rad.
    """
    n = pos.shape[0]
    if model.load_force_N is None or model.load_arm_Nm is None or n == 0:
        return np.zeros(n)
    t = np.arange(n) * model.sample_dt_s
    av = model.motion.vertical(t) if model.motion is not None else np.zeros(n)
    scale = (model.g + av) / model.g
    potential = np.zeros(n)  # sum of F . x_point, J
    for i, body in enumerate(model.bodies):
        fx, fy = model.load_force_N[i]
        m0, q = model.load_arm_Nm[i]
        if body.fixed or not (fx or fy or m0 or q):
            continue
        # F . (R(ang) r_b) = cos(ang) (r_b . F) + sin(ang) (r_b x F) summed over the body's loads
        potential += fx * pos[:, i, 0] + fy * pos[:, i, 1] + np.cos(ang[:, i]) * q + np.sin(ang[:, i]) * m0
    steps = 0.5 * (scale[1:] + scale[:-1]) * np.diff(potential)
    return np.concatenate([[0.0], np.cumsum(steps)])


def worker_frame(model: DemModel, arrays: dict[str, np.ndarray], lowpass: float | None) -> pd.DataFrame:
    """A worker's (YADE's, Siconos's) output arrays as the common time history (:func:`dem_frame`),
    plus the normal force of every contact vertex (``c<i>_fn_N``, N)."""
    frame = dem_frame(
        model,
        arrays["pos"],
        arrays["ang"],
        arrays["angvel"],
        arrays["vpoint"],
        arrays["state"],
        lowpass,
        n_contacts=arrays["ncont"],
        slipping=arrays["slip"],
    )
    names = model.names
    forces = {}
    for i, body in enumerate(model.bodies):
        prefix = f"{body.name}_" if len(names) > 1 else ""
        for v in range(len(body.contact_vertices_m)):
            forces[f"{prefix}c{v}_fn_N"] = arrays["fn"][:, i, v]
    return pd.concat([frame, pd.DataFrame(forces, index=frame.index)], axis=1)
