"""A limit analysis in words: the multiplier, the mechanism (who turns about which corner,
which joints slide), the code's quantities and the checks, as ``rockyade limit`` prints them."""

from __future__ import annotations

import numpy as np

from rockyade.limit.analysis import LimitResult, slides_with_friction
from rockyade.limit.crushing import STRESS_BLOCK
from rockyade.limit.mechanism import Hinge, Sliding
from rockyade.limit.rigid_blocks import RigidBlockModel

#: Hinges and sliding joints listed in the text (the JSON lists all).
MAX_LISTED = 20


def end_name(model: RigidBlockModel, interface: int, end: int) -> str:
    """'left'/'right' end of a bed joint (normal nearer vertical), 'lower'/'upper' of a head joint."""
    itf = model.interfaces[interface]
    here, there = itf.ends_m[end], itf.ends_m[1 - end]
    if abs(itf.normal[1]) >= abs(itf.normal[0]):
        return "left" if here[0] < there[0] else "right"
    return "lower" if here[1] < there[1] else "upper"


def plural(n: int, noun: str) -> str:
    """``n`` and ``noun``, with an s unless n is 1."""
    return f"{n} {noun}{'' if n == 1 else 's'}"


def _num(value: float, scale: float = 1.0) -> str:
    """A coordinate to 4 significant digits, rounding-level values (below 1e-12 x scale) as 0."""
    return "0" if abs(value) < 1e-12 * max(scale, 1e-300) else f"{value:.4g}"


def _towards(vector: np.ndarray) -> str:
    """A direction in words: towards +x, towards -x, up, down, or an angle from +x."""
    angle = float(np.degrees(np.arctan2(vector[1], vector[0])))
    for target, word in (
        (0.0, "towards +x"),
        (180.0, "towards -x"),
        (-180.0, "towards -x"),
        (90.0, "up"),
        (-90.0, "down"),
    ):
        if abs(angle - target) < 0.05:
            return word
    return f"at {angle:.1f} deg from +x"


def hinge_words(model: RigidBlockModel, hinge: Hinge) -> str:
    """One hinge as a sentence."""
    sense = "clockwise" if hinge.relative_omega < 0 else "counter-clockwise"
    other = "the base" if hinge.b == "base" else hinge.b
    x, y = hinge.point_m
    size = model.size_m
    return (
        f"{hinge.a} turns {sense} on {other} about ({_num(x, size)}, {_num(y, size)}) m, "
        f"the {end_name(model, hinge.interface, hinge.end)} end of their joint"
    )


def sliding_words(model: RigidBlockModel, slide: Sliding, velocities: np.ndarray | None = None) -> str:
    """One sliding joint as a sentence, told from the body that moves (a, or b when a is at rest)."""
    itf = model.interfaces[slide.interface]
    mover, other, sense = slide.a, slide.b, itf.tangent * np.sign(slide.slip)
    if velocities is not None and slide.b != "base" and not np.any(velocities[itf.a]):
        mover, other, sense = slide.b, slide.a, -sense
    other = "the base" if other == "base" else other
    return (
        f"{mover} slides {_towards(sense)} on {other} "
        f"(slip {abs(slide.slip):.3g}, opening {slide.opening:.3g} per unit displacement)"
    )


def _fmt(value: float | None, unit: str = "", digits: int = 4) -> str:
    return "-" if value is None else f"{value:.{digits}g}{unit}"


def _friction_sliders(result: LimitResult) -> str:
    """The joints of the mechanism that slide with friction, named (at most three)."""
    assert result.mechanism is not None
    model = result.model
    named = [f"{s.a} on {s.b}" for s in result.mechanism.sliding if model.interfaces[s.interface].friction_angle_deg]
    return ", ".join(named[:3]) + (" ..." if len(named) > 3 else "")


def code_basis_lines(result: LimitResult) -> list[str]:
    """Which answer the code's quantities take, in words (:attr:`LimitResult.for_code`): both friction
    rules' multipliers where the mechanism slides with friction, the masonry's crushing at the hinges."""
    lines: list[str] = []
    if result.status != "collapse" or result.load_multiplier is None:
        return lines
    check = result.friction_check
    if check is not None:
        sliders = _friction_sliders(result)
        lam_c = check.coulomb_multiplier
        if lam_c is None:
            lines.append(
                f"friction: the mechanism slides with friction ({sliders}); the coulomb (non-dilatant) pass did not "
                f"converge ({check.coulomb.reason}): the code's quantities take the associated lambda = "
                f"{check.associated:.4f}, an upper bound of the non-dilatant one"
            )
        else:
            lines.append(
                f"friction: the mechanism slides with friction ({sliders}): associated (dilatant) lambda = "
                f"{check.associated:.4f}, coulomb (non-dilatant) lambda = {lam_c:.4f} (associated / coulomb = "
                f"{check.ratio:.3g}); the code's quantities take the {check.taken} one, the lower of the two"
            )
    elif result.friction_rule == "associated" and slides_with_friction(result.model, result.mechanism):
        lines.append(
            f"friction: the mechanism slides with friction ({_friction_sliders(result)}); no coulomb pass was asked "
            "(--friction-rule associated): the code's quantities take the associated lambda, an upper bound of the "
            "non-dilatant one"
        )
    elif result.friction_rule == "associated" and result.sliding_allowed:
        lines.append(
            "friction: the mechanism does not slide where a joint has friction: the associated and the coulomb rules "
            "give it the same work, so no coulomb pass is needed"
        )
    crushing = result.crushing
    if crushing is not None:
        lines.append(f"masonry crushing at the hinges, fm = {crushing.fm_MPa:g} MPa: {STRESS_BLOCK}")
        first = crushing.history[0] if crushing.history else float("nan")
        state = (
            f"a fixed point in {plural(crushing.iterations, 'iteration')}"
            if crushing.converged
            else f"NOT a fixed point ({crushing.reason})"
        )
        big = crushing.largest_shift
        where = ""
        if big is not None:
            where = (
                f"; the largest shift {big['shift_m'] * 1e3:.3g} mm, {big['a']} on {big['b']} (N = "
                f"{big['normal_N'] / 1e3:.4g} kN, a = {big['width_m'] * 1e3:.3g} mm over {big['length_m']:.4g} m)"
            )
        lines.append(
            f"  lambda = {result.load_multiplier:.4f} with the hinges moved, {first:.4f} with rigid ones: "
            f"{state}{where}"
        )
        if crushing.crushed:
            lines.append(f"  crushed (cannot carry their normal force): {', '.join(crushing.crushed[:5])}")
    if result.rigid is not None and result.for_code is result.rigid.for_code:
        code = result.for_code
        lines.append(
            f"  with the hinges moved the coulomb iteration (a heuristic) settled above the rigid model's lambda = "
            f"{code.load_multiplier:.4f}; crushing cannot raise the capacity: the code's quantities take the rigid one"
        )
    return lines


def text_report(result: LimitResult, source: str = "scene") -> list[str]:
    """The lines ``rockyade limit`` prints."""
    model = result.model
    n_fixed = int(model.fixed.sum())
    fixed = f", {n_fixed} fixed" if n_fixed else ""
    if result.friction_angle_deg is None:
        joints = "no sliding (tangential forces unbounded)"
    elif result.friction_angle_deg == "scene":
        joints = "each joint's friction angle from the scene"
    else:
        joints = f"friction angle {result.friction_angle_deg:g} deg"
    if result.sliding_allowed:
        joints += (
            f"; friction rule coulomb (sliding without dilatancy, {plural(result.iterations, 'iteration')})"
            if result.friction_rule == "coulomb"
            else "; friction rule associated (sliding dilates: --friction-rule coulomb gives the non-dilatant answer)"
        )
    lines = [
        f"limit analysis of {source}: {plural(model.n_blocks - n_fixed, 'moving block')}{fixed}, "
        f"{plural(len(model.interfaces), 'joint')}; load lambda m g towards {result.direction}; joints: {joints}",
    ]
    lines.extend(model.load_lines())
    if result.status == "unstable":
        lines.append("status: unstable: the assembly cannot stand under gravity (and its loads) alone: no")
        lines.append("  equilibrium with no-tension joints exists, so there is no load multiplier")
        if model.loads:
            from rockyade.limit.standing import unbalanced_loads_of_model

            found = unbalanced_loads_of_model(model)
            if found is not None:
                lines.append(f"  {found.message}")
    elif result.status == "no_mechanism":
        lines.append("status: no_mechanism: no horizontal acceleration makes it collapse (lambda is unbounded)")
        if not result.sliding_allowed:
            lines.append(
                "  without sliding a joint cannot open with a motion along it either (a block cannot lift off a "
                "restraint it moves along): a finite friction angle lifts that restriction"
            )
    elif result.status == "not_converged":
        lines.append(f"status: not_converged: the coulomb rule's iteration did not settle ({result.reason}): no")
        lines.append("  load multiplier; the associated rule's answer (the default) bounds it from above")
    if result.status != "collapse":
        lines.extend(f"note: {note}" for note in result.model.notes)
        return lines
    lam = result.load_multiplier
    mech = result.mechanism
    kin = result.kinematic
    assert lam is not None and mech is not None and kin is not None
    lines.append(
        f"status: collapse, load multiplier lambda = {lam:.4f} (a horizontal acceleration of {lam * model.g:.4g} "
        f"m/s^2, lambda x the mechanics' g = {model.g:g} m/s^2)"
    )
    if lam == 0.0:
        lines.append(
            "  lambda = 0: any horizontal acceleration, however small, moves it (a joint without friction, "
            "friction angle 0, slides): it has no lateral capacity to assess"
        )
    n_moving = int(mech.moving.sum())
    opened = f", {plural(len(mech.separating), 'joint')} opening fully" if mech.separating else ""
    lines.append(
        f"mechanism: {plural(n_moving, 'block')} move{'s' if n_moving == 1 else ''}; "
        f"{plural(len(mech.hinges), 'hinge')}, {plural(len(mech.sliding), 'sliding joint')}{opened}"
    )
    for hinge in mech.hinges[:MAX_LISTED]:
        lines.append("  " + hinge_words(model, hinge))
    if len(mech.hinges) > MAX_LISTED:
        lines.append(f"  ... and {len(mech.hinges) - MAX_LISTED} more hinges (--json lists all)")
    for slide in mech.sliding[:MAX_LISTED]:
        lines.append("  " + sliding_words(model, slide, mech.velocities))
    if len(mech.sliding) > MAX_LISTED:
        lines.append(f"  ... and {len(mech.sliding) - MAX_LISTED} more sliding joints (--json lists all)")
    work = "virtual work equal to friction's dissipation" if result.friction_rule == "coulomb" else "virtual work zero"
    lines.append(
        f"checks: kinematic constraints met to {mech.checks.max_closing:.1e}, {work} to "
        f"{mech.checks.virtual_work_residual:.1e} (relative)"
    )
    lines.extend(code_basis_lines(result))
    code = result.for_code
    if code is not result:
        assert code.kinematic is not None and code.mechanism is not None and code.load_multiplier is not None
        kin, cm = code.kinematic, code.mechanism
        lines.append(
            f"kinematic quantities of the {code.friction_rule} mechanism (lambda = {code.load_multiplier:.4f}: "
            f"{plural(int(cm.moving.sum()), 'block')} moving, {plural(len(cm.hinges), 'hinge')}, "
            f"{plural(len(cm.sliding), 'sliding joint')}; --json's code_mechanism), the code's:"
        )
        lines.extend("  " + hinge_words(code.model, h) for h in cm.hinges[:MAX_LISTED])
        lines.extend("  " + sliding_words(code.model, sl, cm.velocities) for sl in cm.sliding[:MAX_LISTED])
    lines.append(f"kinematic quantities (NTC 2018, Circolare 2019 C8.7.1; FC = {kin.FC:g}):")
    lines.append(
        f"  alpha0 = {kin.alpha0:.4f}; M* = {kin.M_star_kg:.4g} kg, e* = {kin.e_star:.4f} "
        f"(of {kin.participating_mass_kg:.4g} kg moving); a0* = alpha0 g / (e* FC) = {kin.a0_star_m_s2:.4g} m/s^2 "
        f"(g = {kin.g:g} m/s^2, standard gravity, the code check's)"
    )
    if kin.d0_star_m is not None:
        lines.append(
            f"  nonlinear (control point: centroid of {kin.control_block}): d0* = {_fmt(kin.d0_star_m, ' m')}, "
            f"du* = {_fmt(kin.du_star_m, ' m')}, ds* = {_fmt(kin.ds_star_m, ' m')}, "
            f"as* = {_fmt(kin.as_star_m_s2, ' m/s^2')}, Ts = {_fmt(kin.Ts_s, ' s')}"
        )
        curve = kin.curve
        if curve is not None and curve.opened:
            lines.append(
                f"  {plural(len(curve.opened), 'hinge')} of the mechanism opened on the way (keeping them all "
                "would lock it)"
            )
        if curve is not None and curve.max_overlap_m > 1e-6 * model.size_m:
            lines.append(
                f"  note: points of opened hinges pass into each other by up to {curve.max_overlap_m * 1e3:.3g} mm "
                "along the curve: new contacts are not followed"
            )
    else:
        lines.append(f"  nonlinear: none ({kin.nonlinear_note})")
    for note in result.notes:
        lines.append(f"note: {note}")
    return lines
