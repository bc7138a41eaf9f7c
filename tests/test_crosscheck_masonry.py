"""rockyade crosscheck on the paper's masonry beyond one block (issue 35, section 3): the
bi-block with its exact solver (``twoblock``) beside the reference DEM, on Dask's in-process
scheduler, and a costly solver run on the first records only (``--records-per-solver``).

The studies themselves (20 records, YADE and Siconos, the wall and the arch) are in
``benchmarks/crosscheck_suite.py``; their figures in docs/verification.md."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rockyade.analysis.crosscheck_statistics import BRACKETED

from .test_crosscheck import cli, write_records

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BIBLOCK = EXAMPLES / "biblock_geometry.toml"


def crosscheck_biblock(records: Path, out: Path, *options: str) -> int:
    """``rockyade crosscheck`` of the bi-block by twoblock and the reference DEM on ``records``."""
    return cli(
        "crosscheck",
        str(BIBLOCK),
        "--records",
        str(records),
        "--solvers",
        "twoblock,reference",
        "--out",
        str(out),
        "--quiet",
        *options,
    )


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    return write_records(tmp_path_factory.mktemp("records") / "records", count=3)


@pytest.fixture(scope="module")
def biblock(records, tmp_path_factory):
    """The bi-block, twoblock on three short records and the reference DEM on the first two,
    at dt x 1 and 0.5, on Dask's threaded scheduler (no cluster, no socket)."""
    out = tmp_path_factory.mktemp("bb") / "out"
    code = crosscheck_biblock(
        records,
        out,
        "--records-per-solver",
        "reference=2",
        "--levels",
        "0.3,0.6,1.2",
        "--resolution",
        "0.1",
        "--tail",
        "1",
        "--executor",
        "dask",
        "--workers",
        "2",
    )
    return code, out


@pytest.mark.slow
def test_the_bi_block_runs_with_its_exact_solver_on_dask(biblock):
    code, out = biblock
    assert code == 0
    ci = pd.read_csv(out / "collapse_intensities.csv")
    # twoblock on the three records, the reference DEM on the first two, at both steps
    counts = ci.groupby(["solver", "dt_factor"]).size().to_dict()
    assert counts == {("reference", 0.5): 2, ("reference", 1.0): 2, ("twoblock", 0.5): 3, ("twoblock", 1.0): 3}
    assert (ci.status == BRACKETED).all()
    runs = pd.read_csv(out / "runs.csv")
    assert set(runs.status) <= {"completed", "overturned"}
    # the exact solver's events are found to machine precision: halving its Runge-Kutta step
    # changes no verdict, so no collapse intensity
    two = ci[ci.solver == "twoblock"].pivot(index="record", columns="dt_factor", values="collapse_intensity")
    assert np.array_equal(two[1.0].to_numpy(), two[0.5].to_numpy())
    pairs = pd.read_csv(out / "pairs.csv")
    dt = pairs[(pairs.kind == "dt") & (pairs.solver_a == "twoblock")].iloc[0]
    assert dt.median_ratio == 1.0 and dt.same_verdict_runs == dt.compared_runs == 3 * 3
    # a pair is over the records both solvers ran: two, their scan runs 2 x 3 levels
    both = pairs[(pairs.kind == "solvers") & (pairs.dt_factor_a == 1.0)].iloc[0]
    assert (both.solver_a, both.solver_b, both.records, both.compared_runs) == ("twoblock", "reference", 2, 6)
    # two independent models of the same stack (the exact solution, the penalty DEM): on each
    # record their collapse intensities within one bisection bracket (10 %) of each other
    at1 = ci[ci.dt_factor == 1.0].pivot(index="record", columns="solver", values="collapse_intensity").dropna()
    ratio = at1.twoblock / at1.reference
    assert len(ratio) == 2 and ((ratio >= 1 / 1.1) & (ratio <= 1.1)).all(), ratio
    index = (out / "index.md").read_text()
    assert "reference on the first 2; a pair is over the records both ran" in index


@pytest.mark.parametrize("value", ["reference", "reference=0", "yade=2", "reference=2,reference=3", "reference=x"])
def test_records_per_solver_is_checked_before_anything_runs(value, records, tmp_path, capsys):
    code = crosscheck_biblock(records, tmp_path / "o", "--records-per-solver", value)
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--records-per-solver" in err[0], err
    assert not (tmp_path / "o").exists()


def test_a_partial_summary_leaves_unfinished_searches_out_of_the_ratios(records):
    """After Ctrl-C a search stopped between its scan and its bisection has a bracket (the scan's
    step) that is not its answer: the partial summary says it is unfinished and pairs only
    finished searches; the complete summary of the same runs would bracket it."""
    from rockyade.studies.crosscheck import Outcomes, summarise
    from rockyade.studies.crosscheck.reporting import UNFINISHED

    from .test_crosscheck import small_plan

    plan = small_plan(records, dt_factors=(1.0,))
    low, mid, high = plan.scan_si
    outcomes = Outcomes()
    row = {"status": "completed", "failure_reason": "", "run": "r"}
    for solver in ("housner", "reference"):
        for i in range(plan.motions.count):
            outcomes.add((solver, 1.0, i), low, row, False)
            outcomes.add((solver, 1.0, i), mid, row, True)
            outcomes.add((solver, 1.0, i), high, row, True)
    # housner's searches bisected to the resolution (10 %) between the two first levels
    level = low
    while level * 1.1 < mid:
        level *= 1.09
        for i in range(plan.motions.count):
            outcomes.add(("housner", 1.0, i), level, row, False)
    step = level
    for i in range(plan.motions.count):
        outcomes.add(("housner", 1.0, i), mid, row, True)
    assert mid / step <= 1.1 + 1e-12
    partial = summarise(plan, outcomes, partial=True)
    ci = partial.collapse.set_index(["solver", "record_index"])
    assert (ci.loc["reference", "status"] == UNFINISHED).all()
    assert ci.loc["reference", "collapse_intensity"].isna().all()
    assert (ci.loc["housner", "status"] == BRACKETED).all()
    pair = partial.pairs[partial.pairs.kind == "solvers"].iloc[0]
    assert pair.records == 0  # no ratio from a bracket the search had not narrowed
    complete = summarise(plan, outcomes, partial=False)
    assert (complete.collapse.status == BRACKETED).all()
