"""``rockyade motion``: records, response spectra, synthetic suites and their check."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from rockyade.cli.common import check_output_dir, check_output_file, json_out, print_wrote
from rockyade.errors import InputError

#: Period range of ``motion spectrum``, s.
SPECTRUM_PERIODS_S = (1.0e-3, 1000.0)


def _read(args: argparse.Namespace):
    from rockyade.motion.records import read_record

    return read_record(args.record, args.format, args.units, args.dt)


def _add_record_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("record", type=Path, help="record file: PEER .AT2, ESM ASCII (.ASC), two-column time/acceleration, or one column")
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


def _add_accel_units(p: argparse.ArgumentParser) -> None:
    """``--accel-units``: the unit accelerations are printed and plotted in (g by default)."""
    p.add_argument(
        "--accel-units",
        choices=["g", "m/s2"],
        default="g",
        help="unit of the accelerations printed and plotted: g (standard gravity, 9.80665 m/s^2; the default) "
        "or m/s2; the other unit is given beside it",
    )


def _accel_text(value_m_s2: float, unit: str) -> str:
    """An acceleration in ``unit`` with the other unit in parentheses."""
    from rockyade.constants import STANDARD_GRAVITY

    g_text, si_text = f"{value_m_s2 / STANDARD_GRAVITY:.4g} g", f"{value_m_s2:.4g} m/s^2"
    return f"{g_text} ({si_text})" if unit == "g" else f"{si_text} ({g_text})"


def cmd_info(args: argparse.Namespace) -> int:
    """Summary of a record."""
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
    """Pseudo-acceleration response spectrum of a record."""
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
    """Generate a spectrum-compatible suite into a directory."""
    import pandas as pd
    from tqdm import tqdm

    from rockyade.io.atomic import atomic_open, write_json
    from rockyade.io.locking import output_lock
    from rockyade.motion.processing import integrate
    from rockyade.motion.synthetic import compatibility_report, suite_record

    if not 1 <= args.count <= 1000:
        raise InputError("count", f"must be in [1, 1000] records, got {args.count}")
    spec = _suite_spec(args)
    out: Path = args.out
    check_output_dir(out, "out")
    if args.plot:
        check_output_file(args.plot, "plot", ".png")
    records = []
    out.mkdir(parents=True, exist_ok=True)
    with (
        output_lock(out),
        tqdm(total=spec.count, desc=f"synthesising {spec.name}", unit="record", disable=args.quiet) as bar,
    ):
        for i in range(1, spec.count + 1):
            rec = suite_record(spec, i)
            records.append(rec)
            v, d = integrate(rec.t_s, rec.accel_m_s2)
            frame = pd.DataFrame({"t_s": rec.t_s, "accel_m_s2": rec.accel_m_s2, "vel_m_s": v, "disp_m": d})
            with atomic_open(out / f"record_{i:02d}.csv") as fh:
                frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")
            bar.update(1)
    report = compatibility_report(records, spec.target)
    write_json(
        out / "suite.json", {"settings": spec.as_dict(), "target": spec.target.as_dict(), "check": _short(report)}
    )
    print(f"wrote {spec.count} records and suite.json to {out}")
    _print_report(report)
    if args.plot:
        _plot_report(records, spec.target, report, args.plot)
        print(f"wrote {args.plot}")
    return 0


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
    """Compatibility report of a suite directory written by ``motion synth``."""
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


def register(sub: Any) -> None:
    """Add ``rockyade motion ...``."""
    motion = sub.add_parser(
        "motion",
        help="records, response spectra, synthetic EC8 suites",
        description="Base motions: read records, response spectra, spectrum-compatible suites.",
    )
    msub = motion.add_subparsers(dest="motion_command", required=True, metavar="MOTION_COMMAND")

    p = msub.add_parser("info", help="summary of a record", description="Samples, dt, duration, PGA of a record.")
    _add_record_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON (pga_m_s2 and pga_g)")
    p.add_argument("--plot", type=Path, help="PNG of acceleration, velocity and displacement")
    _add_accel_units(p)
    p.set_defaults(func=cmd_info)

    p = msub.add_parser(
        "spectrum",
        help="response spectrum of a record",
        description="Pseudo-acceleration spectrum by the exact piecewise-linear recurrence.",
    )
    _add_record_arguments(p)
    p.add_argument("--damping", type=float, default=0.05, help="damping ratio (default 0.05 = 5%%)")
    p.add_argument("--t-min", type=float, default=0.02, help="shortest period, s")
    p.add_argument("--t-max", type=float, default=4.0, help="longest period, s")
    p.add_argument("-n", type=int, default=100, help="number of periods (log-spaced)")
    p.add_argument("--out", type=Path, help="CSV with period_s, psa_g and psa_m_s2")
    p.add_argument("--plot", type=Path, help="PNG of the spectrum")
    _add_accel_units(p)
    p.set_defaults(func=cmd_spectrum)

    p = msub.add_parser(
        "synth",
        help="spectrum-compatible synthetic suite (EC8)",
        description="Generate records compatible with an EC8 elastic spectrum.",
    )
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
    p.set_defaults(func=cmd_synth)

    p = msub.add_parser(
        "check",
        help="compatibility report of a suite directory",
        description="Mean spectrum / target, PGAs and durations of a suite written by 'motion synth'.",
    )
    p.add_argument("dir", type=Path, help="suite directory")
    p.add_argument(
        "--range", type=float, nargs=2, default=[0.05, 2.0], metavar=("T_MIN", "T_MAX"), help="period range, s"
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--plot", type=Path, help="PNG: target vs mean spectrum with the +/-10%% band")
    p.set_defaults(func=cmd_check)


__all__ = ["register"]
