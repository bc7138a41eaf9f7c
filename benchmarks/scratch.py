"""A benchmark's scratch folder: its studies' outputs, removed when the script ends (they are
measured, not kept: ``make bench`` left one folder per run in the temporary folder)."""

from __future__ import annotations

import atexit
import shutil
import tempfile
from pathlib import Path


def scratch_folder(prefix: str) -> Path:
    """A new folder in the temporary folder, named ``prefix`` and a random part, removed (with
    what it holds) when the Python running the benchmark exits."""
    folder = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    return folder
