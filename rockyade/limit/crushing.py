"""Masonry that crushes at the hinges: the joints of the limit analysis with a finite compressive strength.

The rigid-block model puts a hinge at the edge of its joint, where a rigid, infinitely strong
material would carry the joint's normal force N on a line. Masonry of compressive strength fm
carries it on a compressed zone of finite width. With the equivalent rectangular stress block of
0.85 fm over the zone (the block of NTC 2018 7.8.2.2.1, Eq 7.8.2, for masonry in combined
compression and bending, Mu = (l^2 t sigma0 / 2)(1 - sigma0 / (0.85 fd)); EN 1996-1-1 6.1.2.2,
Eq 6.4, Phi_i = 1 - 2 e_i / t, is a rectangular block too, at fd), a joint of length L and depth
t (the wall's length out of the section) carrying N has a compressed zone of width

    a = N / (0.85 fm t),

and the resultant of the stress block, the hinge, lies a / 2 inside the joint's edge. The
Circolare 2019 (C8.7.1) lets the kinematic analysis take the masonry's compressive strength into
account by moving the hinge into the section in this way. Every joint of the model is shortened by
a / 2 at both ends (either end may be the hinge, and a resultant anywhere between the moved ends
keeps its stress block inside the joint): the domain of the resultant, exact for a no-tension
joint with a rectangular block, whose width depends on N. A joint with a / 2 >= L / 2 cannot
carry its force at all: it crushes (its ends meet at its middle, and the output says so).

N is the limit analysis' own normal force at collapse, which depends on where the hinges are: the
hinges are moved with the normal forces of the rigid solution, the programme solved again, and so
on to a fixed point (the multiplier and every joint's normal force unchanged to the tolerances
below, the update relaxed when the multiplier oscillates). As fm tends to infinity a tends to 0 and
the multiplier to the rigid one; it falls as fm falls. Point contacts (a corner on a face: no
length) keep their point.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, TypedDict

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.limit.rigid_blocks import Interface, RigidBlockModel

#: The equivalent rectangular stress block's factor on fm (NTC 2018 7.8.2.2.1, Eq 7.8.2).
STRESS_BLOCK_FACTOR = 0.85
#: What the output says of the stress block and its source.
STRESS_BLOCK = (
    "equivalent rectangular stress block 0.85 fm over the compressed zone a = N / (0.85 fm t), the hinge at its "
    "resultant a / 2 inside the joint's edge (NTC 2018 7.8.2.2.1 Eq 7.8.2, Mu = (l^2 t sigma0 / 2)(1 - sigma0 / "
    "(0.85 fd)); a rectangular block as EN 1996-1-1 6.1.2.2 Eq 6.4; the hinge moved into the section as Circolare "
    "2019 C8.7.1 allows)"
)
#: fm accepted, MPa: (0, FM_MAX_MPA].
FM_MAX_MPA = 1.0e9
#: Fixed point: lambda's relative change, and each joint's normal force's change over the largest weight.
LAMBDA_RTOL = 1.0e-9
FORCE_RTOL = 1.0e-7
#: Programmes after the rigid one, at most.
MAX_ITERATIONS = 60
#: Plain updates before an oscillation of lambda relaxes the update.
PLAIN_ITERATIONS = 10


def check_fm(value: Any, field: str = "fm_MPa") -> float:
    """A compressive strength in (0, 1e9] MPa, else InputError naming ``field``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(field, f"must be a compressive strength in MPa, in (0, {FM_MAX_MPA:g}], got {value!r}")
    if not 0.0 < value <= FM_MAX_MPA:
        raise InputError(
            field,
            f"must be in (0, {FM_MAX_MPA:g}] MPa (the masonry's compressive strength fm, e.g. 1.5 for tuff), "
            f"got {value:g}",
        )
    return float(value)


class JointShift(TypedDict):
    """One joint's row of :attr:`Crushing.joints`: where its hinge moved (module docstring)."""

    a: str
    b: str
    normal_N: float
    depth_m: float
    width_m: float
    shift_m: float
    length_m: float
    crushed: bool


@dataclass(frozen=True)
class Crushing:
    """How the hinges moved into the joints (module docstring).

    Attributes
    ----------
    fm_MPa
        The compressive strength, MPa.
    converged
        True when the fixed point was reached.
    iterations
        Programmes solved after the rigid one.
    history
        lambda of the rigid solution and of every iteration.
    joints
        Per joint of the model with a length (the rigid model's order): ``a``, ``b`` (names),
        ``normal_N`` (N at collapse), ``depth_m`` (t), ``width_m`` (a), ``shift_m`` (a / 2, at most
        half the joint), ``length_m`` (L), ``crushed`` (a / 2 >= L / 2).
    reason
        Why it did not converge ("" when it did).
    """

    fm_MPa: float
    converged: bool
    iterations: int
    history: tuple[float, ...]
    joints: tuple[JointShift, ...]
    reason: str = ""

    @property
    def crushed(self) -> list[str]:
        """The joints that cannot carry their force (``a-b``)."""
        return [f"{j['a']}-{j['b']}" for j in self.joints if j["crushed"]]

    @property
    def largest_shift(self) -> JointShift | None:
        """The joint whose hinge moved furthest."""
        return max(self.joints, key=lambda j: j["shift_m"], default=None)

    def to_dict(self) -> dict[str, object]:
        """Plain data (the JSON's ``crushing``)."""
        return {
            "fm_MPa": self.fm_MPa,
            "stress_block": STRESS_BLOCK,
            "converged": self.converged,
            "iterations": self.iterations,
            "history": list(self.history),
            "reason": self.reason,
            "crushed": self.crushed,
            "joints": [dict(j) for j in self.joints],
        }


def joint_depths(model: RigidBlockModel) -> NDArray[np.float64]:
    """(n_interfaces,) each joint's depth out of the section, m: the smaller of its two blocks'
    (the base: the block's); 1 m where the model has no depths."""
    if model.depths_m is None:
        return np.ones(len(model.interfaces))
    depth = np.asarray(model.depths_m, dtype=float)
    out = []
    for itf in model.interfaces:
        sides = [depth[i] for i in (itf.a, itf.b) if i >= 0]
        out.append(min(sides))
    return np.array(out)


def shifted(
    model: RigidBlockModel, normal_N: NDArray[np.float64], fm_MPa: float
) -> tuple[RigidBlockModel, list[JointShift]]:
    """``model`` with every joint shortened at both ends by a / 2, a = N / (0.85 fm t) (module
    docstring), N its total normal force in ``normal_N`` (n_interfaces,); and the joints' rows."""
    fm_pa = fm_MPa * 1.0e6
    depths = joint_depths(model)
    interfaces: list[Interface] = []
    rows: list[JointShift] = []
    for k, itf in enumerate(model.interfaces):
        e0, e1 = itf.ends_m
        length = float(np.hypot(*(e1 - e0)))
        if length <= 0.0:
            interfaces.append(itf)
            continue
        n = max(float(normal_N[k]), 0.0)
        width = n / (STRESS_BLOCK_FACTOR * fm_pa * depths[k])
        shift = min(0.5 * width, 0.5 * length)
        u = (e1 - e0) / length
        interfaces.append(replace(itf, ends_m=np.array([e0 + shift * u, e1 - shift * u])))
        rows.append(
            JointShift(
                a=model.body_name(itf.a),
                b=model.body_name(itf.b),
                normal_N=n,
                depth_m=float(depths[k]),
                width_m=width,
                shift_m=shift,
                length_m=length,
                crushed=0.5 * width >= 0.5 * length,
            )
        )
    return replace(model, interfaces=tuple(interfaces)), rows


def joint_forces(result: Any, n_interfaces: int) -> NDArray[np.float64]:
    """(n_interfaces,) the total normal force of the first ``n_interfaces`` joints of a solution (the
    model's own; corner ways a search added come after them), N."""
    return np.asarray(result.normal_N, dtype=float)[:n_interfaces].sum(axis=1)


def iterate_crushing(
    model: RigidBlockModel, fm_MPa: float, solve: Callable[[RigidBlockModel], Any]
) -> tuple[Any, RigidBlockModel, Crushing]:
    """The fixed point of the module docstring.

    Parameters
    ----------
    model
        The rigid model (joints at their edges).
    fm_MPa
        The masonry's compressive strength, MPa.
    solve
        A model -> its limit analysis (anything with ``status``, ``load_multiplier`` and
        ``normal_N`` (n_interfaces, 2), N), e.g. :func:`rockyade.limit.limit_analysis` without the
        nonlinear analysis.

    Returns
    -------
    (solution, model, Crushing)
        The last solution, the model with the hinges moved that it was solved on, and how they moved.
    """
    fm_MPa = check_fm(fm_MPa)
    n = len(model.interfaces)
    w_ref = float((model.masses_kg[model.moving] * model.g).max()) if model.moving.size else 1.0
    result = solve(model)
    if result.status != "collapse":
        return result, model, Crushing(fm_MPa, False, 0, (), (), f"the rigid model's status is {result.status}")
    history = [float(result.load_multiplier)]
    n_bar = joint_forces(result, n)
    beta, step_prev = 1.0, 0.0
    rows: list = []
    current = model
    for k in range(1, MAX_ITERATIONS + 1):
        current, rows = shifted(model, n_bar, fm_MPa)
        result = solve(current)
        if result.status != "collapse":
            why = f"iteration {k}: the model with its hinges moved has status {result.status}"
            return result, current, Crushing(fm_MPa, False, k, tuple(history), tuple(rows), why)
        lam = float(result.load_multiplier)
        n_new = joint_forces(result, n)
        d_lam = lam - history[-1]
        history.append(lam)
        settled = abs(d_lam) <= LAMBDA_RTOL * max(abs(lam), 1e-12)
        if settled and float(np.max(np.abs(n_new - n_bar), initial=0.0)) <= FORCE_RTOL * w_ref:
            return result, current, Crushing(fm_MPa, True, k, tuple(history), tuple(rows))
        if k > PLAIN_ITERATIONS and d_lam * step_prev < 0.0 and abs(d_lam) > 0.5 * abs(step_prev):
            beta = max(0.5 * beta, 1.0 / 16.0)
        step_prev = d_lam if d_lam != 0.0 else step_prev
        n_bar = n_bar + beta * (n_new - n_bar)
    why = f"the multiplier and the joints' normal forces did not settle in {MAX_ITERATIONS} iterations"
    return result, current, Crushing(fm_MPa, False, MAX_ITERATIONS, tuple(history), tuple(rows), why)
