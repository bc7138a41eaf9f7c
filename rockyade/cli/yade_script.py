"""``rockyade yade-script``: a scene as a standalone YADE script and its data."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from rockyade.cli.common import Commands

LAUNCHER_WARNING = (
    "note: YADE's own launcher opens a Python console and an XMLRPC server on all network interfaces "
    "while it runs (rockyade never uses it); run it only where that is acceptable, or run the script "
    "with python3.11 and YADE's modules on the path (see docs/yade.md)"
)


def cmd_yade_script(args: argparse.Namespace) -> int:
    """a scene as a standalone YADE script (run.py + scene.json) to go on by hand

    Write run.py (the script rockyade runs in YADE) and scene.json (the scene's data) into a folder.
    `yade -x DIR/run.py` runs it in batch, `yade DIR/run.py` with YADE's GUI; it writes result.npz and
    result.csv beside itself.
    """
    from rockyade.cli.common import check_output_dir
    from rockyade.scene import load_scene
    from rockyade.yade.backend import write_script

    check_output_dir(args.out, "--out")
    paths = write_script(load_scene(args.scene), args.out)
    out = args.out
    print(f"wrote {paths['script']} (and {paths['loop'].name}, which it loads) and {paths['data']}")
    print(f"  batch:        yade -x {out / 'run.py'}")
    print(f"  with the GUI: yade {out / 'run.py'}")
    print(f"  without the launcher (no server): /usr/bin/python3.11 {out / 'run.py'}")
    print(f"  output: {out / 'result.npz'} (rockyade's format) and {out / 'result.csv'}")
    print(LAUNCHER_WARNING)
    return 0


def register(sub: Commands) -> None:
    """Add ``rockyade yade-script``."""
    from rockyade.cli.common import add_command

    p = add_command(sub, cmd_yade_script)
    p.description = f"{p.description} {LAUNCHER_WARNING}."  # the warning the command prints, written once
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument("--out", type=Path, required=True, help="folder for run.py and scene.json")
