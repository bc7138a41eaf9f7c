"""The options of an ``rockyade assess`` run as its report shows them: every option given, with
its value, and rockyade's defaults that the run took, each named as a default with what it means
(:mod:`rockyade.studies.assess_report`)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

#: What a default means where the option's own default is None (the code takes a value or a rule).
MEANINGS: dict[str, tuple[str, str]] = {
    "code_form": (
        "circolare2019",
        "Circolare 2019 C8.7.1.2.1 (the nonlinear check at T_SLV with the mechanism's damping)",
    ),
    "mechanism_damping_pct": (
        "8",
        "% of critical, the mechanism's damping in the nonlinear check (Circolare 2019 C8.7.1.2.1.8, SLV)",
    ),
    "friction_rule": (
        "associated, with a coulomb pass",
        "where the mechanism slides with friction the code's quantities take the lower of the two multipliers",
    ),
    "friction_angle_deg": ("the scene's", "each joint's friction angle as the scene gives it"),
    "fm": ("none", "rigid blocks: each hinge at the edge of its joint (no crushing)"),
    "spectrum": ("ntc2018", "NTC 2018 3.2.3.2.1 (EC8's when its options are given)"),
    "topography": ("T1", "ST = 1 (NTC 2018 Tab. 3.2.V)"),
    "topography_height_ratio": ("1", "at the top of the relief"),
    "importance": ("1", "gamma_I (EN 1998-1 4.2.5)"),
    "t1": ("Ct H^(3/4)", "Ct = 0.05 (EN 1998-1 Eq 4.6)"),
    "building_damping_pct": ("5", "% of critical, the building's damping xi1 of the floor spectrum"),
    "mechanism_period": ("0", "s: rigid until it moves; the demand is the floor's peak acceleration"),
    "records": ("a synthetic suite", "compatible with the site's EC8 spectrum"),
    "solver": ("housner for one block, the reference DEM otherwise", ""),
    "count": ("20", "records of the synthetic suite"),
    "seed": ("1", "seed of the synthetic suite"),
    "load_factors": ("0.35, 0.5, 0.71, 1, 1.41, 2, 2.83", "on the site's scaling (1: the code's demand)"),
}
#: Options whose defaults say nothing of the answer (where and how it runs, what is printed).
NOT_SHOWN = {
    "help",
    "json",
    "out",
    "report",
    "quiet",
    "resume",
    "executor",
    "scheduler",
    "scheduler_timeout",
    "workers",
}
#: The dynamic part's options (not shown as defaults with --static-only).
DYNAMIC = {
    "records",
    "solver",
    "load_factors",
    "count",
    "seed",
    "units",
    "yade_timeout",
    "no_extend",
    "fallen_blocks",
    "sample_dt",
    "tail",
    "allow_large",
}
#: A mechanism at height's options (not shown as defaults at ground level).
HEIGHT = {"z", "building_height", "storeys", "t1", "building_damping_pct", "mechanism_period"}
#: The NTC 2018 site's options and the EC8 site's (each shown with its own site only).
NTC = {"f0", "tc_star", "soil", "topography", "topography_height_ratio"}
EC8 = {"spectrum_type", "ground", "importance"}


def _actions(parser: argparse.ArgumentParser | None) -> list[argparse.Action]:
    if parser is None:
        return []
    return [a for a in parser._actions if a.option_strings and a.dest not in ("help",)]


def _shown(value: Any) -> str:
    if value is True:
        return ""
    if isinstance(value, Path):
        return str(value)
    return str(value)


def options_given(args: argparse.Namespace, parser: argparse.ArgumentParser | None) -> list[tuple[str, str]]:
    """(option, value) of every option given, in the parser's order (a flag's value is empty); the
    value as rockyade read it. An option given with its default's value reads as a default."""
    out = []
    for action in _actions(parser):
        value = getattr(args, action.dest, None)
        if value is None or value is False or value == action.default:
            continue
        out.append((action.option_strings[0], _shown(value)))
    return out


def options_defaulted(
    args: argparse.Namespace, parser: argparse.ArgumentParser | None, result: Any
) -> list[tuple[str, str, str]]:
    """(option, default, what it means) of the options not given that bear on this run's answer."""
    at_height = result.position.at_height
    ntc = result.site.spectrum_code == "ntc2018"
    out = []
    for action in _actions(parser):
        dest = action.dest
        value = getattr(args, dest, None)
        if dest in NOT_SHOWN or (value is not None and value is not False and value != action.default):
            continue
        if (dest in DYNAMIC and result.dynamic is None) or (dest in HEIGHT and not at_height):
            continue
        if (dest in NTC and not ntc) or (dest in EC8 and ntc):
            continue
        if dest in MEANINGS:
            default, meaning = MEANINGS[dest]
        elif action.default not in (None, False):
            default, meaning = str(action.default), ""
        else:
            continue
        if dest == "mechanism_damping_pct" and result.position.method == "circolare2009":
            continue
        out.append((action.option_strings[0], default, f"rockyade's default{': ' + meaning if meaning else ''}"))
    return out


__all__ = ["MEANINGS", "options_defaulted", "options_given"]
