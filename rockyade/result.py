"""The one Result type every solver returns.

A result is a time history (pandas DataFrame: one row per sample at ``sample_dt_s`` from
t = 0) plus its metadata, a :class:`rockyade.run_meta.RunMeta`. Columns: ``t_s``, ``ag_m_s2`` (horizontal base
acceleration) and per block ``theta_rad``, ``omega_rad_s``, ``x_m``, ``y_m`` (centroid
displacement relative to the base from its initial position), ``ax_m_s2``, ``ay_m_s2``
(absolute acceleration at the output point), prefixed ``<block>_`` when the scene has
several blocks. Solvers may add columns (contact states, energies).

Metadata (typed attributes): ``solver``, ``version``, ``scene_hash``, ``wall_time_s`` (the
solver itself), ``status`` (completed | overturned | failed), ``overturn_time_s``,
``overturned_block``, ``failure_reason``, ``blocks``, ``sample_dt_s``, ``dt_s``,
``motion_coverage``, ...; a solver's own values (``contact`` for the DEMs, Siconos's solver
statistics) in ``meta.extra``. On disk the metadata is the JSON beside the CSV, one flat object
(:meth:`RunMeta.to_dict`), written as strict JSON (:mod:`rockyade.io.strict_json`).

A Result knows nothing of figures: :mod:`rockyade.figures.histories` draws it
(``HistoryDisplay.from_result(result)``, ``plot_result(result, ax=...)``).
"""

from __future__ import annotations

import contextlib
import glob
import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from rockyade.errors import InputError
from rockyade.io.atomic import TEMP_SUFFIX, fsync_dir, remove_stale_temporaries, staged_file
from rockyade.io.locking import output_lock
from rockyade.io.strict_json import json_text
from rockyade.run_meta import RunMeta

if TYPE_CHECKING:
    import pandas as pd

PER_BLOCK_QUANTITIES = ("theta_rad", "omega_rad_s", "x_m", "y_m", "ax_m_s2", "ay_m_s2")
CSV_FLOAT_FORMAT = "%.12g"


def column(block: str, quantity: str, blocks: list[str] | tuple[str, ...]) -> str:
    """Column name of ``quantity`` for ``block``: bare for one block, prefixed otherwise.

    Parameters
    ----------
    block
        Block name.
    quantity
        Per-block quantity with its unit, e.g. ``theta_rad``.
    blocks
        Every block of the result.
    """
    return quantity if len(blocks) == 1 else f"{block}_{quantity}"


@dataclass
class Result:
    """A solver's output: time history and metadata (see module docstring)."""

    frame: pd.DataFrame
    meta: RunMeta

    # -------------------------------------------------------------- accessors
    @property
    def status(self) -> str:
        """completed | overturned | failed."""
        return self.meta.status

    @property
    def ok(self) -> bool:
        """True unless the run failed (an overturn is a valid outcome)."""
        return self.meta.ok

    @property
    def blocks(self) -> list[str]:
        """Block names, bottom to top."""
        return list(self.meta.blocks)

    @property
    def t(self) -> np.ndarray:
        """Sample times, s."""
        return self.frame["t_s"].to_numpy()

    def series(self, quantity: str, block: str | None = None) -> np.ndarray:
        """One per-block column as an array (``block`` defaults to the only/top block).

        Parameters
        ----------
        quantity
            ``theta_rad`` (rad), ``omega_rad_s`` (rad/s), ``x_m``, ``y_m`` (m), ``ax_m_s2``,
            ``ay_m_s2`` (m/s^2), or a solver's own per-block column.
        block
            Block name.
        """
        names = self.blocks
        if block is None:
            block = names[-1]
        return self.frame[column(block, quantity, names)].to_numpy()

    # -------------------------------------------------------------- files
    def write(self, csv_path: str | os.PathLike[str], extra_meta: dict[str, Any] | None = None) -> Path:
        """Write ``<name>.csv`` and ``<name>.json``; return the JSON path.

        The JSON (with the CSV's SHA-256) marks the pair complete. Both files are written
        to temporary files first; the old pair is replaced only when the new one is
        complete (CSV renamed, then the JSON), so a kill at any moment leaves the old pair
        or the new one (:meth:`read` finds the new JSON in ``.<name>.json.pending`` if the
        kill fell between the two renames). Another process writing the same result is
        refused (:func:`rockyade.io.locking.output_lock`); temporary files are removed on
        failure.

        Parameters
        ----------
        csv_path
            The CSV to write; the JSON goes beside it.
        extra_meta
            Merged into the metadata.
        """
        csv_path = Path(csv_path)
        json_path = csv_path.with_suffix(".json")
        text = csv_text(self.frame, CSV_FLOAT_FORMAT)
        meta = self.meta.to_dict()
        meta.update(extra_meta or {})
        meta["csv_file"] = csv_path.name
        meta["csv_sha256"] = hashlib.sha256(text.encode()).hexdigest()
        meta["columns"] = list(self.frame.columns)
        pending = pending_json_path(json_path)
        with output_lock(csv_path):
            _settle(csv_path, json_path)
            with staged_file(csv_path) as (fh, csv_tmp):
                fh.write(text)
            leftovers = [csv_tmp, pending]
            try:
                with staged_file(json_path) as (fh, json_tmp):
                    fh.write(json_text(meta) + "\n")
                leftovers.append(json_tmp)
                os.replace(json_tmp, pending)
                os.replace(csv_tmp, csv_path)  # from here the new pair (CSV + pending JSON) is complete
                leftovers = []
                os.replace(pending, json_path)
            except BaseException:
                for leftover in leftovers:
                    with contextlib.suppress(FileNotFoundError):
                        leftover.unlink()
                raise
            fsync_dir(csv_path.parent)
        return json_path

    @classmethod
    def read(cls, csv_path: str | os.PathLike[str]) -> Result:
        """Read a result pair written by :meth:`write`, verifying it is complete.

        Parameters
        ----------
        csv_path
            The CSV; its JSON lies beside it.

        Raises
        ------
        InputError
            A missing file, or a CSV that does not match its JSON (partial or stale).
        """
        csv_path = Path(csv_path)
        json_path = csv_path.with_suffix(".json")
        if not csv_path.is_file():
            raise InputError("result", f"{csv_path} is missing")
        text = csv_path.read_text()
        meta = _matching_meta(csv_path, text)
        if meta is None:
            if not json_path.is_file():
                raise InputError("result", f"{json_path} is missing: the result is incomplete")
            raise InputError("result", f"{csv_path} does not match {json_path.name} (partial or stale)")
        from io import StringIO

        import pandas as pd

        frame = pd.read_csv(StringIO(text))
        for key in ("csv_file", "csv_sha256", "columns"):
            meta.pop(key, None)
        try:
            run_meta = RunMeta.from_dict(meta)
        except (TypeError, ValueError) as exc:
            raise InputError("result", f"{json_path.name}: unreadable metadata ({exc})") from exc
        return cls(frame, run_meta)


#: Column names written as they are by pandas' CSV writer (no quoting needed).
_PLAIN_NAME = re.compile(r'^[^",\r\n]+$')


def csv_text(frame: pd.DataFrame, float_format: str) -> str:
    """``frame.to_csv(index=False, float_format=float_format, lineterminator="\\n")``, the same
    text, formatted row by row when every column is a float without NaN, an integer or a bool
    (pandas formats each value through Python calls: 3 s for a 1,000-block wall's result).

    Parameters
    ----------
    frame
        The table (its index is not written).
    float_format
        printf-style format of the floats, e.g. ``"%.12g"``.
    """
    formats: list[str] | None = []
    has_nan = frame.isna().to_numpy().any(axis=0)
    for (name, dtype), nan in zip(frame.dtypes.items(), has_nan, strict=True):
        if formats is None or not (isinstance(name, str) and _PLAIN_NAME.match(name)):
            formats = None
            break
        if dtype.kind == "f" and dtype.itemsize == 8 and not nan:
            formats.append(float_format)
        elif dtype.kind in "iu":
            formats.append("%d")
        elif dtype.kind == "b":
            formats.append("%s")
        else:
            formats = None
            break
    if not formats:
        return frame.to_csv(index=False, float_format=float_format, lineterminator="\n")
    row = ",".join(formats) + "\n"
    columns = [values.to_numpy().tolist() for _, values in frame.items()]
    body = "".join(row % values for values in zip(*columns, strict=True))
    return ",".join(frame.columns) + "\n" + body


def pending_json_path(json_path: Path) -> Path:
    """Where :meth:`Result.write` keeps the new JSON between its two renames.

    Parameters
    ----------
    json_path
        The result's JSON.
    """
    return json_path.parent / f".{json_path.name}.pending"


def _load_meta(path: Path) -> dict[str, Any] | None:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def stored_status(csv_path: str | os.PathLike[str]) -> str | None:
    """The status of the complete result pair at ``csv_path`` (its JSON's SHA-256 matches the
    CSV), or None: no pair, a damaged or mismatched one, or a link (not followed).

    Parameters
    ----------
    csv_path
        The CSV; its JSON lies beside it.
    """
    csv_path = Path(csv_path)
    if csv_path.is_symlink() or csv_path.with_suffix(".json").is_symlink() or not csv_path.is_file():
        return None
    try:
        meta = _matching_meta(csv_path, csv_path.read_text())
    except (OSError, UnicodeDecodeError):
        return None
    status = meta.get("status") if meta is not None else None
    return str(status) if status is not None else None


def _matching_meta(csv_path: Path, text: str) -> dict[str, Any] | None:
    """The metadata whose SHA-256 matches the CSV: the JSON, or a pending JSON."""
    digest = hashlib.sha256(text.encode()).hexdigest()
    json_path = csv_path.with_suffix(".json")
    for candidate in (json_path, pending_json_path(json_path)):
        meta = _load_meta(candidate) if candidate.is_file() else None
        if meta is not None and meta.get("csv_sha256") == digest:
            return meta
    return None


def _settle(csv_path: Path, json_path: Path) -> None:
    """Finish or discard what a killed writer left (call with the result's lock held)."""
    for name in (csv_path.name, json_path.name):  # temporary files of a killed writer of this result
        for stale in csv_path.parent.glob(f".{glob.escape(name)}.*{TEMP_SUFFIX}"):
            with contextlib.suppress(FileNotFoundError):
                stale.unlink()
    pending = pending_json_path(json_path)
    if not pending.is_file():
        return
    meta = _load_meta(pending)
    try:
        text = csv_path.read_text()
    except OSError:
        text = None
    if meta is not None and text is not None and meta.get("csv_sha256") == hashlib.sha256(text.encode()).hexdigest():
        os.replace(pending, json_path)  # the killed writer's new pair was complete: commit it
    else:
        with contextlib.suppress(FileNotFoundError):
            pending.unlink()


def settle_results(directory: str | os.PathLike[str]) -> None:
    """Commit or discard the pending JSONs and remove the temporary files killed writers left.

    Call it only while holding the directory's lock (no writer is active there).

    Parameters
    ----------
    directory
        The results' directory.
    """
    directory = Path(directory)
    for pending in directory.glob(".*.json.pending"):
        json_path = directory / pending.name[1 : -len(".pending")]
        _settle(json_path.with_suffix(".csv"), json_path)
    remove_stale_temporaries(directory)


def failed_result(solver: str, scene_hash: str | None, reason: str, **values: object) -> Result:
    """A Result with status ``failed``, no samples, and the reason.

    Parameters
    ----------
    solver
        The solver's name.
    scene_hash
        The scene's hash.
    reason
        Why it failed (``failure_reason``).
    **values
        More metadata (:meth:`RunMeta.failed`: by field name, others to ``extra``).
    """
    import pandas as pd

    return Result(pd.DataFrame({"t_s": pd.Series(dtype=float)}), RunMeta.failed(solver, scene_hash, reason, **values))
