"""Start-up of the command line (issue "Studies at scale", item 6).

Each command's start-up is the wall time of ``rockyade COMMAND --help`` in a fresh
interpreter: the interpreter, ``rockyade.cli``, every command's parser, and nothing of the
command's own work (target 0.3 s). ``rockyade run`` of a 1 s single-block scene (specimen 1
released at half its critical angle, each solver's compiled kernel cached by a first
run) is timed end to end with Housner's solver and with the reference DEM (target 0.8 s).
The bare interpreter (``python -c pass``) is
printed for scale. Best of ``--repeat`` runs; the machine may be shared, so its load
average is printed with the numbers.

Run: ``.venv/bin/python benchmarks/bench_startup.py [--repeat 5] [--commands run params] [--quick]``
(``--quick``: once, the ``params`` command, ``run`` with the reference DEM only, no first run to
compile the kernels; a test runs it so that it cannot rot).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

STARTUP_TARGET_S = 0.3
RUN_TARGET_S = 0.8
#: ``rockyade run`` is timed with each (Housner's exact solution, the reference DEM).
RUN_SOLVERS = ("housner", "reference")

SCENE = """duration_s = 1.0
sample_dt_s = 0.001
[[blocks]]
name = "specimen1"
width_m = 0.25
height_m = 1.0
thickness_m = 0.754
mass_kg = 503
alpha_rad = 0.235
p_rad_s = 3.84
mu = 0.936
[contact]
calibration = "paper"
[motion]
type = "free"
theta0_rad = 0.1175
"""


def best_wall_s(args: list[str], repeat: int, cwd: Path) -> float:
    """The best wall time of ``repeat`` runs of ``args``, s (each must exit 0)."""
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        subprocess.run(args, cwd=cwd, check=True, capture_output=True, timeout=600)
        best = min(best, time.perf_counter() - t0)
    return best


def command_names() -> list[str]:
    """Every sub-command of ``rockyade``."""
    from rockyade.cli import build_parser

    parser = build_parser()
    [sub] = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return list(sub.choices)


def main() -> None:
    """Print each command's start-up and ``rockyade run`` end to end against their targets."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5, help="runs per measurement; the best counts")
    ap.add_argument("--commands", nargs="*", help="commands to time (default: all)")
    ap.add_argument(
        "--quick", action="store_true", help="once, the params command, the reference DEM's run only, no warm-up run"
    )
    opts = ap.parse_args()
    if opts.quick:
        opts.repeat, opts.commands = 1, opts.commands or ["params"]
    cli = [sys.executable, "-m", "rockyade"]
    commands = opts.commands or command_names()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        (work / "scene.toml").write_text(SCENE)
        solvers = RUN_SOLVERS[-1:] if opts.quick else RUN_SOLVERS  # quick: the same path, one solver
        runs = {s: [*cli, "run", "scene.toml", "--solver", s, "--out", f"{s}.csv"] for s in solvers}
        for run in runs.values() if not opts.quick else ():  # quick: its one timed run may compile
            subprocess.run(run, cwd=work, check=True, capture_output=True, timeout=600)  # compiles/caches the kernel
        print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())} ({os.cpu_count()} CPUs)")
        bare = best_wall_s([sys.executable, "-c", "pass"], opts.repeat, work)
        print(f"{'python -c pass':<28} {bare:7.3f} s")
        print(f"{'command':<28} {'wall_s':>7} {'target_s':>9} {'ratio':>6}")
        for name in commands:
            wall = best_wall_s([*cli, name, "--help"], opts.repeat, work)
            print(f"{name + ' --help':<28} {wall:7.3f} {STARTUP_TARGET_S:9.2f} {wall / STARTUP_TARGET_S:6.2f}")
        for solver, run in runs.items():
            wall = best_wall_s(run, opts.repeat, work)
            label = f"run --solver {solver} (1 s)"
            print(f"{label:<28} {wall:7.3f} {RUN_TARGET_S:9.2f} {wall / RUN_TARGET_S:6.2f}")
        print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
