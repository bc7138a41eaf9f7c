"""The one Result type every solver returns.

A result is a time history (pandas DataFrame: one row per sample at ``sample_dt_s`` from
t = 0) plus a metadata dictionary. Columns: ``t_s``, ``ag_m_s2`` (horizontal base
acceleration) and per block ``theta_rad``, ``omega_rad_s``, ``x_m``, ``y_m`` (centroid
displacement relative to the base from its initial position), ``ax_m_s2``, ``ay_m_s2``
(absolute acceleration at the output point), prefixed ``<block>_`` when the scene has
several blocks. Solvers may add columns (contact states, energies).

Metadata keys: ``solver``, ``version``, ``scene_hash``, ``wall_time_s`` (the solver
itself), ``status`` (completed | overturned | failed), ``overturn_time_s``,
``overturned_block``, ``failure_reason``, ``blocks``, ``sample_dt_s``, and the parameters
actually used (``contact`` for the DEMs, ``classical`` for Housner).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade import __version__
from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open, write_json

STATUSES = ("completed", "overturned", "failed")
PER_BLOCK_QUANTITIES = ("theta_rad", "omega_rad_s", "x_m", "y_m", "ax_m_s2", "ay_m_s2")
CSV_FLOAT_FORMAT = "%.12g"


def column(block: str, quantity: str, blocks: list[str] | tuple[str, ...]) -> str:
    """Column name of ``quantity`` for ``block``: bare for one block, prefixed otherwise."""
    return quantity if len(blocks) == 1 else f"{block}_{quantity}"


@dataclass
class Result:
    """A solver's output: time history and metadata (see module docstring)."""

    frame: pd.DataFrame
    meta: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        status = self.meta.get("status")
        if status not in STATUSES:
            raise ValueError(f"meta['status'] must be one of {STATUSES}, got {status!r}")
        self.meta.setdefault("rockyade_version", __version__)

    # -------------------------------------------------------------- accessors
    @property
    def status(self) -> str:
        """completed | overturned | failed."""
        return str(self.meta["status"])

    @property
    def ok(self) -> bool:
        """True unless the run failed (an overturn is a valid outcome)."""
        return self.status != "failed"

    @property
    def blocks(self) -> list[str]:
        """Block names, bottom to top."""
        return list(self.meta.get("blocks", []))

    @property
    def t(self) -> np.ndarray:
        """Sample times, s."""
        return self.frame["t_s"].to_numpy()

    def series(self, quantity: str, block: str | None = None) -> np.ndarray:
        """One per-block column as an array (``block`` defaults to the only/top block)."""
        names = self.blocks
        if block is None:
            block = names[-1]
        return self.frame[column(block, quantity, names)].to_numpy()

    # -------------------------------------------------------------- figures
    def plot(
        self,
        quantity: str = "theta_rad",
        ax: Any = None,
        path: str | os.PathLike[str] | None = None,
        label: str | None = None,
        title: str = "",
    ) -> tuple[Any, Any]:
        """Plot a per-block quantity against time, one panel per block.

        A thin wrapper of :func:`rockyade.figures.plot_results` (imported here, so that
        results load without matplotlib). ``ax``: Axes to draw into (one per block), e.g.
        to overlay several results; ``path``: PNG to write; ``label``: legend entry
        (default: the solver). Returns ``(fig, ax)`` (``(fig, axes)`` for several blocks).
        """
        from rockyade.figures.histories import plot_results

        name = label or str(self.meta.get("solver", "result"))
        return plot_results({name: self}, path, title=title, quantity=quantity, ax=ax)

    # -------------------------------------------------------------- files
    def write(self, csv_path: str | os.PathLike[str]) -> Path:
        """Write ``<name>.csv`` and ``<name>.json`` atomically; return the JSON path.

        The JSON (written last, with the CSV's SHA-256) marks the pair complete: a reader
        never mistakes a half-written or stale CSV for a result.
        """
        csv_path = Path(csv_path)
        json_path = csv_path.with_suffix(".json")
        with contextlib.suppress(FileNotFoundError):
            json_path.unlink()  # an old pair stops looking complete before we rewrite it
        text = self.frame.to_csv(index=False, float_format=CSV_FLOAT_FORMAT, lineterminator="\n")
        with atomic_open(csv_path, "w") as fh:
            fh.write(text)
        meta = dict(self.meta)
        meta["csv_file"] = csv_path.name
        meta["csv_sha256"] = hashlib.sha256(text.encode()).hexdigest()
        meta["columns"] = list(self.frame.columns)
        write_json(json_path, meta)
        return json_path

    @classmethod
    def read(cls, csv_path: str | os.PathLike[str]) -> Result:
        """Read a result pair written by :meth:`write`, verifying it is complete."""
        csv_path = Path(csv_path)
        json_path = csv_path.with_suffix(".json")
        if not json_path.is_file():
            raise InputError("result", f"{json_path} is missing: the result is incomplete")
        meta = json.loads(json_path.read_text())
        text = csv_path.read_text()
        if hashlib.sha256(text.encode()).hexdigest() != meta.get("csv_sha256"):
            raise InputError("result", f"{csv_path} does not match {json_path.name} (partial or stale)")
        from io import StringIO

        frame = pd.read_csv(StringIO(text))
        for key in ("csv_file", "csv_sha256", "columns"):
            meta.pop(key, None)
        return cls(frame, meta)


def failed_result(solver: str, scene_hash: str, reason: str, **extra: Any) -> Result:
    """A Result with status ``failed``, no samples, and the reason."""
    meta = {
        "solver": solver,
        "scene_hash": scene_hash,
        "status": "failed",
        "failure_reason": reason,
        "overturn_time_s": None,
        **extra,
    }
    return Result(pd.DataFrame({"t_s": pd.Series(dtype=float)}), meta)
