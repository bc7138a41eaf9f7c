"""The one lognormal fragility fit (rockyade.probability.fragility_curves.fit_lognormal): a known
curve recovered, the answers without a finite maximum, the analytic derivatives against
finite differences, and a warm start that finds the same maximum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from rockyade.errors import InputError
from rockyade.probability.fragility_curves import fit_lognormal, nll_and_derivatives


def test_fragility_fit_recovers_a_known_curve():
    im = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0])
    n = np.full(im.size, 100_000)
    k = np.round(n * stats.norm.cdf(np.log(im / 2.0) / 0.4))
    fit = fit_lognormal(im, k, n)
    assert fit.status == "fitted"
    assert fit.median == pytest.approx(2.0, rel=2e-3) and fit.beta == pytest.approx(0.4, rel=5e-3)
    assert fit.probability([2.0])[0] == pytest.approx(0.5, abs=1e-3)


def test_fragility_fit_on_stripes_drawn_from_a_known_lognormal():
    """Binomial draws of a known curve, 2000 records a stripe: the maximum-likelihood estimate
    is within a few standard errors (about 1 % here) of the truth."""
    rng = np.random.default_rng(2024)
    im = np.geomspace(0.3, 4.0, 12)
    n = np.full(im.size, 2000)
    for median, beta in ((1.1, 0.3), (1.6, 0.6), (0.8, 1.0)):
        k = rng.binomial(n, stats.norm.cdf(np.log(im / median) / beta))
        fit = fit_lognormal(im, k, n)
        assert fit.status == "fitted"
        assert fit.median == pytest.approx(median, rel=0.03)
        assert fit.beta == pytest.approx(beta, rel=0.05)


def test_fragility_fit_on_sampled_outcomes():
    rng = np.random.default_rng(4)
    im = np.linspace(0.2, 3.0, 15)
    n = np.full(im.size, 30)
    k = rng.binomial(30, stats.norm.cdf(np.log(im / 1.2) / 0.35))
    fit = fit_lognormal(im, k, n)
    assert fit.median == pytest.approx(1.2, rel=0.15) and fit.beta == pytest.approx(0.35, rel=0.4)


def test_without_a_finite_maximum_the_fit_says_why():
    no = fit_lognormal([1, 2], [0, 0], [30, 30])
    assert no.status == "no collapse" and no.median == math.inf and math.isnan(no.beta)
    assert list(no.probability([0.5, 10.0])) == [0.0, 0.0]
    every = fit_lognormal([1, 2], [30, 30], [30, 30])
    assert every.status == "all collapse" and every.median == 0.0
    assert list(every.probability([0.5, 10.0])) == [1.0, 1.0]
    # stripes perfectly separated (survivors all below the collapses): a threshold, no slope;
    # the median the geometric mean of the highest survivor and the lowest collapse
    apart = fit_lognormal([1.0, 2.0, 4.0, 8.0], [0, 0, 10, 10], [10, 10, 10, 10])
    assert apart.status == "separated" and apart.median == pytest.approx(math.sqrt(8.0)) and math.isnan(apart.beta)
    # quasi-complete: a stripe with both survivors and collapses, none collapsing below it
    # and none surviving above it: still no finite maximum
    touching = fit_lognormal([1.0, 2.0, 4.0], [0, 3, 10], [10, 10, 10])
    assert touching.status == "separated" and touching.median == pytest.approx(2.0)
    assert list(touching.probability([1.9, 2.1])) == [0.0, 1.0]


def test_collapses_that_do_not_grow_with_the_intensity_are_no_trend():
    fit = fit_lognormal([1.0, 2.0, 3.0, 4.0], [3, 1, 1, 0], [10, 10, 10, 10])
    assert fit.status == "no trend" and math.isnan(fit.median) and math.isnan(fit.beta)
    assert fit.fraction == pytest.approx(5 / 40)


def test_bad_stripes_are_refused():
    with pytest.raises(InputError):
        fit_lognormal([1, 2], [31, 0], [30, 30])
    with pytest.raises(InputError):
        fit_lognormal([-1, 2], [1, 2], [30, 30])
    with pytest.raises(InputError):
        fit_lognormal([1.0], [1], [2])


@pytest.mark.parametrize("params", [(0.3, math.log(0.4)), (-1.0, math.log(0.05)), (2.5, math.log(3.0))])
def test_the_gradient_and_hessian_are_those_of_the_likelihood(params):
    """Central differences of the value (gradient) and of the analytic gradient (Hessian),
    including far tails (beta = 0.05: z up to about 60, where log Phi keeps them finite)."""
    logx = np.log(np.array([0.3, 0.7, 1.0, 1.8, 3.5, 6.0]))
    k = np.array([0.0, 2.0, 5.0, 7.0, 9.0, 10.0])
    n = np.full(k.size, 10.0)
    p = np.array(params)
    value, grad, hess = nll_and_derivatives(p, logx, k, n)
    assert math.isfinite(value)
    h = 1e-6
    for j in range(2):
        e = np.zeros(2)
        e[j] = h
        up, down = nll_and_derivatives(p + e, logx, k, n), nll_and_derivatives(p - e, logx, k, n)
        assert grad[j] == pytest.approx((up[0] - down[0]) / (2 * h), rel=1e-5, abs=1e-6)
        assert hess[:, j] == pytest.approx((up[1] - down[1]) / (2 * h), rel=1e-5, abs=1e-5)


def test_a_warm_start_finds_the_same_maximum():
    rng = np.random.default_rng(7)
    x = np.geomspace(0.5, 6.0, 8)
    fitted = 0
    for _ in range(20):
        median, beta = rng.uniform(1.0, 3.0), rng.uniform(0.2, 0.7)
        n = np.full(x.size, 15.0)
        k = rng.binomial(15, stats.norm.cdf(np.log(x / median) / beta)).astype(float)
        full = fit_lognormal(x, k, n)
        for start in ((2.0, 0.5), (30.0, 5.0), (0.1, 0.01)):  # near, and far on either side
            warm = fit_lognormal(x, k, n, start=start)
            assert warm.status == full.status
            if full.status == "fitted":
                assert warm.median == pytest.approx(full.median, rel=1e-7)
                assert warm.beta == pytest.approx(full.beta, rel=1e-7)
        fitted += full.status == "fitted"
    assert fitted >= 10  # most draws give a curve: the comparison above is not empty
