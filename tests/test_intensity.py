"""Intensity measures (PGV, Arias, significant duration, rocking-dimensionless) and fragility fits
against them; binomial confidence intervals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion
from rockyade.motion.intensity import (
    INTENSITY_MEASURES,
    check_measure,
    intensity_measures,
    scaled,
    significant_duration,
)
from rockyade.probability.fragility_curves import (
    clopper_pearson_interval,
    fit_lognormal,
    fit_lognormal_points,
    wilson_interval,
)


def _sine(amplitude: float, frequency: float, cycles: int, dt: float = 1e-4) -> GroundMotion:
    t = np.arange(0.0, cycles / frequency + 0.5 * dt, dt)
    return GroundMotion(t, amplitude * np.sin(2 * math.pi * frequency * t))


def test_sine_closed_forms():
    """a = A sin(w t) over whole cycles: PGV = 2 A / w, I_A = pi A^2 T / (4 g), PGA = A."""
    a, f, n = 3.0, 2.0, 5
    w = 2 * math.pi * f
    im = intensity_measures(_sine(a, f, n), alpha_rad=0.2, p_rad_s=3.0)
    assert im["pga_m_s2"] == pytest.approx(a, rel=1e-6)
    assert im["pgv_m_s"] == pytest.approx(2 * a / w, rel=1e-6)
    assert im["pgv_over_pga_s"] == pytest.approx(2 / w, rel=1e-6)
    assert im["arias_m_s"] == pytest.approx(math.pi / (2 * G) * a * a * (n / f) / 2, rel=1e-6)
    assert im["pga_over_g_tan_alpha"] == pytest.approx(a / (G * math.tan(0.2)), rel=1e-6)
    assert im["pgv_p_over_g_tan_alpha"] == pytest.approx(2 * a / w * 3.0 / (G * math.tan(0.2)), rel=1e-6)
    assert set(im) == set(INTENSITY_MEASURES)


def test_significant_duration_of_a_steady_motion_is_ninety_percent():
    """Constant |a| (Arias grows linearly): D_5-95 = 0.9 T (Trifunac & Brady 1975)."""
    t = np.linspace(0.0, 10.0, 10001)
    a = np.where(np.arange(t.size) % 2 == 0, 1.5, -1.5)
    motion = GroundMotion(t, a)
    # between two samples of opposite sign a^2 is not constant, but every interval is alike
    assert significant_duration(motion) == pytest.approx(9.0, abs=2e-3)
    # a burst between 2 and 4 s in a quiet record: its 5-95 % window lies inside the burst
    burst = GroundMotion(t, np.where((t >= 2) & (t <= 4), np.sin(40 * t), 0.0))
    assert 1.6 < significant_duration(burst) < 1.9


def test_scaling_with_load_factor_matches_a_scaled_motion():
    rng = np.random.default_rng(4)
    t = np.arange(0, 8, 0.01)
    acc = rng.standard_normal(t.size) * np.exp(-0.3 * t)
    base = intensity_measures(GroundMotion(t, acc), 0.15, 4.0)
    direct = intensity_measures(GroundMotion(t, 1.7 * acc), 0.15, 4.0)
    for k, v in scaled(base, 1.7).items():
        assert v == pytest.approx(direct[k], rel=1e-10), k


def test_block_measures_need_the_block():
    im = intensity_measures(_sine(1.0, 1.0, 1, 1e-3))
    assert math.isnan(im["pga_over_g_tan_alpha"]) and math.isnan(im["pgv_p_over_g_tan_alpha"])
    with pytest.raises(InputError, match="intensity_measure"):
        check_measure("pgd_m")


def test_fragility_from_individual_runs_recovers_median_and_beta():
    rng = np.random.default_rng(11)
    x = np.exp(rng.normal(0.0, 0.8, 3000))
    collapsed = rng.random(x.size) < stats.norm.cdf(np.log(x / 1.3) / 0.5)
    fit = fit_lognormal_points(x, collapsed)
    assert fit.median == pytest.approx(1.3, rel=0.05)
    assert fit.beta == pytest.approx(0.5, rel=0.1)
    # runs at equal intensity: the same fit as the grouped stripes
    im = np.repeat([0.5, 1.0, 2.0], 10)
    c = np.array([0] * 9 + [1] + [0] * 5 + [1] * 5 + [0] * 1 + [1] * 9, dtype=bool)
    grouped = fit_lognormal([0.5, 1.0, 2.0], [1, 5, 9], [10, 10, 10])
    points = fit_lognormal_points(im, c)
    assert points.median == pytest.approx(grouped.median, rel=1e-9)
    assert points.beta == pytest.approx(grouped.beta, rel=1e-9)
    assert fit_lognormal_points(im, np.zeros_like(c)).status == "no collapse"
    # collapses only at the top level, none below: a threshold, not a curve
    step = fit_lognormal([0.5, 1.0, 2.0], [0, 0, 3], [10, 10, 10])
    assert step.status == "separated" and step.median == 2.0 and math.isnan(step.beta)
    assert list(step.probability([1.5, 2.5])) == [0.0, 1.0]


def test_binomial_intervals():
    lo, hi = wilson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(0.2775, abs=1e-4)
    lo, hi = wilson_interval(5, 10)
    assert (lo, hi) == pytest.approx((0.2366, 0.7634), abs=1e-4)
    lo, hi = clopper_pearson_interval(0, 10)
    assert lo == 0.0 and hi == pytest.approx(1 - 0.025 ** (1 / 10), rel=1e-9)
    lo, hi = clopper_pearson_interval(10, 10)
    assert hi == 1.0 and lo == pytest.approx(0.025 ** (1 / 10), rel=1e-9)
    with pytest.raises(InputError):
        wilson_interval(3, 2)


def test_fragility_of_collapses_that_do_not_grow_with_the_intensity_is_no_trend():
    """One collapse at the lowest stripe and none above: the likelihood's maximum runs off to
    beta -> infinity and a median far beyond the data (exp overflowed in the fit). Said as
    'no trend', with the overall fraction as the probability."""
    fit = fit_lognormal([1.0, 2.0, 3.0, 4.0], [1, 0, 0, 1], [10, 10, 10, 10])
    assert fit.status == "no trend" and math.isnan(fit.median) and math.isnan(fit.beta)
    assert fit.probability([0.5, 5.0]) == pytest.approx([0.05, 0.05])
    rising = fit_lognormal([1.0, 2.0, 3.0, 4.0], [0, 2, 5, 9], [10, 10, 10, 10])
    assert rising.status == "fitted" and 2.0 < rising.median < 4.0
