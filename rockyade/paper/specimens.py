"""The seed paper's tables (``data/*.csv``) and the specimens they describe.

This is the only place the paper's numbers are read; tests and reports use it rather than
re-typing values.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING

from rockyade.blocks.geometry import Block, chamfered_rectangle_vertices
from rockyade.errors import InputError

if TYPE_CHECKING:  # pandas is imported when a table is asked for: ``rockyade params`` stays quick
    import pandas as pd

DATA_DIR = Path(__file__).resolve().parent / "data"

TABLE_FILES = {
    1: "table1_specimens.csv",
    2: "table2_biblock.csv",
    3: "table3_classical_single.csv",
    4: "table4_classical_biblock.csv",
    5: "table5_dem_single.csv",
    6: "table6_dem_biblock.csv",
}

SINGLE_SPECIMENS = ("1", "2", "3", "4")
BIBLOCK_BLOCKS = ("upper", "lower")
ALL_SPECIMENS = SINGLE_SPECIMENS + BIBLOCK_BLOCKS


@cache
def _raw_table(number: int) -> pd.DataFrame:
    import pandas as pd

    if number not in TABLE_FILES:
        raise InputError("table", f"must be one of {sorted(TABLE_FILES)}, got {number!r}")
    return pd.read_csv(DATA_DIR / TABLE_FILES[number], dtype=str, keep_default_na=False)


@cache
def _rows(name: str) -> dict[str, dict[str, str]]:
    """A data CSV as {first column: {column: text}} (the standard library's reader)."""
    with (DATA_DIR / name).open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        key = reader.fieldnames[0] if reader.fieldnames else ""
        return {row[key]: row for row in reader}


def table(number: int) -> pd.DataFrame:
    """Paper table ``number`` (1-6) as floats, indexed by specimen or block name."""
    import pandas as pd

    raw = _raw_table(number).copy()
    key = raw.columns[0]
    out = raw.set_index(key)
    return out.apply(pd.to_numeric, errors="coerce")


def printed_decimals(number: int, row: str, column: str) -> int:
    """Number of decimals the paper printed for a value (for rounding-consistency flags)."""
    raw = _raw_table(number)
    text = raw.loc[raw[raw.columns[0]] == row, column].iloc[0]
    return len(text.split(".")[1]) if "." in text else 0


def shapes() -> pd.DataFrame:
    """Base chamfers of the specimens (Section 3.1), indexed by specimen."""
    import pandas as pd

    return pd.read_csv(DATA_DIR / "specimen_shapes.csv", dtype={"specimen": str}).set_index("specimen")


def check_specimen(specimen: str | int) -> str:
    """Normalise a specimen id ("1".."4", "upper", "lower") or raise InputError."""
    key = str(specimen).strip().lower()
    if key not in ALL_SPECIMENS:
        raise InputError("specimen", f"must be one of {', '.join(ALL_SPECIMENS)}, got {specimen!r}")
    return key


@dataclass(frozen=True)
class Specimen:
    """A specimen of the paper with its printed data.

    Attributes
    ----------
    key
        "1".."4", "upper" or "lower".
    width_m, height_m, thickness_m, mass_kg
        Table 1 or 2.
    inertia_I0_printed_kgm2
        Printed I_0 (Table 1 or 2), kg m^2.
    chamfer_m
        Leg of the 45 degree base chamfers, m (specimen 4: 0.040).
    theoretical, experimental
        Printed (alpha_rad, p_rad_s, mu), Tables 3-4.
    """

    key: str
    width_m: float
    height_m: float
    thickness_m: float
    mass_kg: float
    inertia_I0_printed_kgm2: float
    chamfer_m: float
    theoretical: dict[str, float]
    experimental: dict[str, float]

    @property
    def label(self) -> str:
        """Readable name, e.g. "specimen 1" or "upper block"."""
        return f"specimen {self.key}" if self.key in SINGLE_SPECIMENS else f"{self.key} block"

    @property
    def name(self) -> str:
        """Identifier for scenes and result columns."""
        return f"specimen{self.key}" if self.key in SINGLE_SPECIMENS else self.key

    def vertices(self):
        """Cross-section vertices, m (chamfered for specimen 4)."""
        from rockyade.blocks.geometry import rectangle_vertices

        if self.chamfer_m > 0:
            return chamfered_rectangle_vertices(self.width_m, self.height_m, self.chamfer_m)
        return rectangle_vertices(self.width_m, self.height_m)

    def block(self) -> Block:
        """The block with the printed mass and uniform density inertia."""
        return Block.polygon(self.vertices(), self.thickness_m, mass_kg=self.mass_kg, name=self.name)

    def parameters(self, which: str) -> dict[str, float]:
        """Printed classical parameters: ``which`` = "theoretical" or "experimental"."""
        if which not in ("theoretical", "experimental"):
            raise InputError("parameters", f"must be 'theoretical' or 'experimental', got {which!r}")
        return self.theoretical if which == "theoretical" else self.experimental


def specimen(key: str | int) -> Specimen:
    """A specimen of the paper by id: 1-4 (Table 1) or "upper"/"lower" (Table 2)."""
    key = check_specimen(key)
    single = key in SINGLE_SPECIMENS
    dims = _rows(TABLE_FILES[1 if single else 2])[key]
    classical = _rows(TABLE_FILES[3 if single else 4])[key]
    chamfer = float(_rows("specimen_shapes.csv")[key]["base_chamfer_m"]) if single else 0.0

    def triple(tag: str) -> dict[str, float]:
        return {
            "alpha_rad": float(classical[f"alpha_{tag}_rad"]),
            "p_rad_s": float(classical[f"p_{tag}_rad_s"]),
            "mu": float(classical[f"mu_{tag}"]),
        }

    return Specimen(
        key=key,
        width_m=float(dims["width_2b_m"]),
        height_m=float(dims["height_2h_m"]),
        thickness_m=float(dims["thickness_2t_m"]),
        mass_kg=float(dims["mass_kg"]),
        inertia_I0_printed_kgm2=float(dims["inertia_I0_kgm2"]),
        chamfer_m=chamfer,
        theoretical=triple("T"),
        experimental=triple("E"),
    )
