"""Pieces shared by the studies: specimen scenes, the report index, figure helpers."""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from rockyade import paper
from rockyade.blocks.classical import classical_parameters
from rockyade.io.atomic import atomic_open, write_text

PARAMETER_SETS = ("theoretical", "experimental")


def block_table(key: str, parameters: str = "experimental", name: str | None = None) -> dict[str, Any]:
    """A ``[[blocks]]`` table for a specimen of the paper.

    ``experimental``: Table 1-2 geometry with Table 3-4's E values as overrides;
    ``theoretical``: the geometry alone (alpha, p, mu from Eqs 2-4, general forms).
    """
    spec = paper.specimen(key)
    table: dict[str, Any] = {
        "name": name or spec.name,
        "vertices_m": spec.vertices().tolist(),
        "thickness_m": spec.thickness_m,
        "mass_kg": spec.mass_kg,
    }
    if parameters == "experimental":
        table.update(spec.experimental)
    return table


def block_alpha(key: str, parameters: str) -> float:
    """Critical angle of a specimen with the given parameter set, rad."""
    spec = paper.specimen(key)
    if parameters == "experimental":
        return spec.experimental["alpha_rad"]
    return classical_parameters(spec.block()).alpha_rad


def scene_dict(
    blocks: list[dict[str, Any]],
    motion: dict[str, Any],
    duration_s: float,
    sample_dt_s: float = 0.002,
    calibration: str = "matched",
    **contact: Any,
) -> dict[str, Any]:
    """A scene dictionary."""
    return {
        "duration_s": round(float(duration_s), 6),
        "sample_dt_s": sample_dt_s,
        "blocks": copy.deepcopy(blocks),
        "contact": {"calibration": calibration, **contact},
        "motion": copy.deepcopy(motion),
    }


def biblock_blocks(parameters: str = "experimental") -> list[dict[str, Any]]:
    """The bi-block structure, lower block first (Table 2)."""
    return [block_table("lower", parameters), block_table("upper", parameters)]


@dataclass
class Report:
    """The report being written: files in ``out`` and an index with captions."""

    out: Path
    sections: list[tuple[str, list[str]]] = field(default_factory=list)

    def section(self, title: str, intro: str = "") -> None:
        """Start a section of the index."""
        self.sections.append((title, [intro] if intro else []))

    def table(self, name: str, frame: pd.DataFrame, caption: str, float_format: str = "%.6g") -> Path:
        """Write a CSV and index it."""
        path = self.out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_open(path) as fh:
            frame.to_csv(fh, index=False, float_format=float_format, lineterminator="\n")
        self.sections[-1][1].append(f"- **Table** [`{name}`]({name}): {caption}")
        return path

    def figure(self, name: str, caption: str) -> Path:
        """Index a figure (written by the caller at ``out / name``)."""
        self.sections[-1][1].append(f"![{caption}]({name})\n\n*{name}*: {caption}\n")
        return self.out / name

    def note(self, text: str) -> None:
        """A paragraph in the current section."""
        self.sections[-1][1].append(text)

    def write_index(self, title: str, preamble: str) -> Path:
        """``index.md`` with every section."""
        lines = [f"# {title}", "", preamble, ""]
        for heading, items in self.sections:
            lines += [f"## {heading}", ""]
            for item in items:
                lines += [item, ""]
        path = self.out / "index.md"
        write_text(path, "\n".join(lines))
        return path


def fmt(value: float, digits: int = 4) -> str:
    """Compact number for captions (NaN as n/a)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return f"{value:.{digits}g}"


def shade_harmonic_states(ax, phases: dict[str, float], t_end: float, settle_cycles: float, frequency: float) -> None:
    """Shade the transient, stationary and free-rocking states of a harmonic test."""
    transient_end = phases["ramp_up_end_s"] + settle_cycles / frequency
    spans = (
        (0.0, transient_end, "transient", "#f2d7b6"),
        (transient_end, phases["end_s"], "stationary", "#d4e6f1"),
        (phases["end_s"], t_end, "free rocking", "#d5f5e3"),
    )
    for start, end, label, colour in spans:
        if end > start:
            ax.axvspan(start, end, color=colour, alpha=0.5, lw=0, label=label)
