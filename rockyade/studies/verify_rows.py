"""The rows of ``rockyade verify``: a measured value, what it is compared with and the
tolerance, held once (:class:`Tolerance`): the report's text and the pass or fail are both
derived from it, so that they cannot disagree."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

#: How a value is compared with its expected value (:meth:`Tolerance.passes`).
ToleranceKind = Literal["relative", "absolute", "at most", "at least"]


def relative_difference(a: float, b: float) -> float:
    """|a - b| / |b| (infinite when b is 0)."""
    return abs(a - b) / abs(b) if b else math.inf


def _number(x: float) -> str:
    """``x`` in at most three significant digits, exponents without padding (1e-6, not 1e-06)."""
    text = f"{x:.3g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        text = f"{mantissa}e{int(exponent)}"
    return text


@dataclass(frozen=True)
class Tolerance:
    """How close a measured value must be to its expected value.

    Attributes
    ----------
    kind
        "relative": |value - expected| <= ``value`` |expected| (fails when expected is 0);
        "absolute": |value - expected| <= ``value``; "at most": value <= expected + ``value``;
        "at least": value >= expected - ``value``.
    value
        The tolerance, >= 0: a fraction for "relative", in the quantity's unit otherwise.
    unit
        The quantity's unit, for the text (e.g. "m", "rad"; empty for none).
    """

    kind: ToleranceKind
    value: float
    unit: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("relative", "absolute", "at most", "at least"):
            raise ValueError(f"kind must be relative, absolute, at most or at least, got {self.kind!r}")
        if not (math.isfinite(self.value) and self.value >= 0.0):
            raise ValueError(f"value must be a finite number >= 0, got {self.value!r}")

    def _amount(self) -> str:
        return _number(self.value) + (f" {self.unit}" if self.unit else "")

    def text(self) -> str:
        """The tolerance as the report writes it, e.g. "2 %", "1e-9 relative", "0.001 rad",
        "<= expected + 0.001 m", ">= expected", "exact"."""
        if self.kind == "relative":
            return f"{_number(100.0 * self.value)} %" if self.value >= 1e-3 else f"{_number(self.value)} relative"
        if self.kind == "absolute":
            return self._amount() if self.value > 0.0 else "exact"
        sign, op = ("+", "<=") if self.kind == "at most" else ("-", ">=")
        return f"{op} expected" + (f" {sign} {self._amount()}" if self.value > 0.0 else "")

    def passes(self, expected: float, value: float) -> bool:
        """Whether ``value`` is within this tolerance of ``expected`` (never for NaN)."""
        if self.kind == "relative":
            return relative_difference(value, expected) <= self.value
        if self.kind == "absolute":
            return abs(value - expected) <= self.value
        if self.kind == "at most":
            return value <= expected + self.value
        return value >= expected - self.value


def relative(fraction: float) -> Tolerance:
    """|value - expected| <= fraction |expected| (0.02: within 2 %)."""
    return Tolerance("relative", fraction)


def absolute(amount: float, unit: str = "") -> Tolerance:
    """|value - expected| <= amount, in the quantity's ``unit``."""
    return Tolerance("absolute", amount, unit)


def at_most(margin: float = 0.0, unit: str = "") -> Tolerance:
    """value <= expected + margin."""
    return Tolerance("at most", margin, unit)


def at_least(margin: float = 0.0, unit: str = "") -> Tolerance:
    """value >= expected - margin."""
    return Tolerance("at least", margin, unit)


#: The value must equal the expected one (a count or a yes/no as 1/0).
EXACT = absolute(0.0)


@dataclass(frozen=True)
class Row:
    """One verified quantity: its value, the expected value and where that comes from, and the
    tolerance (pass or fail and the report's text both come from it)."""

    check: str
    solver: str
    quantity: str
    value: float
    expected: float
    expected_from: str
    tolerance: Tolerance

    @property
    def difference(self) -> float:
        """Measured minus expected value, in the quantity's unit."""
        return self.value - self.expected

    @property
    def passed(self) -> bool:
        """Whether the value is within the tolerance of the expected value."""
        return self.tolerance.passes(self.expected, self.value)

    def as_dict(self) -> dict[str, object]:
        """The row as ``verify.csv`` writes it."""
        return {
            "check": self.check,
            "solver": self.solver,
            "quantity": self.quantity,
            "value": self.value,
            "expected": self.expected,
            "difference": self.difference,
            "expected_from": self.expected_from,
            "tolerance": self.tolerance.text(),
            "passed": self.passed,
        }


def known(value: float | None, name: str) -> float:
    """``value``, which the check needs (RuntimeError when the analysis gave none)."""
    if value is None:
        raise RuntimeError(f"the analysis gave no {name}")
    return value
