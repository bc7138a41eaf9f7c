"""How much of a scene's base motion its run covers: a scene that ends before its record does.

A record that lasts 41.7 s and peaks at 7.75 s, run in a 3 s scene, gives "completed, 0
fell" for a shaking the blocks never felt. :func:`record_coverage` says how much of the
motion, of its peak (PGA) and of its Arias intensity falls after the scene's end, as plain
data (floats and strings) for a warning and for a result's metadata.

Arias intensity is I_A = pi / (2 g) * integral of a(t)^2 dt (Arias 1970, "A measure of
earthquake intensity"); the fraction left out does not depend on the constant, and the
integral is exact for the piecewise-linear acceleration every solver reads.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from rockyade.motion.ground import GroundMotion

#: Free rocking simulated after a record's end when a scene's duration is not given, s. When
#: the base stops, a block's energy only decreases (impacts dissipate it), so whether it
#: overturns is decided by its next rise: from theta = 0 to a peak below 0.99 alpha, a
#: rectangular block takes at most acosh(100) / p = 5.3 / p s (Housner 1963, free rocking
#: theta = alpha - (alpha - theta_0) cosh(p t), read backwards). 5 s decides it for every
#: block with p >= 1.06 rad/s, i.e. R = 3 g / (4 p^2) <= 6.5 m (a block about 13 m tall).
RECORD_TAIL_S = 5.0


def _arias(t: np.ndarray, a: np.ndarray) -> float:
    """Integral of a^2 dt for ``a`` linear between samples (exact), (m/s^2)^2 s."""
    dt = np.diff(t)
    return float(np.sum(dt * (a[:-1] ** 2 + a[:-1] * a[1:] + a[1:] ** 2) / 3.0))


def record_coverage(motion: Any, duration_s: float) -> dict[str, float | str]:
    """How much of a base motion a run of ``duration_s`` covers.

    Parameters
    ----------
    motion
        A scene's motion (:class:`~rockyade.motion.spec.MotionSpec`, whose base motion over
        ``duration_s`` is built) or a :class:`~rockyade.motion.ground.GroundMotion`.
    duration_s
        The scene's simulated time, s.

    Returns
    -------
    dict
        ``status``: "complete", "cut" (the motion goes on after the scene's end) or
        "no base motion"; ``motion``: its label; ``duration_s``; ``motion_end_s`` (its last
        sample, s); ``time_left_out_s`` and ``time_left_out_fraction`` (of the motion's
        length); ``pga_m_s2`` and ``pga_time_s`` (the whole motion's peak and when);
        ``pga_in_run_m_s2`` (the largest |a| the run sees); ``pga_left_out_fraction``
        (1 - pga_in_run / pga); ``arias_left_out_fraction`` (of the integral of a^2 dt);
        ``suggested_duration_s`` (the motion's end plus :data:`RECORD_TAIL_S`); and
        ``message``, a sentence saying it (empty when complete). Every value is a float
        or a string.
    """
    gm = motion if isinstance(motion, GroundMotion) else motion.ground_motion(duration_s)
    duration = float(duration_s)
    if gm is None:
        return {"status": "no base motion", "motion": "none", "duration_s": duration, "message": ""}
    t, a = gm.t_s, gm.ah_m_s2
    end = float(t[-1])
    pga = float(np.max(np.abs(a)))
    pga_time = float(t[int(np.argmax(np.abs(a)))])
    inside = t <= duration
    t_run = np.append(t[inside], duration) if duration < end else t
    a_run = np.append(a[inside], np.interp(duration, t, a)) if duration < end else a
    pga_run = float(np.max(np.abs(a_run))) if a_run.size else 0.0
    total = _arias(t, a)
    left_arias = max(total - _arias(t_run, a_run), 0.0) if duration < end and t_run.size > 1 else 0.0
    tolerance = 0.5 * float(np.min(np.diff(t)))  # a scene that ends within half a sample of it
    cut = end - duration > tolerance
    left = max(end - duration, 0.0) if cut else 0.0
    out: dict[str, float | str] = {
        "status": "cut" if cut else "complete",
        "motion": gm.label,
        "duration_s": duration,
        "motion_end_s": end,
        "time_left_out_s": left,
        "time_left_out_fraction": left / end if end > 0 else 0.0,
        "pga_m_s2": pga,
        "pga_time_s": pga_time,
        "pga_in_run_m_s2": pga_run if cut else pga,
        "pga_left_out_fraction": (1.0 - pga_run / pga if pga > 0 else 0.0) if cut else 0.0,
        "arias_left_out_fraction": (left_arias / total if total > 0 else 0.0) if cut else 0.0,
        "suggested_duration_s": end + RECORD_TAIL_S,
        "message": "",
    }
    if cut:
        out["message"] = _message(out)
    return out


def _message(c: dict[str, Any]) -> str:
    """One sentence: what of the motion the run leaves out, and the duration that covers it."""
    peak = (
        f"its peak ({c['pga_m_s2']:.4g} m/s^2 at {c['pga_time_s']:.4g} s; the run sees {c['pga_in_run_m_s2']:.4g} "
        "m/s^2 at most)"
        if c["pga_left_out_fraction"] > 0
        else f"not its peak ({c['pga_m_s2']:.4g} m/s^2 at {c['pga_time_s']:.4g} s)"
    )
    suggested = math.ceil(c["suggested_duration_s"] * 100) / 100
    return (
        f"the scene ends at {c['duration_s']:g} s but its base motion ({c['motion']}) lasts {c['motion_end_s']:.4g} s: "
        f"the run leaves out {c['time_left_out_s']:.4g} s ({100 * c['time_left_out_fraction']:.3g} %) of it, "
        f"{peak}, and {100 * c['arias_left_out_fraction']:.3g} % of its Arias intensity; "
        f"duration_s = {suggested:g} covers it with {RECORD_TAIL_S:g} s of free rocking after"
    )
