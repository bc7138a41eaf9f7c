"""What a PEER strong-motion file is, from its header: acceleration, velocity or displacement.

PEER writes one file per quantity with the same layout, told apart by the third header line
(the extension is only a name, and files get renamed):

* NGA-West2 (``RSN..._xxx.AT2`` / ``.VT2`` / ``.DT2``)::

      PEER NGA STRONG MOTION DATABASE RECORD
      San Fernando, 2/9/1971, Pacoima Dam (upper left abut), 164
      ACCELERATION TIME SERIES IN UNITS OF G        (VELOCITY ... CM/S, DISPLACEMENT ... CM)
      NPTS=   4172, DT=   .0100 SEC,

* the older PEER / NGA-West1 layout::

      PEER NGA STRONG MOTION DATABASE RECORD        (or PACIFIC ENGINEERING AND ANALYSIS ...)
      SAN FERNANDO 02/09/71 14:00, PACOIMA DAM, 164
      ACCELERATION TIME HISTORY IN UNITS OF G       (VELOCITY ... CM/SEC, DISPLACEMENT ... CM)
      4164    0.0100    NPTS, DT                    (or NPTS=  4164, DT= .0100 SEC)

rockyade integrates accelerations only: a velocity or displacement file read as an
acceleration gives a base that barely moves (a velocity of 30 cm/s taken for 30 cm/s^2),
hence a block that never rocks, and nothing would say why.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

#: PEER's quantity line (third header line) in both layouts.
_QUANTITY = re.compile(r"\b(ACCELERATION|VELOCITY|DISPLACEMENT)\s+TIME\s+(SERIES|HISTORY)\b", re.I)
_UNITS = re.compile(r"\bUNITS?\s+OF\s+([A-Z][A-Z0-9/^*]*)", re.I)
#: quantity -> PEER's extension for it
EXTENSIONS = {"acceleration": "AT2", "velocity": "VT2", "displacement": "DT2"}
#: How PEER spells units, and how they are written here.
_UNIT_NAMES = {"CM/SEC": "cm/s", "CM/S": "cm/s", "CM": "cm", "G": "g", "CM/S/S": "cm/s2", "CM/SEC/SEC": "cm/s2"}


@dataclass(frozen=True)
class PeerHeader:
    """A PEER header's description of its file.

    Attributes
    ----------
    quantity
        "acceleration", "velocity" or "displacement".
    layout
        "NGA-West2" (``TIME SERIES``) or "older PEER" (``TIME HISTORY``).
    units
        The units as the header names them (``cm/s``, ``g``...), or "" when it does not.
    line
        1-based line of the quantity line.
    text
        That line, stripped.
    """

    quantity: str
    layout: str
    units: str
    line: int
    text: str

    @property
    def extension(self) -> str:
        """PEER's file extension for the quantity (AT2, VT2, DT2)."""
        return EXTENSIONS[self.quantity]

    @property
    def description(self) -> str:
        """E.g. ``a PEER velocity record (VT2, cm/s, NGA-West2 layout)``."""
        units = f", {self.units}" if self.units else ""
        return f"a PEER {self.quantity} record ({self.extension}{units}, {self.layout} layout)"

    def refusal(self) -> str:
        """The message refusing anything but an acceleration."""
        return (
            f"{self.description}, headed {self.text!r}: rockyade needs an acceleration record "
            "(AT2: PEER gives each record as .AT2, .VT2 and .DT2 files; use the .AT2)"
        )


def peer_header(lines: list[str]) -> PeerHeader | None:
    """The PEER quantity line among the first four lines of a file, or None.

    The third line is where both layouts put it; a velocity or displacement line anywhere in
    the first four is reported too (a header with a line missing is still that quantity).
    """
    for index, line in enumerate(lines[:4]):
        match = _QUANTITY.search(line)
        if not match:
            continue
        quantity = match.group(1).lower()
        if quantity == "acceleration" and index != 2:
            continue  # not PEER's layout: the caller reads it as what it seems to be
        layout = "NGA-West2" if match.group(2).upper() == "SERIES" else "older PEER"
        units_match = _UNITS.search(line, match.end())
        units = ""
        if units_match:
            written = units_match.group(1).upper().rstrip(".,")
            units = _UNIT_NAMES.get(written, written.lower())
        return PeerHeader(quantity, layout, units, index + 1, line.strip())
    return None
