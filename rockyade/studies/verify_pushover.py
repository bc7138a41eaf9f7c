"""``rockyade verify``'s pushover checks: the reference DEM's pushover onset against the closed
form of a loaded block and against the limit analysis of a block, an arch, a restrained wall and
a running-bond panel (``loaded_pushover``, ``limit_pushover``; :mod:`rockyade.studies.verification`
describes each), and the short held-level pushover they share."""

from __future__ import annotations

import math
from typing import Any

from rockyade.result import Result
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import arch, rest_motion, wall, wall_section
from rockyade.solvers import Solver, as_solver, run
from rockyade.studies.verify_closed import loaded_block_scene, loaded_lambda
from rockyade.studies.verify_rows import Row, at_most, known, relative


def check_loaded_pushover(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The reference DEM's pushover onset of the loaded block (module docstring); a short scene:
    gravity ramp 0.5 s, settle 0.2 s, rise 0.2 g/s to the levels."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.motion.quasistatic import Pushover
    from rockyade.motion.spec import parse_motion

    expected = loaded_lambda()
    step, start = round(0.01 * expected, 6), round(0.98 * expected, 6)
    motion = {
        "type": "pushover",
        "direction": "+x",
        "ramp_s": 0.5,
        "settle_s": 0.2,
        "rate_g_per_s": 0.2,
        "max_lambda": round(start + 6 * step, 6),
        "start_lambda": start,
        "step_lambda": step,
        "hold_s": 0.4,
    }
    spec = parse_motion(motion)
    assert isinstance(spec, Pushover)
    t_path, _ = spec.lambda_path(0.0)
    scene = loaded_block_scene(motion, float(t_path[-1]) + 0.5)
    result = run(scene, "reference")
    onset = pushover_onset(capacity_curve(result, scene), scene)
    src = "(W b + N d) / (W h_c)"
    return [
        Row(
            "loaded_pushover",
            "reference",
            "pushover onset (first held level it did not stand)",
            onset.multiplier,
            expected,
            src,
            relative(0.02),
        ),
        Row(
            "loaded_pushover",
            "reference",
            "last held level it stood (at most the closed form, levels rounded to 1e-6)",
            onset.below,
            expected,
            src,
            at_most(1e-6),
        ),
    ], {"reference": result}


#: Held levels of ``limit_pushover``: from LIMIT_PUSH_START times the LP multiplier, every
#: LIMIT_PUSH_STEP of it, LIMIT_PUSH_LEVELS of them (0.98, 0.99, ..., 1.02).
LIMIT_PUSH_START, LIMIT_PUSH_STEP, LIMIT_PUSH_LEVELS = 0.98, 0.01, 5


def _short_pushover(expected: float) -> dict[str, Any]:
    """A short pushover about ``expected``: gravity ramp 0.5 s, settle 0.2 s, rise 0.2 g/s, the
    held levels of ``limit_pushover`` (0.4 s each; levels rounded to 1e-6)."""
    step, start = round(LIMIT_PUSH_STEP * expected, 6), round(LIMIT_PUSH_START * expected, 6)
    return {
        "type": "pushover",
        "direction": "+x",
        "ramp_s": 0.5,
        "settle_s": 0.2,
        "rate_g_per_s": 0.2,
        "max_lambda": round(start + (LIMIT_PUSH_LEVELS - 1) * step, 6),
        "start_lambda": start,
        "step_lambda": step,
        "hold_s": 0.4,
    }


ControlPoint = tuple[str, tuple[float, float]] | None


def limit_pushover_scenes(motion: dict[str, Any] | None = None) -> dict[str, tuple[dict[str, Any], ControlPoint]]:
    """The scenes of ``limit_pushover`` as dictionaries (duration 1 s; the check sets it), each
    with its control block and point, m (None: the top block's top centre).

    * ``block``: 0.4 x 2 m, 1000 kg, lambda = b / h = 0.2;
    * ``arch``: 20 voussoirs, t/R = 0.15 (R = 1 m) on fixed piers 0.5 m high (four hinges);
    * ``restrained wall``: 0.3 x 3 m in two blocks split at 1.5 m, a frictionless side
      restraint 0.3 m deep at its top (the three-hinge mechanism, 17/35; control: the hinge
      between the blocks);
    * ``panel``: running bond, 4 courses of 3 units 0.4 x 0.2 m, 30 degree joints (sliding
      on a bed joint, tan(30 deg)).
    """
    m = dict(motion or rest_motion())
    t = 0.15
    arch_data = arch(
        span_m=2.0 * (1.0 - t / 2.0),
        ring_depth_m=t,
        voussoirs=20,
        pier_width_m=2.0 * t,
        pier_height_m=0.5,
        piers="fixed",
        motion=m,
        duration_s=1.0,
    )
    panel = wall(courses=4, units_per_course=3, motion=m, duration_s=1.0)
    panel["contact"]["friction_angle_deg"] = 30.0
    block = {
        "duration_s": 1.0,
        "sample_dt_s": 0.002,
        "blocks": [{"name": "pier", "width_m": 0.4, "height_m": 2.0, "thickness_m": 1.0, "mass_kg": 1000.0}],
        "motion": m,
    }
    restrained = wall_section(
        courses=2, split=0.5, top="restrained-far", restraint_friction_deg=0.0, motion=m, duration_s=1.0
    )
    return {
        "block": (block, None),
        "arch": (arch_data, None),
        "restrained wall": (restrained, ("w01", (-0.15, 1.5))),
        "panel": (panel, None),
    }


def limit_pushover_row(check: str, name: str, solver: Solver | str = "reference") -> Row:
    """The pushover onset of ``limit_pushover_scenes()[name]`` in ``solver`` (the first held level
    at which the control point moved more than 1 mm; NaN for a failed run) against the limit
    analysis's multiplier, within 2 %: a row of check ``check``."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.limit import limit_analysis
    from rockyade.motion.quasistatic import Pushover
    from rockyade.motion.spec import parse_motion

    data, control = limit_pushover_scenes()[name]
    # the multiplier only: the capacity curve to alpha = 0 (nonlinear) cost some 5 s of CPU a scene
    expected = known(
        limit_analysis(scene_from_dict(data), direction="+x", nonlinear=False).load_multiplier, "load multiplier"
    )
    motion = parse_motion(_short_pushover(expected))
    assert isinstance(motion, Pushover)
    t_path, _ = motion.lambda_path(0.0)
    scene = scene_from_dict(data).with_changes(motion=motion, duration_s=float(t_path[-1]) + 0.5)
    block, point = control if control is not None else (None, None)
    result = run(scene, solver)
    onset = (
        pushover_onset(capacity_curve(result, scene, block=block, point_m=point), scene).multiplier
        if result.ok
        else math.nan
    )
    return Row(
        check,
        as_solver(solver).name,
        f"{name}: pushover onset (first held level it did not stand)",
        onset,
        expected,
        "limit analysis",
        relative(0.02),
    )


def check_limit_pushover(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The limit analysis's multiplier against the reference DEM's pushover onset (the first held
    level at which the control point moved more than 1 mm) for a block, an arch, a restrained
    wall and a running-bond panel: within 2 % (:func:`limit_pushover_scenes`). The reference DEM
    only (YADE's onsets are in tests/test_pushover.py: minutes of CPU; Siconos's in
    :func:`rockyade.studies.verify_siconos.check_siconos`)."""
    return [limit_pushover_row("limit_pushover", name) for name in limit_pushover_scenes()], {}
