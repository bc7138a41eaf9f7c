"""``rockyade motion``: records, response spectra, synthetic suites and their check."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from rockyade.cli.common import (
    Commands,
    add_accel_units,
    add_command,
    add_command_group,
    check_output_dir,
    check_output_file,
    json_out,
    print_wrote,
)
from rockyade.cli.site_options import add_period_option, add_site_options
from rockyade.errors import InputError

#: Period range of ``motion spectrum``, s.
SPECTRUM_PERIODS_S = (1.0e-3, 1000.0)


def _read(args: argparse.Namespace):
    from rockyade.motion.records import read_record

    return read_record(args.record, args.format, args.units, args.dt)


def _add_record_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "record",
        type=Path,
        help="record file: PEER .AT2, ESM ASCII (.ASC), two-column time/acceleration, or one column",
    )
    p.add_argument(
        "--format",
        choices=["at2", "csv", "single", "esm"],
        help="file format (default: from the content: a PEER header is at2, an ESM header (KEY: value lines, "
        "SAMPLING_INTERVAL_S, NDATA) is esm, one number a line with --dt is single)",
    )
    p.add_argument(
        "--units",
        help="units of the values when the file does not name them: g, m/s2, cm/s2 (default m/s2); "
        "units named in the file win, and a different --units is refused",
    )
    p.add_argument(
        "--dt",
        type=float,
        help="sampling interval of a one-column file, s (with an AT2 or two-column file it must match the file's)",
    )


#: ``--accel-units``' help: the unit accelerations are printed and plotted in (g by default).
_ACCEL_UNITS_HELP = (
    "unit of the accelerations printed and plotted: g (standard gravity, 9.80665 m/s^2; the default) "
    "or m/s2; the other unit is given beside it"
)


def _accel_text(value_m_s2: float, unit: str) -> str:
    """An acceleration in ``unit`` with the other unit in parentheses."""
    from rockyade.constants import STANDARD_GRAVITY

    g_text, si_text = f"{value_m_s2 / STANDARD_GRAVITY:.4g} g", f"{value_m_s2:.4g} m/s^2"
    return f"{g_text} ({si_text})" if unit == "g" else f"{si_text} ({g_text})"


def cmd_info(args: argparse.Namespace) -> int:
    """summary of a record

    Samples, dt, duration, PGA of a record.
    """
    from rockyade.constants import STANDARD_GRAVITY

    rec = _read(args)
    if args.plot:
        check_output_file(args.plot, "plot", ".png")
    info = {
        "npts": rec.npts,
        "dt_s": rec.dt_s,
        "duration_s": rec.duration_s,
        "pga_m_s2": rec.pga_m_s2,
        "pga_g": rec.pga_m_s2 / STANDARD_GRAVITY,
        "pga_time_s": rec.pga_time_s,
        "units_in_file": rec.units_in_file,
        "title": rec.title,
        "uniform_sampling": rec.uniform,
    }
    if args.plot:
        from rockyade.figures import plot_accelerogram
        from rockyade.motion.processing import integrate

        v, d = integrate(rec.t_s, rec.accel_m_s2)
        plot_accelerogram(
            rec.t_s, rec.accel_m_s2, v, d, args.plot, title=rec.title or str(args.record), accel_unit=args.accel_units
        )
    if args.json:
        json_out(info)
    else:
        print(f"{args.record}: {rec.title}")
        print(f"  {rec.npts} samples at dt = {rec.dt_s:g} s ({rec.duration_s:g} s), units in file: {rec.units_in_file}")
        pga = _accel_text(rec.pga_m_s2, args.accel_units)
        print(f"  PGA = {pga} at t = {rec.pga_time_s:g} s (g: standard gravity)")
    if args.plot:
        print_wrote(args.plot, args.json)
    return 0


def cmd_spectrum(args: argparse.Namespace) -> int:
    """response spectrum of a record

    Pseudo-acceleration spectrum by the exact piecewise-linear recurrence.
    """
    import pandas as pd

    from rockyade.constants import STANDARD_GRAVITY
    from rockyade.motion.spectra import default_periods, response_spectrum

    lo, hi = SPECTRUM_PERIODS_S
    if not lo <= args.t_min <= hi:
        raise InputError("t-min", f"must be in [{lo:g}, {hi:g}] s, got {args.t_min:g}")
    if not args.t_min < args.t_max <= hi:
        raise InputError("t-max", f"must be in ({args.t_min:g}, {hi:g}] s (above --t-min), got {args.t_max:g}")
    if not 2 <= args.n <= 10_000:
        raise InputError("n", f"must be in [2, 10000] periods, got {args.n}")
    if not 0.0 <= args.damping < 1.0:
        raise InputError("damping", f"must be in [0, 1), got {args.damping:g}")
    for option, suffix in (("out", ".csv"), ("plot", ".png")):
        if getattr(args, option):
            check_output_file(getattr(args, option), option, suffix)
    rec = _read(args)
    if not rec.uniform:
        raise InputError("record", "the response spectrum needs a uniformly sampled record")
    periods = default_periods(args.t_min, args.t_max, args.n)
    periods, psa = response_spectrum(rec.accel_m_s2, rec.dt_s, periods, args.damping)
    table = pd.DataFrame({"period_s": periods, "psa_m_s2": psa, "psa_g": psa / STANDARD_GRAVITY})
    if args.accel_units == "g":
        table = table[["period_s", "psa_g", "psa_m_s2"]]
    if args.out:
        from rockyade.io.atomic import atomic_open

        with atomic_open(args.out) as fh:
            table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
        print(f"wrote {args.out}")
    if args.plot:
        from rockyade.figures import plot_spectra

        plot_spectra(
            periods,
            None,
            psa,
            args.plot,
            title=f"{rec.title or args.record}, {100 * args.damping:g} % damping",
            accel_unit=args.accel_units,
        )
        print(f"wrote {args.plot}")
    if not args.out:
        print(table.to_string(index=False))
    return 0


def _suite_spec(args: argparse.Namespace):
    from rockyade.motion.ec8 import ElasticSpectrum
    from rockyade.motion.synthetic import Envelope, SuiteSpec

    if (args.ag is None) == (args.ag_s is None):
        raise InputError("ag", "give exactly one of --ag (ag, m/s^2) and --ag-s (ag times S, m/s^2)")
    target = ElasticSpectrum.ec8(args.type, args.ground, ag_m_s2=args.ag, ag_s_m_s2=args.ag_s)
    envelope = Envelope(args.envelope, args.rise, args.strong, args.decay)
    return SuiteSpec(target, count=args.count, seed=args.seed, envelope=envelope, dt_s=args.dt, name=args.name)


def cmd_synth(args: argparse.Namespace) -> int:
    """spectrum-compatible synthetic suite (EC8)

    Generate records compatible with an EC8 elastic spectrum.
    """
    import pandas as pd
    from tqdm import tqdm

    from rockyade.io.atomic import atomic_open, write_json
    from rockyade.io.folders import output_folder
    from rockyade.io.locking import output_lock
    from rockyade.io.resultset import replacing_set
    from rockyade.motion.processing import integrate
    from rockyade.motion.suite_cache import suite_record
    from rockyade.motion.synthetic import compatibility_report

    if not 1 <= args.count <= 1000:
        raise InputError("count", f"must be in [1, 1000] records, got {args.count}")
    spec = _suite_spec(args)
    out: Path = args.out
    check_output_dir(out, "out")
    names = _suite_files(out, args.plot)
    if args.plot:
        check_output_file(args.plot, "plot", ".png")
    records = []
    with (
        output_folder(out),
        output_lock(out, "--out"),
        replacing_set(out, names, SUITE_JSON) as stage,
        tqdm(total=spec.count, desc=f"synthesising {spec.name}", unit="record", disable=args.quiet) as bar,
    ):
        for i in range(1, spec.count + 1):
            rec = suite_record(spec, i)
            records.append(rec)
            v, d = integrate(rec.t_s, rec.accel_m_s2)
            frame = pd.DataFrame({"t_s": rec.t_s, "accel_m_s2": rec.accel_m_s2, "vel_m_s": v, "disp_m": d})
            with atomic_open(stage / f"record_{i:02d}.csv") as fh:
                frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
            bar.update(1)
        report = compatibility_report(records, spec.target)
        write_json(
            stage / SUITE_JSON,
            {"settings": spec.as_dict(), "target": spec.target.as_dict(), "check": _short(report)},
        )
    print(f"wrote {spec.count} records and suite.json to {out}")
    _print_report(report)
    if args.plot:
        _plot_report(records, spec.target, report, args.plot)
        print(f"wrote {args.plot}")
    return 0


SUITE_JSON = "suite.json"


def _suite_files(out: Path, plot: Path | None) -> list[str]:
    """Every file a suite's folder may hold (its records, ``suite.json`` last), after refusing an
    ``--out`` that is a link or holds another command's files: a suite is written as one set
    (:mod:`rockyade.io.resultset`), so a smaller suite leaves no record of a previous one beside it."""
    from rockyade.io.folders import refuse_link, refuse_other_files

    refuse_link(out, "--out")
    names = [*(f"record_{i:02d}.csv" for i in range(1, 1001)), SUITE_JSON]
    if out.is_dir():
        keep = [*names, plot.name] if plot is not None and plot.parent.resolve() == out.resolve() else names
        refuse_other_files(out, keep, "a suite", "motion synth --out")
    return names


def _short(report: dict[str, Any]) -> dict[str, Any]:
    return {
        k: report[k]
        for k in ("ratio_min", "ratio_max", "period_range_s", "mean_pga_m_s2", "ag_s_m_s2", "pga_ratio", "compatible")
    }


def _print_report(report: dict[str, Any]) -> None:
    lo, hi = report["period_range_s"]
    print(
        f"  mean spectrum / target over {lo:g}-{hi:g} s: min {report['ratio_min']:.3f}, max {report['ratio_max']:.3f}"
    )
    pga, ags = report["mean_pga_m_s2"], report["ag_s_m_s2"]
    print(f"  mean PGA {pga:.3f} m/s^2 against ag S = {ags:.3f} ({report['pga_ratio']:.3f})")
    pgas = [r["pga_m_s2"] for r in report["records"]]
    print(f"  record PGAs {min(pgas):.3f}-{max(pgas):.3f} m/s^2; durations {report['records'][0]['duration_s']:g} s")
    vmax = max(abs(r["final_velocity_m_s"]) for r in report["records"])
    dmax = max(abs(r["final_displacement_m"]) for r in report["records"])
    print(f"  final |v| <= {vmax:.2g} m/s, |d| <= {dmax:.2g} m")
    verdict = "compatible" if report["compatible"] else "NOT compatible"
    print(f"  EC8 3.2.3.1.2 (mean >= 0.9 target, mean PGA >= ag S): {verdict}")


def _plot_report(records, target, report, path) -> None:
    import numpy as np

    from rockyade.figures import plot_spectra
    from rockyade.motion.spectra import response_spectrum

    periods = np.asarray(report["periods_s"])
    individual = [response_spectrum(r.accel_m_s2, r.dt_s, periods, target.damping)[1] for r in records]
    plot_spectra(
        periods, target.psa(periods), np.asarray(report["mean_psa_m_s2"]), path, individual, title=target.label
    )


def cmd_check(args: argparse.Namespace) -> int:
    """compatibility report of a suite directory

    Mean spectrum / target, PGAs and durations of a suite written by 'motion synth'.
    """
    from rockyade.motion.ec8 import ElasticSpectrum
    from rockyade.motion.records import read_two_column
    from rockyade.motion.synthetic import compatibility_report

    if args.plot:
        check_output_file(args.plot, "plot", ".png")
    suite_file = args.dir / "suite.json"
    if not suite_file.is_file():
        raise InputError("dir", f"{suite_file} not found (write a suite with 'rockyade motion synth')")
    try:
        target_d = json.loads(suite_file.read_text(encoding="utf-8"))["target"]
        target = ElasticSpectrum(
            float(target_d["ag_m_s2"]),
            float(target_d["S"]),
            float(target_d["TB_s"]),
            float(target_d["TC_s"]),
            float(target_d["TD_s"]),
            float(target_d["damping"]),
            str(target_d["label"]),
        )
    except (ValueError, KeyError, TypeError) as exc:
        raise InputError("dir", f"{suite_file} is not a suite file written by 'motion synth' ({exc})") from None
    files = sorted(args.dir.glob("record_*.csv"))
    if not files:
        raise InputError("dir", f"no record_*.csv in {args.dir}")
    records = [read_two_column(f) for f in files]
    report = compatibility_report(records, target, tuple(args.range))
    if args.json:
        json_out(report)
    else:
        print(f"{args.dir}: {len(records)} records, target {target.label}")
        _print_report(report)
    if args.plot:
        _plot_report(records, target, report, args.plot)
        print_wrote(args.plot, args.json)
    return 0 if report["compatible"] else 1


def cmd_select(args: argparse.Namespace) -> int:
    """records of a folder selected and scaled to the site's spectrum (NTC 2018 3.2.3.6)

    Pick from a folder of records (PEER .AT2, ESM .ASC, text) a set of --count records and a scale factor for each
    whose mean 5 % spectrum lies nowhere more than 10 % below the site's elastic spectrum nor more than 30 % above it
    over 0.15-2.0 s (0.15 s-2 T1 when longer), NTC 2018 3.2.3.6. Writes selection.csv, spectra.png, selection.json and
    the chosen records into --out (a set that 'assess --records' reads); exit 1 with the best deviation reached and an
    estimate of the records needed when no set is compatible. See docs/howto/base-motions.md.
    """
    import numpy as np

    from rockyade.assess.motions import records_in_folder
    from rockyade.cli.site_options import site_from
    from rockyade.motion import selection as sel
    from rockyade.motion.selection_set import check_out_folder, is_selection

    site = site_from(args)
    t_range = sel.period_range(args.t1)
    bounds = sel.check_bounds(args.scale_bounds)
    if is_selection(args.records):
        raise InputError(
            "--records",
            f"{args.records} is a selection ('motion select' wrote it): give the folder of the records to select from",
        )
    if args.out is not None:
        check_output_dir(args.out, "--out")
        check_out_folder(args.out, args.records)
    folder = records_in_folder(args.records, args.units)
    count = sel.check_count(args.count, folder.count, args.max_response)
    records = [folder.record(i) for i in range(folder.count)]
    names = [folder.label(i) for i in range(folder.count)]
    target = site.spectrum
    grid = sel.check_grid(target, t_range)
    shown = np.union1d(np.geomspace(0.04, max(4.0, t_range[1]), 80), grid)
    spectra = sel.spectra_of(records, shown, names, t_range[1])
    inside = np.isin(shown, grid)
    chosen = sel.select(spectra[:, inside], names, target, grid, count, bounds)
    data = _selection_data(args, site, chosen, records, t_range, bounds, count)
    if args.json:
        json_out(data)
    else:
        _print_selection(chosen, data)
    if not chosen.compatible:
        where = f"; nothing written to {args.out}" if args.out is not None else ""
        print(f"no set of {count} records of {args.records} is compatible with the site's spectrum{where}")
        return 1
    if args.out is not None:
        _write_selection(args, chosen, folder, records, shown, spectra, target, t_range, data)
    return 0


def _selection_data(args, site, chosen, records, t_range, bounds, count) -> dict[str, Any]:
    """selection.json's content, and the table's rows (under ``rows``)."""
    import numpy as np

    from rockyade import __version__
    from rockyade.constants import STANDARD_GRAVITY
    from rockyade.motion.selection import BAND_ABOVE, BAND_BELOW, MEAN_RULE_COUNT
    from rockyade.motion.spectra import response_spectrum

    rows = []
    for i, name, factor in zip(chosen.indices, chosen.names, chosen.scale_factors, strict=True):
        record = records[i]
        row: dict[str, Any] = {"record": name, "scale_factor": float(factor)}
        row["pga_m_s2"] = factor * record.pga_m_s2
        row["pga_g"] = row["pga_m_s2"] / STANDARD_GRAVITY
        if args.t1 is not None:
            sa = float(response_spectrum(record.accel_m_s2, record.dt_s, np.array([args.t1]), 0.05)[1][0]) * factor
            row["sa_t1_m_s2"], row["sa_t1_g"] = sa, sa / STANDARD_GRAVITY
        rows.append(row)
    dev, period = chosen.worst
    rule = (
        "the mean of the records' effects (NTC 2018 7.3.5: 7 records or more)"
        if count >= MEAN_RULE_COUNT
        else "the most unfavourable record's effects (NTC 2018 7.3.5: fewer than 7 records; --max-response)"
    )
    return {
        "compatible": chosen.compatible,
        "summary": chosen.summary(),
        "worst_deviation": dev,
        "worst_deviation_period_s": period,
        "mean_over_target_min": float(chosen.ratio.min()),
        "mean_over_target_max": float(chosen.ratio.max()),
        "band_use": chosen.rho,
        "band": {"below": BAND_BELOW, "above": BAND_ABOVE, "source": "NTC 2018 3.2.3.6"},
        "period_range_s": list(t_range),
        "t1_s": args.t1,
        "periods_checked": len(chosen.periods_s),
        "count": count,
        "rule": rule,
        "scale_bounds": list(bounds),
        "search": {"sets_ranked": chosen.ranked, "how": chosen.how},
        "site": site.to_dict(),
        "records_folder": str(args.records),
        "records_in_folder": len(records),
        "records_needed": chosen.estimate or None,
        "rows": rows,
        "rockyade_version": __version__,
    }


def _print_selection(chosen, data: dict[str, Any]) -> None:
    """The set, one record a line, and the verdict."""
    best = "selected" if chosen.compatible else "the best set found (not compatible)"
    print(
        f"{best}: {data['count']} of {data['records_in_folder']} records ({data['search']['how']}, "
        f"{data['search']['sets_ranked']} sets ranked; scale factors within {data['scale_bounds'][0]:g}-"
        f"{data['scale_bounds'][1]:g})"
    )
    for row in data["rows"]:
        sa = f", Sa(T1) {row['sa_t1_g']:.4g} g" if "sa_t1_g" in row else ""
        print(f"  {row['record']}: x {row['scale_factor']:.4g} (PGA {row['pga_g']:.4g} g{sa})")
    print(chosen.summary())
    if data["records_needed"]:
        est = data["records_needed"]
        needed = est.get("records_needed")
        head = f"records needed: about {needed}" if needed else "records needed: no estimate"
        print(f"{head} ({est['why']})")


def _write_selection(args, chosen, folder, records, shown, spectra, target, t_range, data) -> None:
    """The set into --out (rockyade.motion.selection_set)."""
    import pandas as pd

    from rockyade.figures.record_selection import plot_selection
    from rockyade.motion.selection import BAND_ABOVE, BAND_BELOW
    from rockyade.motion.selection_set import write_selection

    sources = [Path(folder.files[i]) for i in chosen.indices]
    table = pd.DataFrame(data["rows"])
    meta = {k: v for k, v in data.items() if k != "rows"}

    def draw(path: Path) -> None:
        scaled = spectra[list(chosen.indices)] * chosen.scale_factors[:, None]
        title = f"{target.label}; {data['count']} records of {args.records}"
        plot_selection(
            shown,
            target.psa(shown),
            scaled,
            list(chosen.names),
            (BAND_BELOW, BAND_ABOVE),
            t_range,
            path,
            title=title,
            verdict=chosen.summary(),
        )

    given = [str(Path(args.records) / source.name) for source in sources]
    written = write_selection(args.out, sources, table, meta, draw, given)
    print_wrote(Path(f"{', '.join(written)} in {args.out}"), args.json)


def register(sub: Commands) -> None:
    """Add ``rockyade motion ...``."""
    msub = add_command_group(
        sub,
        "motion",
        "records, response spectra, synthetic EC8 suites, records selected to a site",
        "Base motions: read records, response spectra, spectrum-compatible suites, records selected "
        "and scaled to a site's spectrum.",
        "motion_command",
    )

    p = add_command(msub, cmd_info)
    _add_record_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON (pga_m_s2 and pga_g)")
    p.add_argument("--plot", type=Path, help="PNG of acceleration, velocity and displacement")
    add_accel_units(p, _ACCEL_UNITS_HELP)

    p = add_command(msub, cmd_spectrum)
    _add_record_arguments(p)
    p.add_argument("--damping", type=float, default=0.05, help="damping ratio (default 0.05 = 5%%)")
    p.add_argument("--t-min", type=float, default=0.02, help="shortest period, s")
    p.add_argument("--t-max", type=float, default=4.0, help="longest period, s")
    p.add_argument("-n", type=int, default=100, help="number of periods (log-spaced)")
    p.add_argument("--out", type=Path, help="CSV with period_s, psa_g and psa_m_s2")
    p.add_argument("--plot", type=Path, help="PNG of the spectrum")
    add_accel_units(p, _ACCEL_UNITS_HELP)

    p = add_command(msub, cmd_synth)
    p.add_argument("--type", type=int, choices=[1, 2], required=True, help="EC8 spectrum type")
    p.add_argument("--ground", choices=list("ABCDE"), required=True, help="EC8 ground type")
    p.add_argument("--ag", type=float, help="design ground acceleration ag, m/s^2")
    p.add_argument("--ag-s", type=float, help="ag times the soil factor S, m/s^2 (the paper: 2.8)")
    p.add_argument("--count", type=int, default=30, help="number of records")
    p.add_argument("--seed", type=int, required=True, help="seed (record i is reproducible alone)")
    p.add_argument("--dt", type=float, default=0.01, help="sampling interval, s")
    p.add_argument("--envelope", choices=["jennings", "trapezoidal"], default="jennings", help="time modulation")
    p.add_argument("--rise", type=float, default=2.0, help="rise time, s")
    p.add_argument("--strong", type=float, default=10.0, help="strong-motion (stationary) duration, s")
    p.add_argument("--decay", type=float, default=8.0, help="decay time, s")
    p.add_argument("--name", default="suite", help="suite name")
    p.add_argument("--out", type=Path, required=True, help="output directory")
    p.add_argument("--plot", type=Path, help="PNG: target vs mean spectrum with the +/-10%% band")
    p.add_argument("--quiet", action="store_true", help="no progress bar")

    p = add_command(msub, cmd_check)
    p.add_argument("dir", type=Path, help="suite directory")
    p.add_argument(
        "--range", type=float, nargs=2, default=[0.05, 2.0], metavar=("T_MIN", "T_MAX"), help="period range, s"
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--plot", type=Path, help="PNG: target vs mean spectrum with the +/-10%% band")

    p = add_command(msub, cmd_select)
    p.add_argument("--records", type=Path, required=True, metavar="DIR", help="folder of the records to select from")
    p.add_argument(
        "--count",
        type=int,
        default=7,
        help="records of the set: at least 7 (the mean response, NTC 2018 7.3.5; default 7), 3 to 6 with "
        "--max-response",
    )
    p.add_argument(
        "--max-response",
        action="store_true",
        help="a set of 3 to 6 records, whose effects are then taken as the most unfavourable record's (NTC 2018 7.3.5)",
    )
    p.add_argument(
        "--scale-bounds",
        type=float,
        nargs=2,
        default=[0.5, 2.0],
        metavar=("LO", "HI"),
        help="bounds of each record's scale factor (default 0.5 2)",
    )
    p.add_argument(
        "--units",
        help="units of the records that do not name theirs: g, m/s2, cm/s2 (as 'assess --records' takes it)",
    )
    add_site_options(p)
    add_period_option(p, "the range checked becomes 0.15 s-2 T1 when 2 T1 > 2 s (T1 <= 2 s)")
    p.add_argument("--out", type=Path, help="the selection's folder (written only for a compatible set)")
    p.add_argument("--json", action="store_true", help="print the answer as JSON")


__all__ = ["register"]
