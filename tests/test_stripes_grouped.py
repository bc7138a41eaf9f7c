"""Stripes run in groups (rockyade.assess.stripes.run_stripe_job: a GroupSolver steps runs of
one block together, grouped by the one key of every study, rockyade.batch.running.job_key) give
the rows of the runs one at a time (run_stripe_task), for Housner and the reference DEM, on the
paper study's stripes (the load factors exactly as asked)."""

from __future__ import annotations

import pytest

from rockyade.assess.stripes import run_stripe_job, run_stripe_task
from rockyade.batch.running import job_key as stripe_group
from rockyade.studies import fragility_study


@pytest.mark.parametrize("solver", ["housner", "reference"])
def test_grouped_stripes_give_the_rows_of_single_runs(solver):
    plan = fragility_study.stripe_plan("2", solver, records=(1, 2))
    tasks = plan.tasks([0.3, 1.5])
    assert [t.load_factor for t in tasks] == [0.3, 0.3, 1.5, 1.5]  # exactly, not through an intensity
    assert len({stripe_group(t) for t in tasks}) == 1 and stripe_group(tasks[0]) is not None
    grouped = run_stripe_job(tuple(tasks))
    single = [run_stripe_task(t) for t in tasks]
    keys = ("run", "status", "collapsed", "n_fallen", "max_theta_over_alpha", "max_theta_over_own_alpha")
    assert [{k: r[k] for k in keys} for r in grouped] == [{k: r[k] for k in keys} for r in single]
    assert any(r["collapsed"] for r in grouped) and not all(r["collapsed"] for r in grouped)
