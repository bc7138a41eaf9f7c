"""The joint's contact law at one contact point, written once for base and pair contacts.

The same law as YADE's ``Law2_ScGeom_ViscElPhys_Basic`` and the paper's UDEC joint
(Section 4). With delta >= 0 the penetration (m), delta_dot its rate, v_t the tangential
relative velocity at the point and S the shear spring force carried from the last step:

* normal:  F_n = K delta + c_n delta_dot, clamped at zero (no tension), c_n = beta K;
* shear:   S_trial = S + K_s dt v_t (an incremental spring);
* Coulomb: |S_trial| > F_n tan(phi): the point slips, S = sign(S_trial) F_n tan(phi) and
  the shear dashpot is off; it dissipates the slip of the step, (|S_trial| - F_n tan(phi))
  / K_s, against the force the bodies feel, F_n tan(phi) (YADE's plastic dissipation);
* else it sticks: S = S_trial, plus the shear dashpot c_s v_t, c_s = beta K_s;
* the shear memory is reset when the point opens: its stored energy S^2 / (2 K_s) is lost.

The elastic energy stored at a point is K delta^2 / 2 + S^2 / (2 K_s).

The caller supplies the kinematics (delta, delta_dot, v_t along its normal and tangent) and
applies the force F_n n - (S + c_s v_t) t; the law itself is the same for every contact.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numba

if TYPE_CHECKING:
    from rockyade.kernel.state import Joints

#: Contact states of a point (and of a vertex: the worst state of the points at it).
STATE_OPEN, STATE_STICK, STATE_SLIP = 0, 1, 2


class JointLaw(NamedTuple):
    """The constants of one joint's law (module docstring), as every contact path takes them."""

    kn: float  #: normal stiffness K, N/m
    ks: float  #: shear stiffness K_s, N/m
    cn: float  #: normal dashpot c_n = beta K, N s/m
    cs: float  #: shear dashpot c_s = beta K_s, N s/m
    tanphi: float  #: friction coefficient tan(phi)


@numba.njit(cache=True, nogil=True, inline="always")
def joint_law(joints: Joints, j: int) -> JointLaw:
    """The law of joint ``j`` of the packed joints (:class:`rockyade.kernel.state.Joints`)."""
    return JointLaw(joints.kn[j], joints.ks[j], joints.cn[j], joints.cs[j], joints.tanphi[j])


@numba.njit(cache=True, nogil=True, inline="always")
def contact_law(
    delta: float,
    ddot: float,
    vt: float,
    s_old: float,
    law: JointLaw,
    dt: float,
) -> tuple[float, float, float, float, int, float]:
    """Forces of one contact point (module docstring).

    Parameters
    ----------
    delta, ddot
        Penetration (>= 0), m, and its rate, m/s.
    vt
        Tangential relative velocity, m/s.
    s_old
        Shear spring force of the last step, N (0 for a new point).
    law
        The joint's stiffnesses, dashpots and friction coefficient.
    dt
        Time step, s.

    Returns
    -------
    fn
        Normal force, N (>= 0).
    fn_spring
        Its spring part K delta, N (the dashpot part is fn - fn_spring).
    s_new
        Shear spring force carried to the next step, N.
    visc
        Shear dashpot force, N (0 while slipping).
    state
        ``STATE_STICK`` or ``STATE_SLIP``.
    slip_work
        Energy dissipated by friction in this step, J (0 while sticking, or with K_s = 0).
    """
    kn, ks, cn, cs, tanphi = law
    fn_spring = kn * delta
    fn = fn_spring + cn * ddot
    if fn < 0.0:
        fn = 0.0
    s_trial = s_old + ks * dt * vt
    smax = fn * tanphi
    if abs(s_trial) > smax:
        s_new = smax if s_trial > 0.0 else -smax
        slip_work = smax * (abs(s_trial) - smax) / ks if ks > 0.0 else 0.0
        return fn, fn_spring, s_new, 0.0, STATE_SLIP, slip_work
    return fn, fn_spring, s_trial, cs * vt, STATE_STICK, 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def add_stored_energy(e: float, fn_spring: float, delta: float, s_new: float, ks: float) -> float:
    """``e`` plus the elastic energy at a point, K delta^2 / 2 + S^2 / (2 K_s), J."""
    e += 0.5 * fn_spring * delta
    if ks > 0.0:
        e += 0.5 * s_new * s_new / ks
    return e


@numba.njit(cache=True, nogil=True, inline="always")
def add_released_energy(e: float, s2: float, ks: float) -> float:
    """``e`` plus the energy S^2 / (2 K_s) of a shear spring lost when its point opens
    (``s2`` = S^2, N^2), J."""
    if ks > 0.0:
        e += 0.5 * s2 / ks
    return e
