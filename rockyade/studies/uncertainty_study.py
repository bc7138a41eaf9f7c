"""Uncertainty propagation: a block whose alpha, p, mu are uncertain, under a suite of records.

The classical parameters are drawn from distributions (:mod:`rockyade.studies.sampling`:
normal, lognormal or uniform per parameter, or the joint normal of an identification) by
Latin hypercube with an explicit seed; records bring the record-to-record variation. Each
(sample, record, load factor, solver) is one run of the batch engine
(:func:`rockyade.batch.run_study_tasks`, local processes or Dask). The report gives,
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
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from rockyade.batch import BatchTask, batch_task, run_study_tasks
from rockyade.errors import InputError
from rockyade.io.atomic import atomic_open, write_json
from rockyade.io.fields import TableReader
from rockyade.io.locking import output_lock
from rockyade.io.resultset import replacing_set
from rockyade.motion.intensity import INTENSITY_MEASURES, check_measure, intensity_measures, scaled
from rockyade.runner.executor import SCHEDULER_TIMEOUT_S
from rockyade.solvers import solver_names
from rockyade.studies.sampling import (
    PARAMETERS,
    JointNormal,
    Marginal,
    draw_parameters,
    joint_from_identified,
    parse_marginal,
)

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
    block: dict[str, Any]
    nominal: dict[str, float]
    contact: dict[str, Any]
    motions: tuple[tuple[str, dict[str, Any]], ...]
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


def _block_table(r: TableReader, base_dir: Path) -> tuple[dict[str, Any], dict[str, float]]:
    """(block table without alpha/p/mu, nominal alpha/p/mu)."""
    from rockyade.scene import load_scene, scene_from_dict
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
    probe = scene_from_dict(
        {"duration_s": 1.0, "sample_dt_s": 0.1, "blocks": [table], "motion": {"type": "rest"}},
        source=r.source,
    )
    cp = probe.blocks[0].classical()
    nominal = {"alpha_rad": cp.alpha_rad, "p_rad_s": cp.p_rad_s, "mu": cp.mu}
    clean = {k: v for k, v in copy.deepcopy(table).items() if k not in PARAMETERS}
    clean.setdefault("name", "block")
    return clean, nominal


def _motions(r: TableReader, base_dir: Path) -> tuple[list[tuple[str, dict[str, Any]]], list[float], str]:
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
        motions = []
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


# ------------------------------------------------------------------ tasks


def draw_samples(study: UncertaintyStudy) -> pd.DataFrame:
    """The parameter samples: sample 0 the nominal block (when asked), 1..n the hypercube.

    Columns: sample, nominal, alpha_rad, p_rad_s, mu, and for pairing "sampled" the record.
    """
    extra = 1 if study.pairing == "sampled" else 0
    values, u = draw_parameters(study.samples, study.seed, study.marginals, study.joint, extra)
    frame = pd.DataFrame(values, columns=list(PARAMETERS))
    frame.insert(0, "nominal", False)
    frame.insert(0, "sample", np.arange(1, study.samples + 1))
    if extra:
        labels = [lab for lab, _ in study.motions]
        frame["record"] = [labels[min(int(x * len(labels)), len(labels) - 1)] for x in u[:, 0]]
    if study.include_nominal:
        nominal: dict[str, object] = {"sample": 0, "nominal": True, **study.nominal}
        if extra:
            nominal["record"] = "all"
        frame = pd.concat([pd.DataFrame([nominal]), frame], ignore_index=True)
    return frame


def build_tasks(study: UncertaintyStudy, samples: pd.DataFrame) -> list[BatchTask]:
    """One batch task per (sample, record, load factor, solver).

    A sample's scenes share everything but the motion: the first is read whole, the others
    are it with their motion (read, and checked with the block: :meth:`rockyade.scene.Scene.with_changes`)."""
    from rockyade.motion.spec import parse_motion
    from rockyade.scene import scene_from_dict
    from rockyade.solvers import make_solver

    solvers = [make_solver(name) for name in study.solvers]
    motions = dict(study.motions)
    source = study.source or None
    tasks = []
    index = 0
    for row in samples.itertuples(index=False):
        block = dict(study.block, alpha_rad=float(row.alpha_rad), p_rad_s=float(row.p_rad_s), mu=float(row.mu))
        records = [row.record] if study.pairing == "sampled" and not row.nominal else list(motions)
        first = None
        for record in records:
            for lf in study.load_factors:
                motion = dict(motions[record], load_factor=lf)
                if first is None:
                    first = scene_from_dict(
                        {
                            "duration_s": study.duration_s,
                            "sample_dt_s": study.sample_dt_s,
                            "blocks": [block],
                            "contact": copy.deepcopy(study.contact),
                            "motion": motion,
                        },
                        source=source,
                    )
                    scene = first
                else:
                    scene = first.with_changes(motion=parse_motion(motion, source))
                labels = {
                    "base": study.name,
                    "sample": int(row.sample),
                    "nominal": bool(row.nominal),
                    "record": record,
                    "load_factor": lf,
                    "alpha_rad": float(row.alpha_rad),
                    "p_rad_s": float(row.p_rad_s),
                    "mu": float(row.mu),
                }
                for solver in solvers:
                    tasks.append(batch_task(index, solver, scene, labels, save_history=False))
                    index += 1
    return tasks


def record_measures(study: UncertaintyStudy) -> dict[str, dict[str, float]]:
    """Intensity measures of each record at load factor 1 (the motion alone), by label."""
    from rockyade.motion.spec import parse_motion

    out = {}
    for label, table in study.motions:
        motion = parse_motion(dict(table, load_factor=1.0), study.source or None).ground_motion(study.duration_s)
        assert motion is not None  # a record's motion always has a ground acceleration (None: free rocking)
        out[label] = intensity_measures(motion)
    return out


def with_measures(runs: pd.DataFrame, measures: dict[str, dict[str, float]], g: float | None = None) -> pd.DataFrame:
    """The runs with the intensity measures of their scaled record and block."""
    from rockyade.constants import G

    g = G if g is None else g
    rows = []
    for rec, lf, alpha, p in zip(runs["record"], runs["load_factor"], runs["alpha_rad"], runs["p_rad_s"], strict=True):
        im = scaled(measures[rec], float(lf))
        uplift = g * math.tan(alpha)
        im["pga_over_g_tan_alpha"] = im["pga_m_s2"] / uplift
        im["pgv_p_over_g_tan_alpha"] = im["pgv_m_s"] * p / uplift
        rows.append(im)
    return pd.concat([runs.reset_index(drop=True), pd.DataFrame(rows)], axis=1)


# ------------------------------------------------------------------ run


@dataclass
class UncertaintyResult:
    """What an uncertainty study produced (frames also written as CSV in ``out``)."""

    study: UncertaintyStudy
    out: Path
    samples: pd.DataFrame
    runs: pd.DataFrame
    probabilities: pd.DataFrame
    fragility: pd.DataFrame
    spread: pd.DataFrame | None
    figure: Path | None


def prepare(study: UncertaintyStudy) -> None:
    """Generate (and cache) the synthetic records once, before workers start."""
    from rockyade.motion.synthetic import paper_suite, suite_record

    for _label, table in study.motions:
        if table["type"] == "synthetic":
            suite_record(paper_suite(), int(table["record"]))


def run_uncertainty(
    study: UncertaintyStudy,
    out: str | Path,
    *,
    executor: str = "local",
    workers: int = 2,
    scheduler: str | None = None,
    scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
    resume: bool = False,
    progress: bool = True,
    figure: bool = True,
    accel_unit: str = "g",
    group_runs: bool = True,
) -> UncertaintyResult:
    """Draw the samples, run every task through the batch engine and write the report
    (``accel_unit``: "g" or "m/s2", the unit of a PGA axis in the figure).

    With ``group_runs`` the runs of one sample (one block: every record and load factor)
    go to the solver as groups (:func:`rockyade.batch.running.job_key`: one model, the same
    rows); False: one run per job.

    Each run is written as it ends (the batch engine's journal: ``runs/``); ``resume`` keeps
    the runs an interrupted study of the same name, samples and seed left
    (:func:`rockyade.runner.journal.claim` refuses another's); the report files are a set
    replaced as a whole (:mod:`rockyade.io.resultset`)."""
    out = Path(out)
    samples = draw_samples(study)
    prepare(study)
    tasks = build_tasks(study, samples)
    summary = run_study_tasks(
        tasks,
        out,
        executor=executor,
        workers=workers,
        scheduler=scheduler,
        scheduler_timeout_s=scheduler_timeout_s,
        resume=resume,
        progress=progress,
        desc=study.name,
        group_runs=group_runs,
        identity={"command": "uncertainty", "study": study.name, "samples": study.samples, "seed": study.seed},
    )
    with output_lock(out, "out"), replacing_set(out, REPORT_SET, REPORT_LAST) as stage:
        _write_csv(stage / "samples.csv", samples)
        return _report(study, out, stage, samples, summary, figure, accel_unit)


#: The report's files, a set replaced as a whole, and the one that marks it complete.
REPORT_SET = (
    "samples.csv",
    "runs.csv",
    "probabilities.csv",
    "fragility.csv",
    "spread.csv",
    "uncertainty.png",
    "uncertainty.json",
)
REPORT_LAST = "uncertainty.json"


def _report(
    study: UncertaintyStudy,
    out: Path,
    stage: Path,
    samples: pd.DataFrame,
    summary: pd.DataFrame,
    figure: bool,
    accel_unit: str,
) -> UncertaintyResult:
    """Write the report's files in ``stage`` (swapped in for the set in ``out`` after)."""
    from rockyade.probability.exceedance import exceedance_table, fragility_table, spread_table

    runs = with_measures(summary, record_measures(study))
    runs["overturned"] = runs["status"] == "overturned"
    _write_csv(stage / "runs.csv", runs)
    sampled = runs[~runs["nominal"].astype(bool)]
    probabilities = exceedance_table(sampled, study.levels)
    _write_csv(stage / "probabilities.csv", probabilities)
    fragility = fragility_table(sampled, study.measures)
    _write_csv(stage / "fragility.csv", fragility)
    spread = spread_table(runs) if study.pairing == "all" else None
    if spread is not None:
        _write_csv(stage / "spread.csv", spread)
    fig_path = None
    if figure:
        from rockyade.figures.uncertainty_bands import plot_uncertainty

        fig_path = out / "uncertainty.png"
        stage_png = stage / "uncertainty.png"
        plot_uncertainty(study, probabilities, sampled, fragility, spread, stage_png, accel_unit=accel_unit)
    write_json(
        stage / "uncertainty.json",
        {
            "name": study.name,
            "source": study.source,
            "solvers": list(study.solvers),
            "samples": study.samples,
            "seed": study.seed,
            "pairing": study.pairing,
            "records": [label for label, _ in study.motions],
            "load_factors": list(study.load_factors),
            "parameters": study.describe_parameters(),
            "nominal": study.nominal,
            "runs": len(runs),
            "failed_runs": int((runs["status"] == "failed").sum()),
            "probabilities": probabilities.to_dict(orient="records"),
            "fragility": fragility.to_dict(orient="records"),
            "spread": None if spread is None else spread.to_dict(orient="records"),
        },
    )
    return UncertaintyResult(study, out, samples, runs, probabilities, fragility, spread, fig_path)


def _write_csv(path: Path, frame: pd.DataFrame) -> None:
    with atomic_open(path) as fh:
        frame.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
