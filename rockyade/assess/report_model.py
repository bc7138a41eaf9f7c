"""The content model of ``rockyade assess --report``'s page (:mod:`rockyade.assess.report_page`):
sections of paragraphs, tables, lists and figures, each number of a table kept with the key and
value of ``assess.json`` it shows (:class:`Cell`)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

#: The page's figures: file name and caption.
FIGURE_SPECTRUM = "spectrum.png"
FIGURE_MECHANISM = "mechanism.png"
FIGURE_CHECK = "check.png"
FIGURE_FRAGILITY = "fragility.png"
FIGURE_SELECTION = "selection.png"
FIGURES = (FIGURE_SPECTRUM, FIGURE_MECHANISM, FIGURE_CHECK, FIGURE_FRAGILITY, FIGURE_SELECTION)


@dataclass(frozen=True)
class Cell:
    """A table cell: its text and, for a number, the JSON key it comes from and its value there.

    Attributes
    ----------
    text
        What the page shows.
    key
        Where the number is in ``assess.json``: keys and list indices joined by dots (``checks.0.demand``);
        empty for words.
    value
        The number as the JSON holds it (None for words, or a number the JSON holds as null).
    """

    text: str
    key: str = ""
    value: float | None = None


@dataclass(frozen=True)
class Table:
    """A table with a caption; ``ident`` names it in the page (the HTML table's id)."""

    ident: str
    caption: str
    header: tuple[str, ...]
    rows: tuple[tuple[Cell, ...], ...]


@dataclass(frozen=True)
class Bullets:
    """A list of items."""

    items: tuple[str, ...]


@dataclass(frozen=True)
class FigureRef:
    """A figure of the page: its file (:data:`FIGURES`) and caption."""

    name: str
    caption: str


Block = str | Table | Bullets | FigureRef


@dataclass(frozen=True)
class Section:
    """A section: a title and its blocks (a ``str`` block is a paragraph)."""

    ident: str
    title: str
    blocks: tuple[Block, ...]


@dataclass(frozen=True)
class Provenance:
    """Where a report comes from: what the data of ``assess.json`` does not hold.

    Attributes
    ----------
    scene
        The scene file as given.
    scene_sha256
        Its SHA-256 (hex), read when the report was written.
    command
        The command, as rockyade read it (the scene and every option given).
    given
        (option, value) of every option given.
    defaults
        (option, value, what it means) of rockyade's defaults that the run took.
    versions
        (component, version) of rockyade and of what it ran.
    date_utc
        When the report was written (ISO 8601, UTC).
    """

    scene: str
    scene_sha256: str
    command: str
    given: tuple[tuple[str, str], ...] = ()
    defaults: tuple[tuple[str, str, str], ...] = ()
    versions: tuple[tuple[str, str], ...] = ()
    date_utc: str = ""


@dataclass(frozen=True)
class ReportPage:
    """The page (module docstring)."""

    title: str
    verdict: str
    sections: tuple[Section, ...]
    figures: tuple[FigureRef, ...] = field(default=())
    summary: str = ""


def fmt(value: Any, digits: int = 4) -> str:
    """A number as the page shows it (``digits`` significant), "-" for None or NaN."""
    if value is None or isinstance(value, bool) or not isinstance(value, (int, float)):
        return "-" if value is None else str(value)
    if not math.isfinite(value):
        return "-"
    return f"{value:.{digits}g}"


def num(data: Mapping[str, Any], path: str, digits: int = 4, decimals: int | None = None) -> Cell:
    """The number at ``path`` (``checks.0.demand``, dots between keys and list indices) of ``data``, as
    a cell with its key and value: shown with ``digits`` significant digits, or ``decimals`` decimals
    (fractions: 0.000, not 5.55e-17)."""
    value = lookup(data, path)
    number = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None
    if decimals is not None and number is not None and math.isfinite(number):
        return Cell(f"{number:.{decimals}f}", path, number)
    return Cell(fmt(number, digits), path, number)


def lookup(data: Any, path: str) -> Any:
    """``data`` followed along ``path`` (dots; integers index lists); None where it ends early."""
    here = data
    for part in path.split("."):
        if isinstance(here, Mapping):
            here = here.get(part)
        elif isinstance(here, Sequence) and not isinstance(here, str) and part.isdigit():
            k = int(part)
            here = here[k] if k < len(here) else None
        else:
            return None
    return here


def words(text: Any) -> Cell:
    """A cell of words."""
    return Cell("-" if text is None else str(text))


__all__ = [
    "FIGURES",
    "FIGURE_CHECK",
    "FIGURE_FRAGILITY",
    "FIGURE_MECHANISM",
    "FIGURE_SELECTION",
    "FIGURE_SPECTRUM",
    "Block",
    "Bullets",
    "Cell",
    "FigureRef",
    "Provenance",
    "ReportPage",
    "Section",
    "Table",
    "fmt",
    "lookup",
    "num",
    "words",
]
