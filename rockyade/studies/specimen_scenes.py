"""The paper's specimens as scene tables: blocks with theoretical or experimental
parameters, the bi-block, and scene dictionaries built from them (the studies' scenes)."""

from __future__ import annotations

import copy
from typing import Any

from rockyade import paper
from rockyade.blocks.classical import classical_parameters

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
