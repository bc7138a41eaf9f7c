"""What a limit analysis will cost, estimated before its programme is solved (``rockyade limit``).

The rigid-block model is built first (linear in the blocks: about 1 ms of CPU per block, the
contacts at rest included); its size then sets the programme's: 3 rows per moving block, 4
columns per joint and one for lambda (:mod:`rockyade.limit.lp`). One programme's time follows the
method :func:`rockyade.limit.lp.choose_solver` takes, each fitted on the running-bond walls that
``rockyade build wall`` makes (CPU seconds; docs/limit.md, "Cost"):

* the dual simplex (below ``HIPO_COLUMNS`` columns): quadratic in the nonzeros,
  seconds ~ SECONDS_PER_NONZERO x nonzeros ** NONZERO_EXPONENT (0.29 s at 305 blocks);
* HiPO (from ``HIPO_COLUMNS``): seconds ~ HIPO_SECONDS_PER_NONZERO x nonzeros ** 1.5 (1.0, 5.8 and
  34 s at 999, 3,025 and 10,050 blocks), plus ``CHILD_START_S`` where the programme runs in a child
  process (from ``CHILD_COLUMNS`` columns);

memory ~ BASE_MEMORY_BYTES + BYTES_PER_NONZERO x nonzeros (262 MB at most in one process for the
10,050-block wall), an order of magnitude, as the runs' estimates
(:mod:`rockyade.solvers.cost_estimate`). The coulomb rule solves one programme per iteration after
the associated one: most converge within :data:`TYPICAL_ITERATIONS`, and ``--max-iterations``
bounds them.

:data:`LIMITS` are the documented limits (docs/limit.md); above one, ``rockyade limit`` refuses
the analysis unless ``--allow-large`` is given.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rockyade.errors import InputError, at_least, at_most
from rockyade.limit.lp import CHILD_COLUMNS, choose_solver
from rockyade.limit.rigid_blocks import RigidBlockModel

#: The fit of one programme's CPU time by the dual simplex (below HIPO_COLUMNS columns), s.
SECONDS_PER_NONZERO = 5.0e-10
NONZERO_EXPONENT = 2.0
#: The fit of one programme's CPU time by HiPO (from HIPO_COLUMNS columns), s: 1.0, 5.8 and 34 s of
#: CPU at 70,083, 216,265 and 725,250 nonzeros (running-bond walls of 999, 3,025 and 10,050 blocks).
HIPO_SECONDS_PER_NONZERO = 5.4e-8
HIPO_NONZERO_EXPONENT = 1.5
#: A programme solved in a child process (from CHILD_COLUMNS columns) pays the child's start, s of CPU.
CHILD_START_S = 1.0
#: Memory: the interpreter with numpy and scipy, and per nonzero of the programme, bytes.
BASE_MEMORY_BYTES = 150.0e6
BYTES_PER_NONZERO = 200.0
#: Iterations of the coulomb rule assumed by the expected time (the walls measured took 10 to 40).
TYPICAL_ITERATIONS = 30
#: Documented limits (docs/limit.md); ``--allow-large`` lifts them.
LIMITS: dict[str, float] = {
    "expected_time_s": 600.0,  # ten minutes of programmes
    "memory_bytes": 4.0 * 1024**3,  # 4 GiB
}


@dataclass(frozen=True)
class LimitCost:
    """What a limit analysis will cost (module docstring).

    Attributes
    ----------
    blocks, moving_blocks, joints
        The model's size.
    rows, variables, nonzeros
        The equilibrium programme's size.
    friction_rule
        "associated" or "coulomb".
    programmes
        Programmes expected: 1, or 1 + min(max_iterations, TYPICAL_ITERATIONS) for the coulomb rule.
    max_programmes
        Programmes at most (1 + max_iterations for the coulomb rule).
    seconds_per_programme
        One programme's expected time, s (an order of magnitude).
    memory_bytes
        Peak memory, bytes (an order of magnitude).
    """

    blocks: int
    moving_blocks: int
    joints: int
    rows: int
    variables: int
    nonzeros: int
    friction_rule: str
    programmes: int
    max_programmes: int
    seconds_per_programme: float
    memory_bytes: float

    @property
    def expected_time_s(self) -> float:
        """The analysis' expected time, s."""
        return self.programmes * self.seconds_per_programme

    @property
    def max_time_s(self) -> float:
        """Its time if every allowed programme is solved, s."""
        return self.max_programmes * self.seconds_per_programme

    def describe(self) -> str:
        """One line: the sizes, the expected time and memory."""
        if self.max_programmes > 1:
            programmes = (
                f"{self.programmes} programmes expected (at most {self.max_programmes}: {_duration(self.max_time_s)})"
            )
        else:
            programmes = "1 programme"
        return (
            f"{_n(self.blocks, 'block')} ({self.moving_blocks} moving), {_n(self.joints, 'joint')}; "
            f"{self.rows} equations, {self.variables} variables, {self.nonzeros} nonzeros; {programmes}; expected "
            f"{_duration(self.expected_time_s)} and about {self.memory_bytes / 1e6:.0f} MB"
        )

    def to_dict(self) -> dict[str, object]:
        """Plain data (the ``cost`` of ``rockyade limit --json``)."""
        return {
            "blocks": self.blocks,
            "moving_blocks": self.moving_blocks,
            "joints": self.joints,
            "rows": self.rows,
            "variables": self.variables,
            "nonzeros": self.nonzeros,
            "friction_rule": self.friction_rule,
            "programmes": self.programmes,
            "max_programmes": self.max_programmes,
            "seconds_per_programme": self.seconds_per_programme,
            "expected_time_s": self.expected_time_s,
            "memory_bytes": self.memory_bytes,
        }


def _n(count: int, noun: str) -> str:
    return f"{count} {noun}{'' if count == 1 else 's'}"


def _duration(seconds: float) -> str:
    if seconds < 1.0:
        return "under 1 s"
    if seconds < 120.0:
        return f"about {seconds:.0f} s"
    return f"about {seconds / 60.0:.0f} min"


def estimate_limit_cost(
    model: RigidBlockModel, friction_rule: str = "associated", max_iterations: int = 100
) -> LimitCost:
    """The cost of the limit analysis of ``model`` (module docstring).

    Parameters
    ----------
    model
        The rigid-block model.
    friction_rule
        "associated" or "coulomb".
    max_iterations
        The coulomb rule's programmes at most after the associated one.
    """
    moving = int(model.moving.size)
    joints = len(model.interfaces)
    rows = 3 * moving
    variables = 4 * joints + 1
    # each column touches the 3 equations of each moving body it joins: at most 2 x 3, plus lambda's
    nonzeros = sum(
        3 * ((itf.a >= 0 and not model.fixed[itf.a]) + (itf.b >= 0 and not model.fixed[itf.b]))
        for itf in model.interfaces
    )
    nonzeros = 4 * nonzeros + moving
    sliding = any(itf.friction_angle_deg is not None for itf in model.interfaces)
    iterated = friction_rule == "coulomb" and sliding
    programmes = 1 + (min(max_iterations, TYPICAL_ITERATIONS) if iterated else 0)
    max_programmes = 1 + (max_iterations if iterated else 0)
    seconds = programme_seconds(variables, nonzeros)
    memory = BASE_MEMORY_BYTES + BYTES_PER_NONZERO * nonzeros
    return LimitCost(
        model.n_blocks,
        moving,
        joints,
        rows,
        variables,
        nonzeros,
        friction_rule,
        programmes,
        max_programmes,
        seconds,
        memory,
    )


def programme_seconds(variables: int, nonzeros: int) -> float:
    """One programme's expected time, s: the fit of the method :func:`rockyade.limit.lp.choose_solver`
    takes for it (module docstring), with the child process's start where it runs in one."""
    if choose_solver("highs", variables) == "hipo":
        seconds = HIPO_SECONDS_PER_NONZERO * max(nonzeros, 1) ** HIPO_NONZERO_EXPONENT
    else:
        seconds = SECONDS_PER_NONZERO * max(nonzeros, 1) ** NONZERO_EXPONENT
    return seconds + (CHILD_START_S if variables >= CHILD_COLUMNS else 0.0)


_WHAT = {
    "expected_time_s": ("seconds of programmes", "--friction-rule associated (one programme), a smaller model"),
    "memory_bytes": ("bytes of memory", "a smaller model (fewer blocks)"),
}


def check_limit_cost(
    cost: LimitCost,
    allow_large: bool = False,
    limits: dict[str, float] | None = None,
    time_limit_s: float | None = None,
) -> None:
    """Refuse (InputError naming ``--allow-large``) an analysis whose estimate is above ``limits``
    (default :data:`LIMITS`), unless ``allow_large``. ``time_limit_s`` (``--time-limit``) bounds the
    programmes' time: an analysis whose time limit is within the limit is not refused for its
    expected time, whatever the estimate."""
    if allow_large:
        return
    limits = LIMITS if limits is None else limits
    for name, limit in limits.items():
        value = getattr(cost, name)
        if name == "expected_time_s" and time_limit_s is not None and time_limit_s <= limit:
            continue  # the user's bound holds: the programmes stop at time_limit_s
        if math.isfinite(value) and value > limit:
            what, remedy = _WHAT[name]
            if name == "expected_time_s":
                remedy += f", --time-limit S with S <= {limit:g} (it stops the programmes then)"
            raise InputError(
                "--allow-large",
                f"the limit analysis needs {at_least(value)} {what}, above the limit {at_most(limit)} "
                f"({cost.describe()}); use {remedy}, or pass --allow-large to run it anyway",
            )
