"""The content of ``rockyade assess --report``: a page an engineer can attach to a report.

:func:`report_page` builds it from the data ``assess.json`` is written from
(:meth:`rockyade.assess.assessment.Assessment.to_dict`, with ``scene``) and the run's provenance
(:class:`Provenance`): nothing here computes a number of the check, every number shown is one of
that data's, kept beside its text (:class:`Cell`: its JSON key and value) so that a reader or a
test can compare the two. The page holds, in this order:

* the verdict, the code's capacity in ag and the site's ag;
* the inputs and their sources: the scene file and its SHA-256, every option given, rockyade's
  defaults named as defaults, the loads and whether their mass takes part;
* the site's spectrum and its parameters (a figure: the elastic spectrum at 5 % and at the
  nonlinear check's damping, and at height the floor's spectrum);
* the mechanism drawn on the wall with its hinges (a figure) and the kinematic quantities;
* every check with its clause, formula, numbers and verdict (and the figure of the capacity
  curve against the demand);
* the checks not made, with the reason, and the notes;
* the dynamic part when it ran (the fragility figure, the counts at the code's demand, the
  median and its ratio to the code's capacity; the record selection when the records are one);
* the version of rockyade and of what it ran, and the date.

The writers (:mod:`rockyade.assess.report_render`: HTML and Markdown) turn it into text;
:mod:`rockyade.studies.assess_report` draws the figures it names and writes the set.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rockyade.assess.report_model import FigureRef, Provenance, ReportPage, fmt
from rockyade.assess.report_sections import (
    check_section,
    dynamic_section,
    inputs_section,
    mechanism_section,
    not_made_section,
    site_section,
    verdict_section,
    version_section,
)


def report_page(data: Mapping[str, Any], provenance: Provenance) -> ReportPage:
    """The page of an assessment (module docstring).

    Parameters
    ----------
    data
        What ``assess.json`` holds (:meth:`rockyade.assess.assessment.Assessment.to_dict` and ``scene``).
    provenance
        The inputs' sources and the versions.
    """
    sections = (
        verdict_section(data),
        inputs_section(data, provenance),
        site_section(data),
        mechanism_section(data),
        check_section(data),
        not_made_section(data),
        dynamic_section(data),
        version_section(provenance),
    )
    figures = tuple(b for s in sections for b in s.blocks if isinstance(b, FigureRef))
    verdict = str(data.get("verdict", ""))
    shown = "VERIFIED" if verdict == "verified" else verdict.upper()
    summary = shown
    cap, ag = data.get("code_capacity_ag_g"), (data.get("site") or {}).get("ag_g")
    if isinstance(cap, (int, float)) and isinstance(ag, (int, float)):
        summary += f": the code's capacity is ag = {fmt(cap)} g, the site's ag is {fmt(ag)} g"
    return ReportPage(f"Assessment of {provenance.scene}: {shown}", verdict, sections, figures, summary)


__all__ = ["report_page"]
