"""The time history of a two-block run: per block the rotation, the centroid's displacement
and the absolute acceleration of the output point (the columns of a Result,
:mod:`rockyade.result`, as the DEMs write them for a two-block scene)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from rockyade.motion.ground import GroundMotion
from rockyade.result import column
from rockyade.scene import Scene
from rockyade.twoblock.stack import TwoBlockModel
from rockyade.twoblock.trajectory import TwoBlockTrajectory


def _rotate(theta: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(n, 2): the rest vectors ``v`` ((n, 2) or (2,)) turned by ``theta`` (n,)."""
    c, s = np.cos(theta), np.sin(theta)
    v = np.broadcast_to(v, (theta.size, 2))
    return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]])


def _accel(dd: np.ndarray, w: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Acceleration of a point at ``r`` (n, 2) from a centre of rotation at rest: dd k x r - w^2 r."""
    return np.column_stack([-dd * r[:, 1] - w * w * r[:, 0], dd * r[:, 0] - w * w * r[:, 1]])


def output_points(scene: Scene, model: TwoBlockModel) -> list[np.ndarray]:
    """Each block's output point (``[output] accel_point``) in the base frame at rest, m."""
    points = []
    for i, spec in enumerate(scene.blocks):
        block = spec.block()
        cx, cy = block.centroid_m
        point = scene.output.accel_point
        if isinstance(point, str):  # "top_centre", the only word the scene takes
            local = np.array([0.0, block.height_m - cy])
        else:
            local = np.array([float(point[0]) - cx, float(point[1]) - cy])
        points.append(np.asarray(model.centroid_m[i]) + local)
    return points


def two_block_frame(
    scene: Scene, model: TwoBlockModel, motion: GroundMotion | None, traj: TwoBlockTrajectory
) -> pd.DataFrame:
    """The Result's time history (module docstring).

    Positions follow the chain of pivots of each sample's mode: the lower block about its
    base corner O, the upper about its seat corner S carried by the lower block.
    """
    t = traj.t_s
    th, w, dd = traj.theta_rad, traj.omega_rad_s, traj.theta_dd_rad_s2
    sb, ss = traj.modes[:, 0], traj.modes[:, 1]
    ah = motion.horizontal(t) if motion is not None else np.zeros_like(t)
    av = motion.vertical(t) if motion is not None else np.zeros_like(t)
    ox = np.where(sb >= 0, model.base_corners_x_m[0], model.base_corners_x_m[1])
    o = np.column_stack([ox, np.zeros_like(ox)])
    sx = np.where(ss >= 0, model.seat_corners_x_m[0], model.seat_corners_x_m[1])
    s_rest = np.column_stack([sx, np.full_like(sx, model.seat_y_m)])
    g1, g2 = (np.asarray(c) for c in model.centroid_m)
    p1, p2 = output_points(scene, model)
    a_vec = _rotate(th[:, 0], g1 - o)
    c_vec = _rotate(th[:, 0], s_rest - o)
    d_vec = _rotate(th[:, 1], g2 - s_rest)
    pos = [o + a_vec, o + c_vec + d_vec]
    acc_1 = _accel(dd[:, 0], w[:, 0], _rotate(th[:, 0], p1 - o))
    acc_2 = _accel(dd[:, 0], w[:, 0], c_vec) + _accel(dd[:, 1], w[:, 1], _rotate(th[:, 1], p2 - s_rest))
    names = list(model.names)
    data: dict[str, np.ndarray] = {"t_s": t, "ag_m_s2": ah}
    for i, (rest, acc) in enumerate(((g1, acc_1), (g2, acc_2))):
        name = names[i]
        data[column(name, "theta_rad", names)] = th[:, i]
        data[column(name, "omega_rad_s", names)] = w[:, i]
        data[column(name, "x_m", names)] = pos[i][:, 0] - rest[0]
        data[column(name, "y_m", names)] = pos[i][:, 1] - rest[1]
        data[column(name, "ax_m_s2", names)] = acc[:, 0] + ah
        data[column(name, "ay_m_s2", names)] = acc[:, 1] + av
    frame = pd.DataFrame(data)
    if scene.output.accel_lowpass_hz:
        from rockyade.motion.processing import lowpass_zero_phase

        for name in names:
            for q in ("ax_m_s2", "ay_m_s2"):
                col = column(name, q, names)
                frame[col] = lowpass_zero_phase(frame[col].to_numpy(), scene.sample_dt_s, scene.output.accel_lowpass_hz)
    return frame
