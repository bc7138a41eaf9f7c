"""Errors that name the offending input field and, where it applies, the allowed range."""

from __future__ import annotations


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
