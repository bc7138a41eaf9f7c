"""Check 4 of the exact two-block solver: against Siconos (Debian's python3-siconos really
running, restitution e = 0) on the paper's bi-block with the geometry's own parameters,
released from half the upper block's critical angle. Marked ``siconos`` (the fixture
``siconos_present``: ``make test`` runs it, ``make check`` leaves it); skipped only where Siconos
is absent, and ``ROCKYADE_REQUIRE_SICONOS=1`` (``make test``) turns that into a failure."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from rockyade.scene import scene_from_dict
from rockyade.solvers import make_solver, run

LOWER = {"name": "lower", "width_m": 0.20, "height_m": 0.60, "thickness_m": 0.55, "mass_kg": 204}
UPPER = {"name": "upper", "width_m": 0.15, "height_m": 0.60, "thickness_m": 0.40, "mass_kg": 91}


def _zero_crossings(t: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Times at which the sampled rotation changes sign (linear between samples), s."""
    i = np.flatnonzero((np.sign(theta[1:]) != np.sign(theta[:-1])) & (theta[:-1] != 0))
    return t[i] + (t[i + 1] - t[i]) * theta[i] / (theta[i] - theta[i + 1])


def test_first_impact_within_one_percent_of_siconos_and_the_later_rocking_close(siconos_present):
    """The upper block's first impact on its seat within 1 % of Siconos's (measured: 0.01 %);
    the next two impacts within 1 % and the peaks between them within 2 % (measured: 0.15 % and
    0.35 %: docs/twoblock.md explains the drift by the impact models); the lower block barely
    moves in both (thrown by each impact of the upper one, |theta| ~ 1e-4 rad)."""
    alpha = math.atan(0.075 / 0.3)
    scene = scene_from_dict(
        {
            "duration_s": 1.2,
            "sample_dt_s": 0.001,
            "blocks": [LOWER, UPPER],
            "contact": {"calibration": "paper"},
            "motion": {"type": "free", "theta0_rad": 0.5 * alpha, "block": "upper"},
        }
    )
    exact = run(scene, "twoblock")
    siconos = make_solver("siconos", restitution=0.0).run(scene)
    assert exact.status == "completed" and siconos.ok, siconos.meta.failure_reason
    # rocking only ever lifts the centroid (y_m: its rise from the start): the lifted corner pairs
    # with its seat and lands on it (before, it fell through the lower block)
    assert siconos.series("y_m", "upper").min() > -1e-3, "the upper block fell into the lower"
    t_exact = np.array([row[0] for row in exact.meta.extra["impacts"] if row[1] == 1])
    t_sic = _zero_crossings(siconos.t, siconos.series("theta_rad", "upper"))
    assert t_exact[0] == pytest.approx(0.2705, abs=1e-3)
    assert t_sic[0] == pytest.approx(t_exact[0], rel=0.01)
    assert len(t_sic) >= 3
    np.testing.assert_allclose(t_sic[:3], t_exact[:3], rtol=0.01)
    for a, b in itertools.pairwise(t_exact[:3]):
        window = (exact.t > a) & (exact.t < b)
        peak_exact = np.abs(exact.series("theta_rad", "upper")[window]).max()
        peak_sic = np.abs(siconos.series("theta_rad", "upper")[window]).max()
        assert peak_sic == pytest.approx(peak_exact, rel=0.02)
    for result in (exact, siconos):
        assert 1e-5 < np.abs(result.series("theta_rad", "lower")).max() < 1e-3
