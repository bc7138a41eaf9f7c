"""Siconos's numerics path (rockyade.siconos.moreau_jean: Moreau-Jean's one-step problem
assembled with numpy, solved by Siconos's numerics), with Debian's Siconos really running:
a block that starts above the ground lands on it (issue 34: it fell through), a run whose
block goes through the ground fails, a free-rocking upper block lands on its seat, the path
agrees with Siconos's kernel (TimeStepping) on a free-rocking block and is closer to
Housner's restitution, its pair-by-pair and all-pairs-at-once steps agree, and its
FrictionContact(3) with a decoupled out-of-plane row has FrictionContact(2)'s solution.
Skipped only where python3-siconos is absent; ``ROCKYADE_REQUIRE_SICONOS=1`` (``make test``)
turns that into a failure."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest

from rockyade.blocks.restitution import find_peaks, restitution_per_impact
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.generators import rest_motion, stack
from rockyade.scene.generators.arches import arch
from rockyade.siconos import backend as siconos_backend
from rockyade.siconos.calibration import default_dt
from rockyade.siconos.payload import PENETRATION_FRACTION, scene_payload
from rockyade.solvers import make_solver
from rockyade.solvers.siconos import SiconosSolver

from .conftest import EXAMPLES

#: Every test here runs the real Siconos: marked ``siconos`` through the fixture (tests/conftest.py).
pytestmark = pytest.mark.usefixtures("siconos_present")


def _raised(gap_m: float, duration_s: float = 1.0) -> dict:
    """Issue 34's block: 0.3 x 1 m, its base ``gap_m`` above the ground, the base at rest."""
    return {
        "duration_s": duration_s,
        "sample_dt_s": 0.01,
        "blocks": [
            {
                "name": "b",
                "width_m": 0.3,
                "height_m": 1.0,
                "thickness_m": 0.5,
                "mass_kg": 300.0,
                "position_m": [0, gap_m],
            }
        ],
        "contact": {"calibration": "paper"},
        "motion": {"type": "rest"},
    }


@pytest.mark.parametrize("gap_m", [0.001, 0.05, 0.5])
def test_a_block_that_starts_above_the_ground_lands_on_it(gap_m):
    """Issue 34 §5: the block at 0.5 m fell through the ground ("1 still falling", y -4.9 m);
    every vertex of a moving block is now paired with the ground, so it lands: it drops by
    its gap within Moreau-Jean's landing penetration (at most dt x the landing speed: 3 mm
    for the 0.5 m fall at dt 1e-3 s), stays there, and the run ends as the reference DEM's
    (a 0.5 m drop is a fall by the collapse rule every solver shares)."""
    scene = scene_from_dict(_raised(gap_m))
    result = SiconosSolver().run(scene)
    assert result.status == make_solver("reference").run(scene).status != "failed", result.meta.failure_reason
    y = result.frame["y_m"].to_numpy()  # the centroid's displacement from its start
    dt = result.meta.dt_s or 0.0
    landing = dt * math.sqrt(2.0 * 9.81 * gap_m)
    assert y[-1] == pytest.approx(-gap_m, abs=landing + 1e-6)
    assert 0.0 < result.meta.extra["max_penetration_m"] <= landing + 1e-6
    assert np.all(np.abs(np.diff(y[-20:])) < 1e-9)  # at rest on the ground
    assert np.max(np.abs(result.frame["theta_rad"].to_numpy())) < 1e-9


def test_a_block_that_goes_through_the_ground_fails_naming_the_bound():
    """The kernel path pairs only the vertices that start low with the ground (its rule before
    the numerics path): the raised block goes through, and the run fails once a vertex is
    PENETRATION_FRACTION of the block's smallest dimension below the ground, saying so."""
    result = SiconosSolver(integrator="kernel").run(scene_from_dict(_raised(0.5)))
    assert result.status == "failed" and not result.ok
    reason = result.meta.failure_reason or ""
    bound = PENETRATION_FRACTION * 0.3
    assert "below the ground, beyond the bound of" in reason and f"{bound:.3g} m" in reason
    assert result.meta.partial is True and 0 < len(result.frame) < 101


def test_a_free_rocking_upper_block_lands_on_its_seat():
    """The bi-block with its upper block released at half its critical angle: its lifted
    corner starts 16 mm above the lower block's top, beyond the old pairing tolerance (7.5 mm),
    and the upper block rocked through its seat and fell (status ``overturned`` at 0.7 s on
    both paths). Paired within PAIR_REACH_FRACTION of the block's size, it rocks on its seat:
    its impacts' restitution within 1 % of its model's own (Eq 4 with e = 0, ``mu_model``; the
    reference DEM gives 0.914 with its calibrated damping)."""
    scene = load_scene(EXAMPLES / "biblock_free.toml")
    result = SiconosSolver().run(scene)
    assert result.status == "completed", result.meta.failure_reason
    frame = result.frame
    theta = frame["upper_theta_rad"].to_numpy()
    assert np.max(np.abs(theta)) == pytest.approx(0.1145, rel=1e-3)
    peaks = find_peaks(frame["t_s"].to_numpy(), theta)
    mu = restitution_per_impact(peaks, 0.229)[:3]
    own = result.meta.extra["mu_model"]["upper"]
    assert len(mu) == 3 and np.all(np.abs(mu / own - 1.0) < 0.01), (mu, own)
    assert np.max(np.abs(frame["lower_theta_rad"].to_numpy())) < 1e-3  # the lower block stays down


def test_the_numerics_path_agrees_with_the_kernel_and_is_closer_to_housner():
    """Specimen 1's geometry released at alpha/2, 2 s, at the kernel's old default step
    (2.5e-4 s): the numerics path's peaks within 1 % of the kernel path's, and its per-impact
    restitution within 0.3 % of Housner's Eq 4 (the kernel path's twist row, a friction torque
    of 1e-4 m x mu N, dissipates a little more: 0.5 % below it)."""
    alpha = math.atan(0.25)
    scene = scene_from_dict(
        {
            "duration_s": 2.0,
            "sample_dt_s": 0.002,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.5, "density_kg_m3": 2000.0}],
            "contact": {"calibration": "paper"},
            "motion": {"type": "free", "theta0_rad": 0.5 * alpha},
        }
    )
    eq4 = 1.0 - 1.5 * math.sin(alpha) ** 2
    runs = {k: SiconosSolver(dt_s=2.5e-4, integrator=k).run(scene) for k in ("numerics", "kernel")}
    peaks, mus = {}, {}
    for name, result in runs.items():
        assert result.ok, result.meta.failure_reason
        found = find_peaks(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy())
        peaks[name] = found.amplitude_rad[:4]
        mus[name] = restitution_per_impact(found, alpha)[:3]
    assert np.all(np.abs(peaks["numerics"] / peaks["kernel"] - 1.0) < 0.01), peaks
    assert np.all(np.abs(mus["numerics"] / eq4 - 1.0) < 0.003), mus
    assert np.mean(np.abs(mus["numerics"] / eq4 - 1.0)) < np.mean(np.abs(mus["kernel"] / eq4 - 1.0)), mus


def test_the_default_step_is_the_fraction_of_one_over_p_and_its_bounds():
    """3e-3 / p of the fastest moving block, at most 5e-4 s: specimen 1 (p 3.84 rad/s) and the
    bi-block (5.0) get the cap, the wall (its half units' 7.21) 4.2e-4 s, the 20 voussoirs of a
    semicircular arch at t/R 0.08 (9.21) 3.3e-4 s."""
    solver = SiconosSolver()
    scenes = [load_scene(EXAMPLES / name) for name in ("specimen1_free.toml", "biblock_free.toml")]
    scenes.append(load_scene(EXAMPLES / "assemblies" / "wall_5_courses.toml"))
    scenes.append(
        scene_from_dict(arch(span_m=1.92, ring_depth_m=0.08, voussoirs=20, pier_width_m=0.16, pier_height_m=0.5))
    )
    steps = []
    for scene in scenes:
        model = solver.model(scene)
        p = max(b.p_rad_s for b in model.bodies if not b.fixed)
        assert default_dt(model) == pytest.approx(min(3e-3 / p, 5e-4))
        steps.append(default_dt(model))
    assert steps[:2] == [5e-4] * 2 and 4.1e-4 < steps[2] < 4.2e-4 and 3.2e-4 < steps[3] < 3.3e-4, steps


SCRIPT = """
import json, sys
import numpy as np
sys.path.insert(0, sys.argv[1])
import driver
scene = json.load(open(sys.argv[2]))
S = driver._siconos()
states = []
for scalar in (True, False):
    run = driver.NumericsEngine(scene, S)
    run.mj.scalar = scalar
    if not scalar:
        run.mj.q[:], run.mj.v[:] = np.array(run.mj._qs), np.array(run.mj._vs)
    for k in range(int(sys.argv[3])):
        run.step(k)
    q, v = run.mj.state()
    states.append((np.array(q), np.array(v), run.mj.calls))
(qa, va, ca), (qb, vb, cb) = states
print(json.dumps({"dq": float(np.abs(qa - qb).max()), "dv": float(np.abs(va - vb).max()), "calls": [ca, cb],
                  "moved": float(np.abs(qa - np.array(run.mj._qs)[:-1]).max())}))
"""


def _in_debian_python(tmp_path, scene, script: str, *args: str, tol: float = 1e-10) -> dict:
    """Run ``script`` in Debian's Python on the scene's payload (solver tolerance ``tol``)."""
    solver = SiconosSolver(solver_tol=tol)
    model = solver.model(scene)
    numerics, _ = solver.numerics(model)
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene_payload(model, numerics)))
    out = subprocess.run(
        [siconos_backend.SICONOS_PYTHON, "-c", script, str(siconos_backend.DRIVER.parent), str(path), *args],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_pair_by_pair_step_equals_the_all_pairs_step(tmp_path):
    """The bi-block released from its upper block's half critical angle, 600 steps (it rocks
    and impacts), tolerance 1e-10: the step in Python floats (a few pairs) and the step with
    numpy over all pairs give the same positions and velocities to rounding. (At the default
    tolerance they may part by what it allows: Lemke, on W summed in another order, stopped
    once at a residual of 7e-5 on one path and 6e-18 on the other.)"""
    got = _in_debian_python(tmp_path, load_scene(EXAMPLES / "biblock_free.toml"), SCRIPT, "600")
    assert got["calls"][0] == got["calls"][1] > 500
    assert got["dq"] < 1e-12 and got["dv"] < 1e-10, got


DECOUPLED = """
import json, sys
import numpy as np
import scipy.sparse
sys.path.insert(0, sys.argv[1])
import driver
import pair_table as mj
import siconos.numerics as sn
scene = json.load(open(sys.argv[2]))
run = driver.NumericsEngine(scene, driver._siconos())
for k in range(5):
    run.step(k)
eng = run.mj
t = eng.table
gap, closed, H = t.geometry(eng.q)
un = np.einsum("kj,kj->k", H[:, 0, 0], eng.v[t.a]) + np.einsum("kj,kj->k", H[:, 1, 0], eng.v[t.b])
act = np.flatnonzero(closed & (gap + 0.5 * eng.h * un <= eng.threshold))
m = len(act)
Ha = H[act]
v = eng.v.copy()
v[eng.moving] += eng.h * eng.minv * eng.force(5)
q = np.einsum("kij,kj->ki", Ha[:, 0], v[t.a[act]]) + np.einsum("kij,kj->ki", Ha[:, 1], v[t.b[act]])
da, db = eng.dof_a[act], eng.dof_b[act]
ia, ib = np.flatnonzero(da >= 0), np.flatnonzero(db >= 0)
rows, cols, blocks = mj.delassus_blocks(m, np.concatenate([ia, ib]), np.concatenate([da[ia], db[ib]]),
                                        np.concatenate([Ha[ia, 0], Ha[ib, 1]]), eng.minv)
W2 = np.zeros((m, 2, m, 2)); W2[rows, :, cols, :] = blocks; W2 = W2.reshape(2 * m, 2 * m)
Hd = np.zeros((2 * m, 3 * len(eng.mass)))
for k in range(m):
    for side, d in ((0, da[k]), (1, db[k])):
        if d >= 0:
            Hd[2 * k:2 * k + 2, 3 * d:3 * d + 3] += Ha[k, side]
dense = (Hd * eng.minv.ravel()) @ Hd.T
mu = t.mu[act]
csc = scipy.sparse.csc_matrix(W2); csc.indices = csc.indices.astype(np.int64); csc.indptr = csc.indptr.astype(np.int64)
sbm = sn.SBM_from_csparse(2, csc)[1]
so2 = sn.SolverOptions(sn.SICONOS_FRICTION_2D_NSGS); so2.dparam[0] = 1e-12; so2.iparam[0] = 100000
r2 = np.zeros(2 * m)
sn.fc2d_driver(sn.FrictionContactProblem(2, sn.NM_new_SBM(2 * m, 2 * m, sbm), q.ravel(), mu), r2, np.zeros(2 * m), so2)
data, ind, ptr = mj.sparse_fc3(m, rows, cols, blocks)
W3 = scipy.sparse.csc_matrix((data, ind, ptr), shape=(3 * m, 3 * m)); W3.indices, W3.indptr = ind, ptr
q3 = np.zeros((m, 3)); q3[:, :2] = q
so3 = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS); so3.dparam[0] = 1e-12; so3.iparam[0] = 100000
r3 = np.zeros(3 * m)
sn.fc3d_driver(sn.FrictionContactProblem(3, W3, q3.ravel(), mu), r3, np.zeros(3 * m), so3)
r3 = r3.reshape(m, 3)
print(json.dumps({"m": m, "rank": int(np.linalg.matrix_rank(W2)),
                  "W": float(np.abs(W2 - dense).max() / np.abs(dense).max()),
                  "impulse": float(np.abs(W2 @ (r3[:, :2].ravel() - r2)).max() / np.abs(W2 @ r2).max()),
                  "third": float(np.abs(r3[:, 2]).max()), "it2": int(so2.iparam[1]), "it3": int(so3.iparam[1])}))
"""


def test_the_decoupled_frictioncontact3_has_frictioncontact2s_solution(tmp_path):
    """On a 4-block stack at rest (redundant contacts: W singular), the one-step problem's W
    from the blocks of H M^-1 H^T equals the dense product; Siconos's 2-D Gauss-Seidel (on the
    sparse-block matrix) and its 3-D one on the problem with the out-of-plane row decoupled
    give the same contact velocities W r to 1e-8, with the out-of-plane impulse 0, in the same
    number of iterations."""
    scene = scene_from_dict(
        stack(widths_m=[0.6, 0.52, 0.44, 0.36], heights_m=0.4, motion=rest_motion(), duration_s=0.1, sample_dt_s=0.01)
    )
    got = _in_debian_python(tmp_path, scene, DECOUPLED)
    assert got["m"] >= 8 and got["rank"] < 2 * got["m"], got
    assert got["W"] < 1e-12 and got["impulse"] < 1e-8 and got["third"] == 0.0, got
    assert got["it2"] == got["it3"], got
