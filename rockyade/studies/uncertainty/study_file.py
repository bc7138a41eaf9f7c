"""An uncertainty study's file: its grammar, its errors, and :class:`UncertaintyStudy`.

An uncertainty study (:mod:`rockyade.studies.uncertainty`): a block whose alpha, p, mu are
uncertain, under a suite of records.

The classical parameters are drawn from distributions (:mod:`rockyade.studies.sampling`:
normal, lognormal or uniform per parameter, or the joint normal of an identification) by
Latin hypercube with an explicit seed; records bring the record-to-record variation. Each
(sample, record, load factor, solver) is one run of the study
(:func:`rockyade.batch.run_study`, local processes or Dask). The report gives,
per solver and load factor, the probability of overturning and of exceeding theta/alpha
levels with 95 % Wilson bands, lognormal fragility curves against intensity measures
(:mod:`rockyade.motion.intensity`), and, when every sample runs every record, the spread
that the parameters alone cause (per-sample probability of overturning, and the range of
the peak theta/alpha of each record across samples) beside the nominal block.

Study file (TOML)::

    name = "specimen1-uncertainty"
    solvers = ["housner"]                 # housner | reference | yade
    samples = 40                          # Latin hypercube samples of (alpha, p, mu)
    seed = 2024
    duration_s = 25.0
    sample_dt_s = 0.01
    nominal = true                        # also run the nominal block (sample 0)
    theta_over_alpha_levels = [0.25, 0.5, 1.0]
    intensity_measures = ["pga_m_s2", "pgv_m_s", "pga_over_g_tan_alpha"]

    [block]                               # specimen = "1" (experimental values are nominal),
    specimen = "1"                        # or scene = "file.toml" (+ block = "name"), or a
                                          # [[blocks]] table (width_m, height_m, thickness_m, ...)
    [contact]                             # the scenes' contact table (DEM solvers)
    calibration = "matched"

    [parameters]                          # identified = "identified.json" (joint normal,
    [parameters.alpha_rad]                # std_factor = 1; nominal = the identified values),
                                          # or one table per parameter
    distribution = "uniform"              # (a parameter without one keeps its nominal value)
    mean = 0.235
    plus_minus_pct = 5

    [motion]
    suite = "paper"                       # the paper's synthetic suite, or files = [...]
    records = [1, 2, 3, 4, 5]             # default: the whole suite
    load_factors = [0.4, 0.8, 1.2]
    pairing = "all"                       # every sample runs every record; "sampled": one
                                          # record per sample, drawn by the hypercube

Outputs in the study folder: ``samples.csv``, ``summary.csv`` and ``runs/`` (batch engine),
``runs.csv`` (every run with its intensity measures), ``probabilities.csv``,
``fragility.csv``, ``spread.csv`` (pairing "all"), ``uncertainty.png`` and
``uncertainty.json``.
"""

from __future__ import annotations

import copy
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rockyade.errors import InputError
from rockyade.io.fields import TableReader
from rockyade.motion.intensity import INTENSITY_MEASURES, check_measure
from rockyade.solvers import solver_names
from rockyade.studies.sampling import PARAMETERS, JointNormal, Marginal, joint_from_identified, parse_marginal

if TYPE_CHECKING:
    from rockyade.scene import Scene

PAIRINGS = ("all", "sampled")
DEFAULT_LEVELS = (0.25, 0.5, 1.0)
DEFAULT_MEASURES = ("pga_m_s2", "pgv_m_s", "pga_over_g_tan_alpha")


@dataclass(frozen=True)
class UncertaintyStudy:
    """A parsed uncertainty study (module docstring).

    Attributes
    ----------
    block
        The scene's block table without alpha/p/mu (geometry, mass, name).
    nominal
        The block's nominal alpha_rad, p_rad_s, mu.
    marginals, joint
        Per-parameter distributions, or the joint normal of an identification.
    motions
        (label, motion table at load factor 1) for each record.
    """

    name: str
    solvers: tuple[str, ...]
    samples: int
    seed: int
    duration_s: float
    sample_dt_s: float
    block: dict[str, object]
    nominal: dict[str, float]
    contact: dict[str, object]
    motions: tuple[tuple[str, dict[str, object]], ...]
    load_factors: tuple[float, ...]
    pairing: str = "all"
    include_nominal: bool = True
    levels: tuple[float, ...] = DEFAULT_LEVELS
    measures: tuple[str, ...] = DEFAULT_MEASURES
    marginals: dict[str, Marginal] | None = None
    joint: JointNormal | None = None
    source: str = ""
    notes: tuple[str, ...] = field(default=())

    def describe_parameters(self) -> dict[str, str]:
        """How each parameter is drawn."""
        if self.joint is not None:
            return {"alpha_rad, p_rad_s, mu": self.joint.describe()}
        assert self.marginals is not None
        return {k: m.describe() for k, m in self.marginals.items()}

    def with_samples(self, samples: int, seed: int | None = None) -> UncertaintyStudy:
        """The same study with another sample count (and seed)."""
        import dataclasses

        return dataclasses.replace(self, samples=samples, seed=self.seed if seed is None else seed)


# ------------------------------------------------------------------ reading


def block_probe(table: Mapping[str, object], source: str | None = None) -> Scene:
    """A scene of the block ``table`` alone, at rest: read and checked as any scene's block (its
    classical parameters, its geometry's ranges)."""
    from rockyade.scene import scene_from_dict

    return scene_from_dict(
        {"duration_s": 1.0, "sample_dt_s": 0.1, "blocks": [dict(table)], "motion": {"type": "rest"}},
        source=source,
    )


def _block_table(r: TableReader, base_dir: Path) -> tuple[dict[str, object], dict[str, float]]:
    """(block table without alpha/p/mu, nominal alpha/p/mu)."""
    from rockyade.scene import load_scene
    from rockyade.studies.specimen_scenes import block_table

    if r.has("specimen"):
        key = str(r.raw("specimen"))
        which = r.string("parameters", "experimental", choices=["experimental", "theoretical"])
        r.finish()
        table = block_table(key, which)
    elif r.has("scene"):
        scene = load_scene(base_dir / r.string("scene"))
        name = r.string("block", None)
        r.finish()
        blocks = scene.to_dict()["blocks"]
        chosen = [b for b in blocks if name in (None, b.get("name"))]
        if len(chosen) != 1:
            raise r.error("block", f"name one block of the scene ({', '.join(b.get('name', '?') for b in blocks)})")
        table = chosen[0]
    else:
        table = dict(r.table)
        r.used.update(table)
    cp = block_probe(table, r.source).blocks[0].classical()
    nominal = {"alpha_rad": cp.alpha_rad, "p_rad_s": cp.p_rad_s, "mu": cp.mu}
    clean = {k: v for k, v in copy.deepcopy(table).items() if k not in PARAMETERS}
    clean.setdefault("name", "block")
    return clean, nominal


def _motions(r: TableReader, base_dir: Path) -> tuple[list[tuple[str, dict[str, object]]], list[float], str]:
    load_factors = r.number_list("load_factors")
    if any(f <= 0 for f in load_factors):
        raise r.error("load_factors", f"must all be > 0, got {load_factors}")
    pairing = r.string("pairing", "all", choices=PAIRINGS)
    files = r.raw("files", None)
    if files is not None:
        if r.has("suite") or r.has("records"):
            raise r.error("files", "give either files (recorded accelerograms) or a synthetic suite with records")
        if not isinstance(files, list) or not files or not all(isinstance(f, str) for f in files):
            raise r.error("files", "must be a non-empty list of record file paths")
        motions: list[tuple[str, dict[str, object]]] = []
        for f in files:
            path = (base_dir / f).resolve()
            if not path.is_file():
                raise r.error("files", f"record file not found: {path}")
            motions.append((path.stem, {"type": "record", "file": str(path)}))
    else:
        suite = r.string("suite", "paper", choices=["paper"])
        records = r.raw("records", "all")
        if records == "all":
            records = list(range(1, 31))
        if (
            not isinstance(records, list)
            or not records
            or not all(isinstance(i, int) and not isinstance(i, bool) and 1 <= i <= 30 for i in records)
        ):
            raise r.error("records", f'must be "all" or a list of record numbers 1-30, got {records!r}')
        motions = [(f"{suite}-{i}", {"type": "synthetic", "suite": suite, "record": i}) for i in records]
    r.finish()
    return motions, load_factors, pairing


def load_uncertainty_study(path: str | Path) -> UncertaintyStudy:
    """Read and validate an uncertainty study file (module docstring)."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("study", f"file not found: {path}")
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError("study", f"not valid TOML: {exc}", source) from None
    return uncertainty_study_from_dict(data, source, path.parent)


def uncertainty_study_from_dict(data: Any, source: str | None = None, base_dir: Path | None = None) -> UncertaintyStudy:
    """Validate a study given as a dictionary (as read from TOML)."""
    from rockyade.identification.identified import load_identified

    base_dir = base_dir or Path.cwd()
    r = TableReader(data, "", source)
    name = r.string("name", Path(source).stem if source else "uncertainty")
    solvers = r.raw("solvers", ["housner"])
    if not isinstance(solvers, list) or not solvers or any(s not in solver_names() for s in solvers):
        raise r.error("solvers", f"must be a list of {', '.join(solver_names())}, got {solvers!r}")
    samples = r.integer("samples", lo=1, hi=100_000)
    seed = r.integer("seed", lo=0)
    duration = r.positive("duration_s", unit="s")
    sample_dt = r.positive("sample_dt_s", 0.01, unit="s")
    include_nominal = r.boolean("nominal", True)
    levels = r.number_list("theta_over_alpha_levels", list(DEFAULT_LEVELS))
    if any(v <= 0 for v in levels):
        raise r.error("theta_over_alpha_levels", f"must all be > 0, got {levels}")
    measures = r.raw("intensity_measures", list(DEFAULT_MEASURES))
    if not isinstance(measures, list) or not measures:
        raise r.error("intensity_measures", f"must be a list of {', '.join(INTENSITY_MEASURES)}")
    for m in measures:
        check_measure(m, r.field("intensity_measures"))
    block, nominal = _block_table(r.sub("block"), base_dir)
    contact = dict(r.raw("contact", {"calibration": "matched"}))
    contact.setdefault("calibration", "matched")
    motions, load_factors, pairing = _motions(r.sub("motion"), base_dir)
    params = r.sub("parameters")
    marginals: dict[str, Marginal] | None = None
    joint = None
    if params.has("identified"):
        ident_path = base_dir / params.string("identified")
        factor = params.positive("std_factor", 1.0)
        params.finish()
        identified = load_identified(ident_path, field=params.field("identified"), named_in=r.source)
        joint = joint_from_identified(identified, factor, str(ident_path))
        nominal = dict(zip(PARAMETERS, joint.mean, strict=True))  # the identified block is the nominal one
    else:
        marginals = {}
        for k in PARAMETERS:
            if params.has(k):
                marginals[k] = parse_marginal(params.sub(k), k)
            else:
                marginals[k] = Marginal(k, "fixed", nominal[k], nominal[k])
        params.finish()
    r.finish()
    return UncertaintyStudy(
        name=name,
        solvers=tuple(solvers),
        samples=samples,
        seed=seed,
        duration_s=duration,
        sample_dt_s=sample_dt,
        block=block,
        nominal=nominal,
        contact=contact,
        motions=tuple(motions),
        load_factors=tuple(load_factors),
        pairing=pairing,
        include_nominal=include_nominal,
        levels=tuple(levels),
        measures=tuple(measures),
        marginals=marginals,
        joint=joint,
        source=source or "",
    )
