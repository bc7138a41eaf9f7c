"""Uncertainty propagation: Latin hypercube samples of alpha, p, mu, runs through the batch
engine, probabilities with Wilson bands, fragility against intensity measures, the spread."""

from __future__ import annotations

import json
import os

import numpy as np
import pandas as pd
import pytest

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.probability.exceedance import level_column
from rockyade.probability.fragility_curves import wilson_interval
from rockyade.studies.sampling import Marginal, draw_parameters, joint_from_identified
from rockyade.studies.uncertainty import run_uncertainty, uncertainty_study_from_dict
from tests.conftest import EXAMPLES


def _study(**changes) -> dict:
    data = {
        "name": "tiny",
        "solvers": ["housner"],
        "samples": 4,
        "seed": 7,
        "duration_s": 20.0,
        "sample_dt_s": 0.01,
        "theta_over_alpha_levels": [0.5, 1.0],
        "intensity_measures": ["pga_over_g_tan_alpha", "pgv_m_s"],
        "block": {"specimen": "1"},
        "parameters": {
            "alpha_rad": {"distribution": "uniform", "mean": 0.235, "plus_minus_pct": 5},
            "mu": {"distribution": "normal", "mean": 0.936, "cov": 0.01},
        },
        "motion": {"suite": "paper", "records": [1, 2], "load_factors": [1.2, 1.5], "pairing": "all"},
    }
    data.update(changes)
    return data


@pytest.mark.slow
def test_small_study_probabilities_match_independent_runs(tmp_path):
    from rockyade.scene import scene_from_dict
    from rockyade.solvers.housner import HousnerSolver

    study = uncertainty_study_from_dict(_study())
    result = run_uncertainty(study, tmp_path, workers=1, progress=False)
    runs = result.runs
    assert len(runs) == (4 + 1) * 2 * 2  # (samples + nominal) x records x load factors
    assert (runs["status"] != "failed").all()
    assert set(result.samples["sample"]) == {0, 1, 2, 3, 4}
    # p fixed at the nominal value, alpha and mu varied
    assert runs["p_rad_s"].nunique() == 1 and runs["alpha_rad"].nunique() == 5
    sampled = runs[~runs["nominal"]]
    for _, row in result.probabilities.iterrows():
        sel = sampled[sampled["load_factor"] == row["load_factor"]]
        k = int((sel["status"] == "overturned").sum())
        assert row["p_overturn"] == k / len(sel)
        assert (row["p_overturn_lo"], row["p_overturn_hi"]) == pytest.approx(wilson_interval(k, len(sel)))
        k_half = int(((sel["max_theta_over_alpha"] >= 0.5) | (sel["status"] == "overturned")).sum())
        assert row[level_column(0.5)] == k_half / len(sel)
    # one run checked against the solver called directly
    one = sampled.iloc[3]
    block = {
        "name": "specimen1",
        "vertices_m": [[-0.125, 0.0], [0.125, 0.0], [0.125, 1.0], [-0.125, 1.0]],
        "thickness_m": 0.754,
        "mass_kg": 503.0,
        "alpha_rad": one["alpha_rad"],
        "p_rad_s": one["p_rad_s"],
        "mu": one["mu"],
    }
    rec = int(one["record"].split("-")[1])
    motion = {"type": "synthetic", "suite": "paper", "record": rec, "load_factor": one["load_factor"]}
    scene = scene_from_dict({"duration_s": 20.0, "sample_dt_s": 0.01, "blocks": [block], "motion": motion})
    direct = HousnerSolver().run(scene)
    assert direct.status == one["status"]
    peak = np.max(np.abs(direct.series("theta_rad"))) / one["alpha_rad"]
    assert peak == pytest.approx(one["max_theta_over_alpha"], rel=1e-9)
    # intensity measures: PGA / (g tan alpha) uses the sample's alpha
    assert one["pga_over_g_tan_alpha"] == pytest.approx(one["pga_m_s2"] / (9.81 * np.tan(one["alpha_rad"])))
    spread = result.spread
    assert spread is not None and len(spread) == 2
    nominal = runs[runs["nominal"]]
    for row in spread.itertuples(index=False):
        sel = nominal[nominal["load_factor"] == row.load_factor]
        assert row.p_overturn_nominal == (sel["status"] == "overturned").mean()
    for name in ("samples.csv", "runs.csv", "probabilities.csv", "fragility.csv", "spread.csv", "summary.csv"):
        assert (tmp_path / name).is_file()
    assert (tmp_path / "uncertainty.png").stat().st_size > 20_000
    report = json.loads((tmp_path / "uncertainty.json").read_text())
    assert report["runs"] == 20 and report["seed"] == 7


def test_sampled_pairing_and_dask_give_the_same_runs(tmp_path):
    study = uncertainty_study_from_dict(
        _study(
            samples=3,
            nominal=False,
            motion={"suite": "paper", "records": [1, 2], "load_factors": [1.5], "pairing": "sampled"},
        )
    )
    local = run_uncertainty(study, tmp_path / "local", workers=1, progress=False, figure=False)
    assert len(local.runs) == 3  # one record per sample
    assert set(local.samples["record"]) <= {"paper-1", "paper-2"}
    dask = run_uncertainty(study, tmp_path / "dask", executor="dask", workers=2, progress=False, figure=False)
    cols = ["sample", "record", "alpha_rad", "mu", "status", "max_theta_over_alpha"]
    pd.testing.assert_frame_equal(local.runs[cols], dask.runs[cols])


def test_latin_hypercube_is_stratified_reproducible_and_truncated():
    marg = {
        "alpha_rad": Marginal("alpha_rad", "uniform", 0.2, 0.3),
        "p_rad_s": Marginal("p_rad_s", "lognormal", 4.0, 0.05),
        "mu": Marginal("mu", "normal", 0.99, 0.02),
    }
    values, extra = draw_parameters(20, 3, marg, extra_dimensions=1)
    strata = np.floor((values[:, 0] - 0.2) / 0.1 * 20).astype(int)
    assert sorted(strata) == list(range(20))  # one sample per stratum
    assert np.all(values[:, 2] <= 1.0) and np.all(values[:, 2] > 0.9)  # mu truncated to (0, 1]
    assert extra.shape == (20, 1) and np.all((extra > 0) & (extra < 1))
    again, _ = draw_parameters(20, 3, marg, extra_dimensions=1)
    np.testing.assert_array_equal(values, again)
    other, _ = draw_parameters(20, 4, marg, extra_dimensions=1)
    assert not np.allclose(values, other)


def test_every_sample_is_a_block_its_runs_take():
    """mu beyond the 0.9999 a scene takes, or p beyond 0.99 sqrt(g / R), was drawn and the
    sample's scenes refused ('blocks[0].mu: must be in [0.05, 0.9999], got 0.99991583' from
    specimen 2 +/-5 % in ``make bench-all``): samples are drawn in the ranges a scene takes for
    the block, and a distribution cut there by more than 1 % is said."""
    import warnings

    from rockyade.errors import InputNote
    from rockyade.scene import scene_from_dict
    from rockyade.scene.bounds import p_range
    from rockyade.studies.uncertainty.sample_tasks import build_tasks, draw_samples

    cases = (
        ("mu", {"mu": {"distribution": "normal", "mean": 0.99, "std": 0.01}}),
        ("p_rad_s", {"p_rad_s": {"distribution": "lognormal", "mean": 4.05, "cov": 0.3}}),
    )
    for name, parameters in cases:
        data = _study(block={"specimen": "2"}, parameters=parameters, samples=60, seed=1)
        data["motion"] = dict(data["motion"], records=[1], load_factors=[1.0])
        study = uncertainty_study_from_dict(data)
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            samples = draw_samples(study)
        probe = scene_from_dict(
            {"duration_s": 1.0, "sample_dt_s": 0.1, "blocks": [dict(study.block)], "motion": {"type": "rest"}}
        )
        hi = {"mu": 0.9999, "p_rad_s": p_range(probe.blocks[0].block())[1]}[name]
        assert hi * 0.99 < samples[name].max() <= hi  # the range reached, never passed
        notes = [str(w.message) for w in said if issubclass(w.category, InputNote)]
        assert len(notes) == 1 and notes[0].startswith(f"parameters.{name}: ") and f"{hi:.6g}" in notes[0]
        assert len(build_tasks(study, samples)) == len(samples)  # every sample's scene is taken


def test_joint_normal_from_an_identification_keeps_its_covariance():
    cov = np.array([[4e-6, -6e-5, 0.0], [-6e-5, 1.6e-3, 0.0], [0.0, 0.0, 1e-8]])
    joint = joint_from_identified({"alpha_rad": 0.235, "p_rad_s": 3.84, "mu": 0.936, "covariance_alpha_p_mu": cov})
    values, _ = draw_parameters(4000, 1, joint=joint)
    np.testing.assert_allclose(values.mean(axis=0), [0.235, 3.84, 0.936], rtol=1e-3)
    sd = np.sqrt(np.diag(cov))
    np.testing.assert_allclose(values.std(axis=0), sd, rtol=0.05)
    np.testing.assert_allclose(np.corrcoef(values.T), cov / np.outer(sd, sd), atol=0.05)


def test_study_from_an_identified_file(tmp_path):
    ident = {
        "alpha_rad": 0.235,
        "p_rad_s": 3.84,
        "mu": 0.936,
        "alpha_rad_ci": [0.233, 0.237],
        "p_rad_s_ci": [3.80, 3.88],
        "mu_ci": [0.935, 0.937],
    }
    (tmp_path / "identified.json").write_text(json.dumps(ident))
    data = _study(parameters={"identified": "identified.json", "std_factor": 2.0})
    study = uncertainty_study_from_dict(data, str(tmp_path / "s.toml"), tmp_path)
    assert study.joint is not None
    sd = np.sqrt(np.diag(np.array(study.joint.covariance)))
    assert sd[0] == pytest.approx(2.0 * 0.002 / 1.959964, rel=1e-5)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"parameters": {"mu": {"distribution": "beta", "mean": 0.9, "std": 0.1}}}, "parameters.mu.distribution"),
        ({"parameters": {"mu": {"distribution": "normal", "mean": 0.9}}}, "parameters.mu.distribution"),
        ({"parameters": {"mu": {"distribution": "normal", "mean": 1.5, "std": 0.01}}}, "parameters.mu"),
        ({"motion": {"records": [0], "load_factors": [1.0]}}, "motion.records"),
        ({"motion": {"load_factors": [1.0], "pairing": "some"}}, "motion.pairing"),
        ({"solvers": ["udec"]}, "solvers"),
        ({"intensity_measures": ["pgd"]}, "intensity_measures"),
        ({"sample": 3}, "sample"),
    ],
)
def test_bad_studies_name_the_field(change, field):
    with pytest.raises(InputError) as err:
        study = uncertainty_study_from_dict(_study(**change))
        from rockyade.studies.uncertainty import draw_samples

        draw_samples(study)
    assert err.value.field == field


@pytest.mark.slow
def test_cli_uncertainty_on_the_example(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    rel = os.path.relpath(EXAMPLES / "studies" / "uncertainty_specimen1.toml", tmp_path)
    code = main(["uncertainty", rel, "--out", "unc", "--samples", "2", "--quiet", "--workers", "1"])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "P(overturn) per load factor" in out and "fragility" in out
    probabilities = pd.read_csv(tmp_path / "unc" / "probabilities.csv")
    assert list(probabilities["load_factor"]) == [0.8, 1.0, 1.2, 1.4]
    assert (probabilities["n_runs"] == 2 * 6).all()
    assert main(["uncertainty", "missing.toml", "--out", "x"]) == 2


def test_recorded_files_and_block_dimensions(tmp_path):
    """Records given as files (two-column CSV), a block given by its dimensions, lognormal p."""
    t = np.arange(0.0, 4.0, 0.005)
    for k, amp in enumerate((2.0, 3.5)):
        a = amp * np.sin(2 * np.pi * 1.5 * t) * (t < 2.0)
        pd.DataFrame({"t": t, "a": a}).to_csv(tmp_path / f"pulse{k}.csv", index=False)
    data = _study(
        samples=3,
        duration_s=6.0,
        intensity_measures=["arias_m_s"],
        block={"name": "wall", "width_m": 0.3, "height_m": 1.2, "thickness_m": 0.5, "density_kg_m3": 2000.0},
        parameters={"p_rad_s": {"distribution": "lognormal", "mean": 3.5, "cov": 0.05}},
        motion={"files": ["pulse0.csv", "pulse1.csv"], "load_factors": [1.0]},
    )
    study = uncertainty_study_from_dict(data, str(tmp_path / "s.toml"), tmp_path)
    result = run_uncertainty(study, tmp_path / "out", workers=1, progress=False, figure=False)
    runs = result.runs
    assert set(runs["record"]) == {"pulse0", "pulse1"} and len(runs) == 8
    assert runs["alpha_rad"].nunique() == 1  # alpha stays at the geometry's value
    assert runs.loc[runs.record == "pulse1", "arias_m_s"].iloc[0] == pytest.approx(
        (3.5 / 2.0) ** 2 * runs.loc[runs.record == "pulse0", "arias_m_s"].iloc[0], rel=1e-9
    )
    # the stronger pulse rocks the block further
    peak = runs.groupby("record")["max_theta_over_alpha"].median()
    assert peak["pulse1"] > peak["pulse0"]
    with pytest.raises(InputError, match=r"motion\.files"):
        uncertainty_study_from_dict(dict(data, motion={"files": ["none.csv"], "load_factors": [1.0]}), None, tmp_path)


@pytest.mark.slow
def test_grouped_runs_give_the_same_verdicts_peaks_and_probabilities(tmp_path):
    """Each sample's runs (one block, every record and load factor) as groups, Housner and the
    reference DEM: the same summary (verdicts, peaks, metrics) and tables as one run per job."""
    from rockyade.batch import comparable

    study = uncertainty_study_from_dict(
        _study(
            samples=2,
            duration_s=8.0,
            solvers=["housner", "reference"],
            motion={"suite": "paper", "records": [1, 2], "load_factors": [1.0, 2.5], "pairing": "all"},
        )
    )
    # both in this process's thread (the grouping is the question, not where runs run: a pool
    # process each only loaded the kernels again)
    kw = {"executor": "threads", "workers": 1, "progress": False, "figure": False}
    one = run_uncertainty(study, tmp_path / "one", group_runs=False, **kw)
    grouped = run_uncertainty(study, tmp_path / "grouped", **kw)
    runs = grouped.runs
    assert set(runs["solver"]) == {"housner", "reference"} and (runs["status"] != "failed").all()
    assert set(runs["status"]) == {"completed", "overturned"}
    batched = [json.loads(p.read_text()).get("batched") for p in (tmp_path / "grouped" / "runs").glob("*.json")]
    assert all(b is not None and b["runs"] == 4 for b in batched)  # every run in a group of its sample
    pd.testing.assert_frame_equal(comparable(one.runs), comparable(grouped.runs))
    pd.testing.assert_frame_equal(one.probabilities, grouped.probabilities)
    pd.testing.assert_frame_equal(one.fragility, grouped.fragility)


def test_a_samples_scenes_are_the_scenes_read_whole(tmp_path):
    """build_tasks reads a sample's first scene whole and changes only the motion of the
    others: the same scenes and hashes as reading each whole."""
    import copy

    from rockyade.scene import scene_from_dict
    from rockyade.studies.uncertainty import build_tasks, draw_samples

    study = uncertainty_study_from_dict(_study(samples=2))
    samples = draw_samples(study)
    tasks = build_tasks(study, samples)
    assert len(tasks) == 3 * 2 * 2
    for task in tasks:
        lab = task.labels
        block = dict(study.block, alpha_rad=lab["alpha_rad"], p_rad_s=lab["p_rad_s"], mu=lab["mu"])
        whole = scene_from_dict(
            {
                "duration_s": study.duration_s,
                "sample_dt_s": study.sample_dt_s,
                "blocks": [block],
                "contact": copy.deepcopy(study.contact),
                "motion": dict(dict(study.motions)[lab["record"]], load_factor=lab["load_factor"]),
            }
        )
        assert task.scene == whole and task.scene_hash == whole.scene_hash
