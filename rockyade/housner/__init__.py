"""Housner's rocking block: the single-degree-of-freedom model (:mod:`~rockyade.housner.sdof`,
paper Eqs 1-4 with point loads), its exact integration in numba (:mod:`~rockyade.housner.integrator`:
Runge-Kutta between impacts found by root finding) and the time history of a run
(:mod:`~rockyade.housner.history`). The solver adapter is :class:`rockyade.solvers.housner.HousnerSolver`;
the identification and the verification use the integrator directly."""

from rockyade.housner.integrator import MAX_RECORDED_EVENTS, REST_FRACTION, STEPS_PER_RADIAN, Trajectory, solve
from rockyade.housner.sdof import HousnerModel, housner_model

__all__ = [
    "MAX_RECORDED_EVENTS",
    "REST_FRACTION",
    "STEPS_PER_RADIAN",
    "HousnerModel",
    "Trajectory",
    "housner_model",
    "solve",
]
