"""Run every benchmark in this directory (``bench_*.py``) and print their figures."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

if __name__ == "__main__":
    here = Path(__file__).resolve().parent
    selected = sys.argv[1:]
    for path in sorted(here.glob("bench_*.py")):
        if selected and path.stem not in selected:
            continue
        print(f"=== {path.stem}")
        sys.argv = [str(path)]  # each script its own options (none: its full run), not this selection
        runpy.run_path(str(path), run_name="__main__")
