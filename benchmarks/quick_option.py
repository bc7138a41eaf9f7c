"""The options of a benchmark script: ``--quick`` (the short run that ``tests/test_benchmarks.py``
makes) and ``--help`` (the script's docstring), any other argument refused (exit 2)."""

from __future__ import annotations

import argparse


def quick_parser(doc: str | None) -> argparse.ArgumentParser:
    """A parser with ``--quick``, described by the script's docstring ``doc``."""
    parser = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="a short run (what the test suite runs)")
    return parser


def quick_mode(doc: str | None) -> bool:
    """Whether the script was asked for its short run (``--quick``); ``--help`` prints ``doc``."""
    return bool(quick_parser(doc).parse_args().quick)
