"""Snapshots and animation of a run, as ``rockyade run`` and ``rockyade draw`` ask for them: the
options, their checks before a run starts, and the drawing (:mod:`rockyade.figures.assembly`)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from rockyade.errors import InputError


def parse_times(text: str, field: str = "--snapshots") -> list[float]:
    """Snapshot times "0.5,1.0,1.5" in s."""
    try:
        times = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(field, f"must be times in s separated by commas, e.g. 0.5,1.0, got {text!r}") from None
    if not times or any(not math.isfinite(t) or t < 0 for t in times):
        raise InputError(field, f"must be one or more times >= 0 s, got {text!r}")
    return times


def add_snapshot_options(parser: argparse.ArgumentParser) -> None:
    """--snapshots, --snapshot-layout, --snapshot-scale, --animation, --fps, --speed."""
    parser.add_argument(
        "--snapshots",
        metavar="T1,T2,...",
        help="draw the assembly at these times, s "
        "(<name>_snapshots.png beside the result, or one PNG per time with --snapshot-layout files)",
    )
    parser.add_argument(
        "--snapshot-layout", choices=("grid", "files"), default="grid", help="one PNG of panels, or one PNG per time"
    )
    parser.add_argument(
        "--snapshot-scale",
        type=float,
        default=1.0,
        help="magnify displacements and rotations in snapshots and animation (1: true scale)",
    )
    parser.add_argument(
        "--animation",
        type=Path,
        metavar="FILE",
        help="animation of the run: .gif (Pillow, always available) or .mp4 (needs ffmpeg)",
    )
    parser.add_argument("--fps", type=float, default=20.0, help="animation frames per second")
    parser.add_argument(
        "--speed", type=float, default=1.0, help="simulated seconds per second of animation (0.25: slow motion)"
    )


def check_run_drawings(args: argparse.Namespace) -> None:
    """Refuse bad snapshot or animation options before a run starts (InputError naming the option)."""
    if args.snapshots:
        parse_times(args.snapshots)
    for name in ("snapshot_scale", "fps", "speed"):
        value = getattr(args, name)
        if not (math.isfinite(value) and value > 0):
            raise InputError("--" + name.replace("_", "-"), f"must be a number > 0, got {value:g}")
    if args.animation:
        from rockyade.figures.assembly import animation_writer_for

        try:
            animation_writer_for(args.animation, args.fps)
        except InputError as exc:
            raise InputError("--animation", exc.message) from None


def write_run_drawings(args: argparse.Namespace, scene, result, base: Path) -> None:
    """Snapshots (``<base stem>_snapshots.png``) and animation of a run, as asked by the options.

    Times after the end of a run that stopped early (an overturn) are skipped with a note.
    """
    if not (args.snapshots or args.animation):
        return
    if not result.ok or result.t.size == 0:
        print("no snapshots or animation: the run failed")
        return
    from rockyade.figures.assembly import animate, animation_times, write_snapshots

    if args.snapshots:
        times = parse_times(args.snapshots)
        end = float(result.t[-1]) + 0.5 * scene.sample_dt_s
        kept = [t for t in times if t <= end]
        for t in times:
            if t > end:
                print(f"snapshot at t = {t:g} s skipped: the run ends at {result.t[-1]:.4g} s ({result.status})")
        if kept:
            path = base.with_name(f"{base.stem}_snapshots.png")
            try:
                written = write_snapshots(scene, result, kept, path, args.snapshot_layout, args.snapshot_scale)
            except InputError as exc:
                raise InputError(
                    f"--snapshot-{exc.field}" if exc.field in ("scale", "layout") else "--snapshots", exc.message
                ) from None
            print("wrote " + ", ".join(str(p) for p in written))
    if args.animation:
        try:
            animate(scene, result, args.animation, fps=args.fps, speed=args.speed, scale=args.snapshot_scale)
        except InputError as exc:
            raise InputError(f"--{exc.field}", exc.message) from None
        print(f"wrote {args.animation} ({len(animation_times(result, args.fps, args.speed))} frames)")
