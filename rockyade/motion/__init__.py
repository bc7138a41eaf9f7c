"""Base motions: what the base of a scene does, from the scene's ``[motion]`` table.

Every motion type becomes a :class:`GroundMotion` (piecewise-linear acceleration samples)
that all solvers read, so that the Housner solver, the reference DEM and YADE see exactly
the same base acceleration.
"""

from rockyade.motion.ground import GroundMotion
from rockyade.motion.spec import MOTION_TYPES, AtRest, FreeRocking, MotionSpec, SampledMotion, parse_motion
from rockyade.motion.types import HarmonicMotion, PulseMotion, RecordMotion, SyntheticMotion

__all__ = [
    "MOTION_TYPES",
    "AtRest",
    "FreeRocking",
    "GroundMotion",
    "HarmonicMotion",
    "MotionSpec",
    "PulseMotion",
    "RecordMotion",
    "SampledMotion",
    "SyntheticMotion",
    "parse_motion",
]
