"""The ``rockyade`` command line.

Commands: ``params`` (classical parameters of a block), ``calibrate`` (DEM contact
parameters), ``run`` (a scene through a solver), ``tables`` (the paper's tables
reproduced); every command module registers its own (:data:`COMMAND_MODULES`).

Exit codes: 0 success, 1 a run failed (or a file could not be written), 2 bad input (the
message names the field or option), 3 a solver that is not available here, 130 stopped by
Ctrl-C, 141 the output pipe was closed (e.g. ``rockyade tables | head -1``).

A mistyped option or command name is answered with the usage of the command it was given
to and the nearest name ("did you mean --out?"), exit 2 (:class:`CommandParser`).

Building the parser imports no solver, numpy, scipy, numba, pandas or matplotlib: command
modules import them inside their command functions, so ``rockyade --help`` answers at once.
"""

from __future__ import annotations

import argparse
import contextlib
import difflib
import os
import re
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from rockyade import __version__
from rockyade.errors import (
    BatchInterruptedError,
    CalibrationError,
    InputError,
    RockyadeError,
    SolverFailedError,
    SolverUnavailableError,
    os_error_message,
)

if TYPE_CHECKING:
    from rockyade.cli.common import Commands

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
    "rockyade.cli.verify",
    "rockyade.cli.limit",
    "rockyade.cli.fragility",
    "rockyade.cli.crosscheck",
    "rockyade.cli.assess",
    "rockyade.cli.examples",
]

_T0 = time.perf_counter()  # the total wall time printed by ``rockyade run`` counts from here

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_UNAVAILABLE = 0, 1, 2, 3
EXIT_INTERRUPTED = 130  # 128 + SIGINT, as a shell reports a process stopped by Ctrl-C
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, as a shell reports ``yes | head -1``


class CommandParser(argparse.ArgumentParser):
    """An argument parser whose errors name the nearest choice: ``invalid choice: 'rn'``
    (a command, a sub-command or an option's value) adds "did you mean 'run'?". Sub-command
    parsers are of this class too (``add_subparsers`` makes them of their parent's class).

    An option is matched by its whole name only (``allow_abbrev=False``): ``--record DIR`` is
    refused where the option is ``--records``, rather than taken silently as its prefix."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        """Print this parser's usage and ``message`` (with the nearest choice), exit 2."""
        found = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if found:
            choices = re.findall(r"'([^']*)'", found.group(2))
            near = difflib.get_close_matches(found.group(1), choices, n=1, cutoff=0.5)
            if near:
                message += f"; did you mean {near[0]!r}?"
        super().error(message)


def command_parser(parser: argparse.ArgumentParser, argv: Sequence[str]) -> argparse.ArgumentParser:
    """The (sub-)command parser that ``argv`` reaches: ``motion spectrum ...`` gives the
    parser of ``rockyade motion spectrum``."""
    current = parser
    for token in argv:
        subs = [a for a in current._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs:
            break
        if token in subs[0].choices:
            current = subs[0].choices[token]
    return current


def unknown_arguments(parser: argparse.ArgumentParser, argv: Sequence[str], extras: Sequence[str]) -> NoReturn:
    """Refuse arguments no command knows with the usage of the command they were given to
    and, for an option, the nearest of its options (exit 2)."""
    target = command_parser(parser, argv)
    message = f"unrecognized arguments: {' '.join(extras)}"
    options = [s for action in target._actions for s in action.option_strings]
    for extra in extras:
        if extra.startswith("-"):
            near = difflib.get_close_matches(extra.split("=", 1)[0], options, n=1, cutoff=0.6)
            if near:
                message += f" (did you mean {near[0]}?)"
                break
    target.error(message)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every sub-command."""
    import importlib

    parser: argparse.ArgumentParser = CommandParser(
        prog="rockyade",
        description="Seismic rocking of rigid blocks: classical (Housner) parameters, exact "
        "Housner solver, DEM calibration from the classical parameters, reference DEM, YADE and Siconos.",
    )
    parser.add_argument("--version", action="version", version=f"rockyade {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for module_name in COMMAND_MODULES:
        register: Callable[[Commands], None] = importlib.import_module(module_name).register
        register(sub)
    return parser


def _coerce_scale(value: str) -> str | float:
    try:
        return float(value)
    except ValueError:
        return value


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rockyade`` console script: never ends in a traceback for bad
    input, a full disk, a closed pipe or Ctrl-C (see the module docstring for exit codes)."""
    try:
        return _main(argv)
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        _error("interrupted (Ctrl-C)")
        return EXIT_INTERRUPTED


def _show_notes_as_lines() -> None:
    """An :class:`~rockyade.errors.InputNote` (an input accepted but unusual) prints as one line,
    ``rockyade: note: ...``; other warnings as Python shows them."""
    from rockyade.errors import InputNote

    shown = warnings.showwarning
    if getattr(shown, "rockyade_notes", False):  # installed by an earlier main() in this process
        return

    def show(message: Warning | str, category: type[Warning], *rest: Any, **kwargs: Any) -> None:
        if issubclass(category, InputNote):
            _error(f"note: {message}")
        else:
            shown(message, category, *rest, **kwargs)

    show.rockyade_notes = True  # type: ignore[attr-defined]
    warnings.showwarning = show


def _main(argv: Sequence[str] | None) -> int:
    _show_notes_as_lines()
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    args, extras = parser.parse_known_args(argv)
    if extras:
        unknown_arguments(parser, argv, extras)
    args.started_at = _T0
    if hasattr(args, "stiffness_scale") and isinstance(args.stiffness_scale, str):
        args.stiffness_scale = _coerce_scale(args.stiffness_scale)
    try:
        code = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe is reported here rather than at exit
        return code
    except InputError as exc:
        _error(f"error: {exc}")
        return EXIT_INPUT
    except SolverUnavailableError as exc:
        _error(str(exc))
        return EXIT_UNAVAILABLE
    except BatchInterruptedError as exc:
        _error(str(exc))
        if exc.hard:
            _end_now(EXIT_INTERRUPTED)
        return EXIT_INTERRUPTED
    except (CalibrationError, SolverFailedError, RockyadeError) as exc:
        _error(str(exc))
        return EXIT_FAILED
    except MemoryError:
        _error("error: out of memory; a smaller run (shorter duration, larger sample_dt_s) fits")
        return EXIT_FAILED
    except BrokenPipeError:
        raise
    except OSError as exc:
        _error(f"error: {os_error_message(exc)}")
        return EXIT_FAILED


def _end_now(code: int) -> None:
    """End the process at once if threads of stopped runs are still busy (they cannot be
    killed, and the interpreter would wait for them at exit)."""
    import threading

    busy = [t for t in threading.enumerate() if t is not threading.main_thread() and not t.daemon and t.is_alive()]
    if busy:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(code)


def _error(message: str) -> None:
    with contextlib.suppress(OSError):
        print(f"rockyade: {message}", file=sys.stderr, flush=True)


def _silence_stdout() -> None:
    """After a closed pipe: point stdout at /dev/null so that the exit flush stays quiet."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


if __name__ == "__main__":
    sys.exit(main())
