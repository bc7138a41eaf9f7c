"""The reference DEM's pushover beside the code's capacity curve (``rockyade assess --pushover``).

The scene runs under a ``pushover`` motion (:class:`rockyade.motion.quasistatic.Pushover`)
in the governing direction, with levels held from 0.98 alpha0 every 1 % of alpha0 (docs/assemblies.md:
a held level shows whether the assembly stands at it; a continuous rise lags by about 2 %).
Its capacity curve (:func:`rockyade.analysis.capacity.capacity_curve`) is taken at the
mechanism's control point, the centroid of the code's control block k
(:func:`rockyade.limit.kinematic.control_block`), and the onset is
:func:`rockyade.analysis.capacity.pushover_onset`. In the code's spectral coordinates
(Circolare 2019 C8.7.1, as :meth:`rockyade.limit.kinematic.KinematicQuantities.spectral`):

    a* = lambda g / (e* FC),   d* = d_k sum P dx^2 / (dx_k sum P dx).

A pushover is force-controlled: past the onset the mechanism runs away at the held level, so
the DEM's curve is flat there; it does not follow the code's descending branch (the
displacement-controlled equilibrium path of :mod:`rockyade.limit.finite`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rockyade.analysis.capacity import ONSET_THRESHOLD_M, Onset, capacity_curve, pushover_onset
from rockyade.errors import InputError
from rockyade.limit.kinematic import KinematicQuantities
from rockyade.motion.quasistatic import Pushover
from rockyade.scene import Scene
from rockyade.scene.placement import placed_blocks

#: Held levels: from START_FRACTION alpha0, every STEP_FRACTION alpha0, LEVELS of them past the start.
START_FRACTION = 0.98
STEP_FRACTION = 0.01
LEVELS = 6
#: Each level held, s (0.4 s in docs/assemblies.md; a 2.5 m wall at 1 % above alpha0 moves its centroid
#: less than 1 mm in 0.4 s), and the push's rate, 1/s.
HOLD_S = 0.8
RATE_G_PER_S = 0.05
#: Run time after the last level's hold, s (the mechanism runs away in it).
TAIL_S = 0.5
#: Samples kept in the curve handed to the JSON and the figure.
MAX_POINTS = 400


@dataclass(frozen=True)
class PushoverCheck:
    """The reference DEM's pushover of an assessed scene (module docstring).

    Attributes
    ----------
    alpha0
        The limit analysis' multiplier it is compared with.
    onset
        The onset measured (:class:`rockyade.analysis.capacity.Onset`).
    direction
        "+x" or "-x", the push's.
    control_block
        The control block k; the control point is its centroid.
    d_star_m, a_star_m_s2
        The curve from the onset's level on, in the code's coordinates: d*, m; a*, m/s^2.
    motion
        The pushover run.
    """

    alpha0: float
    onset: Onset
    direction: str
    control_block: str
    d_star_m: NDArray[np.float64]
    a_star_m_s2: NDArray[np.float64]
    motion: Pushover

    @property
    def bound(self) -> str:
        """What the held levels say of the onset: "measured" (it stood at one level and not at the
        next), "below" (it did not stand at the first level: the onset is below it), "above" (it
        stood at every level: the onset is above the last) or "none" (no level was reached)."""
        measured, below = math.isfinite(self.onset.multiplier), math.isfinite(self.onset.below)
        if measured:
            return "measured" if below else "below"
        return "above" if below else "none"

    @property
    def difference(self) -> float:
        """(onset - alpha0) / alpha0; NaN unless the onset is bracketed by two held levels
        (:attr:`bound` "measured"): a level it fell at first is a bound, not an onset."""
        if self.bound != "measured":
            return math.nan
        return self.onset.multiplier / self.alpha0 - 1.0

    def onset_words(self) -> str:
        """The onset against alpha0 in words, with a percentage only where it was measured:
        "onset λ = 0.5 (stood at 0.495) ...: +1.00 %", "onset below λ = 0.49, the first held level ...",
        "held at every level up to λ = 0.52 ..."."""
        a0 = f"alpha0 = {self.alpha0:.4f}"
        m, below = self.onset.multiplier, self.onset.below
        bound = self.bound
        if bound == "measured":
            return f"onset λ = {m:.4g} (stood at {below:.4g}) against {a0}: {100 * self.difference:+.2f} %"
        if bound == "below":
            return (
                f"onset below λ = {m:.4g}, the first held level ({m / self.alpha0:.2f} alpha0): it did not stand "
                f"at it, so the onset is not measured, only bounded; {a0} is above it"
            )
        if bound == "above":
            return (
                f"held at every level up to λ = {below:.4g} ({below / self.alpha0:.2f} alpha0): the onset is above "
                f"it, not measured; {a0}"
            )
        return f"no onset measured: the run ended before the first held level ({a0})"

    def to_dict(self) -> dict[str, object]:
        """Plain data: the onset, its difference from alpha0 in %, the rule, the curve."""
        return {
            "pushover_onset_lambda": self.onset.multiplier,
            "pushover_level_below": self.onset.below,
            "pushover_onset_minus_alpha0_pct": 100.0 * self.difference if self.bound == "measured" else None,
            "pushover_onset_bound": self.bound,
            "pushover_onset_words": self.onset_words(),
            "rule": self.onset.rule,
            "solver": "reference",
            "direction": self.direction,
            "control_block": self.control_block,
            "control_point": "the control block's centroid",
            "levels": self.motion.levels().tolist(),
            "hold_s": self.motion.hold_s,
            "curve": {"d_star_m": self.d_star_m.tolist(), "a_star_m_s2": self.a_star_m_s2.tolist()},
        }


def pushover_motion(alpha0: float, direction: str) -> tuple[Pushover, float]:
    """The held levels around alpha0 (module docstring) and the run's duration, s."""
    if not (math.isfinite(alpha0) and 0.0 < alpha0 <= 9.0):
        raise InputError("--pushover", f"needs a mechanism with alpha0 in (0, 9], got {alpha0:g}")
    step = round(STEP_FRACTION * alpha0, 6)
    start = round(START_FRACTION * alpha0, 6)
    motion = Pushover(
        direction=direction,
        rate_g_per_s=RATE_G_PER_S,
        max_lambda=round(start + LEVELS * step, 6),
        start_lambda=start,
        step_lambda=step,
        hold_s=HOLD_S,
    )
    t, _ = motion.lambda_path(0.0)
    return motion, float(t[-1]) + TAIL_S


def _thin(n: int) -> NDArray[np.intp]:
    return np.unique(np.linspace(0, n - 1, min(n, MAX_POINTS)).round().astype(np.intp)) if n else np.zeros(0, np.intp)


def run_pushover(scene: Scene, kin: KinematicQuantities, direction: str) -> PushoverCheck:
    """Push ``scene`` in the reference DEM towards ``direction`` and measure it (module docstring).

    Parameters
    ----------
    scene
        The assessed scene (its motion and duration are replaced).
    kin
        The governing mechanism's quantities (alpha0, e*, FC, the control block, d*/dk).
    direction
        "+x" or "-x".
    """
    from rockyade.solvers import run

    motion, duration = pushover_motion(kin.alpha0, direction)
    pushed = scene.with_changes(motion=motion, duration_s=duration)
    names = [b.name for b in pushed.blocks]
    centroid = placed_blocks(pushed)[names.index(kin.control_block)].centroid_m
    result = run(pushed, "reference")
    curve = capacity_curve(result, pushed, block=kin.control_block, point_m=(float(centroid[0]), float(centroid[1])))
    # a wall that closes a gap onto a restraint moves only that far (then bears on it): mark the onset
    # well within that (the DEM's elastic creep below the onset is a thousand times smaller)
    closed = kin.curve.closed_dk_m if kin.curve is not None else None
    threshold = ONSET_THRESHOLD_M if closed is None else min(ONSET_THRESHOLD_M, 0.25 * closed)
    onset = pushover_onset(curve, pushed, threshold_m=threshold)
    t = curve["t_s"].to_numpy()
    lam = curve["lambda"].to_numpy()
    dk = curve["displacement_m"].to_numpy()
    # from the start of the onset level's hold (where lambda first reaches it) on
    if math.isfinite(onset.multiplier):
        reached = np.nonzero((t >= motion.push_start_s) & (lam >= onset.multiplier * (1 - 1e-9)))[0]
        first = int(reached[0]) if reached.size else 0
    else:
        first = int(np.searchsorted(t, motion.push_start_s))
    keep = first + _thin(t.size - first)
    scale = kin.g / (kin.e_star * kin.FC)
    return PushoverCheck(
        kin.alpha0,
        onset,
        direction,
        kin.control_block,
        dk[keep] * kin.d_star_factor,
        lam[keep] * scale,
        motion,
    )
