"""``rockyade verify``'s rows: the tolerance is held once (rockyade.studies.verify_rows), and a
row's pass or fail and the report's text both come from it."""

from __future__ import annotations

import math

import pandas as pd
import pytest

from rockyade.studies.verification import verify
from rockyade.studies.verify_rows import EXACT, Row, Tolerance, absolute, at_least, at_most, relative


@pytest.mark.parametrize(
    ("tolerance", "expected", "inside", "outside"),
    [
        # values exact in binary: the boundary itself passes, the next step beyond it fails
        (relative(0.25), 4.0, [5.0, 3.0, 4.0], [5.0 + 1e-12, 3.0 - 1e-12, -4.0]),
        (absolute(0.5, "m"), 1.0, [1.5, 0.5, 1.0], [1.5 + 1e-12, 0.5 - 1e-12]),
        (at_most(0.5), 1.0, [1.5, 1.0, -100.0], [1.5 + 1e-12]),
        (at_most(), 1.0, [1.0, 0.0], [1.0 + 1e-12]),
        (at_least(0.5), 1.0, [0.5, 1.0, 100.0], [0.5 - 1e-12]),
        (at_least(), 1.0, [1.0, 2.0], [1.0 - 1e-12]),
        (EXACT, 0.0, [0.0], [1e-300, -1e-300, 1.0]),
    ],
)
def test_tolerance_passes_up_to_its_boundary(tolerance, expected, inside, outside):
    for value in inside:
        assert tolerance.passes(expected, value), (tolerance, value)
    for value in [*outside, math.nan]:
        assert not tolerance.passes(expected, value), (tolerance, value)


def test_relative_tolerance_of_a_zero_expected_value_never_passes():
    """|a - 0| / |0| is infinite: a relative tolerance needs an expected value that is not 0."""
    assert not relative(0.5).passes(0.0, 0.0)
    assert not relative(0.5).passes(0.0, 1e-300)


@pytest.mark.parametrize(
    ("tolerance", "text"),
    [
        (relative(0.02), "2 %"),
        (relative(0.005), "0.5 %"),
        (relative(0.12), "12 %"),
        (relative(0.0289345), "2.89 %"),
        (relative(1e-9), "1e-9 relative"),
        (relative(1e-12), "1e-12 relative"),
        (absolute(1e-3, "rad"), "0.001 rad"),
        (absolute(2e-4), "0.0002"),
        (EXACT, "exact"),
        (at_most(1e-3, "m"), "<= expected + 0.001 m"),
        (at_most(1e-6), "<= expected + 1e-6"),
        (at_least(), ">= expected"),
        (at_least(0.1), ">= expected - 0.1"),
    ],
)
def test_tolerance_text(tolerance, text):
    assert tolerance.text() == text


@pytest.mark.parametrize(("kind", "value"), [("within", 0.1), ("relative", -0.1), ("absolute", math.inf)])
def test_a_bad_tolerance_is_refused(kind, value):
    with pytest.raises(ValueError, match=r"kind|value"):
        Tolerance(kind, value)


def test_a_row_passes_by_its_own_tolerance_and_writes_its_text():
    tol = relative(0.02)
    ok = Row("c", "s", "q (m)", 1.02, 1.0 + 2**-40, "from", tol)
    bad = Row("c", "s", "q (m)", 1.03, 1.0, "from", tol)
    assert ok.passed and not bad.passed
    assert ok.as_dict()["tolerance"] == "2 %" and ok.as_dict()["passed"] is True
    assert bad.difference == pytest.approx(0.03)


def test_every_closed_form_row_passes_its_own_tolerance(tmp_path):
    """The checks that run no solver: each CSV row's pass and tolerance text are its Tolerance's."""
    table = verify(tmp_path, ["code", "fragility_fit", "loaded_block", "loaded_mass"], ["reference"])
    assert len(table) == 9 + 4 + 2 + 3  # code: both forms of the nonlinear check
    assert table["passed"].all(), table[~table["passed"]].to_string()
    csv = pd.read_csv(tmp_path / "verify.csv")
    assert list(csv["tolerance"]) == list(table["tolerance"])
    assert {"1e-12 relative", "1e-6 relative", "exact", ">= expected - 0.1", "5 %", "12 %"} <= set(csv["tolerance"])
