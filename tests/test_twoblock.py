"""The exact two-block solver (rockyade.twoblock, ``--solver twoblock``): on a rigid seat it is
Housner's solution, its energy is constant between impacts, its onset is the limit analysis's
multiplier, its contact forces agree with its equations of motion, its events do not move with
the output sampling, and the scenes it cannot treat are refused with the reason."""

from __future__ import annotations

import itertools
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit import limit_analysis
from rockyade.result import PER_BLOCK_QUANTITIES
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers import make_solver, run, solver_names
from rockyade.twoblock import dynamics as dyn
from rockyade.twoblock import solve, two_block_model

from .benchrun import run_quick
from .conftest import EXAMPLES

ROCKYADE = Path(sys.executable).parent / "rockyade"

#: The paper's bi-block (Table 2) with the geometry's own parameters.
LOWER = {"name": "lower", "width_m": 0.20, "height_m": 0.60, "thickness_m": 0.55, "mass_kg": 204}
UPPER = {"name": "upper", "width_m": 0.15, "height_m": 0.60, "thickness_m": 0.40, "mass_kg": 91}
#: A lower block 100 times heavier and 10 times wider than the upper one: a rigid seat.
SEAT = {"name": "seat", "width_m": 1.5, "height_m": 0.60, "thickness_m": 0.55, "mass_kg": 9100}


def _scene(blocks, motion, duration=3.0, sample_dt=0.001, **extra):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": sample_dt,
            "blocks": blocks,
            "contact": {"calibration": "paper"},
            "motion": motion,
            **extra,
        }
    )


def _peaks(result, block_index=None):
    """(time, theta) of the recorded peaks (of one block of a two-block run)."""
    peaks = np.array(result.meta.extra["peaks"])
    if block_index is None:
        return peaks
    return peaks[peaks[:, 1] == block_index][:, [0, 2]]


# ---------------------------------------------------------------------- check 1


@pytest.mark.parametrize(
    "motion",
    [
        {"type": "free", "theta0_rad": 0.15},
        {"type": "harmonic", "amplitude_mm": 10.0, "frequency_hz": 3.0, "cycles": 4},
        {"type": "pulse", "shape": "sine", "amplitude_g": 0.4, "period_s": 0.6},
    ],
    ids=["free", "harmonic", "pulse-overturn"],
)
def test_upper_block_on_a_rigid_seat_is_housners_block(motion):
    """Check 1: a seat 100x heavier and 10x wider never lifts, and the upper block's peaks and
    impacts are Housner's for the upper block alone: within 0.5 % (here to 1e-9), the same
    count, the same outcome (an overturn at the same time)."""
    two = _scene([SEAT, UPPER], {**motion, **({"block": "upper"} if motion["type"] == "free" else {})}, 4.0)
    one = _scene([UPPER], motion, 4.0)
    exact, housner = run(two, "twoblock"), run(one, "housner")
    assert exact.status == housner.status
    assert np.all(exact.series("theta_rad", "seat") == 0.0)  # the seat never uplifts
    assert all(row[1] == 1 for row in exact.meta.extra["impacts"])  # every impact is the upper block's
    t_exact = np.array(exact.meta.extra["impacts"])[:, 0]
    t_housner = np.array(housner.meta.extra["impacts"])[:, 0]
    assert t_exact.size == t_housner.size >= 1
    np.testing.assert_allclose(t_exact, t_housner, rtol=1e-9)
    p_exact, p_housner = _peaks(exact, 1), _peaks(housner)[:, :2]
    assert len(p_exact) == len(p_housner) >= 1
    np.testing.assert_allclose(p_exact, p_housner, rtol=1e-9)
    if housner.status == "overturned":
        assert exact.meta.overturned_block == "upper"
        assert exact.meta.overturn_time_s == pytest.approx(housner.meta.overturn_time_s, rel=1e-9)
    n = min(len(exact.t), len(housner.t))
    np.testing.assert_allclose(exact.series("theta_rad", "upper")[:n], housner.series("theta_rad")[:n], atol=1e-9)


# ---------------------------------------------------------------------- check 2


@pytest.mark.parametrize(
    ("released", "theta0"),
    [("upper", 0.1225), ("lower", 0.1), ("lower", 0.18)],
    ids=["upper-at-half-alpha", "stack-0.1", "stack-0.18"],
)
def test_energy_is_constant_between_impacts(released, theta0):
    """Check 2: free rocking of the paper's bi-block; between consecutive impacts (and mode
    changes) the energy's relative drift stays below 1e-6, in every mode the run goes through
    (the stack released at 0.1 rad throws the upper block into rocking: both blocks rock)."""
    scene = _scene([LOWER, UPPER], {"type": "free", "theta0_rad": theta0, "block": released})
    model = two_block_model(scene)
    traj = solve(model, None, scene.duration_s, scene.released_index, theta0, 0.0, scene.sample_dt_s)
    energy = np.array(
        [
            model.energy(th[0], th[1] - th[0], w[0], w[1] - w[0])
            for th, w in zip(traj.theta_rad, traj.omega_rad_s, strict=False)
        ]
    )
    events = np.concatenate([[0.0], traj.mode_changes[:, 0], [traj.t_s[-1] + 1.0]])
    modes_seen = {tuple(m) for m in traj.modes.tolist()}
    checked = 0
    for a, b in itertools.pairwise(events):
        inside = (traj.t_s > a) & (traj.t_s < b)
        if inside.sum() < 3:
            continue
        seg = energy[inside]
        assert (seg.max() - seg.min()) / abs(seg).max() < 1e-6, (a, b)
        checked += 1
    assert checked >= 3
    assert any(m[0] != 0 and m[1] != 0 for m in modes_seen) or released == "upper"
    # the energy only falls at impacts
    before = [energy[traj.t_s < t][-1] for t in traj.impacts[:, 0] if np.any(traj.t_s < t)]
    assert all(np.diff(before) <= 1e-9 * energy[0])


# ---------------------------------------------------------------------- check 3


def test_onset_under_a_slow_pulse_is_the_limit_analysis_multiplier():
    """Check 3: the paper's bi-block (geometric parameters) under a one-sine pulse of 2 s: at
    0.95 of the limit analysis's multiplier (0.20615 either way) it stays at rest, at 1.05 it
    rocks, lifting when the base acceleration first reaches lambda g (the quasi-static onset)."""
    base = _scene([LOWER, UPPER], {"type": "pulse", "shape": "sine", "amplitude_g": 0.1, "period_s": 2.0}, 3.0)
    lams = [limit_analysis(base, d, sliding=False, nonlinear=False).load_multiplier for d in ("+x", "-x")]
    assert lams[0] == pytest.approx(0.20615, abs=5e-6) and lams[1] == pytest.approx(lams[0], rel=1e-9)
    lam = lams[0]
    model = two_block_model(base)
    assert model.onset_multiplier == pytest.approx(lam, rel=1e-9)
    for factor in (0.95, 1.05):
        motion = {"type": "pulse", "shape": "sine", "amplitude_g": factor * lam, "period_s": 2.0}
        result_scene = _scene([LOWER, UPPER], motion, 3.0)
        result = run(result_scene, "twoblock")
        theta = np.abs(np.column_stack([result.series("theta_rad", "lower"), result.series("theta_rad", "upper")]))
        uplifts = result.meta.extra["uplift_times_s"]
        if factor < 1:
            assert theta.max() == 0.0 and uplifts == []
        else:
            assert theta.max() > 1e-3 and len(uplifts) >= 1
            assert uplifts[0] == pytest.approx(math.asin(1.0 / factor) / math.pi, abs=1e-5)  # T / (2 pi) asin
            gm = result_scene.motion.ground_motion(3.0)  # the crossing of lambda g on the motion's samples
            k = int(np.flatnonzero(gm.ah_m_s2 >= lam * G)[0])
            a0, a1 = gm.ah_m_s2[k - 1], gm.ah_m_s2[k]
            crossing = gm.t_s[k - 1] + (gm.t_s[k] - gm.t_s[k - 1]) * (lam * G - a0) / (a1 - a0)
            assert uplifts[0] == pytest.approx(crossing, abs=1e-7)  # the margin 1e-9 below zero: 1e-8 s later
            assert result.meta.extra["mode_changes"][0][1:] == [1.0, 0.0]  # the stack, as one body


# ---------------------------------------------------------------------- the mechanics


def test_contact_forces_agree_with_the_equations_of_motion():
    """In every rocking mode, the contact moment about each open pivot is zero (Newton-Euler
    on the parts above each joint against Lagrange's equations), and at rest the joints carry
    the weights above them."""
    model = two_block_model(_scene([LOWER, UPPER], {"type": "free", "theta0_rad": 0.05}))
    prm = model.params()
    m1, m2 = model.mass_kg
    state = (0.07, -0.11, 0.4, -1.3)
    for sb, ss in ((1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (0, 1)):
        th1 = state[0] if sb else 0.0
        phi = state[1] if ss else 0.0
        th1 = abs(th1) * sb if sb else 0.0
        phi = abs(phi) * ss if ss else 0.0
        w1, wp = (state[2] if sb else 0.0), (state[3] if ss else 0.0)
        nb, tb, mbl, mbr, ns, ts, msl, msr = dyn.contact_state(th1, phi, w1, wp, sb, ss, 1.3, -0.4, prm)
        scale = model.weight_N * model.height_m
        if sb:
            assert abs(mbl if sb > 0 else mbr) < 1e-12 * scale
        if ss:
            assert abs(msl if ss > 0 else msr) < 1e-12 * scale
    nb, tb, *_, ns, ts, _msl, _msr = dyn.contact_state(0.0, 0.0, 0.0, 0.0, 0, 0, 0.0, 0.0, prm)
    assert nb == pytest.approx((m1 + m2) * model.g) and ns == pytest.approx(m2 * model.g)
    assert tb == 0.0 and ts == 0.0


def test_the_stack_released_throws_the_upper_block_over_as_the_reference_dem_does():
    """The paper's bi-block released as one body at 0.1 rad (below the stack's alpha): as the
    stack swings back the upper block starts rocking on its seat, and it overturns, as in the
    reference DEM (within 5 % in time)."""
    scene = _scene([LOWER, UPPER], {"type": "free", "theta0_rad": 0.1, "block": "lower"}, 2.0, 0.002)
    exact, dem = run(scene, "twoblock"), run(scene, "reference")
    assert exact.status == dem.status == "overturned"
    assert exact.meta.overturned_block == dem.meta.overturned_block == "upper"
    assert exact.meta.overturn_time_s == pytest.approx(dem.meta.overturn_time_s, rel=0.05)
    first_b = next(row for row in exact.meta.extra["mode_changes"] if row[1] != 0 and row[2] != 0)
    assert first_b[0] < 0.1  # both rock within 0.1 s of the release


def test_a_seat_off_centre_mirrors_exactly():
    """Any seat on the lower block's top: an upper block 0.07 m right of centre released one way
    is the mirror image of one 0.07 m left of centre released the other way (both blocks, every
    sample)."""
    lower = dict(LOWER, width_m=0.30, mass_kg=300)
    runs = []
    for side in (1, -1):
        upper = dict(UPPER, width_m=0.12, height_m=0.5, mass_kg=60, x_offset_m=0.07 * side)
        scene = _scene([lower, upper], {"type": "free", "theta0_rad": 0.12 * side, "block": "upper"}, 2.0)
        runs.append(run(scene, "twoblock"))
    a, b = runs
    assert len(a.meta.extra["impacts"]) >= 5
    for name in ("lower", "upper"):
        np.testing.assert_allclose(a.series("theta_rad", name), -b.series("theta_rad", name), atol=1e-12)
    assert np.abs(a.series("theta_rad", "lower")).max() > 0  # the upper block's landings throw the lower one


def test_sampling_interval_does_not_move_events_and_halving_the_step_changes_little():
    """Event-driven: the output sampling leaves impact times and peaks bit for bit; halving the
    Runge-Kutta step moves them by less than 1e-6 (relative)."""
    motion = {"type": "harmonic", "amplitude_mm": 6.0, "frequency_hz": 5.0, "cycles": 4}
    runs = {dt: run(_scene([LOWER, UPPER], motion, 2.5, dt), "twoblock") for dt in (0.001, 0.0025)}
    a, b = (np.array(runs[dt].meta.extra["impacts"]) for dt in (0.001, 0.0025))
    assert len(a) >= 10
    np.testing.assert_array_equal(a, b)
    assert runs[0.001].meta.extra["peaks"] == runs[0.0025].meta.extra["peaks"]
    half = make_solver("twoblock", dt_factor=0.5).run(_scene([LOWER, UPPER], motion, 2.5, 0.001))
    c = np.array(half.meta.extra["impacts"])
    assert c.shape == a.shape
    np.testing.assert_allclose(c[:, 0], a[:, 0], rtol=1e-6)
    assert half.meta.dt_s == pytest.approx(0.5 * runs[0.001].meta.dt_s)


# ---------------------------------------------------------------------- the solver


def test_result_has_the_dems_columns_and_metadata():
    """The bi-block example: the same per-block columns as the reference DEM's, the classical
    parameters per block, the friction record, the scene's mu beside the model's."""
    scene = load_scene(EXAMPLES / "biblock_free.toml")
    result = run(scene, "twoblock")
    dem = run(scene.with_changes(duration_s=0.05), "reference")
    assert "twoblock" in solver_names()
    columns = ["t_s", "ag_m_s2"] + [f"{b}_{q}" for b in ("lower", "upper") for q in PER_BLOCK_QUANTITIES]
    assert list(result.frame.columns) == columns and set(columns) <= set(dem.frame.columns)
    assert result.status == "completed" and result.meta.blocks == ("lower", "upper")
    assert set(result.meta.classical) == {"lower", "upper"}
    extra = result.meta.extra
    assert extra["mu_scene"] == {"lower": 0.948, "upper": 0.955} and "mu_note" in extra
    assert extra["friction"]["max_ratio"]["base"] < extra["friction"]["coefficient"]["base"]
    assert result.meta.motion_coverage is not None
    assert result.frame["upper_theta_rad"].iloc[0] == pytest.approx(0.1145)


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        ({"blocks": [LOWER, UPPER, dict(UPPER, name="top")]}, "blocks", "two stacked blocks"),
        ({"blocks": [UPPER]}, "blocks", "the housner solver"),
        (
            {
                "blocks": [
                    LOWER,
                    {**UPPER, "width_m": None, "height_m": None, "vertices_m": [[0, 0], [0.15, 0], [0.1, 0.6]]},
                ]
            },
            "blocks[1].vertices_m",
            "not a rectangle",
        ),
        ({"blocks": [LOWER, dict(UPPER, width_m=0.3)]}, "blocks[1].width_m", "beyond the lower block's top"),
        ({"blocks": [LOWER, dict(UPPER, x_offset_m=0.05)]}, "blocks[1].x_offset_m", "beyond the lower block's top"),
        ({"contact": {"calibration": "paper", "friction_angle_deg": 10.0}}, "contact.friction_angle_deg", "slide"),
        (
            {"joints": [{"blocks": ["upper", "lower"], "friction_angle_deg": 11.0}]},
            "joints[0].friction_angle_deg",
            "lambda_0 = 0.2061",
        ),
        ({"blocks": [dict(LOWER, alpha_rad=0.5, p_rad_s=5.45), UPPER]}, "blocks[0].p_rad_s", "cannot be reached"),
        (
            {"blocks": [LOWER, dict(UPPER, mu=0.99)], "contact": {"calibration": "matched"}},
            "contact.calibration",
            "cannot reach",
        ),
        (
            {"loads": [{"block": "upper", "point_m": [0.0, 1.2], "force_N": [0.0, -100.0]}]},
            "loads",
            "no point loads",
        ),
    ],
    ids=["three", "one", "polygon", "wide", "overhang", "friction", "joint-friction", "p", "matched-mu", "loads"],
)
def test_scenes_it_cannot_treat_are_refused_with_the_reason(change, field, words):
    d = {
        "duration_s": 1.0,
        "sample_dt_s": 0.01,
        "blocks": [LOWER, UPPER],
        "contact": {"calibration": "paper"},
        "motion": {"type": "free", "theta0_rad": 0.05},
    }
    for key, value in change.items():
        d[key] = [{k: v for k, v in b.items() if v is not None} for b in value] if key == "blocks" else value
    scene = scene_from_dict(d)
    solver = make_solver("twoblock")
    with pytest.raises(InputError) as err:
        solver.check_scene(scene)
    assert err.value.field == field and words in err.value.message
    with pytest.raises(InputError):
        solver.run(scene)


@pytest.mark.slow
def test_cli_runs_the_bi_block_and_refuses_a_single_block_with_exit_2(tmp_path, monkeypatch, capsys):
    """``rockyade run SCENE --solver twoblock`` as a user types it (the console script); a single
    block: exit 2, one line (the command's ``main`` in this process: a traceback would be an
    exception raised here)."""
    ok = subprocess.run(
        [str(ROCKYADE), "run", str(EXAMPLES / "biblock_free.toml"), "--solver", "twoblock", "--out", "out/bi.csv"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert ok.returncode == 0, ok.stderr
    assert (tmp_path / "out" / "bi.csv").is_file() and (tmp_path / "out" / "bi.json").is_file()
    from rockyade.cli import main

    monkeypatch.chdir(tmp_path)
    capsys.readouterr()
    code = main(["run", str(EXAMPLES / "specimen1_free.toml"), "--solver", "twoblock", "--out", "x.csv"])
    err = capsys.readouterr().err
    assert code == 2
    assert "two stacked blocks" in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "x.csv").exists()


# ---------------------------------------------------------------------- check 5


@pytest.mark.parametrize(("freq", "amp", "pattern"), [(2.0, 2.0, "rest"), (4.0, 4.0, "4"), (5.0, 5.0, "2")])
def test_pattern_map_cells_by_the_exact_solver_beside_the_dem(freq, amp, pattern):
    """Check 5, cell by cell: three cells of the paper's pattern map (experimental parameters, the
    study's scene) give the exact solver the DEM's dominant pattern: rest below the uplift, the
    upper block alone (4), both blocks in opposite ways (2, the paper's pattern at 5 Hz, 5 mm)."""
    from rockyade.analysis.patterns import classify_result
    from rockyade.motion.analytic import Harmonic
    from rockyade.studies.pattern_map import CYCLES
    from rockyade.studies.specimen_scenes import biblock_blocks, scene_dict

    end = Harmonic(1.0, freq, CYCLES, 2).phases_s["end_s"]
    motion = {"type": "harmonic", "amplitude_mm": amp, "frequency_hz": freq, "cycles": CYCLES}
    scene = scene_from_dict(scene_dict(biblock_blocks(), motion, end + 1.0, 0.002, "paper"))
    patterns = {name: classify_result(scene, run(scene, name)).dominant for name in ("twoblock", "reference")}
    assert patterns == {"twoblock": pattern, "reference": pattern}


def test_pattern_map_figure_has_a_panel_per_solver(tmp_path):
    """The study's figure: the DEM's panel and the exact solver's, each with the paper's regions."""
    import pandas as pd

    from rockyade.studies import pattern_map
    from rockyade.studies.report import Report

    cells = pd.DataFrame(
        {
            "frequency_hz": [4.0, 5.0, 7.0],
            "amplitude_mm": [4.0, 5.0, 8.0],
            "pattern_dem": ["4", "2", "1"],
            "pattern_exact": ["4", "2", "2"],
        }
    )
    cells["pattern_paper"] = [
        pattern_map.paper_pattern(f, a) for f, a in zip(cells.frequency_hz, cells.amplitude_mm, strict=False)
    ]
    for key in ("dem", "exact"):
        cells[f"agree_{key}"] = [
            None if p is None else p == d for p, d in zip(cells.pattern_paper, cells[f"pattern_{key}"], strict=False)
        ]
    report = Report(tmp_path)
    report.section("Patterns")
    fig = pattern_map.draw_figure(report, cells, pattern_map.agreement(cells, "dem")).figure_
    titles = [ax.get_title() for ax in fig.axes]
    assert any("reference DEM" in t for t in titles) and any("exact two-block solver" in t for t in titles)
    assert (tmp_path / "pattern_map.png").stat().st_size > 0
    assert "exact two-block solver: pattern 2 2 of 2 cells" in report.sections[-1][1][-1]


@pytest.mark.slow
def test_benchmark_quick_mode_runs_and_finds_the_events_independent_of_sampling(monkeypatch, capsys):
    """``benchmarks/bench_twoblock.py --quick`` runs both solvers on the record and prints the
    sampling check: the same impact times at 0.01 s and 0.001 s (no speed is asserted). In this
    process (tests/benchrun.py)."""
    out = run_quick(Path(__file__).resolve().parents[1] / "benchmarks" / "bench_twoblock.py", monkeypatch, capsys)
    assert "runs/s" in out and "largest difference 0 s" in out
