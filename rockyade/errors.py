"""Errors that name the offending input field and, where it applies, the allowed range."""

from __future__ import annotations

import errno


class RockyadeError(Exception):
    """Base class of every error rockyade raises on purpose."""


class InputError(RockyadeError, ValueError):
    """A bad input value.

    Parameters
    ----------
    field
        Dotted path of the field, e.g. ``blocks[0].height_m`` or ``contact.beta_s``.
    message
        What is wrong, including the allowed range where there is one.
    source
        Optional file name the value came from.
    """

    def __init__(self, field: str, message: str, source: str | None = None) -> None:
        self.field = field
        self.message = message
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field}: {message}")


class InputNote(UserWarning):
    """An input accepted as given but unusual enough to say so (a warning: the ``rockyade``
    command prints it as one line, ``rockyade: note: FIELD: ...``).

    Parameters
    ----------
    field
        Dotted path of the field, e.g. ``loads[0].mass_kg``.
    message
        What is unusual, and what the default would have been.
    source
        Optional file name the value came from.
    """

    def __init__(self, field: str, message: str, source: str | None = None) -> None:
        self.field = field
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field}: {message}")


class CalibrationError(RockyadeError):
    """A calibration that cannot be carried out (e.g. target outside the reachable range)."""


class SolverUnavailableError(RockyadeError):
    """A solver that is not installed or not yet available in this version."""


class SolverFailedError(RockyadeError):
    """A solver run that failed; carries the reason and, where there is one, a log path."""

    def __init__(self, reason: str, log_path: str | None = None) -> None:
        self.reason = reason
        self.log_path = log_path
        extra = f" (log: {log_path})" if log_path else ""
        super().__init__(f"{reason}{extra}")


class BatchInterruptedError(RockyadeError):
    """A batch stopped by Ctrl-C (SIGINT) after writing the summary of what finished.

    Attributes
    ----------
    finished
        Runs that finished (completed, overturned or failed).
    unfinished
        Runs that did not start or were stopped.
    summary_path
        The summary written, or None when it could not be.
    hard
        A second Ctrl-C stopped the running runs (the process should end at once).
    resume_option
        The command's option that resumes (named in the message), None: it has none.
    listed
        What ``summary_path`` lists, in words (default "them": every run, finished or not).
    unfinished_what
        What the unfinished count counts, in words (default "unfinished").
    """

    def __init__(
        self,
        finished: int,
        unfinished: int,
        summary_path: str | None,
        hard: bool = False,
        resume_option: str | None = "--resume",
        listed: str = "them",
        unfinished_what: str = "unfinished",
    ) -> None:
        self.finished = finished
        self.unfinished = unfinished
        self.summary_path = summary_path
        self.hard = hard
        self.resume_option = resume_option
        where = f"; {summary_path} lists {listed}" if summary_path else ""
        then = (
            f" (run the same command with {resume_option} to finish them)"
            if resume_option
            else " (this command does not resume: run it again)"
        )
        super().__init__(f"interrupted: {finished} run(s) finished, {unfinished} {unfinished_what}{where}{then}")


def os_error_message(exc: OSError) -> str:
    """One line for a file-system error: the file and what went wrong (a full disk said so)."""
    what = exc.strerror or str(exc)
    if exc.errno == errno.ENOSPC:
        what = "no space left on the device (disk full)"
    where = f"{exc.filename}: " if exc.filename else ""
    return f"{where}{what}"


# ---------------------------------------------------------------------- numbers in messages
#
# A number a message states as a requirement must stay true once printed: a factor to raise
# something by, or a lower bound, is rounded up; an upper bound or a limit not to exceed is
# rounded down. "Raise K at least 1 times" (for 1.03) or "at least 1.3 times" (for 1.306)
# sent users back with too little.


def _directed(value: float, digits: int, rounding: str) -> str:
    from decimal import Decimal

    if value != value or value in (float("inf"), float("-inf")) or value == 0.0:
        return f"{value:g}"
    exact = Decimal(repr(float(value)))  # the shortest decimal that reads back as this float
    step = Decimal(1).scaleb(exact.adjusted() - digits + 1)
    rounded = exact.quantize(step, rounding=rounding)
    return f"{float(rounded):.{digits}g}"


def at_least(value: float, digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits, rounded up (towards +inf): a factor or
    a lower bound that stays enough once printed.

    Parameters
    ----------
    value
        The number.
    digits
        Significant digits printed.
    """
    return _directed(value, digits, "ROUND_CEILING")


def at_most(value: float, digits: int = 3) -> str:
    """``value`` with ``digits`` significant digits (as :func:`at_least`), rounded down
    (towards -inf): an upper bound or a limit that stays within once printed."""
    return _directed(value, digits, "ROUND_FLOOR")
