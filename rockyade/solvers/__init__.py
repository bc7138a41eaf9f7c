"""Solvers: each turns a Scene into a Result with the same schema.

``housner`` (exact classical SDOF), ``reference`` (standalone rigid-polygon DEM, numba) and
``yade`` (YADE in batch mode). Solvers never import each other; this registry is the only
place that knows them all.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from rockyade.errors import InputError, SolverUnavailableError
from rockyade.result import Result
from rockyade.scene import Scene

#: solver name -> module providing ``run_scene(scene) -> Result``
SOLVER_MODULES = {
    "housner": "rockyade.solvers.housner",
    "reference": "rockyade.solvers.reference",
    "yade": "rockyade.solvers.yade",
}


def solver_names() -> list[str]:
    """All solver names rockyade knows."""
    return list(SOLVER_MODULES)


def get_solver(name: str) -> Callable[[Scene], Result]:
    """The ``run_scene`` function of solver ``name``.

    Raises
    ------
    InputError
        Unknown name.
    SolverUnavailableError
        Known but not available here (module missing, or its engine not installed).
    """
    if name not in SOLVER_MODULES:
        raise InputError("solver", f"must be one of {', '.join(SOLVER_MODULES)}, got {name!r}")
    try:
        module = importlib.import_module(SOLVER_MODULES[name])
    except ModuleNotFoundError as exc:
        if exc.name == SOLVER_MODULES[name]:
            raise SolverUnavailableError(f"solver {name!r} is not available in this version of rockyade") from None
        raise
    return module.run_scene


def run(scene: Scene, solver: str = "housner") -> Result:
    """Run ``scene`` with ``solver``."""
    return get_solver(solver)(scene)
