"""Helpers shared by the command modules (standard library only: the parser stays fast)."""

from __future__ import annotations

import argparse
import inspect
import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeAlias

from rockyade.errors import InputError

if TYPE_CHECKING:
    from rockyade.run_meta import RunMeta
    from rockyade.solvers.base import Solver


#: A parser's table of sub-commands, as ``ArgumentParser.add_subparsers`` returns it (at run
#: time its parsers are of their parent's class, :class:`~rockyade.cli.CommandParser`).
Commands: TypeAlias = "argparse._SubParsersAction[argparse.ArgumentParser]"

#: The solvers' names, as :func:`rockyade.solvers.solver_names` lists them (kept here so that
#: building the parser does not import the solvers; a test checks the two agree).
SOLVER_NAMES: tuple[str, ...] = ("housner", "reference", "yade", "siconos", "twoblock")


def json_out(data: object) -> None:
    """Print ``data`` as indented, sorted JSON (numpy values converted).

    Parameters
    ----------
    data
        JSON-ready values (dicts, lists, numbers, strings, numpy scalars and arrays).
    """
    from rockyade.io.strict_json import json_text

    print(json_text(data))


def print_wrote(path: Path, json_mode: bool = False) -> None:
    """``wrote PATH`` on stdout, or on stderr after ``--json`` (stdout stays one JSON document).

    Parameters
    ----------
    path
        The file written.
    json_mode
        The command prints JSON on stdout.
    """
    import sys

    print(f"wrote {path}", file=sys.stderr if json_mode else sys.stdout)


def add_command(sub: Commands, run: Callable[..., int], name: str | None = None) -> argparse.ArgumentParser:
    """Add the sub-command that ``run`` carries out, documented by ``run``'s docstring: its
    first paragraph is the one-line help of ``rockyade --help``, the rest the description of
    ``rockyade NAME --help`` (one text for readers of the code and users of the command), up
    to its numpydoc sections (``Parameters``, ``Returns``), which are for readers only.

    Parameters
    ----------
    sub
        The sub-parsers to add to (``add_subparsers``' answer).
    run
        The command function, ``run(args) -> exit code``.
    name
        The command's name; default ``run``'s name without ``cmd_``, ``_`` written ``-``.

    Returns
    -------
    argparse.ArgumentParser
        The command's parser, for its arguments.
    """
    text = re.split(r"\n\n(?:Parameters|Returns)\n---", inspect.getdoc(run) or "")[0]  # numpydoc sections stay
    summary, _, description = text.partition("\n\n")
    if name is None:
        name = run.__name__.removeprefix("cmd_").replace("_", "-")
    # argparse %-formats a help string (not a description): a "%" in the summary is a percent sign
    parser = sub.add_parser(name, help=" ".join(summary.split()).replace("%", "%%"), description=description or None)
    parser.set_defaults(func=run)
    return parser


def add_command_group(sub: Commands, name: str, help_text: str, description: str, dest: str) -> Commands:
    """Add a command whose first argument names one of its own sub-commands (``rockyade build
    KIND``, ``rockyade motion MOTION_COMMAND``).

    Parameters
    ----------
    sub
        The sub-parsers to add to.
    name, help_text, description
        The command's name, its line in ``rockyade --help`` and the head of ``rockyade NAME --help``.
    dest
        The attribute of the parsed arguments that names the sub-command (shown in capitals).

    Returns
    -------
    Commands
        The command's own sub-parsers, for its sub-commands.
    """
    group = sub.add_parser(name, help=help_text, description=description)
    return group.add_subparsers(dest=dest, required=True, metavar=dest.upper())


def add_allow_large(p: argparse.ArgumentParser) -> None:
    """``--allow-large``: run above the documented cost limits (docs/robustness.md).

    Parameters
    ----------
    p
        The command's parser.
    """
    p.add_argument(
        "--allow-large",
        action="store_true",
        help="run even when the cost estimate (integration steps, samples, memory) is above the documented limits",
    )


def add_accel_units(p: argparse.ArgumentParser, help_text: str) -> None:
    """``--accel-units``: g (the default) or m/s2, the unit accelerations are shown in.

    Parameters
    ----------
    p
        The command's parser.
    help_text
        The option's help: what is shown in that unit, and where the other unit goes.
    """
    p.add_argument("--accel-units", choices=["g", "m/s2"], default="g", help=help_text)


def add_joint_options(
    p: argparse.ArgumentParser, friction_angle_help: str, friction_rule_help: str, fm_help: str
) -> None:
    """The joints of a limit analysis (``limit``, ``assess``): ``--friction-angle-deg`` or
    ``--no-sliding``, ``--friction-rule`` and ``--fm`` (each checked where it is read).

    Parameters
    ----------
    p
        The command's parser.
    friction_angle_help, friction_rule_help, fm_help
        The help of ``--friction-angle-deg``, ``--friction-rule`` and ``--fm`` in this command.
    """
    joints = p.add_mutually_exclusive_group()
    joints.add_argument("--friction-angle-deg", type=float, metavar="DEG", help=friction_angle_help)
    joints.add_argument("--no-sliding", action="store_true", help="no joint slides (rocking mechanisms only)")
    p.add_argument("--friction-rule", metavar="RULE", help=friction_rule_help)
    p.add_argument("--fm", type=float, metavar="MPA", help=fm_help)


def check_output_dir(path: Path, option: str) -> None:
    """Refuse an output directory that cannot be created or written (InputError naming
    ``option``, e.g. ``out`` or ``--out``), before any work; nothing is created here.

    Parameters
    ----------
    path
        The directory.
    option
        The option that names it.
    """
    option = _flag(option)
    if path.is_file():
        raise InputError(option, f"{path} is a file; give a directory")
    _check_dir(path, option, f"cannot write into {path}")


def check_output_file(path: Path, option: str, suffix: str | tuple[str, ...] | None = None) -> None:
    """Refuse an output file whose folder cannot be created or written, or (``suffix``, e.g.
    ``".png"`` or ``(".toml", ".json")``) whose name does not end as the file it will be (no
    scene overwritten by a plot).

    Parameters
    ----------
    path
        The file.
    option
        The option that names it.
    suffix
        The suffix (or suffixes) it must have; None: any.
    """
    option = _flag(option)
    if path.is_dir():
        raise InputError(option, f"{path} is a directory; give a file name")
    suffixes = (suffix,) if isinstance(suffix, str) else suffix
    if suffixes is not None and path.suffix.lower() not in suffixes:
        raise InputError(option, f"must be a {' or '.join(suffixes)} file, got {path}")
    _check_dir(path.parent if str(path.parent) else Path("."), option, f"cannot write {path}")


def _flag(option: str) -> str:
    """The option as typed on the command line: ``out`` -> ``--out``."""
    return option if option.startswith("-") else "--" + option.replace("_", "-")


def _check_dir(path: Path, option: str, what: str) -> None:
    existing = path
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if existing.exists() and not existing.is_dir():
        raise InputError(option, f"{what}: {existing} is not a directory")
    if not os.access(existing, os.W_OK | os.X_OK):
        raise InputError(option, f"{what}: {existing} is not writable")


def total_time(args: argparse.Namespace) -> float:
    """Seconds since the command line started (imports of the command included), s.

    Parameters
    ----------
    args
        The parsed command line (``started_at``: its ``time.perf_counter()`` at start);
        NaN without it.
    """
    import time

    start = getattr(args, "started_at", None)
    return time.perf_counter() - start if start is not None else float("nan")


def mu_note_line(meta: RunMeta) -> str | None:
    """One console line for a Result's ``mu_note`` (Siconos: the restitution its impacts give
    is the model's own, mu_model, not the scene's mu), with the numbers; None without a note.

    Parameters
    ----------
    meta
        The Result's metadata (``mu_note``, ``mu_model`` and ``mu_scene`` in its ``extra``:
        block -> mu).
    """
    note = meta.extra.get("mu_note")
    if not note:
        return None
    model = meta.extra.get("mu_model") or {}
    scene = meta.extra.get("mu_scene") or {}
    values = [
        f"{name} {mu:.4g}" + (f" (scene mu {scene[name]:.4g})" if scene.get(name) is not None else "")
        for name, mu in model.items()
    ]
    return f"note: {note}: " + ", ".join(values) if values else f"note: {note}"


def print_calibration(result: dict[str, Any], method: str) -> None:
    """The text of a calibration: each DEM parameter with the equation it comes from.

    Parameters
    ----------
    result
        :meth:`rockyade.calibration.calibrate.Calibration.report`'s keys (K in N/m, beta and
        dt in s, b_eq in m, ...); with ``method = "matched"`` the matching's too (its
        achieved mu and reachable range are in the joint's notes).
    method
        ``"paper"`` or ``"matched"``.

    ``calibrate`` and ``calibrate --from`` print through this.
    """
    if method == "matched":
        beta_src = f"matched to mu; Eq 13 gives {result['beta_eq13_s']:.6g} s"
    else:
        beta_src = f"Eq 13, Gamma = {result['gamma']:.6g} (Eq 12)"
    b_eq = result["b_eq_m"]
    print(
        f"  K = Ks   = {result['K_N_per_m']:.6g} N/m (Eq 10: {result['K_paper_units']:.6g}, "
        f"read as {result['stiffness_scale']})"
    )
    print(f"  beta     = {result['beta_s']:.6g} s ({beta_src})")
    print(
        f"  xi_min   = {result['xi_min']:.6g} (Eq 15), f_min = {result['f_min_hz']:.6g} Hz (Eq 14: the number of p "
        "in 1/s), Rayleigh a = 0"
    )
    print(f"  b_eq     = {b_eq:.6g} m (Eq 11; 2 b_eq = {2 * b_eq:.4g} m)")
    print(f"  dt       = {result['dt_s']:.6g} s (Eq 7, frac 0.1)")
    print(f"  friction = {result['friction_angle_deg']:g} deg, cohesion = {result['cohesion_Pa']:g} Pa")
    print(f"  static settlement M g / K = {result['settlement_m']:.3g} m")
    for note in result["notes"]:
        print(f"  note: {note}")


def add_yade_timeout(p: argparse.ArgumentParser) -> None:
    """The ``--yade-timeout`` option (run, compare, batch): YADE's ``timeout_s``."""
    p.add_argument(
        "--yade-timeout",
        type=float,
        metavar="SECONDS",
        help="wall-clock limit of each YADE run (default: 60 s plus 50 us per block-step, at most one hour); "
        "the run is stopped and reported failed when it is reached",
    )


#: Command-line options that set a solver's option: attribute of the arguments -> (option, flag).
SOLVER_OPTION_FLAGS = {"yade_timeout": ("timeout_s", "--yade-timeout")}


def solver_options(args: argparse.Namespace) -> tuple[dict[str, Any], dict[str, str]]:
    """The solver options given on the command line, and the flags that name them in errors."""
    options, flags = {}, {}
    for attr, (option, flag) in SOLVER_OPTION_FLAGS.items():
        value = getattr(args, attr, None)
        if value is not None:
            options[option] = value
            flags[option] = flag
    return options, flags


def solvers_from_args(names: list[str], args: argparse.Namespace) -> list[Solver]:
    """The solvers ``names`` with the command line's solver options, each to the solvers that
    take it (an option none of them takes is refused: ``--yade-timeout`` without yade)."""
    from rockyade.solvers import make_solvers

    options, flags = solver_options(args)
    return make_solvers(names, options, flags)
