"""Results (atomic CSV + JSON pairs) and the reproduction of the paper's tables."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from rockyade import paper
from rockyade.errors import InputError
from rockyade.paper.tables import format_report, reproduction_report
from rockyade.result import Result, failed_result
from rockyade.run_meta import RunMeta


def _result() -> Result:
    frame = pd.DataFrame({"t_s": np.arange(5) * 0.1, "theta_rad": np.linspace(0, 0.1, 5)})
    return Result(frame, RunMeta(status="completed", solver="test", blocks=("b",)))


def test_write_read_round_trip(tmp_path):
    path = tmp_path / "out" / "r.csv"
    json_path = _result().write(path)
    assert json_path == tmp_path / "out" / "r.json"
    back = Result.read(path)
    assert back.status == "completed"
    np.testing.assert_allclose(back.series("theta_rad"), np.linspace(0, 0.1, 5))
    assert not list((tmp_path / "out").glob(".*tmp"))  # no temporary files left


def test_partial_or_stale_csv_is_detected(tmp_path):
    path = tmp_path / "r.csv"
    _result().write(path)
    with open(path, "a") as fh:
        fh.write("0.5,0.2\n")
    with pytest.raises(InputError, match="partial or stale"):
        Result.read(path)
    path.with_suffix(".json").unlink()
    with pytest.raises(InputError, match="incomplete"):
        Result.read(path)


def test_failing_write_keeps_the_old_pair_and_no_temporary_file(tmp_path, monkeypatch):
    path = tmp_path / "r.csv"
    _result().write(path)  # an earlier complete pair
    before = Result.read(path)
    new = _result()
    new.frame["theta_rad"] = new.frame["theta_rad"] + 1.0

    import rockyade.result as result_module

    real_replace = result_module.os.replace

    def full_disk_on_json(src, dst, *args, **kwargs):
        if str(dst).endswith(".json.pending"):
            raise OSError(28, "No space left on device")
        return real_replace(src, dst, *args, **kwargs)

    monkeypatch.setattr(result_module.os, "replace", full_disk_on_json)
    with pytest.raises(OSError):
        new.write(path)
    monkeypatch.undo()
    back = Result.read(path)  # the old pair is still complete
    pd.testing.assert_frame_equal(back.frame, before.frame)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.json"]  # no temporary file left


def test_status_is_validated_and_failed_result():
    with pytest.raises(ValueError):
        RunMeta.from_dict({"status": "fine"})
    r = failed_result("yade", "abc", "YADE exited with 1", log_path="/tmp/x.log")
    assert not r.ok and r.meta.failure_reason == "YADE exited with 1"


def test_paper_tables_load_with_units_in_columns():
    t1 = paper.table(1)
    assert list(t1.index) == ["1", "2", "3", "4", "base"]
    assert t1.loc["1", "mass_kg"] == 503
    assert all(any(u in c for u in ("_m", "_kg", "_kgm2")) for c in t1.columns)
    assert paper.table(5).loc["3", "K_T_paper_N_per_m"] == 1174
    assert paper.printed_decimals(3, "1", "alpha_T_rad") == 3


def test_report_lists_every_printed_value():
    report = reproduction_report()
    # Tables 1-2: 6 inertias; Tables 3-4: 6 rows x 6 values; Table 5: 4 x 8; Table 6: 2 x 4
    assert len(report) == 6 + 36 + 32 + 8
    assert set(report["table"]) == {1, 2, 3, 4, 5, 6}
    assert report["paper"].notna().all() and report["ours"].notna().all()
    text = format_report(report)
    assert "Table 5" in text and "INCONSISTENT" in text


def test_report_flags_known_inconsistencies():
    report = reproduction_report().set_index(["table", "row", "quantity", "column"])
    # DESIGN.md: Table 5, specimen 3, column T: K = 1174 where Eq 9 gives about 1750
    k3 = report.loc[(5, "specimen 3", "K", "T")]
    assert not k3["consistent"] and k3["ours"] == pytest.approx(1752, abs=2)
    # and the values that do follow from the equations are not flagged
    assert report.loc[(5, "specimen 1", "K", "T")]["consistent"]
    assert report.loc[(5, "specimen 2", "f_min", "E")]["consistent"]
    assert report.loc[(3, "specimen 2", "mu", "T")]["consistent"]


@pytest.mark.parametrize("odd", [None, "nan", "text", "quoted name"])
def test_result_csv_text_is_pandas_to_csv_byte_for_byte(odd: str | None) -> None:
    from rockyade.result import CSV_FLOAT_FORMAT, csv_text

    rng = np.random.default_rng(3)
    frame = pd.DataFrame(
        {
            "t_s": np.arange(50) * 0.002,
            "b_theta_rad": rng.normal(scale=1e-3, size=50),
            "b_x_m": rng.normal(scale=1e8, size=50) * rng.integers(0, 2, 50),  # zeros, large values
            "extremes": [0.0, -0.0, np.inf, -np.inf, 5e-324, 1e308, 1 / 3, -2.5] + [1e-17] * 42,
            "b_n_contacts": rng.integers(0, 4, 50),
            "b_slipping": rng.integers(0, 2, 50).astype(bool),
            "small_int": np.arange(50, dtype=np.int8),
        }
    )
    if odd == "nan":
        frame.loc[7, "b_x_m"] = np.nan
    elif odd == "text":
        frame["state"] = "rest"
    elif odd == "quoted name":
        frame['a "b", c'] = 1.5
    assert csv_text(frame, CSV_FLOAT_FORMAT) == frame.to_csv(
        index=False, float_format=CSV_FLOAT_FORMAT, lineterminator="\n"
    )
    empty = frame.iloc[:0]
    assert csv_text(empty, "%.8g") == empty.to_csv(index=False, float_format="%.8g", lineterminator="\n")


def test_the_chamfered_specimens_inertia_names_its_own_formula():
    # specimen 4's I_0 (18.34 kg m^2) is the chamfered polygon's about its pivot; the row printed the
    # rectangle's formula, which gives 19.15 for the printed 0.16 x 0.457 m block and 245 kg
    report = reproduction_report().set_index(["table", "row", "quantity", "column"])
    four = report.loc[(1, "specimen 4", "I_0", "-")]
    assert "polygon" in four["equation"] and four["ours"] == pytest.approx(18.3376, abs=1e-3)
    rect = 4.0 / 3.0 * 245 * (0.08**2 + 0.2285**2)  # the rectangle's formula, by hand
    assert abs(rect - four["ours"]) > 0.5
    assert report.loc[(3, "specimen 4", "alpha", "T")]["equation"] == "Eq 2, polygon form"
    assert report.loc[(3, "specimen 1", "alpha", "T")]["equation"] == "Eq 2"
    one = report.loc[(1, "specimen 1", "I_0", "-")]
    assert one["equation"].startswith("M (b^2+h^2)/3") and one["ours"] == pytest.approx(4 / 3 * 503 * 0.265625)
