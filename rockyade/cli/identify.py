"""``rockyade identify``: alpha, p, mu (with 95 % intervals) from a measured free-rocking test."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from rockyade.cli.common import Commands, add_command, check_output_dir, check_output_file, json_out, print_wrote
from rockyade.errors import InputError

if TYPE_CHECKING:  # the parser stays fast: the identification is imported when the command runs
    from rockyade.identification.fit import Identification


def _led_columns(text: str | None) -> tuple[str, str] | None:
    if text is None:
        return None
    names = [c.strip() for c in text.split(",")]
    if len(names) != 2 or not all(names):
        raise InputError("led_columns", f'must be two column names "led1_y_m,led2_y_m", got {text!r}')
    return names[0], names[1]


def cmd_identify(args: argparse.Namespace) -> int:
    """alpha, p, mu with 95 % intervals from a measured free-rocking test

    Fit Housner's free rocking (exact solver) to a measured rotation history: alpha, p, mu, the release time, the
    release tilt and the sensor offset by least squares, with 95 % intervals. Input: CSV with t_s and theta_rad (or
    theta_deg), or two LED displacement columns. Exit code 1 when a parameter cannot be identified (the message says
    why). See docs/identification.md.

    Parameters
    ----------
    args
        The parsed command line: the record, its columns, ``--out``, ``--plot``, ``--json``.

    Returns
    -------
    int
        Exit code: 0, or 1 when a parameter cannot be identified.
    """
    from rockyade.identification.fit import identify
    from rockyade.identification.measurement import read_measurement

    if args.out:
        check_output_file(args.out, "--out", ".json")
    if args.plot:
        check_output_dir(args.plot, "--plot")
    history = read_measurement(
        args.measured,
        time_column=args.time_column,
        theta_column=args.theta_column,
        degrees=True if args.degrees else None,
        led_columns=_led_columns(args.led_columns),
        led_distance_m=args.led_distance_m,
        led_zero=args.led_zero,
    )
    result = identify(history, max_relative_ci=args.max_relative_ci)
    data = result.as_dict()
    if args.out:
        from rockyade.io.atomic import write_json

        write_json(args.out, data)
    figures = []
    if args.plot:
        from rockyade.figures.identification_fit import plot_error_surface, plot_fit

        stem = Path(args.measured).stem
        figures = [args.plot / f"{stem}_fit.png", args.plot / f"{stem}_error_surface.png"]
        plot_fit(result, figures[0])
        plot_error_surface(result, figures[1])
    if args.json:
        json_out(data)
    else:
        _print_text(result)
    for path in [args.out, *figures] if args.out else figures:
        print_wrote(path, args.json)
    if result.unidentifiable:
        for name, why in result.unidentifiable.items():
            print(f"rockyade: {name} cannot be identified from this record: {why}", file=sys.stderr)
        return 1
    return 0


def _print_text(result: Identification) -> None:
    h = result.history
    fit = result.fit
    print(f"{h.source}: {h.t_s.size} samples at {h.rate_hz:.4g} Hz over {h.duration_s:.4g} s")
    units = {"alpha_rad": "rad", "p_rad_s": "1/s", "mu": ""}
    for name, digits in (("alpha_rad", 5), ("p_rad_s", 4), ("mu", 5)):
        label = name.split("_")[0]
        if name in result.unidentifiable:
            print(f"  {label:5s} = unidentifiable")
            continue
        lo, hi = result.ci[name]
        value = getattr(fit, name)
        print(f"  {label:5s} = {value:.{digits}f} {units[name]:3s}  95 % interval [{lo:.{digits}f}, {hi:.{digits}f}]")
    print("  " + "; ".join(_start_lines(result)))
    print(
        f"  rms residual {result.rms_residual_rad:.3g} rad; {result.n_impacts} impacts above the noise; "
        f"intervals: {result.ci_method}"
    )


def _start_lines(result: Identification) -> list[str]:
    """Release time, release tilt and sensor offset with their 95 % intervals (the JSON's), or
    "not identified" where the interval is wider than ``max_relative_ci`` of the record's
    duration (release time) or of its rotation range (offset; the tilt is measured from it)."""
    import numpy as np

    h, fit, ci, limit = result.history, result.fit, result.ci, result.max_relative_ci
    t_lo, t_hi = ci["release_time_s"]
    o_lo, o_hi = ci["offset_rad"]
    rotation_range = float(np.ptp(h.theta_rad)) if h.theta_rad.size else 0.0
    offset_known = 0.5 * (o_hi - o_lo) <= limit * rotation_range
    if 0.5 * (t_hi - t_lo) <= limit * h.duration_s:
        release = f"release at t = {fit.release_time_s:.4f} s [{t_lo:.4f}, {t_hi:.4f}]"
    else:
        release = f"release time not identified (95 % interval +/-{0.5 * (t_hi - t_lo):.3g} s)"
    if not offset_known:
        return [release, f"release tilt and sensor offset not identified (offset +/-{0.5 * (o_hi - o_lo):.3g} rad)"]
    release += f" from theta = {fit.theta0_rad:.5g} rad"
    return [release, f"sensor offset {fit.offset_rad:.4g} rad [{o_lo:.4g}, {o_hi:.4g}]"]


def register(sub: Commands) -> None:
    """Add ``rockyade identify``."""
    p = add_command(sub, cmd_identify)
    p.add_argument("measured", type=Path, help="measured history (CSV with a header row)")
    p.add_argument("--time-column", default="t_s", help="time column, s (default t_s)")
    p.add_argument("--theta-column", help="rotation column (default theta_rad, or theta_deg in degrees)")
    p.add_argument("--degrees", action="store_true", help="the rotation column is in degrees")
    p.add_argument("--led-columns", help='two vertical LED displacement columns, m: "led1_y_m,led2_y_m"')
    p.add_argument("--led-distance-m", type=float, help="horizontal distance between the LEDs, m (LED 2 to the right)")
    p.add_argument(
        "--led-zero",
        choices=["end", "none"],
        default="end",
        help="upright reference of the LEDs: the rest at the end of the record (default) or zero displacement",
    )
    p.add_argument(
        "--max-relative-ci",
        type=float,
        default=0.10,
        help="a parameter whose 95 %% half interval exceeds this fraction of its value is not identified "
        "(default 0.10)",
    )
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", type=Path, help="write the identified values as JSON (input of calibrate --from)")
    p.add_argument("--plot", type=Path, help="directory for the fit and error-surface figures (PNG)")
