"""Solvers: objects that turn a Scene into a Result with the same schema.

``housner`` (:class:`~rockyade.solvers.housner.HousnerSolver`, exact classical SDOF),
``reference`` (:class:`~rockyade.solvers.reference.ReferenceSolver`, standalone
rigid-polygon DEM, numba), ``yade`` (:class:`~rockyade.solvers.yade.YadeSolver`, YADE
in batch mode), ``siconos`` (:class:`~rockyade.solvers.siconos.SiconosSolver`,
nonsmooth contact dynamics in Debian's Siconos) and ``twoblock``
(:class:`~rockyade.solvers.twoblock.TwoBlockSolver`, the exact solution of two stacked
blocks). Each is a :class:`~rockyade.solvers.base.Solver`: ``run(scene)``,
``estimate_cost(scene)`` and its options as fields. Solvers never import each other; this
registry is the only place that knows them all, and it hands back instances::

    from rockyade.solvers import make_solver, run

    result = run(scene, "housner")                       # a name, or a Solver
    yade = make_solver("yade", timeout_s=600)            # options checked by name
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable, Mapping
from typing import Any

from rockyade.errors import InputError, SolverUnavailableError
from rockyade.result import Result
from rockyade.scene import Scene
from rockyade.solvers.base import Solver, SolverBase

#: solver name -> (module, class) of its Solver
SOLVER_CLASSES = {
    "housner": ("rockyade.solvers.housner", "HousnerSolver"),
    "reference": ("rockyade.solvers.reference", "ReferenceSolver"),
    "yade": ("rockyade.solvers.yade", "YadeSolver"),
    "siconos": ("rockyade.solvers.siconos", "SiconosSolver"),
    "twoblock": ("rockyade.solvers.twoblock", "TwoBlockSolver"),
}


def solver_names() -> list[str]:
    """All solver names rockyade knows."""
    return list(SOLVER_CLASSES)


def solver_class(name: str) -> type[SolverBase]:
    """The class of solver ``name``.

    Raises
    ------
    InputError
        Unknown name.
    SolverUnavailableError
        Known but not available in this version (its module is missing).
    """
    if name not in SOLVER_CLASSES:
        raise InputError("solver", f"must be one of {', '.join(SOLVER_CLASSES)}, got {name!r}")
    module_name, class_name = SOLVER_CLASSES[name]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name == module_name:
            raise SolverUnavailableError(f"solver {name!r} is not available in this version of rockyade") from None
        raise
    return getattr(module, class_name)


def make_solver(name: str, *, fields: Mapping[str, str] | None = None, **options: Any) -> Solver:
    """Solver ``name`` with ``options`` (e.g. ``make_solver("yade", timeout_s=600)``).

    Parameters
    ----------
    fields
        How the options are named in errors (e.g. ``{"timeout_s": "--yade-timeout"}``).

    Raises
    ------
    InputError
        Unknown name, an option the solver does not take, or a value out of range.
    """
    return solver_class(name).from_options(options, fields)


def make_solvers(
    names: Iterable[str], options: Mapping[str, Any] | None = None, fields: Mapping[str, str] | None = None
) -> list[Solver]:
    """Solvers ``names``, each given the ``options`` it takes (an option such as YADE's
    ``timeout_s`` goes to the solvers that have it).

    Raises
    ------
    InputError
        An option none of the solvers takes (naming the solvers that would), or a bad value.
    """
    classes = [solver_class(n) for n in names]
    options = dict(options or {})
    fields = dict(fields or {})
    for key in options:
        if not any(key in cls.OPTIONS for cls in classes):
            owners = [n for n in SOLVER_CLASSES if key in solver_class(n).OPTIONS]
            runs = ", ".join(cls.name for cls in classes)
            raise InputError(
                fields.get(key, key),
                f"applies to the {' and '.join(owners) or 'no'} solver{'s' if len(owners) > 1 else ''} only; "
                f"this runs {runs}",
            )
    return [cls.from_options({k: v for k, v in options.items() if k in cls.OPTIONS}, fields) for cls in classes]


def as_solver(solver: Solver | str) -> Solver:
    """A Solver as given, or the default one of that name."""
    return make_solver(solver) if isinstance(solver, str) else solver


def run(scene: Scene, solver: Solver | str = "housner") -> Result:
    """Run ``scene`` with ``solver`` (a name, or a Solver with its options)."""
    return as_solver(solver).run(scene)


__all__ = ["Solver", "as_solver", "make_solver", "make_solvers", "run", "solver_class", "solver_names"]
