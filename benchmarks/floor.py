"""A hand-written numba loop of the single block's physics: the floor that the kernel's
single-body path is measured against (same process, same model, same steps).

Two corners (the base ones), the same contact law (no-tension spring and dashpot, incremental
Coulomb-capped shear spring, shear dashpot while sticking), leap-frog, the ground motion
linear between samples, theta kept every ``steps_per_sample`` steps; nothing else (no
sanity checks beyond the overturn angle, no counts, no output point).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def floor_loop(cx, cy, mass, inertia, kn, ks, cn, cs, tanphi, g, dt, n_steps, sps, stop, mt, mah, mav, x, y, ang, out):
    """Run the block; ``cx``, ``cy``: (2,) base corners relative to the centroid, m. Returns
    the steps run."""
    vx = 0.0
    vy = 0.0
    w = 0.0
    s0 = 0.0
    s1 = 0.0
    j = 0
    n = mt.size
    step = 0
    for step in range(n_steps + 1):
        t = step * dt
        ah = 0.0
        av = 0.0
        if t <= mt[n - 1]:
            while j < n - 2 and t >= mt[j + 1]:
                j += 1
            u = (t - mt[j]) / (mt[j + 1] - mt[j])
            ah = mah[j] + u * (mah[j + 1] - mah[j])
            av = mav[j] + u * (mav[j + 1] - mav[j])
        c = math.cos(ang)
        s = math.sin(ang)
        fx = -mass * ah
        fy = -mass * (g + av)
        tz = 0.0
        for v in range(2):
            rx = c * cx[v] - s * cy[v]
            ry = s * cx[v] + c * cy[v]
            delta = -(y + ry)
            sh = s0 if v == 0 else s1
            if delta < 0.0:
                sh = 0.0
            else:
                vrx = vx - w * ry
                vry = vy + w * rx
                fn = kn * delta - cn * vry
                if fn < 0.0:
                    fn = 0.0
                st = sh - ks * dt * vrx
                smax = fn * tanphi
                visc = 0.0
                if abs(st) > smax:
                    st = smax if st > 0.0 else -smax
                else:
                    visc = -cs * vrx
                sh = st
                f = st + visc
                fx += f
                fy += fn
                tz += rx * fn - ry * f
            if v == 0:
                s0 = sh
            else:
                s1 = sh
        vx += dt * fx / mass
        vy += dt * fy / mass
        w += dt * tz / inertia
        if step % sps == 0:
            out[step // sps] = ang
        x += dt * vx
        y += dt * vy
        ang += dt * w
        if abs(ang) >= stop:
            break
    return step + 1


def floor_args(arrays: dict) -> tuple:
    """The floor's inputs from :func:`rockyade.dem.engine.model_arrays` of a one-block model."""
    a = arrays
    verts = np.asarray(a["verts"])[0, : int(a["nverts"][0])]
    low = np.argsort(verts[:, 1])[:2]
    cx = np.ascontiguousarray(verts[low, 0])
    cy = np.ascontiguousarray(verts[low, 1])
    j = int(a["base_joint"][0])
    n = int(a["n_steps"]) // int(a["steps_per_sample"]) + 1
    return (
        cx,
        cy,
        float(a["mass"][0]),
        float(a["inertia"][0]),
        float(a["kn"][j]),
        float(a["ks"][j]),
        float(a["cn"][j]),
        float(a["cs"][j]),
        float(a["tanphi"][j]),
        float(a["g"]),
        float(a["dt"]),
        int(a["n_steps"]),
        int(a["steps_per_sample"]),
        float(a["stop_angle"][0]),
        np.asarray(a["mt"], float),
        np.asarray(a["mah"], float),
        np.asarray(a["mav"], float),
        float(a["pos0"][0][0]),
        float(a["pos0"][0][1]),
        float(a["ang0"][0]),
        np.full(n, np.nan),
    )


def floor_ns_per_step(arrays: dict, repeats: int = 5) -> tuple[float, np.ndarray]:
    """Best ns/step of the floor over ``repeats`` runs, and its sampled angles (rad)."""
    args = floor_args(arrays)
    floor_loop(*args)
    best = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        steps = floor_loop(*args)
        best = min(best, (time.perf_counter() - start) / steps)
    return 1e9 * best, args[-1]
