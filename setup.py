"""Packaging beyond pyproject.toml: the repository's ``examples/`` folder ships inside the
wheel as ``rockyade/examples`` (``rockyade examples --out DIR`` copies it out), while git keeps
one copy of it. Each of its subfolders is named as a (data-only) package, so that setuptools
knows where its files go. Everything else is configured in pyproject.toml."""

from pathlib import Path

from setuptools import find_namespace_packages, setup

EXAMPLES = Path(__file__).resolve().parent / "examples"
example_packages = [
    "rockyade.examples",
    *sorted(
        f"rockyade.examples.{p.name}" for p in EXAMPLES.iterdir() if p.is_dir() and not p.name.startswith((".", "__"))
    ),
]

setup(
    packages=[*find_namespace_packages(include=["rockyade*"]), *example_packages],
    package_dir={"rockyade.examples": "examples"},
)
