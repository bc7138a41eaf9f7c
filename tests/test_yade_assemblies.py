"""YADE on assemblies: every vertex meets every block, joints per pair, flush joints once.

The contact plan (sphere copies, masks, materials) is checked without YADE; the rest runs
real YADE (Debian's package): statics of flush stacks and of a frame, a pad case, a wall
standing under gravity, the rocking frame against Makris & Vassiliou's closed form, and
YADE against the reference DEM on a running-bond wall and the frame.

The reference-DEM comparisons need the reference DEM's assembly contacts (fixed bodies,
flush joints counted once); they are skipped, saying so, while the reference DEM refuses
assemblies, and run as soon as it accepts them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.blocks.restitution import find_peaks
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.statics import rest_springs, static_penetration
from rockyade.errors import InputError
from rockyade.result import Result
from rockyade.scene import scene_from_dict
from rockyade.scene.placement import penetration_depth, rotation_matrix
from rockyade.solvers import reference
from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver
from rockyade.yade import backend as yade_backend
from rockyade.yade.contact_plan import BASE_BIT, N_LABELS, body_row, plan_contacts
from rockyade.yade.payload import scene_payload, sphere_radii

from .processes import require_yade

# the module's autouse fixture runs require_yade for every test here
pytestmark = pytest.mark.yade

G = 9.81
STIFF = {"K_N_per_m": 1e9, "beta_s": 1e-4, "friction_angle_deg": 35.0}


def _block(name, x, y, w, h, t=0.3, rho=2400.0, **kw):
    return {
        "name": name,
        "width_m": w,
        "height_m": h,
        "thickness_m": t,
        "density_kg_m3": rho,
        "position_m": [x, y],
        **kw,
    }


def _scene(blocks, motion=None, duration=0.3, contact=None, sample_dt=0.001):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": sample_dt,
            "blocks": blocks,
            "contact": dict(contact or STIFF),
            "motion": motion or {"type": "rest"},
        }
    )


def flush_stack(n=3, w=0.3, h=0.6, **kw):
    """n equal blocks stacked corner on corner."""
    return _scene([_block(f"b{i}", 0.0, i * h, w, h) for i in range(n)], **kw)


def frame(motion=None, duration=0.3, span=1.0, b=0.2, h=1.0, beam_h=0.2, contact=None):
    """Two equal free-standing columns and a free cap beam flush with their outer faces."""
    return _scene(
        [
            _block("left", -span / 2 + b / 2, 0.0, b, h),
            _block("right", span / 2 - b / 2, 0.0, b, h),
            _block("beam", 0.0, h, span, beam_h),
        ],
        motion,
        duration,
        contact,
    )


def running_bond(courses=5, units=2, w=0.25, h=0.25, **kw):
    """A dry running-bond wall, half units at the ends of odd courses."""
    blocks = []
    for c in range(courses):
        if c % 2 == 0:
            row = [(i * w, w) for i in range(units)]
        else:
            row = [(0.0, w / 2)] + [(w / 2 + i * w, w) for i in range(units - 1)] + [(units * w - w / 2, w / 2)]
        blocks += [_block(f"c{c}u{k}", x0 + bw / 2, c * h, bw, h, t=0.2, rho=2200.0) for k, (x0, bw) in enumerate(row)]
    return _scene(blocks, **kw)


def pad_case(**kw):
    """A 0.6 x 0.3 m block on a 0.1 m pad on a 0.6 x 0.3 m block, released rocking."""
    blocks = [
        _block("bottom", 0.0, 0.0, 0.6, 0.3),
        _block("pad", 0.0, 0.3, 0.1, 0.04),
        _block("top", 0.0, 0.34, 0.6, 0.3),
    ]
    motion = {"type": "free", "theta0_rad": 0.1, "omega0_rad_s": 1.5, "block": "top"}
    return _scene(blocks, motion, duration=kw.pop("duration", 1.0), **kw)


# ------------------------------------------------------------------ the contact plan (no YADE)


def _wanted_and_used(model):
    """For every vertex and every other body: the joint the model asks for (joint_for, half at
    flush ends) and the one the payload's masks and materials give, as (joint, factor)."""
    payload = scene_payload(model)
    materials = payload["materials"]
    prisms = [b["prism_mask"] for b in payload["bodies"]]
    plan = plan_contacts(model, sphere_radii(model))
    from rockyade.yade.contact_plan import flush_ends

    flush = flush_ends(model)
    wanted, used = [], []
    for a, body in enumerate(payload["bodies"]):
        row = body_row(model, a)
        for v, copies in enumerate(body["sphere_copies"]):
            for b in range(len(prisms)):
                if b == a:
                    continue
                meets = [m for m, mask in copies if mask & prisms[b]]
                assert len(meets) <= 1, "two copies of one vertex would meet the same block"
                want = None if row[b] < 0 else (int(row[b]), 0.5 if (a, v, b) in flush else 1.0)
                got = None if not meets else (materials[meets[0]]["joint"], materials[meets[0]]["factor"])
                wanted.append(want)
                used.append(got)
            base = [m for m, mask in copies if mask & BASE_BIT]
            want = None if row[-1] < 0 else (int(row[-1]), 1.0)
            got = None if not base else (materials[base[0]]["joint"], materials[base[0]]["factor"])
            wanted.append(want)
            used.append(got)
    return wanted, used, plan.report


def test_plan_gives_every_pair_its_joint_up_to_30_blocks():
    """A 12-block wall with UDEC-style joints (K from each interface's length: bed joints
    under half units differ from full ones): every vertex meets every other block and the
    base with exactly the reference DEM's joint, halved at flush ends; the report says 0."""
    scene = running_bond(contact={"jkn_Pa_per_m": 1e11, "beta_s": 5e-5, "friction_angle_deg": 35.0})
    model = calibrated_model(scene)
    assert len({p.K_N_per_m for p in model.joints.params}) >= 2
    wanted, used, report = _wanted_and_used(model)
    assert wanted == used
    assert report["differ_at_rest"] == report["differ_in_motion"] == 0
    assert any(w is not None and w[1] == 0.5 for w in wanted)  # head joints are flush


def test_plan_beyond_30_blocks_never_lets_a_block_through():
    """A 44-block wall shares mask labels: every vertex still meets every other block (no
    pass-through) and pairs touching at rest get their exact joints. With uniform joints the
    only pairs that differ are a flush-end vertex meeting, in motion, a block that shares its
    flush partner's label (K/2 instead of K): the report counts them exactly, and they are
    at least two units apart at rest."""
    model = calibrated_model(running_bond(courses=8, units=5))
    assert len(model.bodies) > N_LABELS
    wanted, used, report = _wanted_and_used(model)
    assert all(u is not None for w, u in zip(wanted, used, strict=True) if w is not None)
    differ = [(w, u) for w, u in zip(wanted, used, strict=True) if w != u]
    assert all(w == (u[0], 1.0) and u[1] == 0.5 for w, u in differ)
    assert report["labels"] == N_LABELS and report["differ_at_rest"] == 0
    assert report["differ_in_motion"] == len(differ) < 0.02 * report["vertex_body_pairs"]
    assert report["closest_differing_pair_gap_m"] >= 2 * 0.25


def test_plan_reports_the_pairs_that_differ_beyond_30_blocks():
    """With joints that differ per pair beyond 30 blocks, the report counts exactly the
    (vertex, block) pairs whose joint differs, all among pairs that do not touch at rest."""
    scene = running_bond(courses=8, units=5, contact={"jkn_Pa_per_m": 1e11, "beta_s": 5e-5})
    model = calibrated_model(scene)
    wanted, used, report = _wanted_and_used(model)
    assert all(u is not None for w, u in zip(wanted, used, strict=True) if w is not None)
    differ = sum(w != u for w, u in zip(wanted, used, strict=True))
    assert report["differ_at_rest"] == 0
    assert report["differ_in_motion"] == differ
    assert all(not e["touch_at_rest"] for e in report["examples"])
    assert report["closest_differing_pair_gap_m"] >= 2 * 0.25


def test_sphere_places():
    """Base corners rest on the exact corner (tangent to the base), head-joint corners are
    inscribed (no sphere pokes into a neighbour), and each vertex has one radius of play."""
    model = calibrated_model(running_bond(courses=1, units=2))
    payload = scene_payload(model)
    r = payload["min_sphere_radius_m"]
    left = payload["bodies"][0]
    verts = np.array(left["vertices_m"])
    centres = np.array(left["sphere_centers_m"])
    assert centres[0] == pytest.approx(verts[0] + [0.0, r])  # bottom-left: free side
    assert centres[1] == pytest.approx(verts[1] + [-r, r])  # bottom-right: head joint and base


# ------------------------------------------------------------------ YADE runs


@pytest.fixture(scope="module", autouse=True)
def _yade_present():
    require_yade()


def _statics_end_forces(model):
    """Normal force at each end of each rest joint from the rest springs (K u = weights), N."""
    centroids = np.array([b.rest_centroid_m for b in model.bodies])
    fixed = [b.fixed for b in model.bodies]
    springs = rest_springs(centroids, fixed, model.rest_contacts, model.joints)
    pen = static_penetration(springs, [b.mass_kg for b in model.bodies], fixed, model.g)
    forces = springs.k[springs.normal] * pen
    return forces.reshape(len(model.rest_contacts), 2)


def _yade_end_forces(model, result):
    """YADE's normal force at each end of each rest joint: the vertex spheres of both blocks
    at that point (their reported ``c<i>_fn_N``), last sample, N."""
    out = np.zeros((len(model.rest_contacts), 2))
    last = result.frame.iloc[-1]
    for c_index, c in enumerate(model.rest_contacts):
        for e, end in enumerate(np.asarray(c.ends_m)):
            for body in (c.a, c.b):
                if body < 0:
                    continue
                b = model.bodies[body]
                world = b.contact_vertices_m @ rotation_matrix(b.rest_angle_rad).T + np.asarray(b.rest_centroid_m)
                for v in np.flatnonzero(np.hypot(*(world - end).T) < 1e-9):
                    out[c_index, e] += float(last[f"{b.name}_c{v}_fn_N"])
    return out


def test_flush_stack_is_one_joint_per_interface():
    """Three equal blocks corner on corner at rest: every flush corner carries K (not 2K),
    so the load splits as the statics say (equal corners within 1 %), with YADE's reported
    normal forces; each interface carries the weight above it."""
    scene = flush_stack(3)
    model = calibrated_model(scene)
    result = YadeSolver().run(scene)
    assert result.ok, result.meta.failure_reason
    statics = _statics_end_forces(model)
    yade = _yade_end_forces(model, result)
    weights = np.array([b.mass_kg * G for b in model.bodies])
    for c_index, c in enumerate(model.rest_contacts):
        above = weights[c.a :].sum() if c.b < 0 else weights[max(c.a, c.b) :].sum()
        assert statics[c_index].sum() == pytest.approx(above, rel=1e-6)
        assert yade[c_index].sum() == pytest.approx(above, rel=0.01)
        assert yade[c_index, 0] == pytest.approx(yade[c_index, 1], rel=0.01)
        np.testing.assert_allclose(yade[c_index], statics[c_index], rtol=0.01)


def test_frame_at_rest_splits_its_load_as_the_statics():
    """A cap beam on two columns (flush outer corners, inner corners under the beam): the
    statically indeterminate split of the beam's weight over the four top corners is the
    statics' (rest springs), within 2 % (YADE's inscribed corner spheres sit one sphere
    radius from the joint ends)."""
    scene = frame()
    model = calibrated_model(scene)
    result = YadeSolver().run(scene)
    assert result.ok, result.meta.failure_reason
    statics = _statics_end_forces(model)
    yade = _yade_end_forces(model, result)
    np.testing.assert_allclose(yade, statics, rtol=0.02, atol=1e-3 * statics.max())


def test_pad_case_blocks_do_not_pass_through_each_other():
    """A wide block rocking on a pad lands on the block under the pad (which is not its
    neighbour at rest): YADE keeps the overlap of any two blocks below 1 mm (the old
    backend let it sink 117 mm)."""
    scene = pad_case()
    model = calibrated_model(scene)
    result = _yade_run(scene, model)  # the same run as test_pad_case_yade_vs_reference's at Eq 7's step
    assert result.ok, result.meta.failure_reason
    worst = _max_overlap(model, result)
    assert worst < 1e-3
    assert np.max(np.abs(result.series("theta_rad", "top"))) > 0.15  # it did land on the bottom block


def _polygons_at(model, result, k):
    out = []
    for b in model.bodies:
        angle = b.rest_angle_rad + result.series("theta_rad", b.name)[k]
        shift = np.array([result.series("x_m", b.name)[k], result.series("y_m", b.name)[k]])
        centre = np.asarray(b.rest_centroid_m) + shift
        out.append(b.contact_vertices_m @ rotation_matrix(angle).T + centre)
    return out


def _max_overlap(model, result) -> float:
    worst = 0.0
    for k in range(0, len(result.frame), 2):
        polys = _polygons_at(model, result, k)
        for i in range(len(polys)):
            for j in range(i + 1, len(polys)):
                worst = max(worst, penetration_depth(polys[i], polys[j]))
    return worst


def _column_pulse(blocks):
    motion = {"type": "pulse", "shape": "sine", "amplitude_g": 0.4, "period_s": 0.5}
    return YadeSolver().run(_scene(blocks, motion=motion, duration=1.5))


def test_fixed_pedestal_and_rest_rotation_are_the_base_and_no_rotation():
    """A 0.25 x 1 m column rocking to 0.9 rad under a pulse rocks the same (to 1e-7 rad) on
    the base, on a fixed pedestal (which moves with the base: not at all in the base frame),
    and built as a 1 x 0.25 m block turned by pi/2 at rest (theta counts from rest)."""
    on_base = _column_pulse([_block("col", 0.0, 0.0, 0.25, 1.0)])
    on_pedestal = _column_pulse([_block("ped", 0.0, 0.0, 0.6, 0.2, fixed=True), _block("col", 0.0, 0.2, 0.25, 1.0)])
    turned = _column_pulse([_block("col", 0.125, 0.5, 1.0, 0.25, rotation_rad=math.pi / 2)])
    for r in (on_base, on_pedestal, turned):
        assert r.ok, r.meta.failure_reason
    theta = on_base.series("theta_rad")
    assert np.max(np.abs(theta)) > 0.5
    np.testing.assert_allclose(on_pedestal.series("theta_rad", "col"), theta, atol=1e-7)
    np.testing.assert_allclose(turned.series("theta_rad"), theta, atol=1e-7)
    np.testing.assert_allclose(on_pedestal.series("y_m", "col"), on_base.series("y_m"), atol=1e-7)
    assert not np.any(on_pedestal.series("x_m", "ped")) and not np.any(on_pedestal.series("theta_rad", "ped"))


def test_wall_beyond_30_blocks_stands():
    """A 44-block running-bond wall (shared mask labels) at rest: no block moves more than
    0.2 mm or turns more than 1e-3 rad."""
    scene = running_bond(courses=8, units=5, duration=0.2)
    result = YadeSolver().run(scene)
    assert result.ok, result.meta.failure_reason
    names = result.meta.blocks
    assert len(names) > N_LABELS
    for name in names:
        assert np.max(np.abs(result.series("x_m", name))) < 2e-4
        assert np.max(np.abs(result.series("y_m", name))) < 2e-4
        assert np.max(np.abs(result.series("theta_rad", name))) < 1e-3


def _first_peak_and_impact(t, theta, alpha):
    """First peak (value, time) and the first impact (theta back through zero), s."""
    peaks = find_peaks(t, theta, 1e-3 * alpha)
    start = int(np.argmax(np.abs(theta) > 1e-3 * alpha))
    sign = np.sign(theta[start])
    back = start + int(np.argmax(np.sign(theta[start:]) != sign))
    # linear interpolation of the zero crossing
    t0, t1, y0, y1 = t[back - 1], t[back], theta[back - 1], theta[back]
    return float(peaks.theta_rad[0]), float(peaks.t_s[0]), float(t0 - y0 * (t1 - t0) / (y1 - y0))


def _frame_pulse(amplitude=1.5, duration=0.6):
    alpha = math.atan(0.2 / 1.0)
    motion = {"type": "pulse", "shape": "sine", "amplitude_g": amplitude * math.tan(alpha), "period_s": 0.6}
    return frame(motion=motion, duration=duration, contact={"K_N_per_m": 2e9, "beta_s": 2e-5}), alpha


def test_frame_rocks_like_one_column_with_p_hat():
    """Makris & Vassiliou (2013): two equal columns and a free cap beam rock like one column
    with p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)), gamma = beam mass / columns' mass.
    Under a one-sine pulse YADE's frame and Housner's column (p_hat, the column's alpha) reach
    the same first peak within 3 % and the first impact within 2 %."""
    scene, alpha = _frame_pulse()
    model = calibrated_model(scene)
    columns, beam = model.bodies[:2], model.bodies[2]
    gamma = beam.mass_kg / sum(c.mass_kg for c in columns)
    p_hat = columns[0].p_rad_s * math.sqrt((1 + 2 * gamma) / (1 + 3 * gamma))
    result = YadeSolver().run(scene)
    assert result.status in ("completed", "overturned"), result.meta.failure_reason
    column = scene_from_dict(
        {
            "duration_s": scene.duration_s,
            "sample_dt_s": scene.sample_dt_s,
            "blocks": [
                {
                    "name": "column",
                    "width_m": 0.2,
                    "height_m": 1.0,
                    "thickness_m": 0.3,
                    "mass_kg": 144.0,
                    "p_rad_s": p_hat,
                    "mu": 0.9,
                }
            ],
            "motion": scene.motion.to_dict(),
        }
    )
    exact = HousnerSolver().run(column)
    peak_h, t_peak_h, impact_h = _first_peak_and_impact(exact.t, exact.series("theta_rad"), alpha)
    for name in ("left", "right"):
        peak, t_peak, impact = _first_peak_and_impact(result.t, result.series("theta_rad", name), alpha)
        assert peak == pytest.approx(peak_h, rel=0.03)
        assert impact == pytest.approx(impact_h, rel=0.02)
        assert t_peak == pytest.approx(t_peak_h, rel=0.02)
    assert abs(peak_h) > 0.05 * alpha  # a real excursion, not contact noise


# ------------------------------------------------------------------ against the reference DEM


def _reference_runs_assemblies() -> str | None:
    """None when the reference DEM runs assemblies (fixed bodies, flush joints), else why not."""
    blocks = [_block("floor", 0.0, 0.0, 0.6, 0.1, fixed=True), _block("b", 0.0, 0.1, 0.3, 0.6)]
    try:
        ReferenceSolver().run(_scene(blocks, duration=0.002))
    except InputError as exc:
        return f"the reference DEM does not run assemblies yet ({exc})"
    return None


def _dt_halved(run, model):
    return run(model), run(model.with_dt(model.dt_s / 2))


#: YADE's runs of a scene's model at its own time step, by scene hash: a scene two tests run
#: (the pad case: its overlaps, its agreement with the reference DEM) runs once per process.
_YADE_RUNS: dict[str, Result] = {}


def _yade_run(scene, model) -> Result:
    """YADE's run of ``model`` (``calibrated_model(scene)``), once per scene in this process."""
    if scene.scene_hash not in _YADE_RUNS:
        _YADE_RUNS[scene.scene_hash] = yade_backend.run_model(model)
    return _YADE_RUNS[scene.scene_hash]


def _metrics(result, names, alpha):
    """Per block: max |theta|, the time of its first peak and max |x| (centroid)."""
    out = {}
    for name in names:
        theta = result.series("theta_rad", name)
        peaks = find_peaks(result.t, theta, 1e-3 * alpha)
        first = float(peaks.t_s[0]) if len(peaks.t_s) else math.nan
        out[name] = (float(np.max(np.abs(theta))), first, float(np.max(np.abs(result.series("x_m", name)))))
    return out


def _own_change(a, b):
    """Largest relative change of each metric over the blocks between two runs."""
    return [max(abs(b[n][k] / a[n][k] - 1) for n in a) for k in range(3)]


def _compare_with_reference(scene, names, alpha, floors):
    """YADE vs the reference on ``names``: max |theta|, first-peak time and max |x| agree
    within the larger of a floor and 1.5x the larger of the two DEMs' own change when dt is
    halved (rocking amplifies small differences: that change is the resolution either DEM
    has on this scene)."""
    reason = _reference_runs_assemblies()
    if reason:
        pytest.skip(reason)
    model = calibrated_model(scene)
    ref, ref_half = _dt_halved(lambda m: reference.run_model(m, record_energy=False), model)
    yade, yade_half = _yade_run(scene, model), yade_backend.run_model(model.with_dt(model.dt_s / 2))
    for r in (ref, ref_half, yade, yade_half):
        assert r.ok, r.meta.failure_reason
    mr, mr2, my, my2 = (_metrics(r, names, alpha) for r in (ref, ref_half, yade, yade_half))
    own = np.maximum(_own_change(mr, mr2), _own_change(my, my2))
    tol = np.maximum(floors, 1.5 * own)
    for name in names:
        for k, what in enumerate(("max |theta|", "first peak time", "max |x|")):
            assert my[name][k] == pytest.approx(mr[name][k], rel=tol[k]), (name, what, tol[k])


def test_wall_yade_vs_reference():
    """A 5-course running-bond wall rocking under a one-sine pulse of 0.45 g (its top course
    turns about 0.12 rad and moves 90 mm): the top two courses' max |theta| within max(5 %,
    1.5x the DEMs' own dt/2 change: about 11 % here), first peak times within max(2 %, ...)
    and max displacements within max(3 %, ...)."""
    motion = {"type": "pulse", "shape": "sine", "amplitude_g": 0.45, "period_s": 0.5}
    scene = running_bond(motion=motion, duration=1.5, contact={"K_N_per_m": 1e9, "beta_s": 5e-5})
    _compare_with_reference(scene, ["c4u0", "c4u1", "c3u1"], math.atan(0.5 / 1.25), [0.05, 0.02, 0.03])


def test_frame_yade_vs_reference():
    """The rocking frame under its one-sine pulse: the columns' max |theta|, first peak times
    and max |x| within max(3 %, 2 %, 3 %) or 1.5x the DEMs' own dt/2 change. The run ends at
    0.9 s, after the largest excursion (0.779 s in all four runs): the metrics are those of the
    1.5 s run it replaced, to the last digit (measured)."""
    scene, alpha = _frame_pulse(amplitude=1.3, duration=0.9)
    _compare_with_reference(scene, ["left", "right"], alpha, [0.03, 0.02, 0.03])


def test_pad_case_yade_vs_reference():
    """The pad case: the top block's max rotation (landing on the bottom block) within 3 %
    of the reference DEM's; its first peak time and displacement within max(3 %, 1.5x the
    DEMs' own dt/2 change: the landing chatters)."""
    _compare_with_reference(pad_case(), ["top"], math.atan(0.05 / 0.15), [0.03, 0.03, 0.03])
