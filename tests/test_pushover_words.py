"""A pushover's onset in words and in JSON: a percentage only where two held levels bracket
the onset (issue 26 item 5): a panel that fell at the first level reads "below λ = ...", one that
stood at every level "held at every level up to λ = ...", never NaN."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rockyade.analysis.capacity import Onset
from rockyade.assess.pushover import PushoverCheck, pushover_motion


def check(multiplier: float, below: float) -> PushoverCheck:
    motion, _ = pushover_motion(0.5, "+x")
    onset = Onset(multiplier, below, 1.0, "rule")
    return PushoverCheck(0.5, onset, "+x", "b", np.zeros(2), np.zeros(2), motion)


@pytest.mark.parametrize(
    ("multiplier", "below", "bound", "says", "pct"),
    [
        (0.505, 0.5, "measured", "onset λ = 0.505 (stood at 0.5) against alpha0 = 0.5000: +1.00 %", 1.0),
        (0.49, math.nan, "below", "onset below λ = 0.49, the first held level (0.98 alpha0)", None),
        (math.nan, 0.52, "above", "held at every level up to λ = 0.52 (1.04 alpha0)", None),
        (math.nan, math.nan, "none", "no onset measured", None),
    ],
)
def test_onset_words_give_a_percentage_only_when_bracketed(multiplier, below, bound, says, pct):
    p = check(multiplier, below)
    words = p.onset_words()
    assert p.bound == bound
    assert says in words
    assert "nan" not in words.lower()
    if pct is None:
        assert "%" not in words
    data = p.to_dict()
    assert data["pushover_onset_bound"] == bound
    if pct is None:
        assert data["pushover_onset_minus_alpha0_pct"] is None
    else:
        assert data["pushover_onset_minus_alpha0_pct"] == pytest.approx(pct)


def test_the_figure_label_of_an_unbracketed_onset_has_no_nan():
    from rockyade.figures.wall_assessment import _onset_label

    assert _onset_label(check(0.49, math.nan)) == "onset below λ 0.49 (the first level)"
    assert "nan" not in _onset_label(check(math.nan, 0.52))
