"""An uncertainty study's runs: the parameter samples (Latin hypercube, the nominal block
beside them), one task per (sample, record, load factor, solver), and the intensity measures of
each run's scaled record (:mod:`rockyade.studies.uncertainty`)."""

from __future__ import annotations

import copy
import math

import numpy as np
import pandas as pd

from rockyade.batch import BatchTask, batch_task
from rockyade.motion.intensity import intensity_measures, scaled
from rockyade.studies.sampling import PARAMETERS, Ranges, draw_parameters, parameter_ranges
from rockyade.studies.uncertainty.study_file import UncertaintyStudy, block_probe


def draw_samples(study: UncertaintyStudy) -> pd.DataFrame:
    """The parameter samples: sample 0 the nominal block (when asked), 1..n the hypercube.

    Columns: sample, nominal, alpha_rad, p_rad_s, mu, and for pairing "sampled" the record.
    """
    extra = 1 if study.pairing == "sampled" else 0
    ranges = sample_ranges(study)
    values, u = draw_parameters(study.samples, study.seed, study.marginals, study.joint, extra, ranges)
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


def sample_ranges(study: UncertaintyStudy) -> Ranges:
    """The range each parameter's samples are drawn in: those a scene takes for this block
    (:func:`rockyade.studies.sampling.parameter_ranges`, p's from the block's geometry), so that
    every sample is a block its runs can be given."""
    from rockyade.scene.bounds import p_range

    probe = block_probe(study.block, study.source or None)
    return parameter_ranges(p_range(probe.blocks[0].block()))


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


def prepare(study: UncertaintyStudy) -> None:
    """Generate (and cache) the synthetic records once, before workers start."""
    from rockyade.motion.suite_cache import suite_record
    from rockyade.motion.synthetic import paper_suite

    for _label, table in study.motions:
        record = table.get("record")
        if table["type"] == "synthetic" and isinstance(record, int):
            suite_record(paper_suite(), record)
