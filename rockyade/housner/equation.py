"""Housner's rocking equation (paper Eq 1, nonlinear, with point loads): theta'' of a block
rocking on either pivot, compiled by numba; the equations are in
:mod:`rockyade.housner.integrator`'s docstring. Its parameters are one array
(:meth:`rockyade.housner.sdof.HousnerModel.params`, indices :data:`PARAMS`), so that the model
(:mod:`rockyade.housner.sdof`) and its integration (:mod:`rockyade.housner.integrator`) both
read the equation here and neither imports the other's internals."""

from __future__ import annotations

import math

import numba

#: The index of each parameter in the array (:data:`PARAMS`).
I_AL, I_AR, I_PL2G, I_PR2G, I_MULR, I_MURL, I_G, I_PL, I_PR, I_LAL, I_LBL, I_LAR, I_LBR, I_LOADED = range(14)


@numba.njit(cache=True)
def theta_dd(side, theta, ah, av, prm):
    """theta'' of Eq 1, with the point loads' moment when there are some (module docstring)."""
    if side > 0:
        a = prm[I_AL] - theta
        acc = -(prm[I_G] + av) * math.sin(a) + ah * math.cos(a)
        if prm[I_LOADED] != 0.0:
            acc += (prm[I_G] + av) / prm[I_G] * (prm[I_LAL] * math.cos(theta) - prm[I_LBL] * math.sin(theta))
        return prm[I_PL2G] * acc
    a = prm[I_AR] + theta
    acc = (prm[I_G] + av) * math.sin(a) + ah * math.cos(a)
    if prm[I_LOADED] != 0.0:
        acc += (prm[I_G] + av) / prm[I_G] * (prm[I_LAR] * math.cos(theta) - prm[I_LBR] * math.sin(theta))
    return prm[I_PR2G] * acc


#: The parameters' order in the array :func:`theta_dd` takes: alpha_L, alpha_R (rad), p_L^2 / g,
#: p_R^2 / g (1/m), mu L->R, mu R->L, g (m/s^2), p_L, p_R (rad/s), the loads' a_L, b_L, a_R, b_R
#: (m/s^2) and 1.0 when there are loads.
PARAMS = (
    "alpha_left",
    "alpha_right",
    "p_left^2/g",
    "p_right^2/g",
    "mu_left_to_right",
    "mu_right_to_left",
    "g",
    "p_left",
    "p_right",
    "load_a_left",
    "load_b_left",
    "load_a_right",
    "load_b_right",
    "loaded",
)
