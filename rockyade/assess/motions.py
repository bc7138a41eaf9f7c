"""The records a fragility analysis runs: record files of a folder, or a synthetic suite.

A set hands out, for record i and load factor lambda, the ``[motion]`` of a scene
(:mod:`rockyade.motion.types`): ``record`` (the file, read as it is: its units, no
processing) or ``synthetic`` (a spectrum-compatible suite, :mod:`rockyade.motion.synthetic`,
by its settings and number, so that a task pickles small and the record is read from the
cache where the run happens). **A load factor multiplies the record's accelerations as
read** (after the conversion of the file's units to m/s^2; nothing else is done to them).

* :func:`records_in_folder`: every ``.at2``, ``.csv``, ``.txt``, ``.dat`` and ``.asc`` (ESM) file of a folder,
  sorted by name (the same accelerogram twice, e.g. an ``.AT2`` and its ``.csv``, is refused;
  a link to a record file is followed and counted; a link to anything else, and a
  subfolder (real or linked: records are read from the folder itself only), refused rather
  than skipped: :func:`record_files`);
* :func:`ec8_suite`: a suite compatible with the EC8 spectrum of a spectrum type, ground type
  and ag; :func:`paper_suite_set`: the paper's suite (Type 2, ground D, ag S = 2.8 m/s^2).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rockyade.assess.measures import Measure
from rockyade.errors import InputError
from rockyade.motion.record_text import Record, normalise_units
from rockyade.motion.records import read_record
from rockyade.motion.selection_set import is_selection, read_selection
from rockyade.motion.spec import MotionSpec
from rockyade.motion.suite_cache import suite_record
from rockyade.motion.synthetic import SuiteSpec, paper_suite
from rockyade.motion.types import RecordMotion, SyntheticMotion

#: File names a records folder is read for (case-insensitive suffixes).
RECORD_SUFFIXES = (".at2", ".csv", ".txt", ".dat", ".asc")
#: Records of a set, at most.
MAX_RECORDS = 1000
#: Records of a synthetic suite, at most (generation takes about a second each).
MAX_SUITE_RECORDS = 200


@dataclass(frozen=True)
class RecordFiles:
    """Record files, each run as read (module docstring).

    Attributes
    ----------
    files
        Absolute paths.
    units
        Units of files that do not name theirs (``g``, ``m/s2``, ``cm/s2``); None: m/s^2.
    folder
        The folder as the user gave it (a link stays a link), for people (:meth:`describe`);
        None: the first file's folder. Not part of what the records are (not compared, not in
        :meth:`to_dict`).
    scale_factors
        Each record's factor when the folder is a selection (``rockyade motion select``): the
        records are read scaled by them, and lambda = 1 is the selection's own scaling to the
        site's spectrum; None: the records as read.
    selection
        What the selection says of itself (:meth:`rockyade.motion.selection_set.SelectionFiles.summary`),
        or None.
    """

    files: tuple[str, ...]
    units: str | None = None
    folder: str | None = field(default=None, compare=False)
    scale_factors: tuple[float, ...] | None = None
    selection: dict[str, Any] | None = field(default=None, compare=False)

    @property
    def count(self) -> int:
        """Number of records."""
        return len(self.files)

    def label(self, i: int) -> str:
        """Record i (0-based) by its file name."""
        return Path(self.files[i]).name

    def scale(self, i: int) -> float:
        """Record i's scale factor (1 outside a selection)."""
        return 1.0 if self.scale_factors is None else float(self.scale_factors[i])

    def record(self, i: int) -> Record:
        """Record i as read (m/s^2), times its selection's factor."""
        record = read_record(self.files[i], None, self.units)
        if self.scale_factors is None:
            return record
        return record.with_accel(record.accel_m_s2 * self.scale(i), f"scaled by {self.scale(i):.8g} (selection)")

    def motion(self, i: int, load_factor: float) -> MotionSpec:
        """The scene's ``[motion]``: record i times its selection's factor times ``load_factor``."""
        factor = float(load_factor) * self.scale(i)
        return RecordMotion(self.files[i], None, self.units, None, False, None, None, factor)

    def describe(self) -> str:
        """One line."""
        folder = self.folder if self.folder is not None else Path(self.files[0]).parent if self.files else Path(".")
        text = f"{self.count} record file{'' if self.count == 1 else 's'} of {folder}"
        if self.selection is None:
            return text
        s = self.selection
        verdict = "compatible" if s.get("compatible") else "NOT compatible"
        dev, period = s.get("worst_deviation"), s.get("worst_deviation_period_s")
        worst = f"worst deviation {100 * dev:+.1f} % at {period:.3g} s" if dev is not None and period else ""
        few = (
            "; fewer than 7 records: NTC 2018 7.3.5 takes the most unfavourable record's effects, not the mean"
            if self.count < 7
            else ""
        )
        return (
            f"{text}: the selection {s['selection']} (rockyade motion select), each scaled by its factor, {verdict} "
            f"with the site's spectrum (NTC 2018 3.2.3.6; {worst}); lambda = 1 is its scaling{few}"
        )

    def to_dict(self) -> dict[str, object]:
        """JSON-ready."""
        out: dict[str, object] = {"kind": "records", "files": list(self.files), "units": self.units}
        if self.scale_factors is not None:
            out["scale_factors"] = list(self.scale_factors)
            out["selection"] = self.selection
        return out

    def check_site(self, site_dict: dict[str, Any]) -> None:
        """Refuse a selection made for another site than ``site_dict`` (a site's ``to_dict``): its
        factors scale the records to that site's spectrum. Nothing to check outside a selection."""
        if self.selection is None:
            return
        made = self.selection.get("site") or {}
        keys = (
            *("spectrum_code", "ag_m_s2", "F0", "TC_star_s", "soil", "topography", "topography_height_ratio"),
            *("spectrum_type", "ground", "importance_factor"),
        )
        differ = [k for k in keys if (k in made or k in site_dict) and not _same(made.get(k), site_dict.get(k))]
        if differ:
            k = differ[0]
            raise InputError(
                "--records",
                f"the selection {self.selection['selection']} was made for another site ({k} = {made.get(k)!r} there, "
                f"{site_dict.get(k)!r} here): its factors scale the records to that site's spectrum; select again "
                "with this site's options",
            )


@dataclass(frozen=True)
class SyntheticSuite:
    """The records of a synthetic suite (module docstring).

    Attributes
    ----------
    template
        The ``[motion]`` of record 1 at load factor 1; record i is the same with ``record = i + 1``.
    count
        Records used (the first ``count`` of the suite).
    """

    template: SyntheticMotion
    count: int

    @property
    def spec(self) -> SuiteSpec:
        """The suite's settings."""
        return self.template.suite_spec()

    def label(self, i: int) -> str:
        """Record i (0-based): ``<suite> record 01``."""
        return f"{self.template.suite} record {i + 1:02d}"

    def record(self, i: int) -> Record:
        """Record i, from the cache or generated (then cached)."""
        return suite_record(self.spec, i + 1)

    def motion(self, i: int, load_factor: float) -> MotionSpec:
        """The scene's ``[motion]``: record i times ``load_factor``."""
        return dataclasses.replace(self.template, record=i + 1, load_factor=float(load_factor))

    def describe(self) -> str:
        """One line."""
        spec = self.spec
        return f"{self.count} records of the synthetic suite '{spec.name}' ({spec.target.label}, seed {spec.seed})"

    def to_dict(self) -> dict[str, object]:
        """JSON-ready."""
        spec = self.spec
        return {
            "kind": "synthetic",
            "suite": spec.name,
            "count": self.count,
            "seed": spec.seed,
            "target": spec.target.as_dict(),
            "envelope_s": [spec.envelope.rise_s, spec.envelope.strong_s, spec.envelope.decay_s],
            "dt_s": spec.dt_s,
        }


MotionSet = RecordFiles | SyntheticSuite


def records_in_folder(folder: str | Path, units: str | None = None, field: str = "--records") -> RecordFiles:
    """The record files of a folder (module docstring), each read once now so that a bad
    file is reported before any run.

    Raises
    ------
    InputError
        Not a folder, no record file in it, more than :data:`MAX_RECORDS`, a file that does
        not read, or the same accelerogram twice.
    """
    path = Path(folder)
    if not path.is_dir():
        raise InputError(field, f"{path} is not a folder of record files")
    if is_selection(path):
        return selection_records(path, units, field)
    files = record_files(path, field)
    if not files:
        raise InputError(field, f"no record file ({', '.join(RECORD_SUFFIXES)}) in {path}")
    if len(files) > MAX_RECORDS:
        raise InputError(field, f"{len(files)} record files in {path}, more than {MAX_RECORDS}")
    if units is not None:
        units = normalise_units(units, "--units")
    records = RecordFiles(tuple(str(f.resolve()) for f in files), units, str(folder))
    read = [records.record(i) for i in range(records.count)]
    _refuse_duplicates(read, [f.name for f in files], field)
    return records


def selection_records(folder: Path, units: str | None = None, field: str = "--records") -> RecordFiles:
    """The records of a selection folder (``rockyade motion select``), checked
    (:func:`rockyade.motion.selection_set.read_selection`) and read once now.

    Raises
    ------
    InputError
        ``units`` given (a selection's records name theirs as read when selected), or a damaged selection.
    """
    if units is not None:
        raise InputError(
            "--units", "applies to a folder of records, not to a selection (its records were read already)"
        )
    chosen = read_selection(folder, field)
    records = RecordFiles(chosen.files, None, str(folder), chosen.scale_factors, chosen.summary())
    for i in range(records.count):
        records.record(i)
    return records


def _same(a: Any, b: Any) -> bool:
    """Two values of a site's description alike (numbers to 1e-9 relative)."""
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
    return a == b


def record_files(folder: Path, field: str = "--records") -> list[Path]:
    """The record files of a folder, sorted by name: its files whose names end in one of
    :data:`RECORD_SUFFIXES`. A symbolic link named so and leading to a regular file is
    followed and counted as the file it names (a folder of links to a shared set of records
    reads as that set). Nothing else is followed or skipped silently: a subfolder (records are
    not read from it) and any other link (to a folder, to nothing, or without a record
    suffix) are refused, naming them. Hidden entries (``.name``), Python's bytecode folder
    (``__pycache__``, written beside a script of the folder that was imported, as
    ``examples/records/make_example_records.py``) and other regular files (a README) are not
    records and are left alone.

    Raises
    ------
    InputError
        A subfolder, or a link that is not a record link.
    """
    files = []
    for p in sorted(folder.iterdir()):
        record_name = p.suffix.lower() in RECORD_SUFFIXES
        if p.is_symlink():
            if record_name and p.is_file():
                files.append(p)
                continue
            what = "a folder" if p.is_dir() else "a file without a record suffix" if p.is_file() else "nothing"
            raise InputError(
                field,
                f"{p} is a symbolic link to {what} ({os.readlink(p)}), not to a record file; the records are read "
                f"from {folder} itself, links only to record files ({', '.join(RECORD_SUFFIXES)}): remove or fix it",
            )
        if p.name.startswith(".") or (p.name == "__pycache__" and p.is_dir()):
            continue
        if p.is_dir():
            raise InputError(
                field,
                f"{p} is a subfolder: records are read from {folder} itself, not from its subfolders; give "
                "the subfolder as the records folder, or move its files up",
            )
        if record_name and p.is_file():
            files.append(p)
    return files


def _refuse_duplicates(records: Sequence[Record], names: Sequence[str], field: str) -> None:
    """InputError when two files hold the same accelerogram (to 1e-5 of its peak)."""
    for j, b in enumerate(records):
        for i in range(j):
            a = records[i]
            if a.npts != b.npts or not np.allclose(a.t_s, b.t_s, rtol=0, atol=1e-9 * max(a.duration_s, 1.0)):
                continue
            scale = max(a.pga_m_s2, b.pga_m_s2, 1e-12)
            if np.max(np.abs(a.accel_m_s2 - b.accel_m_s2)) <= 1e-5 * scale:
                raise InputError(
                    field,
                    f"{names[i]} and {names[j]} hold the same accelerogram: it would count twice; keep one of them",
                )


def ec8_suite(
    spectrum_type: int, ground: str, ag_m_s2: float, count: int = 20, seed: int = 1, name: str | None = None
) -> SyntheticSuite:
    """A synthetic suite compatible with the EC8 elastic spectrum of a site.

    Parameters
    ----------
    spectrum_type, ground
        1 or 2; A-E.
    ag_m_s2
        Design ground acceleration on type A ground, m/s^2 (the suite's target is ag S).
    count
        Records, 1 to :data:`MAX_SUITE_RECORDS`.
    seed
        The suite's seed (record i: ``SeedSequence(seed, spawn_key=(i,))``).
    name
        The suite's name (default ``ec8-<type><ground>``).
    """
    from rockyade.motion.ec8 import EC8_GROUND, ElasticSpectrum

    _check_count(count, MAX_SUITE_RECORDS)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError("--seed", f"must be an integer >= 0, got {seed!r}")
    target = ElasticSpectrum.ec8(spectrum_type, ground, ag_m_s2=ag_m_s2)  # checks type and ground
    S = EC8_GROUND[spectrum_type][str(ground).upper()][0]
    template = SyntheticMotion(
        record=1,
        suite=name or f"ec8-{spectrum_type}{str(ground).upper()}",
        spectrum_type=spectrum_type,
        ground=str(ground).upper(),
        ag_s_m_s2=float(ag_m_s2 * S),
        seed=seed,
        count=count,
        load_factor=1.0,
    )
    assert abs(template.suite_spec().target.ag_s_m_s2 - target.ag_s_m_s2) <= 1e-12 * target.ag_s_m_s2
    return SyntheticSuite(template, count)


def paper_suite_set(count: int = 30) -> SyntheticSuite:
    """The first ``count`` records of the paper's suite (EC8 Type 2, ground D, ag S = 2.8 m/s^2)."""
    _check_count(count, paper_suite().count)
    return SyntheticSuite(SyntheticMotion(record=1, suite="paper"), count)


def _check_count(count: int, most: int) -> None:
    if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= most:
        raise InputError("--count", f"must be an integer in [1, {most}] records, got {count!r}")


def record_summary(job: tuple[MotionSet, int, Measure | None]) -> dict[str, float]:
    """Duration (s), PGA (m/s^2) and the measure (SI; NaN without one) of record i of a set
    at load factor 1, the record generated or read where the job runs.

    Parameters
    ----------
    job
        (the set, the record's 0-based index, the intensity measure or None).
    """
    motions, i, measure = job
    record = motions.record(i)
    value = measure.of_record(record) if measure is not None and measure.kind != "ag" else float("nan")
    return {"duration_s": record.duration_s, "pga_m_s2": record.pga_m_s2, "im_si": value}
