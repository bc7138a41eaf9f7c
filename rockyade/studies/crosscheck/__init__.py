"""``rockyade crosscheck``: several solvers on one scene over a record set, compared by their
collapse intensities (the statistics: :mod:`rockyade.analysis.crosscheck_statistics`; the method
and what was measured: docs/verification.md).

Three rooms, one idea each, each importing only those before it:

* :mod:`rockyade.studies.crosscheck.plan`: what a cross-check runs, its checks and its cost
  before anything runs, and what its searches found so far (:class:`~rockyade.studies.crosscheck.plan.Outcomes`);
* :mod:`rockyade.studies.crosscheck.reporting`: the summary of the outcomes (collapse
  intensities, paired ratios and their intervals, the convergence in the time step, the
  fragility per solver), ``index.md`` and the set's files;
* :mod:`rockyade.studies.crosscheck.search`: the searches run round by round in the study's
  folder, resumed, stopped by Ctrl-C, the set swapped in.

::

    from rockyade.studies.crosscheck import crosscheck_plan, run_crosscheck
"""

from rockyade.runner.study_folder import CROSSCHECK
from rockyade.studies.crosscheck.plan import (
    DT_FACTORS,
    ROUND_OVERHEAD_S,
    CrosscheckPlan,
    Outcomes,
    check_dt_factors,
    classical_static,
    crosscheck_plan,
    parse_solvers,
)
from rockyade.studies.crosscheck.reporting import Summary, summarise, write_summary
from rockyade.studies.crosscheck.search import Study, check_out, journal_dir, run_crosscheck

#: The files of a complete set.
RESULT_FILES = CROSSCHECK.names

__all__ = [
    "DT_FACTORS",
    "RESULT_FILES",
    "ROUND_OVERHEAD_S",
    "CrosscheckPlan",
    "Outcomes",
    "Study",
    "Summary",
    "check_dt_factors",
    "check_out",
    "classical_static",
    "crosscheck_plan",
    "journal_dir",
    "parse_solvers",
    "run_crosscheck",
    "summarise",
    "write_summary",
]
