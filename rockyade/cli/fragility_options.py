"""What ``rockyade fragility`` and ``rockyade assess`` share: the options of the runs (solver,
workers, records, collapse, sampling), the synthetic suite, the plan's printout and the tables."""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import TYPE_CHECKING

from rockyade.cli.common import SOLVER_NAMES, add_allow_large, add_yade_timeout, solvers_from_args
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: these are imported when a command runs
    from rockyade.assess import SyntheticSuite
    from rockyade.assess.fragility_analysis import FragilityPlan, FragilityResult
    from rockyade.assess.motions import MotionSet
    from rockyade.runner import Executor
    from rockyade.solvers.base import Solver

#: Records of a synthetic suite, and its seed, by default.
DEFAULT_COUNT = 20
DEFAULT_SEED = 1


def float_list(text: str, option: str) -> tuple[float, ...]:
    """``"0.1,0.2, 0.4"`` as numbers (InputError naming ``option``)."""
    try:
        values = tuple(float(v) for v in str(text).split(",") if v.strip())
    except ValueError:
        raise InputError(option, f"must be numbers separated by commas, got {text!r}") from None
    if not values:
        raise InputError(option, "needs at least one number")
    return values


def executor_from(args: argparse.Namespace) -> Executor:
    """The executor of ``--executor``, ``--workers`` and ``--scheduler`` (as ``batch``)."""
    from rockyade.cli.resumable import executor_from as from_args

    return from_args(args)


def solver_from(args: argparse.Namespace) -> Solver | None:
    """The ``--solver`` with ``--yade-timeout`` (None: the default for the scene)."""
    if args.solver is None:
        if args.yade_timeout is not None:
            raise InputError("--yade-timeout", "applies to --solver yade")
        return None
    [solver] = solvers_from_args([args.solver], args)
    return solver


def suite_from(args: argparse.Namespace) -> SyntheticSuite:
    """The synthetic suite of ``--suite`` (ec8: ``--spectrum-type``, ``--ground``, ``--ag``)."""
    from rockyade.assess import ec8_suite, paper_suite_set, parse_acceleration

    if args.suite == "paper":
        for option in ("spectrum_type", "ground", "ag"):
            if getattr(args, option) is not None:
                raise InputError("--" + option.replace("_", "-"), "applies to --suite ec8 (the paper's suite is fixed)")
        if args.seed is not None:
            raise InputError("--seed", "applies to --suite ec8 (the paper's suite has its own)")
        return paper_suite_set(30 if args.count is None else args.count)  # --count 0 is refused, not 30
    missing = [o for o in ("spectrum_type", "ground", "ag") if getattr(args, o) is None]
    if missing:
        flags = ", ".join("--" + o.replace("_", "-") for o in missing)
        raise InputError(
            missing[0].replace("_", "-"), f"--suite ec8 needs {flags} (e.g. --spectrum-type 1 --ground B --ag 0.25g)"
        )
    ag = parse_acceleration(args.ag, "--ag")
    return ec8_suite(args.spectrum_type, args.ground, ag, *count_and_seed(args))


def motions_from(args: argparse.Namespace) -> MotionSet:
    """The record set of ``--records DIR`` (with ``--units``) or ``--suite`` (its own options),
    each option refused where it does not apply."""
    from rockyade.assess import records_in_folder

    if args.records is not None:
        for option in ("spectrum_type", "ground", "ag"):
            if getattr(args, option) is not None:
                raise InputError("--" + option.replace("_", "-"), "applies to --suite ec8, not to --records")
        refuse_suite_options_with_records(args)
        return records_in_folder(args.records, args.units)
    if args.units is not None:
        raise InputError("--units", "applies to --records")
    return suite_from(args)


def count_and_seed(args: argparse.Namespace) -> tuple[int, int]:
    """``--count`` and ``--seed`` of a synthetic suite, or their defaults."""
    count = DEFAULT_COUNT if args.count is None else args.count
    return count, DEFAULT_SEED if args.seed is None else args.seed


def refuse_suite_options_with_records(args: argparse.Namespace) -> None:
    """``--count`` and ``--seed`` are a synthetic suite's: refused with ``--records``."""
    for option in ("count", "seed"):
        if getattr(args, option) is not None:
            raise InputError("--" + option, "applies to a synthetic suite, not to --records")


#: What argparse takes for a value, not an option, when it starts with "-": a negative number
#: however written (``-0.3,0.6`` for ``--levels``, ``-0.25g`` for ``--ag``), so that the option's
#: own check names it and its range rather than argparse's "expected one argument".
NEGATIVE_VALUE = r"-\.?\d"


def accept_negative_values(p: argparse.ArgumentParser, also: str = "") -> None:
    """Let ``p`` take values that start with a minus sign and a digit (:data:`NEGATIVE_VALUE`),
    and ``also`` (a regular expression of other such values, e.g. ``-x``)."""
    pattern = f"^(?:{NEGATIVE_VALUE}" + (f"|{also}" if also else "") + ")"
    p._negative_number_matcher = re.compile(pattern)  # argparse's own hook for values like "-1"


def add_record_source(p: argparse.ArgumentParser) -> None:
    """The record set of a study of many records: ``--records DIR`` or ``--suite``, with the EC8
    suite's ``--spectrum-type``, ``--ground`` and ``--ag``."""
    accept_negative_values(p)
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--records", type=Path, metavar="DIR", help="a folder of record files (.at2, .csv, .txt, .dat)")
    source.add_argument(
        "--suite",
        choices=("ec8", "paper"),
        help="a spectrum-compatible synthetic suite: ec8 (with --spectrum-type, --ground, --ag) or the paper's",
    )
    p.add_argument("--spectrum-type", type=int, help="EC8 spectrum type of --suite ec8: 1 or 2")
    p.add_argument("--ground", help="EC8 ground type of --suite ec8: A, B, C, D or E")
    p.add_argument("--ag", help="design ground acceleration of --suite ec8, with its unit: 0.25g or 2.45m/s2")


def add_run_options(p: argparse.ArgumentParser, count_help: str) -> None:
    """Options shared by ``fragility`` and ``assess``: solver, workers, records, collapse, sampling."""
    from rockyade.cli.resumable import add_executor_options

    p.add_argument(
        "--solver",
        choices=SOLVER_NAMES,
        help="housner, reference, yade, siconos or twoblock (default: housner for a single block, the reference "
        "DEM otherwise)",
    )
    add_yade_timeout(p)
    add_executor_options(p)
    p.add_argument("--count", type=int, help=count_help)
    p.add_argument("--seed", type=int, help=f"seed of the synthetic suite (default {DEFAULT_SEED})")
    p.add_argument("--units", help="units of record files that do not name theirs: g, m/s2, cm/s2 (default m/s2)")
    p.add_argument(
        "--fallen-blocks",
        type=int,
        default=1,
        metavar="N",
        help="a run of a scene of several blocks collapses when N blocks fell (rockyade.analysis.collapse; default 1)",
    )
    p.add_argument(
        "--sample-dt", type=float, default=0.01, metavar="S", help="output sampling of every run, s (default 0.01)"
    )
    p.add_argument("--tail", type=float, default=5.0, metavar="S", help="free motion after each record, s (default 5)")
    p.add_argument("--no-extend", action="store_true", help="run the levels as given, without adding any")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    add_allow_large(p)


def print_plan(plan: FragilityPlan, workers: int, indent: str = "") -> None:
    """The plan and its cost, before anything runs."""
    from rockyade.assess.report_lines import plan_lines

    for line in [*plan_lines(plan), plan.cost_line(workers)]:
        print(indent + line, flush=True)


def write_tables(out: Path, result: FragilityResult, prefix: str = "") -> list[str]:
    """``runs.csv``, ``stripes.csv`` and ``records.csv`` of a fragility result; their names."""
    from rockyade.io.atomic import atomic_open

    names = []
    for name, frame in (("runs", result.runs), ("stripes", result.stripes), ("records", result.plan.records)):
        path = out / f"{prefix}{name}.csv"
        with atomic_open(path) as fh:
            frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
        names.append(path.name)
    return names
