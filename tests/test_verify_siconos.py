"""``rockyade verify --only siconos``: Siconos's rows run with Debian's Siconos and pass. Skipped
only where python3-siconos is absent; ``ROCKYADE_REQUIRE_SICONOS=1`` (``make test``) turns that
into a failure."""

from __future__ import annotations

import pytest

from rockyade.studies.verification import verify
from rockyade.studies.verify_siconos import SICONOS_PUSHOVERS

pytestmark = [pytest.mark.slow, pytest.mark.usefixtures("siconos_present")]


def test_siconos_rows_pass_against_closed_forms(tmp_path):
    """Free-rocking restitution (Housner Eq 4), the pushover onsets against the limit analysis,
    the rocking frame against Housner's column with p_hat, a stack at rest: every row passes."""
    table = verify(tmp_path, ["siconos"], ["reference"])
    assert set(table["check"]) == {"siconos"} and set(table["solver"]) == {"siconos"}
    assert table["passed"].all(), table[~table["passed"]].to_string()
    quantity = list(table["quantity"])
    assert len(quantity) == 1 + len(SICONOS_PUSHOVERS) + 2 + 2
    expected = dict(zip(quantity, table["expected"], strict=True))
    assert expected["block: pushover onset (first held level it did not stand)"] == pytest.approx(0.2, rel=1e-9)
    assert {"frame: first impact time (s)", "frame: first peak (rad)"} <= set(quantity)
    onsets = table[table["quantity"].str.contains("pushover onset")]
    ratio = onsets["value"] / onsets["expected"]
    assert ((ratio >= 1.0 - 1e-5) & (ratio <= 1.02)).all(), onsets.to_string()
