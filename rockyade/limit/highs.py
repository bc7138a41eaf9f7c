"""One linear programme solved by HiGHS (``highspy``), in this process or in a child process.

A :class:`Programme` is HiGHS's form of a linear programme: minimise c x subject to
row_lower <= A x <= row_upper and col_lower <= x <= col_upper. :func:`solve_programme` solves it
with one of HiGHS's methods (:data:`SOLVERS`) and returns a :class:`ProgrammeOutcome` whose status
follows scipy's ``linprog`` (0 optimal, 1 stopped at the time limit, 2 infeasible, 3 unbounded,
4 failed), whose ``marginals`` are the row duals as scipy's ``eqlin.marginals`` (d objective /
d b), and HiGHS's log can go to standard output.

HiGHS (Huangfu & Hall 2018, "Parallelizing the dual revised simplex method", Math. Prog. Comp.
10, 119-142; its interior point solvers IPX, Schork & Gondzio 2020, and HiPO, Zanetti & Gondzio
2025) is the library scipy's ``linprog`` wraps; ``highspy`` gives its current version, HiPO (an
interior point method with a direct factorisation, in ``highspy-extras``) and its log.

:mod:`rockyade.limit.highs_child` runs :func:`solve_programme` in a child process that Ctrl-C can
end at once, and that dies with its parent.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from rockyade.errors import InputError

#: The methods: "simplex" (HiGHS's dual simplex: a vertex), "ipx" (the interior point method IPX
#: with its crossover to a vertex), "hipo" (the interior point method HiPO, no crossover: a point of
#: the optimal face's interior, to HiGHS's tolerance 1e-8).
SOLVERS = ("simplex", "ipx", "hipo")


@dataclass(frozen=True)
class Programme:
    """minimise c x subject to row_lower <= A x <= row_upper, col_lower <= x <= col_upper.

    Attributes
    ----------
    c
        (n,) costs.
    A
        (m, n) constraint matrix (any scipy.sparse format; stored column-wise).
    row_lower, row_upper
        (m,) row bounds (equal for an equation); +-inf for none.
    col_lower, col_upper
        (n,) variable bounds; +-inf for none.
    """

    c: NDArray[np.float64]
    A: sp.csc_matrix
    row_lower: NDArray[np.float64]
    row_upper: NDArray[np.float64]
    col_lower: NDArray[np.float64]
    col_upper: NDArray[np.float64]

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns)."""
        return (int(self.A.shape[0]), int(self.A.shape[1]))

    def arrays(self) -> dict[str, NDArray[Any]]:
        """Plain arrays (for ``numpy.savez``), the matrix as CSC; :meth:`from_arrays` reads them."""
        A = sp.csc_matrix(self.A)
        return {
            "c": self.c,
            "indptr": A.indptr,
            "indices": A.indices,
            "data": A.data,
            "shape": np.asarray(A.shape),
            "row_lower": self.row_lower,
            "row_upper": self.row_upper,
            "col_lower": self.col_lower,
            "col_upper": self.col_upper,
        }

    @classmethod
    def from_arrays(cls, a: Mapping[str, NDArray[Any]]) -> Programme:
        """The programme of :meth:`arrays`."""
        shape = tuple(int(s) for s in a["shape"])
        A = sp.csc_matrix((a["data"], a["indices"], a["indptr"]), shape=shape)
        return cls(a["c"], A, a["row_lower"], a["row_upper"], a["col_lower"], a["col_upper"])


@dataclass(frozen=True)
class ProgrammeOutcome:
    """What HiGHS gave (module docstring).

    Attributes
    ----------
    status
        0 optimal, 1 stopped at the time limit (or interrupted), 2 infeasible, 3 unbounded, 4 failed.
    x
        (n,) the solution (optimal only, else None).
    marginals
        (m,) d objective / d row bound (optimal only, else None).
    message
        HiGHS's model status in words.
    seconds
        Wall time of HiGHS's run, s.
    iterations
        {"simplex": ..., "ipm": ..., "crossover": ...}.
    """

    status: int
    x: NDArray[np.float64] | None
    marginals: NDArray[np.float64] | None
    message: str
    seconds: float
    iterations: dict[str, int] = field(default_factory=dict)


def check_solver(solver: str) -> str:
    """``solver`` if it is one of :data:`SOLVERS`, else InputError."""
    if solver not in SOLVERS:
        raise InputError("method", f"must be one of {', '.join(SOLVERS)}, got {solver!r}")
    return solver


def _options(solver: str) -> dict[str, str | int]:
    if solver == "simplex":
        return {"solver": "simplex", "simplex_strategy": 1}  # the dual simplex
    if solver == "ipx":
        return {"solver": "ipx", "run_crossover": "on"}
    # HiPO on the normal equations (lp.py removes the one dense column, lambda's), no presolve (it
    # would put that column back), no crossover: the crossover of a programme this degenerate costs
    # more than the interior point method (docs/limit.md, "Cost")
    return {"solver": "hipo", "run_crossover": "off", "presolve": "off", "hipo_system": "normaleq"}


_STATUS = {
    "kOptimal": 0,
    "kTimeLimit": 1,
    "kIterationLimit": 1,
    "kInterrupt": 1,
    "kInfeasible": 2,
    "kUnbounded": 3,
}


def solve_programme(
    programme: Programme, solver: str = "simplex", time_limit_s: float | None = None, log: bool = False
) -> ProgrammeOutcome:
    """Solve ``programme`` with HiGHS's ``solver`` (:data:`SOLVERS`) in this process.

    Parameters
    ----------
    programme
        The programme.
    solver
        "simplex", "ipx" or "hipo" (:data:`SOLVERS`).
    time_limit_s
        Wall time HiGHS may take, s (None: none); past it status 1.
    log
        HiGHS writes its log (its progress) on standard output (the child process's: a file).
    """
    import highspy
    from highspy._core import _Highs

    check_solver(solver)
    A = sp.csc_matrix(programme.A)
    m, n = A.shape
    # The solver itself, not highspy.Highs: that wrapper's constructor calls a HiGHS method while
    # output_flag is still at its default (on), which logs HiGHS's banner ("Running HiGHS ...") on
    # this process's standard output, in front of `rockyade limit --json`'s and `assess --json`'s
    # JSON. Nothing of the wrapper's (callbacks, its own Ctrl-C handling) is used here.
    h = _Highs()
    h.setOptionValue("output_flag", log)
    for key, value in _options(solver).items():
        h.setOptionValue(key, value)
    if time_limit_s is not None:
        h.setOptionValue("time_limit", max(float(time_limit_s), 1.0e-3))
    inf = highspy.kHighsInf
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, m
    lp.col_cost_ = np.asarray(programme.c, dtype=float)
    lp.col_lower_ = np.clip(programme.col_lower, -inf, inf)
    lp.col_upper_ = np.clip(programme.col_upper, -inf, inf)
    lp.row_lower_ = np.clip(programme.row_lower, -inf, inf)
    lp.row_upper_ = np.clip(programme.row_upper, -inf, inf)
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_ = A.indptr
    lp.a_matrix_.index_ = A.indices
    lp.a_matrix_.value_ = A.data
    h.passModel(lp)
    start = time.perf_counter()
    h.run()
    model_status = h.getModelStatus()
    if model_status.name == "kUnboundedOrInfeasible":  # presolve cannot tell which: solve without it
        h.setOptionValue("presolve", "off")
        h.run()
        model_status = h.getModelStatus()
    seconds = time.perf_counter() - start
    message = h.modelStatusToString(model_status)
    status = _STATUS.get(model_status.name, 4)
    info = h.getInfo()
    iterations = {
        "simplex": int(info.simplex_iteration_count),
        "ipm": int(info.ipm_iteration_count),
        "crossover": int(info.crossover_iteration_count),
    }
    if status != 0:
        return ProgrammeOutcome(status, None, None, message, seconds, iterations)
    solution = h.getSolution()
    x = np.array(solution.col_value, dtype=float)
    marginals = np.array(solution.row_dual, dtype=float)
    return ProgrammeOutcome(0, x, marginals, message, seconds, iterations)
