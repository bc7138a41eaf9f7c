"""Limit analysis of a scene in one call: the programme, its mechanism, the code's quantities.

::

    from rockyade.limit import PointLoad, limit_analysis
    result = limit_analysis(scene, direction="+x", loads=[PointLoad("b01", (0.1, 2.0), (0.0, -5e3))])
    result.status, result.load_multiplier, result.kinematic.a0_star_m_s2
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.limit.kinematic import DEFAULT_FC, KinematicQuantities, check_fc, kinematic_quantities
from rockyade.limit.lp import DIRECTIONS, solve_equilibrium
from rockyade.limit.mechanism import Mechanism, mechanism_of
from rockyade.limit.model import PointLoad, RigidBlockModel, rigid_block_model

#: The note every answer with finite friction carries (docs/limit.md, "Friction").
FRICTION_NOTE = (
    "with finite friction the rigid-block programme assumes associated (dilatant) sliding; real "
    "Coulomb friction does not dilate, so the multiplier can overestimate the collapse load where "
    "joints slide, and also where a lower mechanism needs a joint to slide without opening (a "
    "running-bond wall's heel units: docs/assemblies.md) (Gilbert, Casapulla & Ahmed 2006; "
    "Ferris & Tin-Loi 2001)"
)


@dataclass(frozen=True)
class LimitResult:
    """The answer of :func:`limit_analysis`.

    Attributes
    ----------
    status
        "collapse" (a multiplier and a mechanism), "unstable" (the assembly cannot stand
        under gravity and the loads: no multiplier) or "no_mechanism" (no horizontal
        acceleration makes it collapse).
    load_multiplier
        lambda: the horizontal acceleration, in g, that the assembly carries at collapse.
    direction
        "+x" or "-x".
    model
        The rigid-block model solved.
    mechanism
        The collapse mechanism (status "collapse" only).
    normal_N, tangential_N
        (n_interfaces, 2) contact forces at the interface ends at collapse, N.
    kinematic
        The code's quantities (status "collapse" only).
    friction_angle_deg
        The friction angle applied to every joint, degrees; None when sliding is excluded;
        "scene" when each joint takes its own from the scene.
    solve_time_s
        Time of the programme, s.
    """

    status: str
    load_multiplier: float | None
    direction: str
    model: RigidBlockModel
    mechanism: Mechanism | None
    normal_N: NDArray[np.float64] | None
    tangential_N: NDArray[np.float64] | None
    kinematic: KinematicQuantities | None
    friction_angle_deg: float | str | None
    solve_time_s: float

    @property
    def sliding_allowed(self) -> bool:
        """True when joints may slide (finite friction)."""
        return self.friction_angle_deg is not None

    @property
    def notes(self) -> list[str]:
        """Caveats that apply to this answer."""
        out = list(self.model.notes)
        if self.sliding_allowed:
            out.append(FRICTION_NOTE)
        if self.mechanism is not None and self.mechanism.slides:
            out.append(
                "joints slide in this mechanism: its multiplier bounds from above the one with non-dilatant "
                "Coulomb friction, which can be lower"
            )
        return out

    def to_dict(self) -> dict[str, Any]:
        """Plain data (JSON-ready): the keys of ``rockyade limit --json``."""
        model = self.model
        out: dict[str, Any] = {
            "status": self.status,
            "load_multiplier": self.load_multiplier,
            "direction": self.direction,
            "friction_angle_deg": self.friction_angle_deg,
            "sliding_allowed": self.sliding_allowed,
            "n_blocks": model.n_blocks,
            "n_interfaces": len(model.interfaces),
            "solve_time_s": self.solve_time_s,
            "notes": self.notes,
            "mechanism": None,
            "hinges": [],
            "sliding": [],
            "contacts": [],
        }
        keys = ("alpha0", "e_star", "M_star_kg", "a0_star_m_s2", "d0_star_m", "du_star_m", "Ts_s")
        out.update(dict.fromkeys(keys))
        if self.mechanism is not None:
            mech = self.mechanism
            out["mechanism"] = {
                name: {"vx": float(v[0]), "vy": float(v[1]), "omega": float(v[2])}
                for name, v, moves in zip(model.names, mech.velocities, mech.moving, strict=True)
                if moves
            }
            out["hinges"] = [h.to_dict() for h in mech.hinges]
            out["sliding"] = [s.to_dict() for s in mech.sliding]
            out["checks"] = mech.checks.to_dict()
        if self.normal_N is not None and self.tangential_N is not None:  # both or neither
            out["contacts"] = [
                {
                    "a": model.body_name(itf.a),
                    "b": model.body_name(itf.b),
                    "ends_m": itf.ends_m.tolist(),
                    "normal_N": self.normal_N[k].tolist(),
                    "tangential_N": self.tangential_N[k].tolist(),
                }
                for k, itf in enumerate(model.interfaces)
            ]
        if self.kinematic is not None:
            kin = self.kinematic.to_dict()
            out["kinematic"] = kin
            for key in keys:
                out[key] = kin[key]
        return out


def limit_analysis(
    scene,
    direction: str = "+x",
    loads: Sequence[PointLoad] = (),
    friction_angle_deg: float | None = None,
    sliding: bool = True,
    fc: float = DEFAULT_FC,
    nonlinear: bool = True,
) -> LimitResult:
    """The collapse multiplier, mechanism and kinematic quantities of a scene.

    Parameters
    ----------
    scene
        A validated :class:`~rockyade.scene.Scene`, or a :class:`RigidBlockModel` (then
        ``loads``, ``friction_angle_deg`` and ``sliding`` must be left at their defaults).
    direction
        "+x" or "-x": the sense of the horizontal force lambda m g on every moving block.
    loads
        External loads (forces without mass), :class:`PointLoad`.
    friction_angle_deg
        Friction angle of every joint, degrees in [0, 90); None: the scene's.
    sliding
        False: no joint slides (the multiplier of pure rocking mechanisms).
    fc
        The code's confidence factor FC in [1, 10] (default 1.35).
    nonlinear
        Also the nonlinear kinematic analysis (the capacity curve to alpha = 0).
    """
    if direction not in DIRECTIONS:
        raise InputError("direction", f"must be +x or -x, got {direction!r}")
    fc = check_fc(fc)
    if isinstance(scene, RigidBlockModel):
        if loads or friction_angle_deg is not None or not sliding:
            raise InputError("loads", "give loads and friction when building the RigidBlockModel, not here")
        model = scene
    else:
        model = rigid_block_model(scene, loads=loads, friction_angle_deg=friction_angle_deg, sliding=sliding)
    angles = {itf.friction_angle_deg for itf in model.interfaces}
    if angles == {None} or not model.interfaces:
        phi: float | str | None = None
    elif len(angles) == 1:
        phi = float(next(a for a in angles if a is not None))
    else:
        phi = "scene"
    sol = solve_equilibrium(model, direction)
    if sol.status != "collapse":
        return LimitResult(sol.status, None, direction, model, None, None, None, None, phi, sol.solve_time_s)
    assert sol.load_multiplier is not None  # a "collapse" always carries its multiplier (lp.py)
    mech = mechanism_of(model, sol)
    kin = kinematic_quantities(model, mech, sol.load_multiplier, direction, fc=fc, nonlinear=nonlinear)
    return LimitResult(
        "collapse",
        sol.load_multiplier,
        direction,
        model,
        mech,
        sol.normal_N,
        sol.tangential_N,
        kin,
        phi,
        sol.solve_time_s,
    )
