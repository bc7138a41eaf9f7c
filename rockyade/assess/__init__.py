"""A verdict on a wall: collapse fragility of any scene, and the code's kinematic checks beside
the rocking dynamics.

``site`` (the site's EC8 spectrum; a mechanism at ground level or at a height of a
building), ``code`` (the kinematic checks of NTC 2018, Circolare 2019 C8.7.1, on the
quantities of :mod:`rockyade.limit`), ``measures`` (PGA, PGV, Sa(T), the site's ag),
``motions`` (record files, synthetic suites), ``stripes`` (every record scaled to each
level, run through :mod:`rockyade.runner`, collapse per run), ``stripe_fit`` (the lognormal fit of
:mod:`rockyade.probability.fragility_curves` and its bootstrap band), ``fragility_analysis`` (a fragility
analysis of any scene), ``assessment`` (the code's checks and the dynamics beside them) and
``report_lines`` (text). Figures: :mod:`rockyade.figures.wall_assessment`. See docs/limit.md and
docs/howto/is-this-wall-safe.md.

Layer: above analysis, probability and runner (it runs solvers through the runner and fits
curves), below figures and studies.
"""

from rockyade.assess.assessment import Assessment, DynamicSettings, assess
from rockyade.assess.code import CODES, Check, code_checks
from rockyade.assess.fragility_analysis import (
    FragilityPlan,
    FragilityResult,
    SceneCannotStandError,
    fragility_plan,
    run_fragility,
)
from rockyade.assess.measures import Measure, parse_measure
from rockyade.assess.motions import RecordFiles, SyntheticSuite, ec8_suite, paper_suite_set, records_in_folder
from rockyade.assess.site import Position, Site, parse_acceleration

__all__ = [
    "CODES",
    "Assessment",
    "Check",
    "DynamicSettings",
    "FragilityPlan",
    "FragilityResult",
    "Measure",
    "Position",
    "RecordFiles",
    "SceneCannotStandError",
    "Site",
    "SyntheticSuite",
    "assess",
    "code_checks",
    "ec8_suite",
    "fragility_plan",
    "paper_suite_set",
    "parse_acceleration",
    "parse_measure",
    "records_in_folder",
    "run_fragility",
]
