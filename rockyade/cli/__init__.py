"""The ``rockyade`` command line.

Commands: ``params`` (classical parameters of a block), ``calibrate`` (DEM contact
parameters), ``run`` (a scene through a solver), ``tables`` (the paper's tables
reproduced); every command module registers its own (:data:`COMMAND_MODULES`).

Exit codes: 0 success, 1 a run failed, 2 bad input (the message names the field),
3 a solver that is not available here.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import Any

from rockyade import __version__
from rockyade.errors import (
    CalibrationError,
    InputError,
    RockyadeError,
    SolverFailedError,
    SolverUnavailableError,
)

#: Modules that add sub-commands, each through ``register(subparsers)``.
COMMAND_MODULES: list[str] = [
    "rockyade.cli.blocks",
    "rockyade.cli.run",
    "rockyade.cli.motion",
    "rockyade.cli.studies",
    "rockyade.cli.yade_script",
    "rockyade.cli.build",
    "rockyade.cli.identify",
    "rockyade.cli.uncertainty",
]



def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    import importlib

    parser = argparse.ArgumentParser(
        prog="rockyade",
        description="Seismic rocking of rigid blocks: classical (Housner) parameters, exact "
        "Housner solver, DEM calibration from the classical parameters, reference DEM and YADE.",
    )
    parser.add_argument("--version", action="version", version=f"rockyade {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module_name in COMMAND_MODULES:
        register: Callable[[Any], None] = importlib.import_module(module_name).register
        register(sub)
    return parser


def _coerce_scale(value: str) -> str | float:
    try:
        return float(value)
    except ValueError:
        return value


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rockyade`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if hasattr(args, "stiffness_scale") and isinstance(args.stiffness_scale, str):
        args.stiffness_scale = _coerce_scale(args.stiffness_scale)
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"rockyade: error: {exc}", file=sys.stderr)
        return 2
    except SolverUnavailableError as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 3
    except (CalibrationError, SolverFailedError) as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 1
    except RockyadeError as exc:
        print(f"rockyade: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
