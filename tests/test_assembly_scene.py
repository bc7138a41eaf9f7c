"""Assemblies: positioned scenes, their validation, rest contacts, joint rules, statics."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.joints import default_pair_joint
from rockyade.errors import CalibrationError, InputError
from rockyade.scene import load_scene, scene_from_dict
from rockyade.scene.placement import placed_blocks, rest_contacts

from .conftest import EXAMPLES


def brick(name, x, y, w=0.4, h=0.2, t=0.2, **extra):
    block = {"name": name, "width_m": w, "height_m": h, "thickness_m": t, "density_kg_m3": 2000.0}
    return block | {"position_m": [x, y]} | extra


def scene(blocks, contact=None, motion=None, joints=None, **top):
    d = {
        "duration_s": 0.5,
        "sample_dt_s": 0.001,
        "blocks": blocks,
        "contact": contact or {"calibration": "paper"},
        "motion": motion or {"type": "rest"},
        **top,
    }
    if joints:
        d["joints"] = joints
    return d


def running_bond(courses=2):
    """Two full bricks below, one centred on their head joint above (and more courses alike)."""
    blocks = []
    for c in range(courses):
        if c % 2 == 0:
            blocks += [brick(f"c{c}_a", 0.2, 0.2 * c), brick(f"c{c}_b", 0.6, 0.2 * c)]
        else:
            blocks += [brick(f"c{c}_m", 0.4, 0.2 * c)]
    return blocks


def test_side_by_side_blocks_load_and_touch():
    s = scene_from_dict(scene(running_bond()))
    assert s.positioned
    contacts = rest_contacts(placed_blocks(s))
    kinds = sorted((c.kind, c.a, c.b) for c in contacts)
    # two bricks on the base, their head joint, and the upper brick on both
    assert kinds == [("bed", 0, -1), ("bed", 0, 2), ("bed", 1, -1), ("bed", 1, 2), ("head", 0, 1)]
    lengths = {(c.a, c.b): c.length_m for c in contacts}
    assert lengths[(0, 2)] == pytest.approx(0.2) and lengths[(0, 1)] == pytest.approx(0.2)
    assert lengths[(0, -1)] == pytest.approx(0.4)


def test_overlapping_blocks_are_named():
    blocks = running_bond()
    blocks[2]["position_m"] = [0.4, 0.19]
    with pytest.raises(InputError) as info:
        scene_from_dict(scene(blocks))
    assert "c0_a" in str(info.value) and "c1_m" in str(info.value) and "overlap" in str(info.value)


def test_position_on_every_block_or_none():
    blocks = running_bond()
    del blocks[1]["position_m"]
    with pytest.raises(InputError) as info:
        scene_from_dict(scene(blocks))
    assert info.value.field == "blocks[1].position_m"


def test_block_below_the_base_refused():
    with pytest.raises(InputError) as info:
        scene_from_dict(scene([brick("a", 0.0, -0.01)]))
    assert "below the base" in str(info.value)


def test_rotation_and_vertex_origin():
    """position_m places the origin of the user's vertex coordinates, rotated about it."""
    tri = {
        "name": "q",
        "vertices_m": [[0.0, 1.0], [2.0, 1.0], [2.0, 2.0], [0.0, 2.0]],  # lowest at y = 1: origin kept
        "thickness_m": 0.1,
        "mass_kg": 10.0,
        "position_m": [5.0, 0.0],
        "rotation_rad": math.pi / 2,
    }
    s = scene_from_dict(scene([tri]))
    verts = placed_blocks(s)[0].vertices_m
    # (x, y) -> (-y, x) + (5, 0)
    expected = {(4.0, 0.0), (4.0, 2.0), (3.0, 2.0), (3.0, 0.0)}
    assert {(round(x, 9), round(y, 9)) for x, y in verts} == expected


def test_explicit_contact_needs_no_classical_calibration():
    """A light, squat brick: Eq 13 has no value (sqrt(b) < 0) but explicit K and beta need none."""
    light = [brick("a", 0.0, 0.0, w=0.2, h=0.05, t=0.1)]
    with pytest.raises(CalibrationError):
        calibrated_model(scene_from_dict(scene(light)))
    model = calibrated_model(scene_from_dict(scene(light, contact={"K_N_per_m": 1e8, "beta_s": 1e-4})))
    joint = model.joints.params[0]
    assert joint.K_N_per_m == 1e8 and joint.beta_s == 1e-4 and joint.method == "explicit"
    model = calibrated_model(scene_from_dict(scene(light, contact={"calibration": "paper", "beta_s": 1e-4})))
    assert model.joints.params[0].beta_s == 1e-4  # the paper's K with an explicit beta: Eq 13 not needed


def test_joint_rules_bed_head_base_fixed():
    blocks = running_bond()
    blocks[1]["height_m"] = 0.2
    blocks[1]["density_kg_m3"] = 1000.0  # the softer of the two lower bricks (K ~ mass)
    blocks.append(brick("wall", 1.0, 0.0, w=0.2, h=0.6, fixed=True))
    blocks.append(brick("top", 0.75, 0.2, w=0.3, h=0.2))  # on c0_b, beside c1_m, against the fixed wall
    model = calibrated_model(scene_from_dict(scene(blocks)))
    J = model.joints
    names = model.names
    idx = {n: i for i, n in enumerate(names)}
    K = [p.K_N_per_m for p in J.params]
    own = {n: K[J.own_joint[i]] for n, i in idx.items() if not model.bodies[i].fixed}
    assert own["c0_b"] < own["c0_a"]
    # bed joints take the upper block's own joint
    assert K[J.joint_for(idx["c0_a"], idx["c1_m"])] == own["c1_m"]
    assert K[J.joint_for(idx["c0_b"], idx["top"])] == own["top"]
    # head joint: the softer of the two
    assert K[J.joint_for(idx["c0_a"], idx["c0_b"])] == own["c0_b"]
    # block-fixed: the moving block's own joint; base: own
    assert K[J.joint_for(idx["top"], idx["wall"])] == own["top"]
    assert K[J.joint_for(idx["c0_a"], -1)] == own["c0_a"]
    assert J.base_joint[idx["wall"]] == -1
    # a pair that does not touch at rest: the softer own joint
    assert K[J.joint_for(idx["c0_a"], idx["top"])] == min(own["c0_a"], own["top"])
    kinds = dict(zip(zip(J.pair_a.tolist(), J.pair_b.tolist(), strict=True), J.pair_kind, strict=True))
    assert kinds[(idx["c0_a"], idx["c0_b"])] == "head"
    assert kinds[(min(idx["top"], idx["wall"]), max(idx["top"], idx["wall"]))] == "fixed"


def test_udec_stiffness_per_area_and_overrides():
    jkn = 1e10  # Pa/m
    model = calibrated_model(
        scene_from_dict(
            scene(
                running_bond(),
                contact={"jkn_Pa_per_m": jkn, "beta_s": 5e-5},
                joints=[
                    {"blocks": ["c0_a", "c0_b"], "friction_angle_deg": 20.0},
                    {"blocks": ["c0_b", "base"], "K_N_per_m": 3e8},
                ],
            )
        )
    )
    J = model.joints
    # bed joint of c1_m on c0_a: shared length 0.2 m, thickness 0.2 m -> K = jkn * 0.1 * 0.2
    bed = J.params[J.joint_for(0, 2)]
    assert bed.K_N_per_m == pytest.approx(jkn * 0.5 * 0.2 * 0.2)
    base = J.params[J.joint_for(0, -1)]
    assert base.K_N_per_m == pytest.approx(jkn * 0.5 * 0.4 * 0.2)
    head = J.params[J.joint_for(0, 1)]
    assert head.friction_angle_deg == 20.0 and head.K_N_per_m == pytest.approx(jkn * 0.5 * 0.2 * 0.2)
    assert J.params[J.joint_for(1, -1)].K_N_per_m == 3e8


def test_udec_needs_beta_and_not_both_stiffnesses():
    with pytest.raises(InputError) as info:
        scene_from_dict(scene(running_bond(), contact={"jkn_Pa_per_m": 1e10}))
    assert info.value.field == "contact.beta_s"
    with pytest.raises(InputError):
        scene_from_dict(scene(running_bond(), contact={"jkn_Pa_per_m": 1e10, "K_N_per_m": 1e9, "beta_s": 0.0}))
    with pytest.raises(InputError) as info:
        scene_from_dict(scene(running_bond(), joints=[{"blocks": ["c0_a", "nope"], "beta_s": 0.0}]))
    assert "nope" in str(info.value)


def test_statics_flush_stack_and_settlement_refusal():
    """Two equal blocks corner to corner: one joint (K per end), equal load at both ends."""
    stack = [brick("low", 0.0, 0.0, w=0.3, h=0.6), brick("up", 0.0, 0.6, w=0.3, h=0.6)]
    model = calibrated_model(scene_from_dict(scene(stack)))
    beds = [c for c in model.rest_contacts if c.b >= 0]
    assert len(beds) == 1 and beds[0].length_m == pytest.approx(0.3)
    weight = model.bodies[1].mass_kg * 9.81
    k = model.joints.params[model.joints.joint_for(0, 1)].K_N_per_m
    # one joint of two ends of stiffness K each: the upper block settles by W / (2 K)
    from rockyade.dem.statics import rest_springs, static_penetration

    springs = rest_springs(model.pos0_m, [False, False], list(model.rest_contacts), model.joints)
    pen = static_penetration(springs, [b.mass_kg for b in model.bodies], [False, False], 9.81)
    joint_pen = pen[springs.contact[springs.normal] == model.rest_contacts.index(beds[0])]
    assert joint_pen == pytest.approx([weight / (2 * k)] * 2, rel=1e-9)
    with pytest.raises(InputError) as info:
        calibrated_model(scene_from_dict(scene(stack, contact={"calibration": "paper", "stiffness_scale": "N/m"})))
    assert "sink" in str(info.value)


def test_free_rocking_in_an_assembly_tilts_the_block_and_what_rests_on_it():
    blocks = [brick("low", 0.0, 0.0, w=0.3, h=0.6), brick("up", 0.0, 0.6, w=0.3, h=0.6), brick("side", 0.5, 0.0)]
    with pytest.raises(InputError) as info:
        scene_from_dict(scene(blocks, motion={"type": "free", "theta0_rad": 0.05}))
    assert info.value.field == "motion.block"
    released = scene(blocks, motion={"type": "free", "theta0_rad": 0.05, "block": "low"})
    model = calibrated_model(scene_from_dict(released))
    assert model.ang0_rad.tolist() == [0.05, 0.05, 0.0]
    # both tilted about low's left base corner (-0.15, 0)
    r = model.pos0_m[1] - np.array([-0.15, 0.0])
    assert np.hypot(*r) == pytest.approx(np.hypot(0.15, 0.9))


def test_default_rule_matches_joint_for():
    model = calibrated_model(scene_from_dict(scene(running_bond(3))))
    J = model.joints
    for a in range(len(model.bodies)):
        for b in range(a + 1, len(model.bodies)):
            listed = any((J.pair_a == a) & (J.pair_b == b))
            if not listed:
                assert J.joint_for(a, b) == default_pair_joint(J.params, J.own_joint, J.fixed, a, b)


def test_column_scenes_unchanged():
    """Scenes without positions keep their meaning (and canonical form: hashes, resume)."""
    s = load_scene(EXAMPLES / "biblock_free.toml")
    d = s.to_dict()
    assert not s.positioned
    for b in d["blocks"]:
        assert "position_m" not in b and "rotation_rad" not in b and "fixed" not in b
    assert "joints" not in d
    model = calibrated_model(s)
    assert model.joints.pair_kind == ("bed",) and model.joints.n_pairs == 1
