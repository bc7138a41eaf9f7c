"""YADE's Result columns that must mean what the reference DEM's mean: a continuous rotation
from rest (never wrapped at +/- pi) and the per-block contact points and slip flag.

YADE really runs (Debian package); skipped only where it is absent and
ROCKYADE_REQUIRE_YADE is not set.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from rockyade.analysis.collapse import collapse_report
from rockyade.calibration.model_stage import calibrated_model
from rockyade.scene import load_scene, scene_from_dict
from rockyade.solvers import reference
from rockyade.solvers.reference import ReferenceSolver
from rockyade.solvers.yade import YadeSolver
from rockyade.yade import backend as yade_backend

from .conftest import EXAMPLES
from .processes import require_yade

pytestmark = pytest.mark.yade


@pytest.fixture(scope="module", autouse=True)
def _yade_present():
    require_yade()


# ------------------------------------------------------------------ rotation


@pytest.mark.parametrize(
    ("spin_rad_s", "sample_dt_s"),
    [
        (12.0, 0.002),  # turns past pi, 2 pi, 3 pi between ordinary samples
        (400.0, 0.01),  # 4 rad per sample: only the driver's tracking between samples follows it
    ],
)
def test_spinning_block_has_a_continuous_rotation(spin_rad_s, sample_dt_s):
    """A block thrown up spinning (no contact during the run) turns at a constant rate: its
    theta is spin x t, far beyond pi, in YADE as in the reference DEM (YADE's orientation
    wraps at +/- pi: the driver accumulates it)."""
    scene = scene_from_dict(
        {
            "duration_s": 1.0,
            "sample_dt_s": sample_dt_s,
            "blocks": [{"name": "b", "width_m": 0.2, "height_m": 0.6, "thickness_m": 0.2, "mass_kg": 50}],
            "contact": {"K_N_per_m": 1e8, "beta_s": 1e-4, "friction_angle_deg": 35.0},
            "motion": {"type": "rest"},
        }
    )
    model = calibrated_model(scene)
    pos0 = model.pos0_m.copy()
    pos0[0, 1] += 10.0  # falls 4.9 m in 1 s: never lands
    model = replace(model, pos0_m=pos0, angvel0_rad_s=np.array([spin_rad_s]), stop_on_overturn=False)
    y, r = yade_backend.run_model(model), reference.run_model(model)
    assert y.ok, y.meta.failure_reason
    expected = spin_rad_s * y.t
    theta = y.series("theta_rad")
    assert theta[-1] > 3 * math.pi
    np.testing.assert_allclose(theta, expected, atol=1e-6 * spin_rad_s)
    np.testing.assert_allclose(theta, r.series("theta_rad"), atol=1e-6 * spin_rad_s)
    assert y.meta.extra["max_rotation_step_rad"] < math.pi


# ------------------------------------------------------------------ contacts and slip


def _slab(motion: dict) -> object:
    return scene_from_dict(
        {
            "duration_s": 1.0,
            "sample_dt_s": 0.002,
            "blocks": [{"name": "slab", "width_m": 1.0, "height_m": 0.2, "thickness_m": 0.5, "mass_kg": 250}],
            "contact": {"calibration": "paper", "friction_angle_deg": 10.0},
            "motion": motion,
        }
    )


def test_sliding_slab_slips_in_yade_as_in_the_reference():
    """A squat slab (never rocks) on a base accelerating at 3 m/s^2 > g tan(10 deg): from the
    start of the plateau its two base corners slip, in YADE as in the reference DEM."""
    scene = _slab({"type": "sampled", "t_s": [0.0, 0.05, 2.0], "accel_m_s2": [0.0, 3.0, 3.0]})
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.ok, y.meta.failure_reason
    for column in ("n_contacts", "slipping"):
        assert y.frame[column].dtype == r.frame[column].dtype
    late = y.t > 0.2
    assert y.frame["slipping"][late].all() and r.frame["slipping"][late].all()
    assert (y.frame["n_contacts"][late] == 2).all() and (r.frame["n_contacts"][late] == 2).all()
    assert not y.frame["slipping"].iloc[0]  # at rest before the base moves
    # it really slides: x falls behind the base by (a - g tan phi) t^2 / 2
    assert y.series("x_m")[-1] == pytest.approx(r.series("x_m")[-1], rel=0.02)


def test_slab_at_rest_does_not_slip():
    """At rest on the base both corners carry the weight and none slips (a flag that is
    always on, or always off, fails one of these two tests)."""
    scene = _slab({"type": "rest"})
    y = YadeSolver().run(scene)
    assert y.ok, y.meta.failure_reason
    assert not y.frame["slipping"].any()
    # YADE's contacts at a sample are those of the step before (none at t = 0)
    assert y.frame["n_contacts"].iloc[0] == 0
    assert (y.frame["n_contacts"].iloc[1:] == 2).all()


def test_drums_of_a_rocking_column_slide_as_briefly_as_in_the_reference():
    """The 8-drum column under a 0.25 g, 1 s sine pulse rocks as one body: its upper drums
    move fast but barely slip. With YADE's slip flag the collapse analysis gives the top
    drum's sliding time of the reference DEM (without it, seconds of 'sliding')."""
    data = load_scene(EXAMPLES / "assemblies/column_8_drums.toml").to_dict()
    data.update(duration_s=3.0, motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.25, "period_s": 1.0})
    scene = scene_from_dict(data)
    y, r = YadeSolver().run(scene), ReferenceSolver().run(scene)
    assert y.ok, y.meta.failure_reason
    ry, rr = (collapse_report(scene, x).set_index("block") for x in (y, r))
    top_y, top_r = ry.loc["d08", "sliding_time_s"], rr.loc["d08", "sliding_time_s"]
    assert max(top_y, top_r) < 0.5
    assert abs(top_y - top_r) < 0.2
    assert ry.loc["d08", "rocking_time_s"] > 1.0  # it rocks (a frozen theta would not)
    # the drums touch the one below and the one above (the top one only below)
    assert (y.frame["d08_n_contacts"] <= 2).all() and (y.frame["d04_n_contacts"] <= 4).all()
    assert y.frame["d04_n_contacts"].iloc[1] == r.frame["d04_n_contacts"].iloc[1] == 4
