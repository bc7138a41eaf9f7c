"""``rockyade verify``'s checks of the DEMs (and any solver named) on assemblies: the rocking
frame and the drum column against closed forms, the pad case's overlaps, a 1,000-block wall at
rest, the reference DEM against YADE and this version's baseline (``frame``, ``drums``,
``pad``, ``wall``, ``agreement``, ``baseline``; :mod:`rockyade.studies.verification` describes each)."""

from __future__ import annotations

import io
import json
import math
from collections.abc import Callable, Sequence
from importlib import resources
from typing import Any

import numpy as np
import pandas as pd

from rockyade.analysis.overlap import max_overlap
from rockyade.blocks.restitution import effective_restitution, find_peaks
from rockyade.constants import G
from rockyade.result import Result
from rockyade.scene import Scene, scene_from_dict
from rockyade.scene.generators import drum_column, pulse_motion, rest_motion, rocking_frame, wall
from rockyade.solvers import Solver, as_solver, run
from rockyade.studies.verify_rows import Row, absolute, at_least, at_most, relative, relative_difference


def _first_impact_and_peak(result: Result, name: str | None = None) -> tuple[float, float]:
    theta = result.series("theta_rad", name)
    t = result.t
    lifted = np.flatnonzero(np.abs(theta) > 1e-4)
    start = int(lifted[0]) if lifted.size else 0
    crossings = np.flatnonzero(np.sign(theta[start + 1 :]) != np.sign(theta[start:-1])) + start
    impact = float(t[crossings[0]]) if crossings.size else math.nan
    return impact, float(np.max(np.abs(theta)))


def frame_scene(solver_dt: float | None = None) -> Scene:
    """The frame of the check: 0.2 x 1.2 m columns 1.2 m apart, a 0.2 m beam, gamma from
    equal densities, a one-sine pulse of 0.6 g and 0.5 s (rocks them to about 0.7 alpha)."""
    data = rocking_frame(
        column_width_m=0.2,
        column_height_m=1.2,
        span_m=1.2,
        beam_height_m=0.2,
        beam_overhang_m=0.1,
        thickness_m=0.3,
        density_kg_m3=2400,
        motion=pulse_motion(amplitude_g=0.6, period_s=0.5),
        duration_s=1.0,
        sample_dt_s=0.0005,
    )
    return scene_from_dict(data)


def _named(solvers: Sequence[str | Solver]) -> dict[str, Solver]:
    """The solvers by name (a name gives the solver with its default options)."""
    return {as_solver(s).name: as_solver(s) for s in solvers}


def check_frame(solvers: Sequence[str | Solver]) -> tuple[list[Row], dict[str, Result]]:
    """A rocking frame under a one-sine pulse against Housner's column with
    p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)) (Makris & Vassiliou 2013): first impact
    time (s) within 2 %, first peak (rad) within 3 % (module docstring, ``frame``).

    Parameters
    ----------
    solvers
        The solvers to check, by name (e.g. ``["reference", "yade"]``) or with their options.

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
    """
    scene = frame_scene()
    named = _named(solvers)
    results = {name: run(scene, solver) for name, solver in named.items()}
    body = results[next(iter(named))].meta.bodies or {}
    col = scene.blocks[0]
    m_col = col.block().mass_kg
    gamma = scene.blocks[2].block().mass_kg / (2 * m_col)
    p_col = body[col.name]["p_rad_s"]
    p_hat = p_col * math.sqrt((1 + 2 * gamma) / (1 + 3 * gamma))
    single = scene_from_dict(
        {
            "duration_s": scene.duration_s,
            "sample_dt_s": scene.sample_dt_s,
            "blocks": [
                {
                    "name": "column",
                    "width_m": col.width_m,
                    "height_m": col.height_m,
                    "thickness_m": col.thickness_m,
                    "density_kg_m3": col.density_kg_m3,
                    "alpha_rad": body[col.name]["alpha_rad"],
                    "p_rad_s": p_hat,
                }
            ],
            "contact": {"calibration": "paper"},
            "motion": scene.motion.to_dict(),
        }
    )
    exact = run(single, "housner")
    results["housner (p_hat)"] = exact
    t_exact, peak_exact = _first_impact_and_peak(exact)
    rows = []
    source = f"Housner column, p_hat = {p_hat:.4g} 1/s (gamma {gamma:.3g})"
    for solver in named:
        t_imp, peak = _first_impact_and_peak(results[solver], col.name)
        rows.append(Row("frame", solver, "first impact time (s)", t_imp, t_exact, source, relative(0.02)))
        rows.append(Row("frame", solver, "first peak (rad)", peak, peak_exact, source, relative(0.03)))
    return rows, results


def check_drums(
    solvers: Sequence[str | Solver], rate_g_per_s: float = 0.05, duration_s: float = 3.2
) -> tuple[list[Row], dict[str, Result]]:
    """A column of 8 drums under a slow ramp of base acceleration (m/s^2) uplifts as one body
    at g b / (H / 2), within 2 %, its top and bottom drums turning together within 5 %
    (module docstring, ``drums``).

    Parameters
    ----------
    solvers
        The solvers to check, by name (e.g. ``["reference", "yade"]``) or with their options.
    rate_g_per_s, duration_s
        The ramp's rise, g/s, and its length, s (the monolith runs the same ramp).

    Returns as :func:`check_frame`.
    """
    rate, duration = rate_g_per_s * G, duration_s
    motion = {"type": "sampled", "t_s": [0.0, duration], "accel_m_s2": [0.0, rate * duration]}
    drums = scene_from_dict(
        drum_column(
            8, diameter_m=0.3, drum_height_m=0.3, thickness_m=0.3, motion=motion, duration_s=duration, sample_dt_s=0.001
        )
    )
    monolith = scene_from_dict(
        drum_column(
            1, diameter_m=0.3, drum_height_m=2.4, thickness_m=0.3, motion=motion, duration_s=duration, sample_dt_s=0.001
        )
    )
    exact = run(monolith, "housner")
    results: dict[str, Result] = {"housner (monolith)": exact}

    def level(result: Result, name: str | None) -> tuple[int, float]:
        theta = np.abs(result.series("theta_rad", name))
        k = int(np.argmax(theta >= 1e-3))
        return (k, result.t[k] * rate / G) if theta[k] >= 1e-3 else (-1, math.nan)

    _, exact_level = level(exact, None)
    names = [b.name for b in drums.blocks]
    rows = []
    for solver, how in _named(solvers).items():
        result = run(drums, how)
        results[solver] = result
        k, bottom = level(result, names[0])
        _, top = level(result, names[-1])
        src = "monolithic Housner column (same height)"
        rows.append(
            Row(
                "drums",
                solver,
                "uplift ramp level, bottom drum (g)",
                bottom,
                exact_level,
                src,
                relative(0.02),
            )
        )
        rows.append(
            Row(
                "drums",
                solver,
                "uplift ramp level, top drum (g)",
                top,
                exact_level,
                src,
                relative(0.02),
            )
        )
        ratio = (
            result.series("theta_rad", names[-1])[k] / result.series("theta_rad", names[0])[k] if k >= 0 else math.nan
        )
        rows.append(
            Row(
                "drums",
                solver,
                "top / bottom rotation at uplift",
                ratio,
                1.0,
                "one body",
                relative(0.05),
            )
        )
    return rows, results


def pad_scene() -> Scene:
    """A 0.6 x 0.3 m block on a 0.1 m pad on a 0.6 x 0.3 m block; a one-sine pulse (0.5 g, 0.4 s)."""

    def block(name: str, w: float, h: float, y: float) -> dict[str, Any]:
        return {
            "name": name,
            "width_m": w,
            "height_m": h,
            "thickness_m": 0.3,
            "density_kg_m3": 2400,
            "position_m": [0.0, y],
        }

    return scene_from_dict(
        {
            "duration_s": 2.0,
            "sample_dt_s": 0.002,
            "blocks": [block("lower", 0.6, 0.3, 0.0), block("pad", 0.1, 0.1, 0.3), block("upper", 0.6, 0.3, 0.4)],
            "contact": {"K_N_per_m": 1e8, "beta_s": 1e-4},
            "motion": pulse_motion(amplitude_g=0.5, period_s=0.4),
        }
    )


def check_pad(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """A block above a pad on a lower block under a pulse: no overlap beyond 1 mm (module
    docstring, ``pad``).

    Parameters and returns as :func:`check_frame` (solvers by name).
    """
    scene = pad_scene()
    rows, results = [], {}
    for solver in solvers:
        result = run(scene, solver)
        results[solver] = result
        worst = max_overlap(result)
        rows.append(
            Row(
                "pad",
                solver,
                f"deepest overlap (m), {'-'.join(worst.between)} at {worst.t_s:.3g} s",
                worst.depth_m,
                0.0,
                "no missed contact",
                at_most(1e-3, "m"),
            )
        )
        peak = float(np.max(np.abs(result.series("theta_rad", "upper"))))
        reach = math.atan2(0.1, 0.25)
        rows.append(
            Row(
                "pad",
                solver,
                "upper block peak (rad): reaches the lower block",
                peak,
                reach,
                "atan(pad height / (half width - pad half width))",
                at_least(),
            )
        )
    return rows, results


def check_wall(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """About 1,000 blocks at rest: they settle elastically to the linear statics of the joints
    (rockyade.dem.statics) and do not move beyond it."""
    from rockyade.calibration.model_stage import calibrated_model
    from rockyade.dem.statics import rest_springs, static_displacement

    data = wall(courses=32, units_per_course=32, motion=rest_motion(), duration_s=1.5, sample_dt_s=0.005)
    scene = scene_from_dict(data)
    model = calibrated_model(scene)
    fixed = [b.fixed for b in model.bodies]
    springs = rest_springs(model.pos0_m, fixed, list(model.rest_contacts), model.joints)
    static = static_displacement(springs, [b.mass_kg for b in model.bodies], fixed, model.g)
    result = run(scene, "reference")
    names = [b.name for b in scene.blocks]
    late = result.t >= 0.8 * result.t[-1]
    x = np.array([result.series("x_m", n) for n in names])
    y = np.array([result.series("y_m", n) for n in names])
    turn = max(float(np.max(np.abs(result.series("theta_rad", n)))) for n in names)
    src = f"{len(names)} blocks at rest"
    rows = [Row("wall", "reference", "largest block rotation (rad)", turn, 0.0, src, absolute(1e-3, "rad"))]
    if static is not None:
        move = float(np.max(np.hypot(x[:, late] - static[:, [0]], y[:, late] - static[:, [1]])))
        rows.append(
            Row(
                "wall",
                "reference",
                "largest movement beyond the static settlement, last 20 % (m)",
                move,
                0.0,
                src,
                absolute(2e-4, "m"),
            )
        )
        # the wall rings in its lightly damped vertical mode: average over the last 20 %
        settle, settle_static = float(-y[:, late].mean(axis=1).min()), float(-static[:, 1].min())
        rows.append(
            Row(
                "wall",
                "reference",
                "largest settlement, mean of the last 20 % (m)",
                settle,
                settle_static,
                "linear statics of the rest joints",
                relative(0.05),
            )
        )
    return rows, {"reference": result}


def _dt_sensitivity(scene: Scene, solver: str, measure: Callable[[Result], float]) -> tuple[float, float]:
    """The measure at the scene's time step and its relative change at half the step."""
    base = run(scene, solver)
    d = scene.to_dict()
    d["contact"]["dt_s"] = 0.5 * (base.meta.dt_s if base.meta.dt_s is not None else math.nan)
    finer = run(scene_from_dict(d), solver)
    a, b = measure(base), measure(finer)
    return a, relative_difference(b, a)


def check_agreement(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """Reference DEM against YADE on a slender 5-course wall and on the frame: peak rotation
    (rad) within 5 %, peak displacement (m) within 10 % or the DEMs' own changes at half the
    time step (module docstring, ``agreement``); nothing unless both solvers are given.

    Parameters and returns as :func:`check_frame` (solvers by name).
    """
    if not {"reference", "yade"} <= set(solvers):
        return [], {}
    wall5 = scene_from_dict(
        wall(
            courses=5,
            units_per_course=1,  # a 0.4 m long, 1 m high wall: uplifts at 0.4 g, rocks under 0.5 g
            motion=pulse_motion(amplitude_g=0.5, period_s=0.4),
            duration_s=1.5,
            sample_dt_s=0.002,
        )
    )
    last_course = max(b.name.split("_")[0] for b in wall5.blocks)
    top = [b.name for b in wall5.blocks if b.name.startswith(last_course + "_")]
    cases: list[tuple[str, Scene, str, Callable[[Result], float], float]] = [
        (
            "5-course wall (0.4 x 1 m): top course peak rotation (rad)",
            wall5,
            "rot",
            lambda r: max(float(np.max(np.abs(r.series("theta_rad", n)))) for n in top),
            0.05,
        ),
        (
            "5-course wall (0.4 x 1 m): top course peak displacement (m)",
            wall5,
            "disp",
            lambda r: max(float(np.max(np.abs(r.series("x_m", n)))) for n in top),
            0.10,
        ),
        (
            "frame: column peak rotation (rad)",
            frame_scene(),
            "rot",
            lambda r: float(np.max(np.abs(r.series("theta_rad", "column_left")))),
            0.05,
        ),
    ]
    rows, results = [], {}
    for label, scene, _, measure, floor in cases:
        ref, s_ref = _dt_sensitivity(scene, "reference", measure)
        yade, s_yade = _dt_sensitivity(scene, "yade", measure)
        tol = max(floor, s_ref + s_yade)
        src = f"reference DEM (dt/2 changes: reference {s_ref:.1%}, YADE {s_yade:.1%})"
        rows.append(Row("agreement", "yade", label, yade, ref, src, relative(tol)))
    results["reference"] = run(wall5, "reference")
    results["yade"] = run(wall5, "yade")
    return rows, results


def check_baseline(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The paper's single blocks and bi-block against this version's first release
    (``data/baseline_0_1.csv``): first five peaks (rad) within 1 %, mu_eff within 0.2 %
    (module docstring, ``baseline``).

    Parameters and returns as :func:`check_frame` (solvers by name).
    """
    data = resources.files("rockyade.studies").joinpath("data")
    base = pd.read_csv(io.StringIO(data.joinpath("baseline_0_1.csv").read_text()), comment="#")
    scenes = json.loads(data.joinpath("baseline_scenes.json").read_text())
    rows = []
    for (case, calibration, solver), group in base.groupby(["case", "calibration", "solver"], sort=False):
        if solver not in solvers:
            continue
        d = json.loads(json.dumps(scenes[case]))
        d["contact"]["calibration"] = calibration
        scene = scene_from_dict(d)
        result = run(scene, solver)
        for _, b in group.iterrows():
            spec = scene.blocks[scene.block_index(b["block"])]
            alpha = spec.classical().alpha_rad
            peaks = find_peaks(result.t, result.series("theta_rad", spec.name), 1e-3 * alpha)
            label = f"{case} ({calibration}) {spec.name}"
            for k in range(5):
                old = b[f"peak{k + 1}_rad"]
                if not np.isfinite(old):
                    continue
                new = float(peaks.amplitude_rad[k]) if len(peaks) > k else math.nan
                rows.append(
                    Row(
                        "baseline",
                        solver,
                        f"{label}: peak {k + 1} (rad)",
                        new,
                        old,
                        "rockyade 0.1.0",
                        relative(0.01),
                    )
                )
            if np.isfinite(b["mu_eff"]):
                mu = effective_restitution(peaks, alpha, 5)
                rows.append(
                    Row(
                        "baseline",
                        solver,
                        f"{label}: effective mu",
                        mu,
                        b["mu_eff"],
                        "rockyade 0.1.0",
                        relative(0.002),
                    )
                )
    return rows, {}
