"""The seed paper: its printed tables, its specimens, and the reproduction of its tables.

The paper is *Modeling the dynamic behavior of masonry walls as rigid blocks* (a DEM
calibrated from Housner's classical parameters, checked on shake-table tests of four
granite blocks and a two-block stack). Its Tables 1-6 ship as CSV in ``data/`` and are
read only through :mod:`rockyade.paper.specimens`. May import ``rockyade.blocks``.
"""

from rockyade.paper.specimens import (
    ALL_SPECIMENS,
    BIBLOCK_BLOCKS,
    SINGLE_SPECIMENS,
    Specimen,
    check_specimen,
    printed_decimals,
    shapes,
    specimen,
    table,
)

__all__ = [
    "ALL_SPECIMENS",
    "BIBLOCK_BLOCKS",
    "SINGLE_SPECIMENS",
    "Specimen",
    "check_specimen",
    "printed_decimals",
    "shapes",
    "specimen",
    "table",
]
