"""``rockyade verify``: the DEMs on assemblies against closed forms, each other and this
version's baseline, as a report (CSV, figures, index.md).

Checks (each a row per solver: measured value, what it is compared with, the difference,
the tolerance, pass or fail):

* ``frame``: a rocking frame (two equal free-standing columns, a free cap beam) rocks like
  one column with p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)), gamma = beam mass /
  columns' mass (Makris & Vassiliou 2013): under a one-sine pulse the first impact within
  2 % and the first peak within 3 % of Housner's column with p_hat;
* ``drums``: a column of 8 equal drums under a slow ramp of base acceleration uplifts as
  one body at g b / (H / 2): the ramp level at which |theta| reaches 1e-3 rad within 2 % of
  a monolithic Housner column's, the top and bottom drums turning together (within 5 %);
* ``pad``: a 0.6 x 0.3 m block above a 0.1 m pad on a lower block, under a pulse: no
  overlap beyond 1 mm (a vertex passing through a block it did not touch at rest);
* ``wall``: a dry running-bond wall of about 1,000 blocks stands under gravity: no block
  moves more than 0.2 mm or turns more than 1e-3 rad (reference DEM);
* ``agreement``: reference DEM against YADE on a slender 5-course wall (0.4 m long, 1 m
  high: it rocks and its top course slides) and on the frame, under a one-sine pulse: peak
  rotation within 5 % and peak displacement within 10 %, or the sum of the two DEMs' own
  changes when their time step is halved if larger (rocking amplifies small differences:
  two DEMs cannot agree better than each converges). The 10 % on displacements is YADE's
  modelling difference, measured and documented (docs/yade.md): its contact spheres round
  the corners, and a flush joint's end that slides apart carries K/2 there (8.8 % measured
  here, against dt/2 changes of 2.7 % and 0.2 %);
* ``baseline``: the paper's single blocks and bi-block (free rocking, harmonic, pulse):
  first five peaks and effective restitution against the values this version's first
  release computed (``data/baseline_0_1.csv``): peaks within 1 %, mu_eff within 0.2 %;
* ``kinematic``: limit analysis and the code's kinematic quantities against closed forms
  (lambda = b/h, e* = 1 and d0* = b of a block, e* of a wall of n courses, the minimum
  thickness of a semicircular arch approaching Milankovitch's t/R = 0.1075);
* ``code``: the NTC 2018 checks of a free-standing wall against the hand calculation of
  docs/limit.md (the wall of docs/howto/is-this-wall-safe.md);
* ``fragility_fit``: the lognormal fit of stripes and its bootstrap band recover the curve
  that synthetic outcomes were drawn from;
* ``loaded_block``: a block 0.4 x 2 m (1000 kg) with a vertical top load N = 8 kN at
  0.05 m from its axis, pushed towards +x (the load at d = 0.15 m from the pivot):
  lambda = (W b + N d) / (W h_c) = 0.32232 from the limit analysis and from Housner's uplift
  multiplier with the load's moment (modified Eq 1), within 1e-6;
* ``loaded_pushover``: the reference DEM's pushover onset of that block (levels held 0.4 s
  every 1 % of the closed form from 0.98 of it) within 2 % of the closed form, and the last
  level at which it stood at most the closed form;
* ``limit_pushover``: the limit analysis's multiplier against the reference DEM's pushover
  onset (held levels every 1 % of it from 0.98 of it) within 2 %, for a block, a 20-voussoir
  arch, a wall restrained at its top (three hinges) and a running-bond panel that slides on a
  bed joint (a slender panel goes below the limit analysis: docs/assemblies.md);
* ``siconos``: Siconos (nonsmooth contact dynamics) against closed forms: free-rocking
  restitution against Housner's Eq 4 (0.5 %) and a block's pushover onset against the limit
  analysis (2 %) (:func:`check_siconos`).

``kinematic``, ``code``, ``fragility_fit`` and ``loaded_block`` run no solver (the
limit-analysis programme, Housner's model and the fit only).
"""

from __future__ import annotations

import io
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from rockyade.analysis.overlap import max_overlap
from rockyade.blocks.restitution import effective_restitution, find_peaks
from rockyade.constants import CODE_GRAVITY, G
from rockyade.io.atomic import atomic_open, write_text
from rockyade.result import Result
from rockyade.scene import Scene, scene_from_dict
from rockyade.scene.generators import (
    arch,
    drum_column,
    pulse_motion,
    rest_motion,
    rocking_frame,
    stack,
    wall,
    wall_section,
)
from rockyade.solvers import run
from rockyade.studies.checks import CHECKS

if TYPE_CHECKING:
    from rockyade.limit.analysis import LimitResult
    from rockyade.limit.kinematic import KinematicQuantities


@dataclass(frozen=True)
class Row:
    """One verified quantity."""

    check: str
    solver: str
    quantity: str
    value: float
    expected: float
    expected_from: str
    tolerance: str
    passed: bool

    @property
    def difference(self) -> float:
        """Measured minus expected value, in the quantity's unit."""
        return self.value - self.expected


def _rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b) if b else math.inf


def _kinematic(result: LimitResult) -> KinematicQuantities:
    """The kinematic quantities of a limit analysis (the scenes checked here all collapse)."""
    if result.kinematic is None:
        raise RuntimeError(f"the limit analysis found no mechanism ({result.status})")
    return result.kinematic


def _known(value: float | None, name: str) -> float:
    """``value``, which the check needs (RuntimeError when the analysis gave none)."""
    if value is None:
        raise RuntimeError(f"the analysis gave no {name}")
    return value


def _first_impact_and_peak(result: Result, name: str | None = None) -> tuple[float, float]:
    theta = result.series("theta_rad", name)
    t = result.t
    lifted = np.flatnonzero(np.abs(theta) > 1e-4)
    start = int(lifted[0]) if lifted.size else 0
    crossings = np.flatnonzero(np.sign(theta[start + 1 :]) != np.sign(theta[start:-1])) + start
    impact = float(t[crossings[0]]) if crossings.size else math.nan
    return impact, float(np.max(np.abs(theta)))


# ---------------------------------------------------------------------- checks


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


def check_frame(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """A rocking frame under a one-sine pulse against Housner's column with
    p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)) (Makris & Vassiliou 2013): first impact
    time (s) within 2 %, first peak (rad) within 3 % (module docstring, ``frame``).

    Parameters
    ----------
    solvers
        Names of the solvers to check (e.g. ``["reference", "yade"]``).

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
    """
    scene = frame_scene()
    results = {s: run(scene, s) for s in solvers}
    body = results[solvers[0]].meta.bodies or {}
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
    for solver in solvers:
        t_imp, peak = _first_impact_and_peak(results[solver], col.name)
        rows.append(
            Row("frame", solver, "first impact time (s)", t_imp, t_exact, source, "2 %", _rel(t_imp, t_exact) <= 0.02)
        )
        rows.append(
            Row("frame", solver, "first peak (rad)", peak, peak_exact, source, "3 %", _rel(peak, peak_exact) <= 0.03)
        )
    return rows, results


def check_drums(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """A column of 8 drums under a slow ramp of base acceleration (m/s^2) uplifts as one body
    at g b / (H / 2), within 2 %, its top and bottom drums turning together within 5 %
    (module docstring, ``drums``).

    Parameters
    ----------
    solvers
        Names of the solvers to check (e.g. ``["reference", "yade"]``).

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
    """
    rate, duration = 0.05 * G, 3.2
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
    for solver in solvers:
        result = run(drums, solver)
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
                "2 %",
                _rel(bottom, exact_level) <= 0.02,
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
                "2 %",
                _rel(top, exact_level) <= 0.02,
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
                "5 %",
                abs(ratio - 1) <= 0.05,
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

    Parameters
    ----------
    solvers
        Names of the solvers to check (e.g. ``["reference", "yade"]``).

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
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
                "<= 1 mm",
                worst.depth_m <= 1e-3,
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
                ">= expected",
                peak >= reach,
            )
        )
    return rows, results


def check_wall(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """About 1,000 blocks at rest: they settle elastically to the linear statics of the joints
    (rockyade.dem.statics) and do not move beyond it."""
    from rockyade.calibration.model import calibrated_model
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
    rows = [Row("wall", "reference", "largest block rotation (rad)", turn, 0.0, src, "<= 1e-3 rad", turn <= 1e-3)]
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
                "<= 0.2 mm",
                move <= 2e-4,
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
                "5 %",
                _rel(settle, settle_static) <= 0.05,
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
    return a, _rel(b, a)


def check_agreement(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """Reference DEM against YADE on a slender 5-course wall and on the frame: peak rotation
    (rad) within 5 %, peak displacement (m) within 10 % or the DEMs' own changes at half the
    time step (module docstring, ``agreement``); nothing unless both solvers are given.

    Parameters
    ----------
    solvers
        Names of the solvers to check (e.g. ``["reference", "yade"]``).

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
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
        rows.append(Row("agreement", "yade", label, yade, ref, src, f"{tol:.1%}", _rel(yade, ref) <= tol))
    results["reference"] = run(wall5, "reference")
    results["yade"] = run(wall5, "yade")
    return rows, results


def check_baseline(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The paper's single blocks and bi-block against this version's first release
    (``data/baseline_0_1.csv``): first five peaks (rad) within 1 %, mu_eff within 0.2 %
    (module docstring, ``baseline``).

    Parameters
    ----------
    solvers
        Names of the solvers to check (e.g. ``["reference", "yade"]``).

    Returns
    -------
    rows, results
        One :class:`Row` per solver and quantity (value, expected value, tolerance, pass),
        and the Results the figures are drawn from, by solver.
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
                        "1 %",
                        _rel(new, old) <= 0.01,
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
                        "0.2 %",
                        _rel(mu, b["mu_eff"]) <= 0.002,
                    )
                )
    return rows, {}


# ---------------------------------------------------------------------- limit analysis and the code


def _block_scene(width: float, height: float) -> Scene:
    """One block on the base (a column scene), 1 m thick, 1800 kg/m^3, friction 30 degrees."""
    return scene_from_dict(
        stack(widths_m=[width], heights_m=height, thickness_m=1.0, density_kg_m3=1800.0, layout="column")
    )


def _arch_minimum_thickness(voussoirs: int, tol: float = 2e-5) -> float:
    """t/R of a semicircular arch of mean radius 1 m on fixed piers below which it cannot stand
    (the programme's status 'unstable' under gravity), by bisection."""
    from rockyade.limit import rigid_block_model
    from rockyade.limit.lp import solve_equilibrium

    def stands(t_over_r: float) -> bool:
        data = arch(
            span_m=2.0 - t_over_r,
            ring_depth_m=t_over_r,
            voussoirs=voussoirs,
            pier_width_m=2.0 * t_over_r,
            pier_height_m=0.5,
            piers="fixed",
            motion=rest_motion(),
        )
        return solve_equilibrium(rigid_block_model(scene_from_dict(data), sliding=False)).status == "collapse"

    lo, hi = 0.09, 0.13
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if stands(mid) else (mid, hi)
    return 0.5 * (lo + hi)


def check_kinematic(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """Limit analysis and the code's kinematic quantities against closed forms: lambda = b/h,
    e* = 1 and d0* = b of a block; e* of a wall of n courses turning as one about its toe,
    (1/4) / (1/3 - 1/(12 n^2)) -> 0.75; the minimum thickness of a semicircular arch
    approaching Milankovitch's t/R = 0.1075 (60 voussoirs: 0.10745, docs/limit.md)."""
    from rockyade.limit import limit_analysis

    rows = []
    for width, height in ((0.25, 2.5), (0.4, 2.0), (1.0, 0.5)):
        res = limit_analysis(_block_scene(width, height), sliding=False)
        kin = _kinematic(res)
        lam = _known(res.load_multiplier, "load multiplier")
        d0 = _known(kin.d0_star_m, "d0*")
        label = f"block {width:g} x {height:g} m"
        rows += [
            Row(
                "kinematic",
                "limit",
                f"{label}: lambda",
                lam,
                width / height,
                "b/h",
                "1e-9",
                _rel(lam, width / height) <= 1e-9,
            ),
            Row(
                "kinematic",
                "limit",
                f"{label}: e*",
                kin.e_star,
                1.0,
                "a block: 1",
                "1e-9",
                abs(kin.e_star - 1.0) <= 1e-9,
            ),
            Row(
                "kinematic",
                "limit",
                f"{label}: d0* (m)",
                d0,
                width / 2,
                "b (centroid over the pivot)",
                "1e-6",
                _rel(d0, width / 2) <= 1e-6,
            ),
        ]
    for n in (2, 5, 10):
        data = wall(courses=n, units_per_course=1, bond="stack", unit_length_m=0.4, unit_height_m=0.5)
        kin = _kinematic(limit_analysis(scene_from_dict(data), sliding=False))
        expected = 0.25 / (1.0 / 3.0 - 1.0 / (12.0 * n * n))
        rows.append(
            Row(
                "kinematic",
                "limit",
                f"wall of {n} courses turning as one: e*",
                kin.e_star,
                expected,
                "(1/4) / (1/3 - 1/(12 n^2))",
                "1e-9",
                _rel(kin.e_star, expected) <= 1e-9,
            )
        )
    rows += _restrained_wall_rows()
    t60 = _arch_minimum_thickness(60)
    rows.append(
        Row(
            "kinematic",
            "limit",
            "semicircular arch, 60 voussoirs: minimum t/R",
            t60,
            0.1075,
            "Milankovitch (the inscribed polygonal arch approaches it from below)",
            "2e-4",
            abs(t60 - 0.1075) <= 2e-4,
        )
    )
    return rows, {}


def _restrained_wall_rows() -> list[Row]:
    """The wall restrained at its top against closed forms (docs/assemblies.md, tests/test_restraints.py):
    the two-block wall's three-hinge mechanism, 17/35 (t 0.3, H 3, split 0.5, restraint 0.3 deep,
    frictionless); the 8-course tuff wall (H 2.4, t 0.36, 1600 kg/m^3, joints 35 degrees, a roof of
    6 kN/m at 0.05 m without mass, a frictionless restraint on its far face): the seven lower
    courses turn about the toe and the top course is squeezed up, (W_L t/2 + (W_c + N)(t + 2.1
    tan 35)) / (W_L 1.05), below the three-hinge mechanism's 1.3619."""
    from rockyade.limit import limit_analysis

    two = wall_section(courses=2, split=0.5, top="restrained-far", restraint_friction_deg=0.0)
    lam2 = _known(limit_analysis(scene_from_dict(two), direction="+x").load_multiplier, "load multiplier")
    eight = wall_section(
        height_m=2.4,
        thickness_m=0.36,
        courses=8,
        top="restrained-far",
        gap_m=0.0,
        overburden_n_per_m=6000.0,
        overburden_eccentricity_m=0.05,
        density_kg_m3=1600.0,
        contact={"calibration": "paper", "friction_angle_deg": 35.0},
    )
    eight["loads"] = [{**q, "mass_kg": 0.0} for q in eight["loads"]]  # the case's roof: without mass
    lam8 = _known(limit_analysis(scene_from_dict(eight), direction="+x").load_multiplier, "load multiplier")
    wc = 1600.0 * G * 0.36 * 0.3
    expected8 = (7 * wc * 0.18 + (wc + 6000.0) * (0.36 + 2.1 * math.tan(math.radians(35.0)))) / (7 * wc * 1.05)
    return [
        Row(
            "kinematic",
            "limit",
            "wall restrained at its top, 2 blocks: lambda",
            lam2,
            17 / 35,
            "three hinges: 17/35",
            "1e-9",
            _rel(lam2, 17 / 35) <= 1e-9,
        ),
        Row(
            "kinematic",
            "limit",
            "8-course wall restrained on its far face: lambda",
            lam8,
            expected8,
            "top course squeezed up (<= three hinges 1.3619)",
            "1e-9",
            _rel(lam8, expected8) <= 1e-9 and lam8 <= 1.3619,
        ),
    ]


def check_code(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The code's checks of a free-standing wall 0.25 m x 2.5 m against the hand calculation of
    docs/limit.md ("A hand calculation", the wall of the how-to): EC8 Type 1, ground B (S = 1.2,
    TC = 0.5 s), ag = 0.25 g, FC = 1.35, q = 2."""
    from rockyade.assess import Position, Site, code_checks
    from rockyade.limit import limit_analysis

    kin = _kinematic(limit_analysis(_block_scene(0.25, 2.5), fc=1.35))
    ag, S, q = 0.25 * CODE_GRAVITY, 1.2, 2.0  # ag in g and a0* with standard gravity (docs/conventions.md)
    linear, nonlinear = code_checks(kin, Site(1, "B", ag), Position())
    a0 = 0.1 * CODE_GRAVITY / 1.35
    ts = _known(kin.Ts_s, "Ts")
    du = _known(kin.du_star_m, "du*")
    sde = 2.5 * ag * S * 0.5 / ts * (ts / (2 * math.pi)) ** 2  # TC < Ts < TD
    src = "hand calculation (docs/limit.md)"
    rows = [
        Row(
            "code",
            "assess",
            "a0* = alpha0 g / (e* FC) (m/s^2)",
            kin.a0_star_m_s2,
            a0,
            src,
            "1e-12",
            _rel(kin.a0_star_m_s2, a0) <= 1e-12,
        ),
        Row(
            "code",
            "assess",
            "linear demand ag S / q (m/s^2)",
            linear.demand,
            ag * S / q,
            src,
            "1e-12",
            _rel(linear.demand, ag * S / q) <= 1e-12,
        ),
        Row(
            "code",
            "assess",
            "code capacity of the linear check, ag = a0* q / S (m/s^2)",
            linear.ag_capacity_m_s2,
            a0 * q / S,
            src,
            "1e-12",
            _rel(linear.ag_capacity_m_s2, a0 * q / S) <= 1e-12,
        ),
        Row("code", "assess", "du* = 0.4 b (m)", du, 0.05, src, "1e-6", _rel(du, 0.05) <= 1e-6),
        Row(
            "code",
            "assess",
            "nonlinear demand SDe(Ts) = 2.5 ag S TC / Ts (Ts / 2 pi)^2 (m)",
            nonlinear.demand,
            sde,
            src,
            "1e-12",
            _rel(nonlinear.demand, sde) <= 1e-12,
        ),
        Row(
            "code",
            "assess",
            "verdict (1: verified)",
            float(linear.status == "verified"),
            0.0,
            "a0* = 0.727 < 1.472 m/s^2: not verified",
            "exact",
            linear.status == "not verified",
        ),
    ]
    return rows, {}


def check_fragility_fit(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The lognormal fit of the stripes and its bootstrap band recover a known curve: 400 records,
    each collapsing above its own capacity drawn from lognormal(median 2, beta 0.4) (seed 11), at
    9 levels from 0.5 to 8."""
    from scipy import stats

    from rockyade.assess.fit import fit_stripes

    rng = np.random.default_rng(11)
    levels = np.geomspace(0.5, 8.0, 9)
    capacity = 2.0 * np.exp(0.4 * rng.standard_normal(400))
    runs = pd.DataFrame(
        [
            {"record_index": r, "level": float(x), "status": "completed", "collapsed": bool(x >= capacity[r])}
            for x in levels
            for r in range(capacity.size)
        ]
    )
    fit = fit_stripes(runs, "level")
    f = fit.fragility
    truth = stats.norm.cdf(np.log(fit.grid_si / 2.0) / 0.4)
    covered = float(np.mean((fit.band_lo - 0.02 <= truth) & (truth <= fit.band_hi + 0.02)))
    lo, hi = fit.median_interval_si
    src = "the lognormal the outcomes were drawn from"
    rows = [
        Row("fragility_fit", "assess", "median", f.median, 2.0, src, "5 %", _rel(f.median, 2.0) <= 0.05),
        Row("fragility_fit", "assess", "beta", f.beta, 0.4, src, "12 %", _rel(f.beta, 0.4) <= 0.12),
        Row(
            "fragility_fit",
            "assess",
            "90 % band of the median holds the true median (1: yes)",
            float(lo < 2.0 < hi),
            1.0,
            src,
            "exact",
            lo < 2.0 < hi,
        ),
        Row(
            "fragility_fit",
            "assess",
            "fraction of the curve's grid inside the 90 % band (within 0.02)",
            covered,
            1.0,
            src,
            ">= 0.9",
            covered >= 0.9,
        ),
    ]
    return rows, {}


#: The loaded block of ``loaded_block`` and ``loaded_pushover``: mass kg, width m, height m,
#: the top load N and its offset from the axis towards +x, m.
LOADED_MASS_KG, LOADED_WIDTH_M, LOADED_HEIGHT_M, LOADED_N, LOADED_X_M = 1000.0, 0.4, 2.0, 8000.0, 0.05


def loaded_lambda() -> float:
    """lambda = (W b + N d) / (W h_c) of the loaded block pushed towards +x: b = half the width,
    d = b - x the load's lever about the +x pivot, h_c = half the height (moment equilibrium
    about the pivot at uplift)."""
    w = LOADED_MASS_KG * G
    b, h_c = LOADED_WIDTH_M / 2, LOADED_HEIGHT_M / 2
    return (w * b + LOADED_N * (b - LOADED_X_M)) / (w * h_c)


def loaded_block_scene(
    motion: dict[str, Any] | None = None, duration_s: float = 1.0, load_mass_kg: float = 0.0
) -> Scene:
    """The loaded block (:func:`loaded_lambda`) under ``motion`` (default at rest); its load
    without mass unless ``load_mass_kg`` is given."""
    return scene_from_dict(
        {
            "duration_s": duration_s,
            "sample_dt_s": 0.002,
            "blocks": [
                {
                    "name": "pier",
                    "width_m": LOADED_WIDTH_M,
                    "height_m": LOADED_HEIGHT_M,
                    "thickness_m": 1.0,
                    "mass_kg": LOADED_MASS_KG,
                }
            ],
            "motion": motion or rest_motion(),
            "loads": [
                {
                    "block": "pier",
                    "point_m": [LOADED_X_M, LOADED_HEIGHT_M],
                    "force_N": [0.0, -LOADED_N],
                    "mass_kg": load_mass_kg,
                }
            ],
        }
    )


def check_loaded_mass(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The loaded block with the load's mass (its weight / g) shaking with it: the limit
    analysis and Housner's uplift multiplier against (W b + N d) / (W h_c + N h_N), h_N the
    load's height (its horizontal force lambda N at its point), and the code's e* with the
    load as a P_i at h_N: (W h_c + N h_N)^2 / ((W + N) (W h_c^2 + N h_N^2))."""
    from rockyade.limit import limit_analysis
    from rockyade.solvers.housner import housner_model

    scene = loaded_block_scene(load_mass_kg=LOADED_N / G)
    w, n = LOADED_MASS_KG * G, LOADED_N
    b, h_c, h_n = LOADED_WIDTH_M / 2, LOADED_HEIGHT_M / 2, LOADED_HEIGHT_M
    expected = (w * b + n * (b - LOADED_X_M)) / (w * h_c + n * h_n)
    result = limit_analysis(scene, direction="+x")
    lam = _known(result.load_multiplier, "load multiplier")
    housner = housner_model(scene).uplift_multiplier(-1)
    e_star = _kinematic(result).e_star
    e_expected = (w * h_c + n * h_n) ** 2 / ((w + n) * (w * h_c**2 + n * h_n**2))
    src = "(W b + N d) / (W h_c + N h_N)"
    return [
        Row("loaded_mass", "limit", "lambda towards +x", lam, expected, src, "1e-6", _rel(lam, expected) <= 1e-6),
        Row(
            "loaded_mass",
            "housner",
            "uplift multiplier about the +x pivot",
            housner,
            expected,
            src,
            "1e-6",
            _rel(housner, expected) <= 1e-6,
        ),
        Row(
            "loaded_mass",
            "limit",
            "e* with the load a P_i",
            e_star,
            e_expected,
            "(W h_c + N h_N)^2 / ((W + N)(W h_c^2 + N h_N^2))",
            "1e-6",
            _rel(e_star, e_expected) <= 1e-6,
        ),
    ], {}


def check_loaded_block(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The loaded block's multiplier (module docstring) from the limit analysis and from
    Housner's uplift multiplier about the +x (right) pivot, against the closed form."""
    from rockyade.housner import housner_model
    from rockyade.limit import limit_analysis

    scene = loaded_block_scene()
    expected = loaded_lambda()
    lam = _known(limit_analysis(scene, direction="+x").load_multiplier, "load multiplier")
    housner = housner_model(scene).uplift_multiplier(-1)
    src = "(W b + N d) / (W h_c)"
    return [
        Row("loaded_block", "limit", "lambda towards +x", lam, expected, src, "1e-6", _rel(lam, expected) <= 1e-6),
        Row(
            "loaded_block",
            "housner",
            "uplift multiplier about the +x pivot",
            housner,
            expected,
            src,
            "1e-6",
            _rel(housner, expected) <= 1e-6,
        ),
    ], {}


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
            "2 %",
            _rel(onset.multiplier, expected) <= 0.02,
        ),
        Row(
            "loaded_pushover",
            "reference",
            "last held level it stood (at most the closed form, levels rounded to 1e-6)",
            onset.below,
            expected,
            src,
            "<= expected + 1e-6",
            onset.below <= expected + 1e-6,
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


def check_limit_pushover(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """The limit analysis's multiplier against the reference DEM's pushover onset (the first held
    level at which the control point moved more than 1 mm) for a block, an arch, a restrained
    wall and a running-bond panel: within 2 % (:func:`limit_pushover_scenes`). The reference DEM
    only (YADE's onsets are in tests/test_pushover.py: minutes of CPU)."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.limit import limit_analysis
    from rockyade.motion.quasistatic import Pushover
    from rockyade.motion.spec import parse_motion

    rows = []
    for name, (data, control) in limit_pushover_scenes().items():
        expected = _known(limit_analysis(scene_from_dict(data), direction="+x").load_multiplier, "load multiplier")
        motion = parse_motion(_short_pushover(expected))
        assert isinstance(motion, Pushover)
        t_path, _ = motion.lambda_path(0.0)
        scene = scene_from_dict(data).with_changes(motion=motion, duration_s=float(t_path[-1]) + 0.5)
        block, point = control if control is not None else (None, None)
        onset = pushover_onset(capacity_curve(run(scene, "reference"), scene, block=block, point_m=point), scene)
        rows.append(
            Row(
                "limit_pushover",
                "reference",
                f"{name}: pushover onset (first held level it did not stand)",
                onset.multiplier,
                expected,
                "limit analysis",
                "2 %",
                _rel(onset.multiplier, expected) <= 0.02,
            )
        )
    return rows, {}


def check_siconos(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """Siconos (nonsmooth contact dynamics) against closed forms, whatever ``solvers`` says:

    * free rocking of specimen 1's geometry (0.25 x 1.0 m, released at alpha / 2, e = 0): the
      mean restitution of the first four impacts within 0.5 % of Housner's Eq 4,
      1 - 1.5 sin^2 alpha (nothing tuned: the model's own);
    * the pushover onset of the 0.4 x 2 m block of ``limit_pushover`` within 2 % of the limit
      analysis (b / h = 0.2).

    The frame, the drums, the arch, the restrained wall and the panel are not here: Siconos's
    friction solver (NSGS) does not converge on stacks of more than two blocks within its
    iterations (measured, docs/siconos.md)."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.blocks.restitution import restitution_per_impact
    from rockyade.limit import limit_analysis
    from rockyade.motion.quasistatic import Pushover
    from rockyade.motion.spec import parse_motion

    rows = []
    alpha = math.atan(0.25)
    free = scene_from_dict(
        {
            "duration_s": 3.0,
            "sample_dt_s": 0.002,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503.0}],
            "motion": {"type": "free", "theta0_rad": alpha / 2.0},
        }
    )
    result = run(free, "siconos")
    eq4 = 1.0 - 1.5 * math.sin(alpha) ** 2
    per_impact = restitution_per_impact(
        find_peaks(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy()), alpha
    )[:4]
    mu = float(np.mean(per_impact)) if result.ok and len(per_impact) else math.nan
    rows.append(
        Row(
            "siconos",
            "siconos",
            "specimen 1 free rocking: mean restitution of 4 impacts (e = 0)",
            mu,
            eq4,
            "Housner Eq 4, 1 - 1.5 sin^2 alpha",
            "0.5 %",
            _rel(mu, eq4) <= 0.005,
        )
    )
    data, _ = limit_pushover_scenes()["block"]
    expected = _known(limit_analysis(scene_from_dict(data), direction="+x").load_multiplier, "load multiplier")
    motion = parse_motion(_short_pushover(expected))
    assert isinstance(motion, Pushover)
    t_path, _ = motion.lambda_path(0.0)
    scene = scene_from_dict(data).with_changes(motion=motion, duration_s=float(t_path[-1]) + 0.5)
    pushed = run(scene, "siconos")
    onset = pushover_onset(capacity_curve(pushed, scene), scene).multiplier if pushed.ok else math.nan
    rows.append(
        Row(
            "siconos",
            "siconos",
            "block 0.4 x 2 m: pushover onset (first held level it did not stand)",
            onset,
            expected,
            "limit analysis",
            "2 %",
            _rel(onset, expected) <= 0.02,
        )
    )
    return rows, {}


CHECK_FUNCTIONS: dict[str, Callable[[list[str]], tuple[list[Row], dict[str, Result]]]] = {
    "frame": check_frame,
    "drums": check_drums,
    "pad": check_pad,
    "wall": check_wall,
    "agreement": check_agreement,
    "baseline": check_baseline,
    "kinematic": check_kinematic,
    "code": check_code,
    "fragility_fit": check_fragility_fit,
    "loaded_block": check_loaded_block,
    "loaded_mass": check_loaded_mass,
    "loaded_pushover": check_loaded_pushover,
    "limit_pushover": check_limit_pushover,
    "siconos": check_siconos,
}


# ---------------------------------------------------------------------- report


def _figure(check: str, results: dict[str, Result], path: Path) -> None:
    from rockyade.figures.verify import plot_check

    plot_check(check, results, path)


def verify(
    out: str | Path,
    checks: list[str] | None = None,
    solvers: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Run the checks, write ``verify.csv``, a figure per check and ``index.md``; return the rows."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    solvers = solvers or ["reference", "yade"]
    rows: list[Row] = []
    figures: dict[str, str] = {}
    for check in checks or list(CHECKS):
        if progress:
            progress(check)
        found, results = CHECK_FUNCTIONS[check](solvers)
        rows += found
        if results:
            name = f"verify_{check}.png"
            _figure(check, results, out / name)
            figures[check] = name
    table = pd.DataFrame(
        [
            {
                "check": r.check,
                "solver": r.solver,
                "quantity": r.quantity,
                "value": r.value,
                "expected": r.expected,
                "difference": r.difference,
                "expected_from": r.expected_from,
                "tolerance": r.tolerance,
                "passed": r.passed,
            }
            for r in rows
        ]
    )
    with atomic_open(out / "verify.csv") as fh:
        table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
    write_text(out / "index.md", _index(table, figures))
    return table


def _index(table: pd.DataFrame, figures: dict[str, str]) -> str:
    failed = table[~table["passed"]] if len(table) else table
    lines = [
        "# rockyade verification report",
        "",
        f"{len(table)} quantities checked, {len(failed)} failed. Each check is described in "
        "`rockyade.studies.verify` and docs/assemblies.md; `verify.csv` has every row.",
        "",
    ]
    if len(failed):
        lines += [
            "## Failed",
            "",
            "| check | solver | quantity | value | expected | tolerance |",
            "|---|---|---|---|---|---|",
        ]
        for _, r in failed.iterrows():
            lines.append(
                f"| {r.check} | {r.solver} | {r.quantity} | {r.value:.6g} | {r.expected:.6g} | {r.tolerance} |"
            )
        lines.append("")
    for check in dict.fromkeys(table["check"]) if len(table) else []:
        part = table[table["check"] == check]
        lines += [
            f"## {check}",
            "",
            "| solver | quantity | value | expected | from | tolerance | pass |",
            "|---|---|---|---|---|---|---|",
        ]
        for _, r in part.iterrows():
            mark = "yes" if r.passed else "**NO**"
            cells = [r.solver, r.quantity, f"{r.value:.6g}", f"{r.expected:.6g}", r.expected_from, r.tolerance, mark]
            lines.append("| " + " | ".join(cells) + " |")
        if check in figures:
            lines += ["", f"![{check}]({figures[check]})"]
        lines.append("")
    return "\n".join(lines)
