"""Rocking patterns of a two-block stack (paper Fig. 16, after its ref. [14]).

Each sample is classified from the lower block's rotation theta_L and the upper block's
rotation relative to it, phi = theta_U - theta_L:

* the lower block rocks when |theta_L| > ``ROCK_FRACTION`` alpha_L, the upper block rocks
  on it when |phi| > ``ROCK_FRACTION`` alpha_U (elastic tilts of the contacts, ~1e-6 rad,
  stay far below);
* ``rest``: neither rocks;
* ``3``: only the lower one rocks: the stack rocks as one body;
* ``4``: only the upper one rocks;
* ``1``: both rock and theta_U, theta_L have the same sign (same way);
* ``2``: both rock and they have opposite signs (opposite ways).

A window's pattern is its most frequent rocking class when rocking samples make at least
``MIN_ACTIVE`` of it, else ``rest``. The dominant pattern of a run is the most frequent
window pattern among windows that rock (``rest`` if none), or ``overturn-lower`` /
``overturn-upper`` when a block overturned. For harmonic motions the windows are taken
over the stationary part (the paper's patterns describe that state).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np

from rockyade.motion.types import HarmonicMotion
from rockyade.result import Result
from rockyade.scene import Scene

ROCK_FRACTION = 0.01
MIN_ACTIVE = 0.1
WINDOW_S = 1.0
PATTERNS = ("rest", "1", "2", "3", "4")


@dataclass(frozen=True)
class PatternReport:
    """Pattern classification of a stack run.

    Attributes
    ----------
    dominant
        "1"-"4", "rest", "overturn-lower" or "overturn-upper".
    windows
        (start_s, end_s, pattern) per window.
    fractions
        Share of each class among all classified samples.
    """

    dominant: str
    windows: tuple[tuple[float, float, str], ...]
    fractions: dict[str, float]


def classify_samples(
    theta_lower: np.ndarray, theta_upper: np.ndarray, alpha_lower: float, alpha_upper: float
) -> np.ndarray:
    """Class of every sample (array of "rest", "1", "2", "3", "4").

    Parameters
    ----------
    theta_lower, theta_upper
        Rotations of the lower and upper block, rad (absolute).
    alpha_lower, alpha_upper
        Their slenderness angles, rad.
    """
    phi = theta_upper - theta_lower
    lower = np.abs(theta_lower) > ROCK_FRACTION * alpha_lower
    upper = np.abs(phi) > ROCK_FRACTION * alpha_upper
    same = np.sign(theta_upper) == np.sign(theta_lower)
    out = np.full(theta_lower.shape, "rest", dtype=object)
    out[lower & ~upper] = "3"
    out[~lower & upper] = "4"
    out[lower & upper & same] = "1"
    out[lower & upper & ~same] = "2"
    return out


def classify(
    t: np.ndarray,
    theta_lower: np.ndarray,
    theta_upper: np.ndarray,
    alpha_lower: float,
    alpha_upper: float,
    window_s: float = WINDOW_S,
    span: tuple[float, float] | None = None,
    overturned: str | None = None,
) -> PatternReport:
    """Pattern per window and dominant pattern of a two-block history.

    Parameters
    ----------
    t, theta_lower, theta_upper
        Samples (s, rad).
    alpha_lower, alpha_upper
        Critical angles, rad.
    window_s
        Window length, s.
    span
        (start, end) of the part classified (default: all).
    overturned
        "lower" or "upper" if a block overturned.
    """
    classes = classify_samples(theta_lower, theta_upper, alpha_lower, alpha_upper)
    lo, hi = span if span is not None else (float(t[0]), float(t[-1]))
    inside = (t >= lo) & (t <= hi)
    windows = []
    start = lo
    while start < hi - 1e-9:
        end = min(start + window_s, hi)
        sel = inside & (t >= start) & (t < end if end < hi else t <= end)
        if np.any(sel):
            counts = Counter(classes[sel])
            active = sum(v for k, v in counts.items() if k != "rest")
            if active >= MIN_ACTIVE * sel.sum():
                pattern = max((k for k in counts if k != "rest"), key=lambda k: (counts[k], k))
            else:
                pattern = "rest"
            windows.append((start, end, pattern))
        start = end
    counts_all = Counter(classes[inside])
    total = max(1, int(inside.sum()))
    fractions = {k: counts_all.get(k, 0) / total for k in PATTERNS}
    if overturned:
        dominant = f"overturn-{overturned}"
    else:
        rocking = Counter(p for _, _, p in windows if p != "rest")
        dominant = max(rocking, key=lambda k: (rocking[k], k)) if rocking else "rest"
    return PatternReport(dominant, tuple(windows), fractions)


def classify_result(scene: Scene, result: Result) -> PatternReport:
    """Pattern classification of a two-block scene's result (blocks bottom to top).

    Parameters
    ----------
    scene
        The two-block scene (its blocks' alpha, rad, and its motion).
    result
        The run's Result.
    """
    if len(scene.blocks) != 2:
        raise ValueError("pattern classification is defined for two-block stacks")
    lower, upper = scene.blocks
    span = None
    motion = scene.motion
    if isinstance(motion, HarmonicMotion):
        phases = motion.harmonic.phases_s
        span = (phases["ramp_up_end_s"], min(phases["stationary_end_s"], float(result.t[-1])))
    overturned = None
    if result.status == "overturned":
        overturned = "lower" if result.meta.overturned_block == lower.name else "upper"
    return classify(
        result.t,
        result.series("theta_rad", lower.name),
        result.series("theta_rad", upper.name),
        lower.classical().alpha_rad,
        upper.classical().alpha_rad,
        span=span,
        overturned=overturned,
    )
