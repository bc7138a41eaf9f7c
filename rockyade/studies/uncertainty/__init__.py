"""Uncertainty propagation: a block whose alpha, p, mu are uncertain, under a suite of records.

Three rooms, one idea each (as :mod:`rockyade.batch`):

* :mod:`rockyade.studies.uncertainty.study_file`: the study file (its grammar and errors) and
  :class:`~rockyade.studies.uncertainty.study_file.UncertaintyStudy`;
* :mod:`rockyade.studies.uncertainty.sample_tasks`: the parameter samples (Latin hypercube),
  the runs' tasks and the intensity measures of their records;
* :mod:`rockyade.studies.uncertainty.propagation`: the runs in the study's folder and the
  report (probabilities with Wilson bands, fragility fits, the spread the parameters cause).

::

    from rockyade.studies.uncertainty import load_uncertainty_study, run_uncertainty

    result = run_uncertainty(load_uncertainty_study("examples/studies/uncertainty_specimen1.toml"), "reports/unc")
"""

from rockyade.studies.uncertainty.propagation import UncertaintyResult, run_uncertainty
from rockyade.studies.uncertainty.sample_tasks import build_tasks, draw_samples, record_measures, with_measures
from rockyade.studies.uncertainty.study_file import (
    UncertaintyStudy,
    load_uncertainty_study,
    uncertainty_study_from_dict,
)

__all__ = [
    "UncertaintyResult",
    "UncertaintyStudy",
    "build_tasks",
    "draw_samples",
    "load_uncertainty_study",
    "record_measures",
    "run_uncertainty",
    "uncertainty_study_from_dict",
    "with_measures",
]
