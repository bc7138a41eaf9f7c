"""The overturning spectrum's scans in groups: the same rows (verdicts, statuses, where a scan
stops) as one run at a time, for Housner's full scan and the reference DEM's scan that stops
at the first overturn."""

from __future__ import annotations

import pytest

from rockyade.solvers.housner import HousnerSolver
from rockyade.solvers.reference import ReferenceSolver
from rockyade.studies import overturning
from rockyade.studies.specimen_scenes import block_table


@pytest.mark.parametrize(
    ("solver", "ratio_w", "full", "max_ratio"),
    [
        pytest.param(HousnerSolver(), 3.0, True, 4.0, id="housner-full"),
        pytest.param(ReferenceSolver(record_energy=False, record_contacts=False), 6.0, False, None, id="dem-stops"),
    ],
)
def test_grouped_scan_gives_the_rows_of_runs_one_at_a_time(solver, ratio_w, full, max_ratio):
    block = block_table("1")
    alpha, p = block["alpha_rad"], block["p_rad_s"]
    one = overturning._scan(overturning.Scan(solver, ratio_w, alpha, p, full, False, max_ratio))
    grouped = overturning._scan(overturning.Scan(solver, ratio_w, alpha, p, full, True, max_ratio))
    assert grouped == one
    assert any(row["overturned"] for row in one) and not all(row["overturned"] for row in one)
    if not full:  # it stops at the first overturn, past the first group of amplitudes
        assert one[-1]["overturned"] and sum(row["overturned"] for row in one) == 1
        assert len(one) > overturning.CHUNK
    else:
        assert [row["amplitude_ratio"] for row in one] == [round(a, 4) for a in overturning.amplitude_ratios(4.0)]
