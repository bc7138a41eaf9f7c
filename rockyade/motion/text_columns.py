"""The columns of one data line of a text record: separators and decimal commas.

A line's columns are separated by semicolons if it has any, else by commas if it has any,
else by blanks (spaces, tabs). A decimal comma (``0,0123``, as spreadsheets write numbers in
much of Europe) is read where it cannot be a separator:

* in a semicolon-separated line (``0,01;0,0123``);
* in a blank-separated line whose numbers use it or no decimal mark at all
  (``0,01<TAB>0,0123``, ``0,01 -1E-03``);
* as the only number of a one-column line (``0,0123``), when the file is known to have one
  column.

A line separated by commas whose numbers also use decimal commas (``0,01,0,0123``) cannot be
read: it holds four comma-separated parts, and is refused as such by the reader, which says
which separator it saw.
"""

from __future__ import annotations

import re

#: A number written with a decimal comma (one comma, digits after it, optional exponent).
DECIMAL_COMMA = re.compile(r"^[-+]?[0-9]*,[0-9]+(?:[eEdD][-+]?[0-9]+)?$", re.ASCII)
#: A number with no decimal mark at all (``0``, ``-1E-03``).
_NO_MARK = re.compile(r"^[-+]?[0-9]+(?:[eEdD][-+]?[0-9]+)?$", re.ASCII)


def with_point(token: str) -> str:
    """``token`` with a decimal comma written as a point (other tokens unchanged)."""
    return token.replace(",", ".") if DECIMAL_COMMA.match(token) else token


def split_columns(body: str) -> tuple[list[str], str]:
    """The columns of a data line (comments removed, stripped) and the separator seen.

    Returns
    -------
    (columns, separator)
        ``separator`` is "semicolon", "comma", "blank" or "none" (one column). Decimal
        commas are returned with a point where they are unambiguous (module docstring).
    """
    if ";" in body:
        return [with_point(part.strip()) for part in body.split(";")], "semicolon"
    if "," in body:
        blanks = body.split()
        commas = [bool(DECIMAL_COMMA.match(t)) for t in blanks]
        plain = all(c or _NO_MARK.match(t) for c, t in zip(commas, blanks, strict=True))
        if len(blanks) >= 2 and any(commas) and plain:
            return [with_point(t) for t in blanks], "blank"
        return [part.strip() for part in body.split(",")], "comma"
    parts = body.split()
    return parts, "blank" if len(parts) > 1 else "none"
