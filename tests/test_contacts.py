"""The reference DEM's contacts: manifolds at flush corners, joints per pair, fixed bodies,
and the broad phase and temporal coherence leaving the results unchanged."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.engine import model_arrays, polygon_arrays, simulate_model
from rockyade.dem.overturn import LANDING_TOL_RAD
from rockyade.dem.statics import rest_springs, static_penetration
from rockyade.kernel import simulation as kernel
from rockyade.kernel.narrowphase import NO_FACE, clip_manifold, incident_edge, joint_for, separating_axis_test
from rockyade.kernel.state import pack
from rockyade.scene import scene_from_dict
from rockyade.scene.placement import penetration_depth, rotation_matrix
from rockyade.solvers.reference import ReferenceSolver, run_model

EXPLICIT = {"K_N_per_m": 1e8, "Ks_N_per_m": 1e8, "beta_s": 1e-4, "friction_angle_deg": 35.0}


def block(name, w, h, x=None, y=None, **extra):
    d = {"name": name, "width_m": w, "height_m": h, "thickness_m": 0.3, "density_kg_m3": 2400.0}
    if x is not None:
        d["position_m"] = [x, y]
    return d | extra


def scene(blocks, motion=None, contact=None, duration=0.3, sample_dt=0.001, **top):
    return scene_from_dict(
        {
            "duration_s": duration,
            "sample_dt_s": sample_dt,
            "blocks": blocks,
            "contact": contact or {"calibration": "paper"},
            "motion": motion or {"type": "rest"},
            **top,
        }
    )


def polygons_at(model, result, k):
    """Every body's contact polygon in the base frame at sample k."""
    out = []
    for body in model.bodies:
        theta = result.series("theta_rad", body.name)[k] + body.rest_angle_rad
        shift = [result.series("x_m", body.name)[k], result.series("y_m", body.name)[k]]
        out.append(body.contact_vertices_m @ rotation_matrix(theta).T + np.asarray(body.rest_centroid_m) + shift)
    return out


def bed_forces(model, result, lower, upper):
    """Normal forces K x depth at the two ends (left, right) of the bed joint of ``upper``
    on ``lower``, at the last sample (at rest the dashpots carry nothing): the depth of the
    upper block's bottom face below the lower block's top face at the ends of their overlap."""
    k = model.joints.params[model.joints.joint_for(lower, upper)].K_N_per_m
    polys = polygons_at(model, result, -1)
    top = polys[lower][np.argsort(polys[lower][:, 1])[-2:]]
    top = top[np.argsort(top[:, 0])]
    bottom = polys[upper][np.argsort(polys[upper][:, 1])[:2]]
    bottom = bottom[np.argsort(bottom[:, 0])]
    edge = top[1] - top[0]
    n = np.array([-edge[1], edge[0]]) / np.hypot(*edge)
    ends = [max(top[0, 0], bottom[0, 0]), min(top[1, 0], bottom[1, 0])]
    forces = []
    for x in ends:
        w = (x - bottom[0, 0]) / (bottom[1, 0] - bottom[0, 0])
        point = bottom[0] + w * (bottom[1] - bottom[0])
        forces.append(-k * float((point - top[0]) @ n))
    return np.array(forces)


def statics_forces(model, pair):
    """Normal spring forces of the rest contact ``pair`` = (a, b) from the linear statics."""
    fixed = [b.fixed for b in model.bodies]
    springs = rest_springs(
        np.array([b.rest_centroid_m for b in model.bodies]), fixed, list(model.rest_contacts), model.joints
    )
    pen = static_penetration(springs, [b.mass_kg for b in model.bodies], fixed, model.g)
    owners = springs.contact[springs.normal]
    k = springs.k[springs.normal]
    return np.array(
        [
            kk * p
            for o, kk, p in zip(owners, k, pen, strict=True)
            if (model.rest_contacts[o].a, model.rest_contacts[o].b) == pair
        ]
    )


# ---------------------------------------------------------------------- the manifold itself


def _world(polys):
    arrays = polygon_arrays([np.asarray(p, dtype=float) for p in polys])
    return arrays["verts"], arrays["normals"], arrays["edge_len"], arrays["nverts"]


def _manifold(polys, prev=(NO_FACE, NO_FACE)):
    wv, wn, flen, nverts = _world(polys)  # polygons given in world coordinates directly
    wd = np.einsum("bvk,bvk->bv", wn, wv)
    side, face, slack = separating_axis_test(wv, wn, wd, flen, nverts, 0, 1, prev[0], prev[1], 1e-9)
    if side == NO_FACE:
        return side, face, slack, np.zeros((0, 3))
    ref, inc = (0, 1) if side == 0 else (1, 0)
    edge, _ = incident_edge(wn, ref, face, inc, nverts[inc])
    out = np.zeros((2, 3))
    n = clip_manifold(wv, wn, flen, nverts, ref, face, inc, edge, out)
    return side, face, slack, out[:n]


def rect(x0, y0, x1, y1):
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


def test_flush_corner_gives_two_points_on_the_bed_face():
    """Two equal blocks corner to corner, the upper one sunk by 1e-5 m: one manifold, the
    lower block's top face (normal +y) as reference, two points at the corners, each at the
    penetration depth; never the side face, whose axis separates by the whole width."""
    side, face, slack, points = _manifold([rect(0, 0, 0.3, 0.6), rect(0, 0.6 - 1e-5, 0.3, 1.2)])
    assert side == 0 and face == 2  # lower block, its top edge (vertex 2 to 3)
    assert points[:, 0] == pytest.approx([0.0, 0.3], abs=1e-12)
    assert points[:, 2] == pytest.approx([1e-5, 1e-5], rel=1e-6)
    assert 0 < slack < 1e-5
    # the same pair listed the other way round: the same face of the same block
    side, face, _, points = _manifold([rect(0, 0.6 - 1e-5, 0.3, 1.2), rect(0, 0, 0.3, 0.6)])
    assert side == 1 and face == 2 and len(points) == 2


def test_narrow_on_wide_and_offset_and_separated():
    # a narrow block on a wide one: the wide face is the reference, the points the narrow corners
    side, _, _, points = _manifold([rect(0, 0.6 - 1e-5, 0.1, 1.0), rect(-0.2, 0, 0.3, 0.6)])
    assert side == 1 and sorted(points[:, 0]) == pytest.approx([0.0, 0.1])
    # offset equal blocks (running bond): the points are the ends of the overlap
    _, _, _, points = _manifold([rect(0, 0, 0.4, 0.2), rect(0.2, 0.2 - 2e-6, 0.6, 0.4)])
    assert sorted(points[:, 0]) == pytest.approx([0.2, 0.4]) and points[:, 2] == pytest.approx([2e-6, 2e-6])
    # apart by 3 mm: a separating axis, whose separation is the slack
    side, _, slack, points = _manifold([rect(0, 0, 0.3, 0.6), rect(0, 0.603, 0.3, 1.2)])
    assert side == NO_FACE and slack == pytest.approx(0.003) and len(points) == 0


def test_tilted_corner_on_corner_keeps_the_last_reference_face():
    """The upper block of a flush pair tilts about its left corner (a vertex on a vertex): by
    the bare separating-axis test its own bottom face would win by delta (1 - cos theta);
    the hysteresis keeps the lower block's face, so the normal stays +y and the left corner
    is the one contact point."""
    c, s = math.cos(0.01), math.sin(0.01)
    upper = np.array(rect(0, 0, 0.3, 0.6)) @ np.array([[c, s], [-s, c]]) + [0.0, 0.6 - 1e-5]
    fresh = _manifold([rect(0, 0, 0.3, 0.6), upper])
    kept = _manifold([rect(0, 0, 0.3, 0.6), upper], prev=(0, 2))
    assert kept[0] == 0 and kept[1] == 2
    assert len(kept[3]) == 1 and kept[3][0, 0] == pytest.approx(0.0, abs=1e-6)
    assert kept[3][0, 2] == pytest.approx(1e-5, rel=1e-3)
    assert len(fresh[3]) == 1  # either face gives the same single point


# ---------------------------------------------------------------------- forces at rest


def test_flush_stack_at_rest_splits_as_statics():
    """Two equal blocks, flush: each corner of the bed joint carries half the upper weight
    (within 1 %, and as the linear statics says); offset by 3 cm the split follows the
    statics too (both corners stay closed)."""
    model = calibrated_model(scene([block("lower", 0.2, 0.6), block("upper", 0.2, 0.6)], duration=1.0))
    result = run_model(model, record_energy=False)
    forces = bed_forces(model, result, 0, 1)
    weight = model.bodies[1].mass_kg * model.g
    assert forces == pytest.approx([weight / 2, weight / 2], rel=0.01)
    assert abs(forces[0] / forces[1] - 1) < 0.01
    assert statics_forces(model, (0, 1)) == pytest.approx([weight / 2, weight / 2], rel=1e-9)
    assert result.frame["upper_n_contacts"].iloc[-1] == 2  # one joint: two points, not four
    # corner states: both blocks' corners at the flush joint and on the base, not the top ones
    last = result.frame.iloc[-1]
    states = {f"{b}_c{v}": str(last[f"{b}_c{v}_state"]) for b in ("lower", "upper") for v in range(4)}
    assert states == {**dict.fromkeys(states, "stick"), "upper_c2": "open", "upper_c3": "open"}

    offset = scene([block("lower", 0.2, 0.6, 0.0, 0.0), block("upper", 0.2, 0.6, 0.03, 0.6)], duration=1.0)
    model = calibrated_model(offset)
    result = run_model(model, record_energy=False, per_corner=False)
    forces = bed_forces(model, result, 0, 1)
    expected = statics_forces(model, (0, 1))  # from the left end to the right end of the joint
    assert sorted(forces) == pytest.approx(sorted(expected), rel=0.01)
    assert forces[1] > 1.3 * forces[0]  # the overhang loads the lower block's right corner


def test_block_on_a_fixed_pedestal_rocks_as_on_the_base():
    """A fixed body is a polygon that never moves: a block rocking on a fixed pedestal
    follows the same block rocking on the base (peaks within 0.1 %), and the pedestal
    stays where it is."""
    free = {"type": "free", "theta0_rad": 0.1, "block": "b"}
    on_base = scene([block("b", 0.25, 1.0, 0.0, 0.0)], motion=free, contact=EXPLICIT, duration=2.0)
    pedestal = scene(
        [block("ped", 0.6, 0.4, 0.0, 0.0, fixed=True), block("b", 0.25, 1.0, 0.0, 0.4)],
        motion=free,
        contact=EXPLICIT,
        duration=2.0,
    )
    a = ReferenceSolver().run(on_base)
    b = ReferenceSolver().run(pedestal)
    theta_a, theta_b = a.series("theta_rad"), b.series("theta_rad", "b")
    assert np.max(np.abs(theta_b - theta_a)) < 1e-3 * np.max(np.abs(theta_a))
    assert np.all(b.series("x_m", "ped") == 0.0) and np.all(b.series("theta_rad", "ped") == 0.0)


# ---------------------------------------------------------------------- joints


def test_kernel_joint_lookup_is_the_joint_table_rule():
    """Every pair of a scene with a bed joint, a head joint, an override, a fixed block and
    pairs that meet only in motion: the kernel's lookup equals JointTable.joint_for."""
    blocks = [
        block("a", 0.4, 0.2, 0.2, 0.0, density_kg_m3=2000.0),
        block("b", 0.4, 0.2, 0.6, 0.0, density_kg_m3=2600.0),
        block("c", 0.4, 0.2, 0.4, 0.2),
        block("wall", 0.2, 1.0, 1.1, 0.0, fixed=True),
        block("d", 0.2, 0.6, -0.4, 0.0),
        block("e", 0.2, 0.3, 2.0, 0.0, density_kg_m3=1800.0),
    ]
    joints = [{"blocks": ["c", "b"], "K_N_per_m": 3e7}]
    model = calibrated_model(scene(blocks, joints=joints))
    table = model.joints
    args = model_arrays(model)
    nb = len(model.bodies)
    for i in range(nb):
        for j in list(range(-1, nb)):
            if i == j or (j >= 0 and table.fixed[i] and table.fixed[j]) or (j < 0 and table.fixed[i]):
                continue
            expected = table.joint_for(i, j)
            got = joint_for(
                i,
                j,
                nb,
                args["base_joint"],
                args["own_joint"],
                args["pair_keys"],
                args["pair_joint"],
                table.fixed,
                args["kn"],
            )
            assert got == expected, (model.names[i], j)
    assert len({table.joint_for(0, 1), table.joint_for(1, 2), table.joint_for(0, 2)}) >= 2


# ---------------------------------------------------------------------- broad phase, coherence


PAD_BLOCKS = [
    block("lower", 0.6, 0.3, 0.0, 0.0),
    block("pad", 0.1, 0.1, 0.0, 0.3),
    block("upper", 0.6, 0.3, 0.0, 0.4),
]
PAD_PULSE = {"type": "pulse", "shape": "sine", "amplitude_g": 0.5, "period_s": 0.4}


def test_pad_case_keeps_overlaps_below_a_millimetre():
    """A 0.6 x 0.3 m block on a 0.1 m pad on a lower block, under a pulse: it rocks on the
    pad, lands on the lower block beside it (a pair that did not touch at rest) and kicks
    the pad out; no two bodies ever overlap by more than 1 mm."""
    sc = scene(PAD_BLOCKS, motion=PAD_PULSE, contact=EXPLICIT, duration=2.0, sample_dt=0.002)
    model = calibrated_model(sc)
    result = ReferenceSolver().run(sc)
    assert result.status == "completed"
    theta = result.series("theta_rad", "upper")
    assert np.max(np.abs(theta)) > math.atan2(0.1, 0.25)  # tilted far enough to reach the lower block
    worst = 0.0
    touched_lower = False
    for k in range(len(result.t)):
        polys = polygons_at(model, result, k)
        for i in range(3):
            worst = max(worst, -float(polys[i][:, 1].min()))
            for j in range(i + 1, 3):
                depth = penetration_depth(polys[i], polys[j])
                worst = max(worst, depth)
                touched_lower |= (i, j) == (0, 2) and depth > -1e-4
    assert touched_lower
    assert worst < 1e-3


def test_broad_phase_and_coherence_do_not_change_the_results():
    """The pad case (rebuilds, a pair meeting in motion, a pad in flight): the same bits
    with every pair tested every step, and with every pair of bodies in the candidate list."""
    sc = scene(PAD_BLOCKS, motion=PAD_PULSE, contact=EXPLICIT, duration=1.4, sample_dt=0.002)
    model = calibrated_model(sc)
    args = model_arrays(model)
    flags = {"stop_on_overturn": True, "record_energy": False, "record_corners": False}
    runs = {
        "default": kernel.simulate(*pack(args, coherent=True, **flags)),
        "every pair tested": kernel.simulate(*pack(args, coherent=False, **flags)),
        "all pairs listed": kernel.simulate(
            *pack({**args, "margin": args["margin"] * 0 + 100.0}, coherent=True, **flags)
        ),
    }
    base = runs["default"]
    assert base[13] > 1  # the candidate list was rebuilt
    assert base[15] < 0.5 * runs["every pair tested"][15]  # most pair-steps reuse the last test
    assert runs["all pairs listed"][14] == 3
    for name, out in runs.items():
        np.testing.assert_array_equal(out[0], base[0], err_msg=name)
        np.testing.assert_array_equal(out[1], base[1], err_msg=name)


def test_assembly_runs_on_when_a_block_falls():
    """Positioned scenes record when each block passes its stop angle (the landing angle,
    pi/2 - 0.01 rad for a rectangle) and run to the end, overturned at the first fall;
    column scenes stop at the first overturn, as before."""
    blocks = [block("slender", 0.1, 1.0, 0.0, 0.0), block("squat", 0.6, 0.3, 1.0, 0.0)]
    pulse = {"type": "pulse", "shape": "sine", "amplitude_g": 0.6, "period_s": 0.5}
    result = ReferenceSolver().run(scene(blocks, motion=pulse, contact=EXPLICIT, duration=2.5, sample_dt=0.002))
    assert result.status == "overturned" and result.t[-1] == pytest.approx(2.5)
    assert set(result.meta.overturn_times_s) == {"slender"}
    t_fall = result.meta.overturn_times_s["slender"]
    assert result.meta.overturned_block == "slender" and result.meta.overturn_time_s == t_fall
    theta = np.abs(result.series("theta_rad", "slender"))
    assert result.t[np.argmax(theta >= math.pi / 2 - LANDING_TOL_RAD)] == pytest.approx(t_fall, abs=0.002)
    column = scene([block("slender", 0.1, 1.0)], motion=pulse, contact=EXPLICIT, duration=2.5, sample_dt=0.002)
    stopped = ReferenceSolver().run(column)
    assert stopped.status == "overturned" and stopped.meta.overturn_time_s == pytest.approx(t_fall, abs=1e-9)
    out, _ = simulate_model(calibrated_model(column), False, stop_angle_rad=np.array([0.5]))
    assert out.status == kernel.STATUS_OVERTURNED and out.t_stop < t_fall
