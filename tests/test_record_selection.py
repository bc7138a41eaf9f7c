"""``rockyade motion select``: records of a folder selected and scaled to the site's spectrum
(NTC 2018 3.2.3.6), the set written as one result set and read back by ``assess --records``;
no set when none is compatible, said so with the best deviation and an estimate; bad input
refused naming the option."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pandas as pd
import pytest

from rockyade.assess import DynamicSettings, records_in_folder
from rockyade.assess.assessment import dynamic_plan
from rockyade.assess.site import NtcSite
from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.motion.analytic import Pulse
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.records import read_record
from rockyade.motion.selection import (
    BAND_ABOVE,
    BAND_BELOW,
    band_use,
    check_count,
    check_grid,
    optimal_factors,
    period_range,
    records_needed,
    select,
)
from rockyade.motion.spectra import response_spectrum
from rockyade.runner import Executor
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import rest_motion, stack

from .conftest import EXAMPLES

SITE = ["--ag", "0.2g", "--f0", "2.4", "--tc-star", "0.3", "--soil", "B"]
RECORDS = EXAMPLES / "site_records"


def site() -> NtcSite:
    return NtcSite(0.2, 2.4, 0.3, "B")


@pytest.fixture(scope="module")
def selection(tmp_path_factory):
    """The how-to's selection: 7 of the 10 example records for the how-to's site."""
    out = tmp_path_factory.mktemp("sel") / "sel"
    assert main(["motion", "select", "--records", str(RECORDS), "--count", "7", *SITE, "--out", str(out)]) == 0
    return out


@pytest.mark.slow
def test_the_set_written_is_compatible_when_checked_independently(selection):
    table = pd.read_csv(selection / "selection.csv")
    assert list(table.columns) == ["record", "scale_factor", "pga_m_s2", "pga_g"]
    assert len(table) == 7 and table["scale_factor"].between(0.5, 2.0).all()
    meta = json.loads((selection / "selection.json").read_text())
    assert meta["compatible"] is True and meta["command"] == "rockyade motion select"
    assert (selection / "spectra.png").read_bytes()[:4] == b"\x89PNG"
    # the copies beside the CSV, scaled by their factors: their mean within -10 %/+30 % of the site's spectrum
    target = site().spectrum
    periods = check_grid(target, (0.15, 2.0))
    spectra = []
    for name, factor, pga in table[["record", "scale_factor", "pga_m_s2"]].itertuples(index=False):
        record = read_record(selection / name)
        assert (selection / name).read_bytes() == (RECORDS / name).read_bytes()  # copied byte for byte
        assert factor * record.pga_m_s2 == pytest.approx(pga, rel=1e-6)
        spectra.append(factor * response_spectrum(record.accel_m_s2, record.dt_s, periods, 0.05)[1])
    ratio = np.mean(spectra, axis=0) / target.psa(periods)
    assert ratio.min() >= 1 - BAND_BELOW - 1e-6 and ratio.max() <= 1 + BAND_ABOVE + 1e-6
    assert meta["worst_deviation"] == pytest.approx(ratio.min() - 1, abs=1e-6)  # the lower edge is the closer here


def test_the_shipped_selection_is_what_the_command_writes(selection):
    """examples/site_selection (which the docs' assess command reads) is the fixture's set."""
    shipped = EXAMPLES / "site_selection"
    assert (shipped / "selection.csv").read_bytes() == (selection / "selection.csv").read_bytes()
    for name in pd.read_csv(shipped / "selection.csv")["record"]:
        assert (shipped / name).read_bytes() == (RECORDS / name).read_bytes()
    meta = json.loads((shipped / "selection.json").read_text())
    assert meta["compatible"] and meta["records_folder"] == "examples/site_records"
    assert records_in_folder(shipped).count == 7


@pytest.mark.slow
def test_selecting_again_gives_the_same_set_and_replaces_it_whole(selection, tmp_path, capsys):
    out = tmp_path / "again"
    shutil.copytree(selection, out)
    before = (out / "selection.csv").read_bytes()
    assert main(["motion", "select", "--records", str(RECORDS), "--count", "8", *SITE, "--out", str(out)]) == 0
    capsys.readouterr()
    assert len(pd.read_csv(out / "selection.csv")) == 8 and (out / "selection.csv").read_bytes() != before
    assert main(["motion", "select", "--records", str(RECORDS), "--count", "7", *SITE, "--out", str(out)]) == 0
    assert (out / "selection.csv").read_bytes() == before  # deterministic, and the 8th record's copy is gone
    names = set(pd.read_csv(out / "selection.csv")["record"])
    assert {p.name for p in out.iterdir() if not p.name.startswith(".")} == names | {
        "selection.csv",
        "selection.json",
        "spectra.png",
    }


def test_assess_reads_the_selection_scaled_and_says_so(selection):
    records = records_in_folder(selection)
    table = pd.read_csv(selection / "selection.csv")
    assert records.count == 7 and records.scale_factors == pytest.approx(tuple(table["scale_factor"]))
    assert records.record(0).pga_m_s2 == pytest.approx(table["pga_m_s2"][0], rel=1e-6)
    assert records.motion(0, 1.5).load_factor == pytest.approx(1.5 * table["scale_factor"][0])
    assert "compatible with the site's spectrum" in records.describe() and "worst deviation -" in records.describe()
    assert records.to_dict()["selection"]["count"] == 7
    scene = scene_from_dict(stack(widths_m=[0.25], heights_m=2.5, layout="column", motion=rest_motion()))
    one = Executor("threads", 1)
    plan = dynamic_plan(scene, site(), DynamicSettings(records=records, load_factors=(1.0,)), one, False)
    assert plan.stripes.im_si == pytest.approx((site().ag_m_s2,) * 7)  # lambda = 1: the selection's scaling
    with pytest.raises(InputError, match=r"--records: .* was made for another site \(ag_m_s2"):
        dynamic_plan(scene, NtcSite(0.25, 2.4, 0.3, "B"), DynamicSettings(records=records), one, False)


def test_a_damaged_selection_is_refused(selection, tmp_path):
    out = tmp_path / "damaged"
    shutil.copytree(selection, out)
    name = pd.read_csv(out / "selection.csv")["record"][0]
    (out / name).write_bytes((out / name).read_bytes().replace(b"0", b"1", 1))
    with pytest.raises(InputError, match="SHA-256 differs"):
        records_in_folder(out)
    (out / name).unlink()
    (out / name).symlink_to(RECORDS / name)
    with pytest.raises(InputError, match="missing \\(or not a regular file beside it\\)"):
        records_in_folder(out)
    meta = json.loads((out / "selection.json").read_text())
    (out / "selection.json").write_text(json.dumps({**meta, "command": "rockyade assess"}))
    with pytest.raises(InputError, match="was not written by 'rockyade motion select'"):
        records_in_folder(out)


@pytest.mark.parametrize(
    ("args", "option"),
    [
        (["--count", "11"], "--records"),  # the folder holds 10
        (["--count", "2"], "--count"),
        (["--count", "5"], "--count"),  # fewer than 7 without --max-response
        (["--t1", "2.5"], "--t1"),  # 2 T1 = 5 s: beyond the spectra's 4 s
        (["--scale-bounds", "2", "1"], "--scale-bounds"),
        (["--f0", "9"], "--f0"),
    ],
)
def test_bad_input_is_refused_naming_the_option(tmp_path, capsys, args, option):
    out = tmp_path / "sel"
    assert main(["motion", "select", "--records", str(RECORDS), *SITE, *args, "--out", str(out)]) == 2
    assert option in capsys.readouterr().err and not out.exists()


def test_an_out_folder_holding_other_files_or_the_records_is_refused(selection, tmp_path, capsys):
    other = tmp_path / "other"
    other.mkdir()
    (other / "assess.json").write_text("{}")
    for out in (other, RECORDS):
        assert main(["motion", "select", "--records", str(RECORDS), *SITE, "--out", str(out)]) == 2
        assert "--out" in capsys.readouterr().err
    assert main(["motion", "select", "--records", str(selection), *SITE]) == 2
    assert "is a selection" in capsys.readouterr().err


def test_an_out_folder_that_is_a_link_is_refused_and_nothing_is_written_through_it(tmp_path, capsys):
    """As every study's --out (rockyade.runner.study_folder): a link to an empty folder was written through."""
    target = tmp_path / "elsewhere"
    target.mkdir()
    link = tmp_path / "sel"
    link.symlink_to(target)
    dangling = tmp_path / "dangling"
    dangling.symlink_to(tmp_path / "nothing")
    for out in (link, dangling):
        assert main(["motion", "select", "--records", str(RECORDS), *SITE, "--out", str(out)]) == 2
        assert "--out" in (err := capsys.readouterr().err) and "symbolic link" in err
    assert not any(target.iterdir()) and not (tmp_path / "nothing").exists()


def test_three_records_with_the_maximum_response_rule(tmp_path, capsys):
    out = tmp_path / "three"
    args = ["--records", str(RECORDS), "--count", "3", "--max-response", *SITE, "--out", str(out)]
    assert main(["motion", "select", *args]) == 0
    assert "3 records: compatible" in capsys.readouterr().out
    assert "most unfavourable" in json.loads((out / "selection.json").read_text())["rule"]


def test_no_compatible_set_says_so_with_the_best_deviation_and_writes_nothing(tmp_path, capsys):
    """Ricker pulses of 0.3-0.5 s: their spectra peak near their period and fall fast: no mean of
    them covers the plateau and the long periods at once."""
    folder = tmp_path / "pulses"
    folder.mkdir()
    dt = 0.01
    t = np.arange(round(8.0 / dt) + 1) * dt
    for k, period in enumerate(np.linspace(0.3, 0.5, 9)):
        a = Pulse("ricker", amplitude_m_s2=2.0 + 0.1 * k, period_s=float(period), start_s=1.0).acceleration(t)
        rows = "\n".join(f"{ti:.2f},{ai:.8g}" for ti, ai in zip(t, a, strict=True))
        (folder / f"pulse_{k}.csv").write_text("t_s,accel_m_s2\n" + rows + "\n")
    out = tmp_path / "sel"
    assert main(["motion", "select", "--records", str(folder), "--count", "7", *SITE, "--out", str(out)]) == 1
    text = capsys.readouterr().out
    assert "the best set found (not compatible)" in text and "NOT compatible" in text
    assert "no set of 7 records" in text and "nothing written to" in text and "records needed:" in text
    assert not out.exists()


def test_the_factors_of_a_set_put_its_mean_on_the_target_when_they_can():
    """Records whose spectra are c_i times the target: a mean exactly on the target (rho = 0),
    with the factors closest to 1 among those that do it."""
    periods = np.geomspace(0.15, 2.0, 20)
    c = np.array([0.8, 1.25, 1.0])
    ratios = np.outer(c, np.ones(periods.size))
    factors, rho = optimal_factors(ratios, (0.5, 2.0))
    assert rho == pytest.approx(0.0, abs=1e-8)  # the second programme may use its 1e-9 relaxation
    assert float(np.mean(c * factors)) == pytest.approx(1.0, abs=1e-8)
    assert np.sum(np.abs(factors - 1)) <= np.sum(np.abs(1 / c - 1)) + 1e-9  # no more scaling than 1/c_i
    assert band_use(np.array([[0.9, 1.0, 1.3]]))[0] == pytest.approx(1.0)  # both edges of the band use it fully


def test_the_search_is_deterministic_and_prefers_lower_indices_on_ties():
    target = site().spectrum
    periods = check_grid(target, (0.15, 2.0))
    spectra = np.vstack([target.psa(periods)] * 9)  # nine identical records: every set ties
    names = [f"r{i}" for i in range(9)]
    first = select(spectra, names, target, periods, 7)
    assert first.indices == tuple(range(7)) and first.rho == pytest.approx(0.0, abs=1e-8)
    assert first.scale_factors == pytest.approx(np.ones(7))
    assert select(spectra, names, target, periods, 7).indices == first.indices


def test_more_records_of_the_wrong_shape_are_said_not_to_help():
    periods = np.geomspace(0.15, 2.0, 30)
    shape = (periods / 0.5) ** 1.5  # every record 5 times too strong at 2 s against 0.15 s
    rng = np.random.default_rng(3)
    ratios = np.vstack([shape * rng.uniform(0.9, 1.1) for _ in range(10)])
    estimate = records_needed(ratios, 7, (0.5, 2.0))
    assert estimate["records_needed"] is None and "would not help" in estimate["why"]


def test_the_range_and_the_count_follow_the_code():
    assert period_range(None) == (0.15, 2.0) and period_range(1.5) == (0.15, 3.0) and period_range(0.5) == (0.15, 2.0)
    with pytest.raises(InputError, match="--t1"):
        period_range(2.1)
    assert check_count(7, 10, False) == 7 and check_count(3, 10, True) == 3
    for count, records, max_response, option in ((6, 10, False, "--count"), (8, 7, False, "--records")):
        with pytest.raises(InputError, match=option):
            check_count(count, records, max_response)
    assert math.isclose(BAND_BELOW, 0.10) and math.isclose(BAND_ABOVE, 0.30)


def test_the_records_needed_are_estimated_from_how_the_best_set_improves():
    """14 records scattered about the target (log-normal, sigma 0.6 at each period): no set of 7 is
    compatible; the trend of random subsets says about 32 such records would do, and 32 drawn from
    the same scatter do give a compatible set (band use 0.86)."""
    periods = np.geomspace(0.15, 2.0, 30)
    pool = np.exp(np.random.default_rng(5).normal(0.0, 0.6, (40, periods.size)))
    estimate = records_needed(pool[:14], 7, (0.5, 2.0))
    assert estimate["records_needed"] == 32 and "reaches 1 at about n = 32" in estimate["why"]
    assert [t["pool"] for t in estimate["trend"]] == [7, 8, 9, 11, 12, 14]
    names = [f"r{i}" for i in range(40)]
    target = ElasticSpectrum(1.0, 1.0, 0.1, 0.4, 2.0)
    spectra = pool * target.psa(periods)
    assert not select(spectra[:14], names[:14], target, periods, 7, estimate=False).compatible
    larger = select(spectra[:32], names[:32], target, periods, 7, estimate=False)
    assert larger.compatible and larger.rho == pytest.approx(0.862, abs=0.005)


@pytest.mark.slow
def test_the_example_records_are_what_their_script_writes(tmp_path, monkeypatch, capsys):
    """The script run as ``python make_site_records.py out`` from another folder, in this process
    (runpy, its own sys.argv; the records are the question, not a process: one of its own paid
    Python's start and rockyade's imports again)."""
    import runpy
    import sys

    script = RECORDS / "make_site_records.py"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script), "out"])
    runpy.run_path(str(script), run_name="__main__")  # an error is an exception here: the test fails
    assert capsys.readouterr().out.count("wrote ") == 10
    fresh = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert len(fresh) == 10
    for name in fresh:
        assert (RECORDS / name).read_bytes() == (tmp_path / "out" / name).read_bytes(), name
