"""The time history of a Housner run: rotation, centroid displacement and point accelerations
(the columns of a Result, :mod:`rockyade.result`)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rockyade.blocks.geometry import Block
from rockyade.housner.integrator import Trajectory
from rockyade.housner.sdof import HousnerModel
from rockyade.motion.ground import GroundMotion
from rockyade.result import column
from rockyade.scene import Scene


def housner_frame(
    scene: Scene, block: Block, model: HousnerModel, motion: GroundMotion | None, traj: Trajectory
) -> pd.DataFrame:
    """The Result's time history: rotation, centroid displacement, point accelerations.

    Kinematics about the active pivot, placed at the equivalent base b_eq = h tan(alpha)
    (the real corners when alpha comes from the geometry).
    """
    times, theta, omega, alpha_dd = traj.t_s, traj.theta_rad, traj.omega_rad_s, traj.theta_dd_rad_s2
    ah = motion.horizontal(times) if motion is not None else np.zeros_like(times)
    av = motion.vertical(times) if motion is not None else np.zeros_like(times)
    cx, cy = block.centroid_m
    pivot_left = np.array([cx - cy * math.tan(model.alpha_left), 0.0])
    pivot_right = np.array([cx + cy * math.tan(model.alpha_right), 0.0])
    if scene.output.accel_point == "top_centre":
        point = np.array([cx, block.height_m])
    else:
        point = np.asarray(scene.output.accel_point, dtype=float)
    pivots = np.where((theta >= 0)[:, None], pivot_left, pivot_right)
    c, s = np.cos(theta), np.sin(theta)
    g0 = np.array([cx, cy]) - pivots
    gx = pivots[:, 0] + c * g0[:, 0] - s * g0[:, 1]
    gy = pivots[:, 1] + s * g0[:, 0] + c * g0[:, 1]
    q0 = point - pivots
    rx = c * q0[:, 0] - s * q0[:, 1]
    ry = s * q0[:, 0] + c * q0[:, 1]
    ax = -alpha_dd * ry - omega**2 * rx + ah
    ay = alpha_dd * rx - omega**2 * ry + av
    name = scene.blocks[0].name
    names = [name]
    frame = pd.DataFrame(
        {
            "t_s": times,
            "ag_m_s2": ah,
            column(name, "theta_rad", names): theta,
            column(name, "omega_rad_s", names): omega,
            column(name, "x_m", names): gx - cx,
            column(name, "y_m", names): gy - cy,
            column(name, "ax_m_s2", names): ax,
            column(name, "ay_m_s2", names): ay,
        }
    )
    if scene.output.accel_lowpass_hz:
        from rockyade.motion.processing import lowpass_zero_phase

        for q in ("ax_m_s2", "ay_m_s2"):
            col = column(name, q, names)
            frame[col] = lowpass_zero_phase(frame[col].to_numpy(), scene.sample_dt_s, scene.output.accel_lowpass_hz)
    return frame
