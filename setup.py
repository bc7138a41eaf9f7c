"""Packaging beyond pyproject.toml: the repository's ``examples/`` folder ships inside the
wheel as ``rockyade/examples`` (``rockyade examples --out DIR`` copies it out), while git keeps
one copy of it. Everything else is configured in pyproject.toml."""

from setuptools import find_namespace_packages, setup

setup(
    packages=[*find_namespace_packages(include=["rockyade*"]), "rockyade.examples"],
    package_dir={"rockyade.examples": "examples"},
)
