"""Limit analysis of a scene in one call: the programme, its mechanism, the code's quantities.

::

    from rockyade.limit import PointLoad, limit_analysis
    result = limit_analysis(scene, direction="+x", loads=[PointLoad("b01", (0.1, 2.0), (0.0, -5e3))])
    result.status, result.load_multiplier, result.kinematic.a0_star_m_s2
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.limit.admissible import solve_admissible
from rockyade.limit.coulomb import MAX_ITERATIONS, solve_coulomb
from rockyade.limit.crushing import Crushing, check_fm, iterate_crushing
from rockyade.limit.kinematic import DEFAULT_FC, KinematicQuantities, check_fc, kinematic_quantities
from rockyade.limit.lp import DIRECTIONS
from rockyade.limit.mechanism import Mechanism, mechanism_of
from rockyade.limit.rigid_blocks import PointLoad, RigidBlockModel, rigid_block_model

#: The note every answer with finite friction carries (docs/limit.md, "Friction").
FRICTION_NOTE = (
    "with finite friction the rigid-block programme assumes associated (dilatant) sliding; real "
    "Coulomb friction does not dilate, so the multiplier can overestimate the collapse load where "
    "joints slide, and also where a lower mechanism needs a joint to slide without opening (a "
    "running-bond wall's heel units: docs/assemblies.md) (Gilbert, Casapulla & Ahmed 2006; "
    "Ferris & Tin-Loi 2001); the coulomb friction rule (--friction-rule coulomb) gives the non-dilatant answer"
)
#: A multiplier this small (in g) is zero: the assembly moves under any horizontal acceleration
#: (a joint without friction slides); the solver's tolerance is far below it.
ZERO_MULTIPLIER = 1.0e-9
#: The friction rules of :func:`limit_analysis` (docs/limit.md, "Friction").
FRICTION_RULES = ("associated", "coulomb")
#: What the coulomb rule's answer says of itself.
COULOMB_NOTE = (
    "Coulomb friction without dilatancy, by iterated linear programmes (Gilbert, Casapulla & Ahmed 2006): "
    "a heuristic, not guaranteed to find the lowest collapse load"
)


def slides_with_friction(model: RigidBlockModel, mechanism: Mechanism | None) -> bool:
    """Whether a joint of ``mechanism`` slides where it has friction (angle > 0): where the associated
    (dilatant) rule and Coulomb's non-dilatant one part (frictionless sliding, on a restraint, is the
    same under both)."""
    if mechanism is None:
        return False
    return any(model.interfaces[s.interface].friction_angle_deg for s in mechanism.sliding)


@dataclass(frozen=True)
class FrictionCheck:
    """The coulomb pass of an associated answer whose mechanism slides with friction: the code's
    quantities take the lower of the two multipliers (a check an engineer signs must not take the
    dilatant upper bound; docs/limit.md, "Friction in the code's quantities").

    Attributes
    ----------
    associated
        The associated (dilatant) multiplier.
    coulomb
        The coulomb rule's answer (status ``collapse``, or ``not_converged``: then the associated one
        stands, and the output says so).
    """

    associated: float
    coulomb: LimitResult

    @property
    def coulomb_multiplier(self) -> float | None:
        """The non-dilatant multiplier, or None (not converged)."""
        return self.coulomb.load_multiplier if self.coulomb.status == "collapse" else None

    @property
    def taken(self) -> str:
        """``coulomb`` when it converged at a multiplier no higher than the associated one, else ``associated``."""
        lam = self.coulomb_multiplier
        return "coulomb" if lam is not None and lam <= self.associated else "associated"

    @property
    def ratio(self) -> float:
        """associated / coulomb (NaN without a coulomb multiplier)."""
        lam = self.coulomb_multiplier
        return self.associated / lam if lam else math.nan

    def to_dict(self) -> dict[str, object]:
        """Plain data (the JSON's ``code_friction``)."""
        return {
            "associated": self.associated,
            "coulomb": self.coulomb_multiplier,
            "coulomb_status": self.coulomb.status,
            "coulomb_iterations": self.coulomb.iterations,
            "coulomb_reason": self.coulomb.reason,
            "associated_over_coulomb": self.ratio,
            "taken": self.taken,
            "why": "the associated mechanism slides with friction: its multiplier bounds Coulomb's non-dilatant one "
            "from above; the code's quantities take the lower of the two",
        }


def check_friction_rule(value: str, field: str = "friction_rule") -> str:
    """One of :data:`FRICTION_RULES`, else InputError naming ``field``."""
    if value not in FRICTION_RULES:
        raise InputError(field, f"must be one of {', '.join(FRICTION_RULES)}, got {value!r}")
    return value


@dataclass(frozen=True)
class LimitResult:
    """The answer of :func:`limit_analysis`.

    Attributes
    ----------
    status
        "collapse" (a multiplier and a mechanism), "unstable" (the assembly cannot stand
        under gravity and the loads: no multiplier), "no_mechanism" (no horizontal
        acceleration makes it collapse) or "not_converged" (the coulomb rule's iteration did
        not settle: no multiplier, ``reason`` says why).
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
        Time of the programme(s), s.
    friction_rule
        "associated" or "coulomb" (:func:`limit_analysis`).
    iterations
        Programmes solved by the coulomb rule's iteration after the associated one (0 under the
        associated rule, or when no joint has friction).
    reason
        Why the coulomb rule's iteration stopped without converging (status "not_converged"), else "".
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
    friction_rule: str = "associated"
    iterations: int = 0
    reason: str = ""
    friction_check: FrictionCheck | None = None
    crushing: Crushing | None = None
    rigid: LimitResult | None = None

    @property
    def for_code(self) -> LimitResult:
        """The answer whose mechanism and quantities the code's check takes: the coulomb pass's when
        the associated mechanism slides with friction and the coulomb multiplier is the lower
        (:class:`FrictionCheck`), else this one; with the masonry's compressive strength
        (``crushing``) and the coulomb rule, the rigid model's answer where it is lower (crushing
        cannot raise the capacity, while the coulomb iteration, a heuristic, may settle at another,
        higher fixed point once the hinges have moved: ``rigid``)."""
        check = self.friction_check
        code = check.coulomb if check is not None and check.taken == "coulomb" else self
        if self.rigid is not None and code.load_multiplier is not None:
            other = self.rigid.for_code
            if other.load_multiplier is not None and other.load_multiplier < code.load_multiplier:
                return other
        return code

    @property
    def sliding_allowed(self) -> bool:
        """True when joints may slide (finite friction)."""
        return self.friction_angle_deg is not None

    @property
    def notes(self) -> list[str]:
        """Caveats that apply to this answer."""
        out = list(self.model.notes)
        if self.sliding_allowed and self.friction_rule == "coulomb":
            out.append(COULOMB_NOTE)
            return out
        if self.sliding_allowed:
            out.append(FRICTION_NOTE)
        if self.mechanism is not None and self.mechanism.slides:
            out.append(
                "joints slide in this mechanism: its multiplier bounds from above the one with non-dilatant "
                "Coulomb friction, which can be lower"
            )
        return out

    def to_dict(self) -> dict[str, object]:
        """Plain data (JSON-ready): the keys of ``rockyade limit --json``."""
        model = self.model
        out: dict[str, object] = {
            "status": self.status,
            "load_multiplier": self.load_multiplier,
            "direction": self.direction,
            "friction_angle_deg": self.friction_angle_deg,
            "sliding_allowed": self.sliding_allowed,
            "friction_rule": self.friction_rule,
            "iterations": self.iterations,
            "reason": self.reason,
            "n_blocks": model.n_blocks,
            "n_interfaces": len(model.interfaces),
            "solve_time_s": self.solve_time_s,
            "notes": self.notes,
            "loads": model.loads_table(),
            "mechanism": None,
            "hinges": [],
            "sliding": [],
            "contacts": [],
        }
        keys = ("alpha0", "e_star", "M_star_kg", "a0_star_m_s2", "d0_star_m", "du_star_m", "Ts_s")
        out.update(dict.fromkeys(keys))
        out["code_friction"] = None if self.friction_check is None else self.friction_check.to_dict()
        out["fm_MPa"] = None if self.crushing is None else self.crushing.fm_MPa
        out["crushing"] = None if self.crushing is None else self.crushing.to_dict()
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
        code = self.for_code  # the code's quantities: the coulomb pass's where it governs (FrictionCheck)
        if code.kinematic is not None:
            kin = code.kinematic.to_dict()
            out["kinematic"] = kin
            for key in keys:
                out[key] = kin[key]
        if code is not self:
            out["code_mechanism"] = code.to_dict()
        out["code_multiplier"] = code.load_multiplier
        out["code_friction_rule"] = code.friction_rule
        if self.rigid is not None:
            out["rigid"] = {
                "load_multiplier": self.rigid.load_multiplier,
                "code_multiplier": self.rigid.for_code.load_multiplier,
            }
        return out


def limit_analysis(
    scene,
    direction: str = "+x",
    loads: Sequence[PointLoad] = (),
    friction_angle_deg: float | None = None,
    sliding: bool = True,
    fc: float = DEFAULT_FC,
    nonlinear: bool = True,
    friction_rule: str = "associated",
    max_iterations: int = MAX_ITERATIONS,
    time_limit_s: float | None = None,
    on_iteration: Callable[[int, float, float], None] | None = None,
    coulomb_check: bool = False,
    fm_MPa: float | None = None,
    on_progress: Callable[[float, str], None] | None = None,
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
        Friction angle of every joint, degrees in [0, 89.9] (rigid_blocks.MAX_FRICTION_ANGLE_DEG); None: the scene's.
    sliding
        False: no joint slides (the multiplier of pure rocking mechanisms).
    fc
        The code's confidence factor FC in [1, 10] (default 1.35).
    nonlinear
        Also the nonlinear kinematic analysis (the capacity curve to alpha = 0).
    friction_rule
        "associated" (default): Coulomb's cone with its associated flow, sliding joints dilate
        (:mod:`rockyade.limit.lp`); "coulomb": sliding without dilatancy, by the iteration of
        :mod:`rockyade.limit.coulomb` from the associated solution. Its status is
        "not_converged" (no multiplier) when the iteration does not settle.
    max_iterations
        The coulomb rule's programmes at most, an integer in [1, 10000] (default 100).
    time_limit_s
        Wall time the programmes may take, s, in (0, 1e6] (None: no limit). The associated programme
        past it raises :class:`rockyade.limit.lp.TimeLimitError`; the coulomb rule's iteration past it
        stops with status "not_converged" and a reason that says so.
    on_iteration
        The coulomb rule's progress: called after every programme with (iteration, lambda, seconds).
    coulomb_check
        Under the associated rule, when the mechanism slides where a joint has friction, also solve
        the coulomb rule (from the same model) and attach it (``friction_check``): the code's
        quantities (``for_code``) take the lower multiplier. Not run when the mechanism does not
        slide with friction (the two rules then give the same mechanism's work).
    fm_MPa
        The masonry's compressive strength, MPa in (0, 1e9]: the hinges move into the joints by the
        stress block's resultant, iterated with the programme's normal forces to a fixed point
        (:mod:`rockyade.limit.crushing`); None: rigid blocks (hinges at the joints' edges).
    on_progress
        Progress within a large programme, solved in a child process: called every 10 s with (seconds,
        HiGHS's latest iteration in words) (:func:`rockyade.limit.lp.solve_equilibrium`).
    """
    if direction not in DIRECTIONS:
        raise InputError("direction", f"must be +x or -x, got {direction!r}")
    check_friction_rule(friction_rule)
    if isinstance(max_iterations, bool) or not isinstance(max_iterations, int) or not 1 <= max_iterations <= 10000:
        raise InputError("max_iterations", f"must be an integer in [1, 10000], got {max_iterations!r}")
    fc = check_fc(fc)
    if time_limit_s is not None and not (
        isinstance(time_limit_s, (int, float)) and math.isfinite(time_limit_s) and 0.0 < time_limit_s <= 1.0e6
    ):
        raise InputError("time_limit_s", f"must be a time in (0, 1e6] s, got {time_limit_s!r}")
    if fm_MPa is not None:
        fm_MPa = check_fm(fm_MPa)
    if isinstance(scene, RigidBlockModel):
        if loads or friction_angle_deg is not None or not sliding:
            raise InputError("loads", "give loads and friction when building the RigidBlockModel, not here")
        model = scene
    else:
        model = rigid_block_model(scene, loads=loads, friction_angle_deg=friction_angle_deg, sliding=sliding)
    # the settings every pass shares (the crushing iteration's, the coulomb check's)
    solve = functools.partial(
        limit_analysis, fc=fc, max_iterations=max_iterations, on_iteration=on_iteration, on_progress=on_progress
    )
    if fm_MPa is not None:
        start = time.perf_counter()
        _, crushed_model, crushing = iterate_crushing(
            model,
            fm_MPa,
            lambda m: solve(m, direction, nonlinear=False, friction_rule=friction_rule),
        )
        left = None if time_limit_s is None else max(time_limit_s - (time.perf_counter() - start), 1e-3)
        result = solve(crushed_model, direction, nonlinear=nonlinear, friction_rule=friction_rule, time_limit_s=left)
        result = replace(result, crushing=crushing)
    else:
        result = _limit_analysis(
            model, direction, fc, nonlinear, friction_rule, max_iterations, time_limit_s, on_iteration, on_progress
        )
    if coulomb_check and friction_rule == "associated" and slides_with_friction(result.model, result.mechanism):
        assert result.load_multiplier is not None  # a mechanism comes with its multiplier
        coulomb = solve(
            model, direction, nonlinear=nonlinear, friction_rule="coulomb", time_limit_s=time_limit_s, fm_MPa=fm_MPa
        )
        result = replace(result, friction_check=FrictionCheck(result.load_multiplier, coulomb))
    if fm_MPa is not None and (friction_rule == "coulomb" or result.friction_check is not None):
        rigid = solve(
            model,
            direction,
            nonlinear=nonlinear,
            friction_rule=friction_rule,
            time_limit_s=time_limit_s,
            coulomb_check=coulomb_check,
        )
        result = replace(result, rigid=rigid)
    return result


def _limit_analysis(
    model: RigidBlockModel,
    direction: str,
    fc: float,
    nonlinear: bool,
    friction_rule: str,
    max_iterations: int,
    time_limit_s: float | None,
    on_iteration: Callable[[int, float, float], None] | None,
    on_progress: Callable[[float, str], None] | None = None,
) -> LimitResult:
    """:func:`limit_analysis` of a model with its joints as they are (checked arguments)."""
    angles = {itf.friction_angle_deg for itf in model.interfaces}
    if angles == {None} or not model.interfaces:
        phi: float | str | None = None
    elif len(angles) == 1:
        phi = float(next(a for a in angles if a is not None))
    else:
        phi = "scene"
    t0 = time.perf_counter()
    sol, model = solve_admissible(model, direction, time_limit_s=time_limit_s, on_progress=on_progress)
    rule = friction_rule
    if sol.status != "collapse":
        return LimitResult(sol.status, None, direction, model, None, None, None, None, phi, sol.solve_time_s, rule)
    iterations = 0
    if friction_rule == "coulomb" and phi is not None:
        left = None if time_limit_s is None else time_limit_s - (time.perf_counter() - t0)
        iterated = solve_coulomb(
            model,
            sol,
            max_iterations=max_iterations,
            time_limit_s=left,
            on_iteration=on_iteration,
            on_progress=on_progress,
        )
        iterations, sol = iterated.iterations, iterated.solution
        if not iterated.converged:
            time_s, why = iterated.solve_time_s, iterated.reason
            return LimitResult(
                "not_converged", None, direction, model, None, None, None, None, phi, time_s, rule, iterations, why
            )
        sol = replace(sol, solve_time_s=iterated.solve_time_s)
    assert sol.load_multiplier is not None  # a "collapse" always carries its multiplier (lp.py)
    lam = 0.0 if abs(sol.load_multiplier) <= ZERO_MULTIPLIER else sol.load_multiplier  # -1e-17 is 0, not "-0"
    sol = replace(sol, load_multiplier=lam)
    mech = mechanism_of(model, sol, "coulomb" if sol.friction_capacity_N is not None else "associated")
    kin = kinematic_quantities(model, mech, lam, direction, fc=fc, nonlinear=nonlinear)
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
        friction_rule,
        iterations,
    )
