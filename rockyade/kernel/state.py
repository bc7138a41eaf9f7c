"""The kernel's inputs as five records (named tuples of arrays and scalars, which numba
passes as one argument each): what the bodies are, how they touch, how the base moves,
how to run, and where the bodies start.

Arrays are float64 unless stated; nb bodies, maxv the most vertices of a polygon, nj joint
parameter sets. :func:`pack` makes the records from the flat arrays of
:func:`rockyade.dem.engine.model_arrays`.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray


class Bodies(NamedTuple):
    """The rigid bodies: inertia, contact polygons and per-body tolerances."""

    mass: NDArray[np.float64]  #: (nb,) kg
    inertia: NDArray[np.float64]  #: (nb,) about the centroid, kg m^2
    moving: NDArray[np.bool_]  #: (nb,) False for fixed bodies (never integrated)
    fixed: NDArray[np.bool_]  #: (nb,) not moving
    verts: NDArray[np.float64]  #: (nb, maxv, 2) polygon relative to the centroid, body frame, CCW, m
    normals: NDArray[np.float64]  #: (nb, maxv, 2) outward unit normal of edge e (vertex e to e + 1)
    edge_len: NDArray[np.float64]  #: (nb, maxv) edge lengths, m
    nverts: NDArray[np.int64]  #: (nb,) vertices of each polygon
    radius: NDArray[np.float64]  #: (nb,) largest vertex distance from the centroid, m
    scale: NDArray[np.float64]  #: (nb,) smallest width of each polygon, m
    feature_tol: NDArray[np.float64]  #: (nb,) distance within which a contact point keeps its shear spring, m
    margin: NDArray[np.float64]  #: (nb,) broad-phase box growth, m
    rest_ang: NDArray[np.float64]  #: (nb,) orientation at rest (theta = angle - rest_ang), rad
    stop_angle: NDArray[np.float64]  #: (nb,) |theta| at which a body counts as overturned, rad
    accel_points: NDArray[np.float64]  #: (nb, 2) output point relative to the centroid, body frame, m
    #: (nb, 2) resultant of the point loads, N (:mod:`rockyade.kernel.point_loads`; (0, 2): none)
    load_force: NDArray[np.float64] = np.zeros((0, 2))
    #: (nb, 2) their (M0, Q) = sums of r_b x F and r_b . F, N m (module point_loads)
    load_arm: NDArray[np.float64] = np.zeros((0, 2))


class Joints(NamedTuple):
    """Joint parameter sets and which joint each contact uses."""

    kn: NDArray[np.float64]  #: (nj,) normal stiffness, N/m
    ks: NDArray[np.float64]  #: (nj,) shear stiffness, N/m
    cn: NDArray[np.float64]  #: (nj,) normal dashpot, N s/m
    cs: NDArray[np.float64]  #: (nj,) shear dashpot, N s/m
    tanphi: NDArray[np.float64]  #: (nj,) friction coefficient tan(phi)
    base_joint: NDArray[np.int64]  #: (nb,) joint of each body against the base (-1 for fixed bodies)
    own_joint: NDArray[np.int64]  #: (nb,) each body's own joint
    pair_keys: NDArray[np.int64]  #: (np,) pairs resolved at build, key lo * (nb + 1) + hi, sorted
    pair_joint: NDArray[np.int64]  #: (np,) their joints


class BaseMotion(NamedTuple):
    """Base acceleration samples (may be empty: the base does not move)."""

    t_s: NDArray[np.float64]  #: (n,) s
    ah: NDArray[np.float64]  #: (n,) horizontal, m/s^2
    av: NDArray[np.float64]  #: (n,) vertical, m/s^2


class Settings(NamedTuple):
    """How to run: step, length, sampling and what to record."""

    g: float  #: gravity, m/s^2
    dt: float  #: time step, s
    n_steps: int  #: steps to run
    steps_per_sample: int  #: steps between samples
    mass_damping: float  #: mass-proportional viscous damping a, 1/s (0 in the paper)
    stop_on_overturn: bool  #: end the run when a moving body reaches its stop angle
    record_energy: bool  #: record the energy terms
    record_corners: bool  #: record the contact state of every vertex
    coherent: bool  #: keep a pair's separating-axis answer while it cannot change


class Initial(NamedTuple):
    """Initial state (the velocities at t = -dt/2 of the leap-frog scheme)."""

    pos: NDArray[np.float64]  #: (nb, 2) centroids, m
    ang: NDArray[np.float64]  #: (nb,) angles, rad
    vel: NDArray[np.float64]  #: (nb, 2) m/s
    angvel: NDArray[np.float64]  #: (nb,) rad/s


def pack(
    arrays: Mapping[str, object],
    *,
    stop_on_overturn: bool,
    record_energy: bool,
    record_corners: bool,
    coherent: bool,
) -> tuple[Bodies, Joints, BaseMotion, Settings, Initial]:
    """The kernel's records from the flat arrays of :func:`rockyade.dem.engine.model_arrays`
    (keys as the records' fields; ``mt``, ``mah``, ``mav`` the motion; ``pos0`` ... the
    initial state) and the run's flags."""
    a = arrays
    moving = np.ascontiguousarray(a["moving"], dtype=np.bool_)
    bodies = Bodies(
        mass=_f(a["mass"]),
        inertia=_f(a["inertia"]),
        moving=moving,
        fixed=~moving,
        verts=_f(a["verts"]),
        normals=_f(a["normals"]),
        edge_len=_f(a["edge_len"]),
        nverts=_i(a["nverts"]),
        radius=_f(a["radius"]),
        scale=_f(a["scale"]),
        feature_tol=_f(a["feature_tol"]),
        margin=_f(a["margin"]),
        rest_ang=_f(a["rest_ang"]),
        stop_angle=_f(a["stop_angle"]),
        accel_points=_f(a["accel_points"]),
        load_force=_f(a.get("load_force", np.zeros((0, 2)))),
        load_arm=_f(a.get("load_arm", np.zeros((0, 2)))),
    )
    joints = Joints(
        kn=_f(a["kn"]),
        ks=_f(a["ks"]),
        cn=_f(a["cn"]),
        cs=_f(a["cs"]),
        tanphi=_f(a["tanphi"]),
        base_joint=_i(a["base_joint"]),
        own_joint=_i(a["own_joint"]),
        pair_keys=_i(a["pair_keys"]),
        pair_joint=_i(a["pair_joint"]),
    )
    motion = BaseMotion(_f(a["mt"]), _f(a["mah"]), _f(a["mav"]))
    settings = Settings(
        g=float(a["g"]),  # type: ignore[arg-type]
        dt=float(a["dt"]),  # type: ignore[arg-type]
        n_steps=int(a["n_steps"]),  # type: ignore[call-overload]
        steps_per_sample=int(a["steps_per_sample"]),  # type: ignore[call-overload]
        mass_damping=float(a["mass_damping"]),  # type: ignore[arg-type]
        stop_on_overturn=bool(stop_on_overturn),
        record_energy=bool(record_energy),
        record_corners=bool(record_corners),
        coherent=bool(coherent),
    )
    initial = Initial(_f(a["pos0"]), _f(a["ang0"]), _f(a["vel0"]), _f(a["angvel0"]))
    return bodies, joints, motion, settings, initial


def _f(x: object) -> NDArray[np.float64]:
    return np.ascontiguousarray(x, dtype=np.float64)


def _i(x: object) -> NDArray[np.int64]:
    return np.ascontiguousarray(x, dtype=np.int64)
