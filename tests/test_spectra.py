"""Response spectra exact at their peaks: against a fine-grid reference at every period."""

from __future__ import annotations

import numpy as np
import pytest

from rockyade.motion.spectra import response_spectrum

from .oscillator import fine_grid_psa


@pytest.mark.parametrize("damping", [0.0, 0.05])
@pytest.mark.slow
def test_spectrum_peaks_within_0p1_percent_of_a_fine_grid(damping):
    """Periods of 1.5-60 samples, where taking the peak at samples alone is up to 2 % low."""
    rng = np.random.default_rng(3)
    dt = 0.01
    accel = np.convolve(rng.standard_normal(300), np.ones(2) / 2, "same") * np.minimum(1, np.arange(300) / 50)
    periods = dt * np.geomspace(1.5, 40.0, 13)
    _, psa = response_spectrum(accel, dt, periods, damping)
    reference = np.array([fine_grid_psa(accel, dt, T, damping) for T in periods])
    np.testing.assert_allclose(psa, reference, rtol=1e-3)
    # a fine grid can only miss a peak: ours may not be lower than it by more than the
    # reference's round-off (its recurrence in transfer-function form: 2e-8, tests/oscillator.py)
    assert np.all(psa >= reference * (1 - 1e-7))
