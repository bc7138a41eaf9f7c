"""``rockyade verify``: the DEMs on assemblies against closed forms, each other and the baseline."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rockyade.cli.common import Commands, add_command, check_output_dir
from rockyade.errors import InputError
from rockyade.studies.verification_checks import CHECKS


def cmd_verify(args: argparse.Namespace) -> int:
    """verification report: assemblies in both DEMs against closed forms and each other

    Rocking frame (Makris & Vassiliou p_hat), 8-drum column uplift, pad case overlaps, a 1,000-block wall at rest,
    reference DEM against YADE, this version's single-block and bi-block baseline, the limit analysis' kinematic
    quantities and the code's checks against closed forms and a hand calculation, the fragility fit recovering a known
    curve, and a block with a top load (its multiplier from the limit analysis, Housner's uplift and the reference
    DEM's pushover against the closed form), and the limit analysis' multiplier against the reference DEM's pushover
    onset for a block, a 20-voussoir arch, a wall restrained at its top and a running-bond panel (within 2 %), and
    Siconos against closed forms (free-rocking restitution, a block's pushover, the rocking frame, a stack at rest).
    Writes verify.csv, a figure per check and index.md; exits 1 if any check fails.
    """
    checks = [c.strip() for c in args.only.split(",")] if args.only else list(CHECKS)
    unknown = [c for c in checks if c not in CHECKS]
    if unknown or not checks:
        raise InputError("only", f"must be a comma-separated list of {', '.join(CHECKS)}, got {args.only!r}")
    check_output_dir(args.out, "out")
    from rockyade.studies.verification import verify

    solvers = ["reference"] if args.no_yade else ["reference", "yade"]
    if not args.no_yade:
        from rockyade.yade.backend import yade_available

        if not yade_available():
            raise InputError("no-yade", "YADE is not installed here: install Debian's yade or pass --no-yade")

    def progress(check: str) -> None:
        print(f"verify: {check} ...", file=sys.stderr, flush=True)

    table = verify(args.out, checks, solvers, progress=progress)
    failed = table[~table["passed"]] if len(table) else table
    print(f"{len(table)} quantities checked, {len(failed)} failed; wrote {args.out / 'index.md'} and verify.csv")
    for _, r in failed.iterrows():
        print(f"  FAILED {r.check} ({r.solver}): {r.quantity} = {r.value:.6g}, expected {r.expected:.6g}", end="")
        print(f" ({r.tolerance})")
    return 1 if len(failed) else 0


def register(sub: Commands) -> None:
    """Add ``rockyade verify``."""
    p = add_command(sub, cmd_verify)
    p.add_argument("--out", type=Path, required=True, help="output directory")
    p.add_argument("--only", help=f"comma-separated checks among {', '.join(CHECKS)} (default: all)")
    p.add_argument("--no-yade", action="store_true", help="the reference DEM only")
