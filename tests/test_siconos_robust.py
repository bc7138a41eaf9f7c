"""Siconos on scenes whose contacts are redundant or whose motion is violent, with Debian's
Siconos really running: a 33-block running-bond wall stands (its coinciding corners and
two contacts per joint made the nonsmooth Newton's LU factorisation singular), an arch
below its minimum thickness collapses and is reported ``overturned`` (the worker used to
abort), a run no solver can step ends ``failed`` with its reason and its samples, and the
numpy contact geometry equals the pair-by-pair one. Skipped only where python3-siconos is
absent; ``ROCKYADE_REQUIRE_SICONOS=1`` (``make test``) turns that into a failure."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, wall
from rockyade.scene.generators.arches import arch
from rockyade.siconos import backend as siconos_backend
from rockyade.siconos.payload import scene_payload
from rockyade.solvers.siconos import SiconosSolver

pytestmark = pytest.mark.usefixtures("siconos_present")  # the real Siconos: marked siconos (conftest)


def _wall(duration_s: float) -> dict:
    """A dry running-bond wall of 6 courses of 5 units: 33 blocks (half units at the ends of
    every other course)."""
    return wall(courses=6, units_per_course=5, motion=rest_motion(), duration_s=duration_s, sample_dt_s=0.005)


def _arch(t_over_r: float, voussoirs: int, duration_s: float) -> dict:
    """A semicircular arch of mean radius 1 m on fixed piers 0.5 m high, at rest."""
    return arch(
        span_m=2.0 * (1.0 - t_over_r / 2.0),
        ring_depth_m=t_over_r,
        voussoirs=voussoirs,
        pier_width_m=2.0 * t_over_r,
        pier_height_m=0.5,
        piers="fixed",
        motion=rest_motion(),
        duration_s=duration_s,
        sample_dt_s=0.01,
    )


@pytest.mark.parametrize("integrator", ["numerics", "kernel"])
def test_a_33_block_wall_stands_at_rest(integrator):
    """The running-bond wall at rest for 0.03 s at dt 1e-3 s: every block stays within 1 um
    and 1e-6 rad, no step left unconverged. On the kernel path the nonsmooth Newton fails on
    the redundant contacts and the fallback solver takes those steps (counted); on the
    numerics path Gauss-Seidel, warm-started, takes every step."""
    scene = scene_from_dict(_wall(0.03))
    assert len(scene.blocks) == 33
    result = SiconosSolver(dt_s=1e-3, integrator=integrator).run(scene)
    assert result.ok, result.meta.failure_reason
    frame = result.frame
    for block in scene.blocks:
        name = block.name
        assert np.max(np.abs(frame[f"{name}_x_m"] - frame[f"{name}_x_m"].iloc[0])) < 1e-6
        assert np.max(np.abs(frame[f"{name}_y_m"] - frame[f"{name}_y_m"].iloc[0])) < 1e-6
        assert np.max(np.abs(frame[f"{name}_theta_rad"] - frame[f"{name}_theta_rad"].iloc[0])) < 1e-6
    meta = result.meta
    assert meta.unconverged_steps == 0 and meta.extra["integrator"] == integrator
    assert meta.extra["retried_steps_converged"] == meta.extra["retried_steps"]
    if integrator == "kernel":
        assert meta.extra["retried_steps"] >= 1 and meta.extra["fallback_steps"] >= 1
        assert list(meta.extra["friction_solvers"]) == ["nsn", "nsgs", "admm"]
    else:
        assert meta.extra["solver_calls"] == 30 and meta.extra["max_solver_residual"] <= meta.extra["solver_tol"]
        assert list(meta.extra["friction_solvers"]) == ["fc2d_lemke", "fc3d_nsgs", "fc3d_prox"]


def test_an_arch_below_its_minimum_thickness_collapses_and_is_reported_overturned():
    """A 6-voussoir arch at t/R = 0.05 (far below Milankovitch's 0.1075) cannot stand: the
    run goes through its collapse (the worker aborted on such arches, exit -6) and ends
    ``overturned``, a voussoir named, as the other solvers report a collapse."""
    scene = scene_from_dict(_arch(0.05, 6, 1.5))
    result = SiconosSolver(dt_s=1e-3).run(scene)
    assert result.status == "overturned", result.meta.failure_reason
    assert result.meta.overturned_block in result.meta.blocks
    assert 0.0 < (result.meta.overturn_time_s or 0.0) < 1.5


@pytest.mark.parametrize(
    ("integrator", "said"),
    [("numerics", "left body 0 with a non-finite state or a runaway speed"), ("kernel", "no friction-contact solver")],
)
def test_a_run_no_solver_can_step_fails_with_its_reason_and_keeps_its_samples(integrator, said):
    """A block under a 1,000 m/s^2 step of ground acceleration (the largest a motion may have)
    passes 100 m/s (MAX_SPEED_M_S) within about 0.1 s: the step runs away (on the kernel path
    every solver's), and the run ends ``failed``, saying why, with the samples before it
    (``partial``), never looking complete."""
    scene = scene_from_dict(
        {
            "duration_s": 0.5,
            "sample_dt_s": 0.01,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.5, "mass_kg": 250.0}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "sampled", "t_s": [0.0, 0.001, 1.0], "accel_m_s2": [0.0, 1000.0, 1000.0]},
        }
    )
    result = SiconosSolver(dt_s=1e-3, integrator=integrator).run(scene)
    assert result.status == "failed" and not result.ok
    reason = result.meta.failure_reason or ""
    assert said in reason and "runaway" in reason
    assert result.meta.partial is True and 0 < len(result.frame) == result.meta.partial_samples < scene.n_samples


def test_the_numpy_contact_geometry_equals_the_pair_by_pair_one(tmp_path):
    """Run in Debian's Python on the wall and an arch, their blocks moved at random by 1 mm and
    1 mrad: the numpy update (all pairs at once) and the plain-float one (which writes each
    pair's C and e directly) give the same C, e and gaps, and the twins found are the
    coinciding corners (one per head joint end)."""
    solver = SiconosSolver(dt_s=1e-3)
    script = """
import json, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import driver
scene = json.load(open(sys.argv[2]))
contacts = driver.build(scene, driver._siconos())["contacts"]
rng = np.random.default_rng(7)
for i in contacts.moving_ids:
    ds = contacts.ds_of[i]
    ds.setQ(np.array(ds.q()) + rng.normal(0.0, 1e-3, 3))
contacts.read_state()
contacts.geometry()
jac = np.concatenate([contacts.jac[k][:, c].ravel() for k, c in enumerate(contacts.cols)])
a = (jac, contacts.off.copy(), contacts.gaps.copy())
contacts.geometry_scalar()  # writes each pair's C and e directly
b = (np.concatenate([np.ravel(C) for C, _ in contacts.views]), np.array([e for _, e in contacts.views]),
     contacts.gaps)
same_open = bool(np.array_equal(np.isinf(a[2]), np.isinf(b[2])))
gaps = np.where(np.isinf(a[2]), 0.0, a[2] - np.where(np.isinf(b[2]), 0.0, b[2]))
print(json.dumps({"jac": float(np.abs(a[0] - b[0]).max()), "off": float(np.abs(a[1] - b[1]).max()),
                  "gap": float(np.abs(gaps).max()), "same_open": same_open, "pairs": len(contacts.pairs),
                  "twins": int((contacts.twin >= 0).sum()), "closed": int(np.isfinite(a[2]).sum())}))
"""
    for name, data in (("wall", _wall(0.01)), ("arch", _arch(0.08, 20, 0.01))):
        scene = scene_from_dict(data)
        model = solver.model(scene)
        numerics, _ = solver.numerics(model)
        path = tmp_path / f"{name}.json"
        path.write_text(json.dumps(scene_payload(model, numerics)))
        out = subprocess.run(
            [siconos_backend.SICONOS_PYTHON, "-c", script, str(siconos_backend.DRIVER.parent), str(path)],
            capture_output=True,
            text=True,
            check=True,
            timeout=120,
        )
        got = json.loads(out.stdout.strip().splitlines()[-1])
        assert got["jac"] < 1e-12 and got["off"] < 1e-12 and got["gap"] < 1e-12 and got["same_open"], got
        assert got["twins"] > 0 and 0 < got["closed"] < got["pairs"], got
