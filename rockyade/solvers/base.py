"""What a solver is: an object that turns a Scene into a Result, carrying its own options.

A solver has a ``name`` (the registry's, :func:`rockyade.solvers.solver_names`), runs a
scene (``run(scene) -> Result``), says what a run will cost before it starts
(``estimate_cost(scene)``, :mod:`rockyade.runner.cost_limits`) and places the files it keeps, if
any (``keeping_files(folder, stem)``: YADE's scene data, output and log; the other solvers
keep none and return themselves). Solver objects are frozen dataclasses: they pickle, so
they travel to worker processes and Dask workers with the scene.

Options are the dataclass's fields (e.g. ``ReferenceSolver(record_energy=False)``,
``YadeSolver(timeout_s=600)``); :meth:`SolverBase.from_options` checks options given by
name (from a command line or a study file) and refuses one the solver does not take.

Every solver derived from :class:`SolverBase` goes through one place on its way out: its
``run`` is wrapped (:meth:`SolverBase.__init_subclass__`) so that every Result it returns,
failed ones included, carries ``meta.motion_coverage``, how much of the scene's base
motion the run leaves out (:func:`motion_coverage`).

A solver that runs scenes sharing one structure together (one model, many base motions) is
also a :class:`GroupSolver`: ``group_key(scene)`` says which scenes go together and
``run_group(scenes, uplift_rad)`` runs them, one :class:`GroupRun` each (no time history).
Batches and the overturning study ask ``isinstance(solver, GroupSolver)``.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, Self, runtime_checkable

import numpy as np

from rockyade import __version__
from rockyade.errors import InputError, RockyadeError
from rockyade.io.warm_program import check_timeout
from rockyade.run_meta import RunMeta, as_status

if TYPE_CHECKING:
    from rockyade.result import Result
    from rockyade.scene import Scene
    from rockyade.solvers.cost_estimate import CostEstimate

#: Checks an option's value: (value, field named in errors) -> the value to use.
OptionCheck = Callable[[Any, str], Any]


@runtime_checkable
class Solver(Protocol):
    """The interface every solver offers (see the module docstring)."""

    @property
    def name(self) -> str:
        """The registry's name of this solver (a class attribute in :class:`SolverBase`)."""
        ...

    def run(self, scene: Scene) -> Result:
        """Run ``scene``; a failed run is a Result with status ``failed`` or an exception."""
        ...

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """What running ``scene`` will cost (steps, samples, memory, time)."""
        ...

    def keeping_files(self, folder: str | Path, stem: str | None = None) -> Self:
        """This solver with the files it keeps in ``folder``, named ``stem`` (default: the
        scene hash and the solver's name); itself when it keeps none."""
        ...


@dataclass(frozen=True)
class GroupRun:
    """One run of :meth:`GroupSolver.run_group`.

    Attributes
    ----------
    meta
        The Result's metadata of the run.
    theta_rad
        (n,) sampled rotation from rest, rad.
    sample_dt_s
        Time between samples, s.
    metrics
        Computed by the solver: ``max_abs_theta_rad`` (rad), ``residual_theta_rad`` (rad),
        ``uplift_time_s`` (s, NaN: never).
    """

    meta: RunMeta
    theta_rad: np.ndarray
    sample_dt_s: float
    metrics: dict[str, float]

    @property
    def status(self) -> str:
        """completed | overturned | failed."""
        return self.meta.status


@runtime_checkable
class GroupSolver(Solver, Protocol):
    """A solver that also runs scenes sharing one structure together (module docstring)."""

    def group_key(self, scene: Scene) -> str | None:
        """What the scenes run together have in common (equal keys: one group); None: this
        scene's run goes alone."""
        ...

    def run_group(self, scenes: Sequence[Scene], uplift_rad: float, threads: int = 1) -> list[GroupRun]:
        """Run scenes of one :meth:`group_key` together, in their order: each run's metadata (as
        ``run``'s Result, without the history), its sampled rotation and its metrics.

        Parameters
        ----------
        scenes
            Scenes with one group key (not None).
        uplift_rad
            |theta| above which the block counts as lifted off (``uplift_time_s``), rad.
        threads
            Threads the solver may use for the group.
        """
        ...


def check_scene(solver: Solver, scene: Scene) -> None:
    """``solver.check_scene(scene)`` where the solver has it (:meth:`SolverBase.check_scene`):
    raise the InputError its run would raise, before any run starts."""
    check = getattr(solver, "check_scene", None)
    if check is not None:
        check(scene)


def check_flag(value: object, field: str) -> bool:
    """A true/false option."""
    if not isinstance(value, bool):
        raise InputError(field, f"must be true or false, got {value!r}")
    return value


def check_float(value: Any, field: str, lo: float, hi: float, what: str, *, lo_open: bool = False) -> float:
    """``value`` (a number, or text that reads as one; not a bool) as a float in [lo, hi], or
    in (lo, hi] with ``lo_open``; else InputError naming ``field``: "must be ``what``"."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be {what}, got {value!r}") from None
    low_ok = x > lo if lo_open else x >= lo
    if isinstance(value, bool) or not (low_ok and x <= hi):
        raise InputError(field, f"must be {what}, got {value!r}")
    return x


def check_folder(value: object, field: str) -> str | None:
    """A folder path (text or a Path) or None."""
    if value is not None and not isinstance(value, (str, Path)):
        raise InputError(field, f"must be a folder path, got {value!r}")
    return None if value is None else str(value)


#: Range of ``dt_factor``, the factor on a solver's own time step: [DT_FACTOR_MIN, 1].
DT_FACTOR_MIN = 1e-3


def check_dt_factor(value: object, field: str) -> float:
    """A factor on the solver's own time step, in [0.001, 1] (1: the step the solver chooses;
    0.5: half of it, the convergence check of a cross-check). Below :data:`DT_FACTOR_MIN`
    it is refused (a thousand times the steps is not a check, it is a hang)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not DT_FACTOR_MIN <= float(value) <= 1.0:
        raise InputError(
            field, f"must be a number in [{DT_FACTOR_MIN:g}, 1] (a factor on the solver's time step), got {value!r}"
        )
    return float(value)


#: The options of a solver that runs another program in a worker (YADE, Siconos): the run's
#: timeout, a warm worker or a process of its own, the factor on the time step, the folder its
#: files are kept in.
WORKER_OPTIONS: Mapping[str, OptionCheck] = {
    "timeout_s": check_timeout,
    "warm": check_flag,
    "dt_factor": check_dt_factor,
    "workdir": check_folder,
}


def motion_coverage(scene: Scene) -> dict[str, Any]:
    """How much of ``scene``'s base motion its run covers
    (:func:`rockyade.motion.coverage.record_coverage`: status, time, PGA and Arias intensity
    left out, a sentence); when it cannot be worked out, ``status`` "unknown" and why.

    Worked out once per scene content (``scene.scene_hash``, which covers the motion's files by
    their bytes and the duration): ``rockyade run`` warns of a cut motion before the run and the
    solver's Result then carries the same coverage without reading the record again. A copy is
    returned each time.
    """
    try:
        key = scene.scene_hash
    except (RockyadeError, OSError, ValueError):  # a motion file that cannot be read: said below
        return _coverage(scene)
    if key not in _COVERAGE:
        if len(_COVERAGE) >= _COVERAGE_KEPT:
            _COVERAGE.pop(next(iter(_COVERAGE)))
        _COVERAGE[key] = _coverage(scene)
    return copy.deepcopy(_COVERAGE[key])


#: :func:`motion_coverage` of the last scenes, by scene hash (at most ``_COVERAGE_KEPT``).
_COVERAGE: dict[str, dict[str, Any]] = {}
_COVERAGE_KEPT = 16


def _coverage(scene: Scene) -> dict[str, Any]:
    """:func:`motion_coverage`, worked out."""
    from rockyade.motion.coverage import record_coverage

    try:
        return record_coverage(scene.motion, scene.duration_s)
    except (RockyadeError, OSError, ValueError) as exc:  # the run itself says what is wrong
        return {"status": "unknown", "message": f"{type(exc).__name__}: {exc}"}


def classical_meta(scene: Scene) -> dict[str, Any]:
    """``meta.classical`` of a run: per moving block, the classical parameters of the body that
    rocks, the masses of the loads it carries merged in, each direction its own alpha, R, p, mu
    and uplift acceleration (:func:`rockyade.scene.carried.loaded_classical`), as every solver
    reports them."""
    from rockyade.constants import G
    from rockyade.scene.carried import loaded_classical

    return {name: cp.as_dict() for name, cp in loaded_classical(scene, G).items()}


def _with_coverage(run: Callable[[Any, Scene], Result]) -> Callable[[Any, Scene], Result]:
    """``run`` whose Result carries ``meta.motion_coverage`` and ``meta.classical``
    (:func:`classical_meta`), refusing first a scene whose loads
    cannot be carried at rest (:func:`rockyade.limit.standing.check_loads_stand`: its blocks would
    leave their supports for good, and no solver's answer would mean anything)."""

    @functools.wraps(run)
    def wrapper(self: Any, scene: Scene) -> Result:
        if getattr(scene, "loads", ()):
            from rockyade.limit.standing import check_loads_stand

            check_loads_stand(scene)
        say_if_compiling(self, scene)
        result = run(self, scene)
        if result.meta.motion_coverage is None:
            result.meta = dataclasses.replace(result.meta, motion_coverage=motion_coverage(scene))
        if result.meta.classical is None:
            result.meta = dataclasses.replace(result.meta, classical=classical_meta(scene))
        return result

    wrapper.records_coverage = True  # type: ignore[attr-defined]
    return wrapper


def say_if_compiling(solver: Any, scene: Scene) -> None:
    """Say on stderr, before a run, that it compiles the solver's code first (numba's cache
    lacks it, :meth:`SolverBase.compiled_cached`): else the first run of a process is silent
    for a minute or more. ``make setup`` compiles it ahead (:mod:`rockyade.solvers.compile_cache`)."""
    compiled_cached = getattr(solver, "compiled_cached", None)
    if compiled_cached is None or compiled_cached(scene):
        return
    print(
        f"rockyade: compiling the solver (first run only): {solver.name}, not in numba's cache (about "
        f"{solver.COMPILE_S:.0f} s of CPU; 'python -m rockyade.solvers.compile_cache' compiles every solver ahead) ...",
        file=sys.stderr,
        flush=True,
    )


def _with_compile_cost(estimate_cost: Callable[[Any, Scene], CostEstimate]) -> Callable[[Any, Scene], CostEstimate]:
    """``estimate_cost`` whose estimate counts the compilation a cold cache costs the first run
    (``compile_s``, :attr:`SolverBase.COMPILE_S`)."""

    @functools.wraps(estimate_cost)
    def wrapper(self: Any, scene: Scene) -> CostEstimate:
        estimate = estimate_cost(self, scene)
        if self.COMPILE_S and not estimate.compile_s and not self.compiled_cached(scene):
            estimate = dataclasses.replace(estimate, compile_s=self.COMPILE_S)
        return estimate

    wrapper.counts_compile = True  # type: ignore[attr-defined]
    return wrapper


class SolverBase:
    """What the solvers share: options by name and no files kept (override both as needed).

    Subclasses are frozen dataclasses whose fields are their options, with ``name`` and
    ``OPTIONS`` (option -> :data:`OptionCheck`) as class attributes. The ``run`` a subclass
    defines is wrapped so that its Results carry ``meta.motion_coverage`` and so that a scene
    whose loads cannot be carried at rest is refused before it runs, by every solver alike.
    """

    name: ClassVar[str] = ""
    OPTIONS: ClassVar[Mapping[str, OptionCheck]] = {}
    #: The solver computes in this process (numba code a parent loads once before it forks
    #: workers); False: it runs another program (YADE, Siconos).
    IN_PROCESS: ClassVar[bool] = False
    #: CPU time compiling this solver's numba code when the cache lacks it, s (0: it compiles
    #: nothing here), every path it takes; measured by ``python -m rockyade.solvers.compile_cache``
    #: on a cold cache (the 2-core machine: reference 79 s, twoblock 24 s, housner 9 s).
    COMPILE_S: ClassVar[float] = 0.0

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        run = cls.__dict__.get("run")
        if run is not None and not getattr(run, "records_coverage", False):
            # Replacing each subclass's own run with its wrapped self is deliberate (class docstring).
            cls.run = _with_coverage(run)  # type: ignore[method-assign,assignment]
        estimate = cls.__dict__.get("estimate_cost")
        if estimate is not None and not getattr(estimate, "counts_compile", False):
            cls.estimate_cost = _with_compile_cost(estimate)  # type: ignore[method-assign,assignment]

    @classmethod
    def from_options(cls, options: Mapping[str, Any], fields: Mapping[str, str] | None = None) -> Self:
        """The solver with ``options`` checked; ``fields`` names them in errors (e.g.
        ``{"timeout_s": "--yade-timeout"}``).

        Raises
        ------
        InputError
            An option this solver does not take, or a value out of its range.
        """
        fields = fields or {}
        checked = {}
        for key, value in options.items():
            field = fields.get(key, key)
            if key not in cls.OPTIONS:
                takes = ", ".join(cls.OPTIONS) or "none"
                raise InputError(field, f"is not an option of the {cls.name} solver (its options: {takes})")
            checked[key] = cls.OPTIONS[key](value, field)
        return cls(**checked)

    def __post_init__(self) -> None:
        """Check every option field by its :data:`OPTIONS` entry: a solver built in Python is
        checked as one built from options by name (:meth:`from_options`)."""
        for key, check in self.OPTIONS.items():
            object.__setattr__(self, key, check(getattr(self, key), key))

    def keeping_files(self, folder: str | Path, stem: str | None = None) -> Self:
        """Itself: this solver keeps no files."""
        return self

    def compiled_cached(self, scene: Scene) -> bool:
        """Whether the compiled code this solver runs ``scene`` with is in numba's on-disk cache
        (:func:`rockyade.solvers.cost_estimate.numba_cached`): else the first run in a process
        compiles it. True for a solver that compiles nothing here."""
        return True

    def warm_up(self) -> None:
        """Load this solver's compiled code in this process, compiling it into numba's cache
        when the cache lacks it (:mod:`rockyade.solvers.compile_cache`); nothing for a solver
        that compiles nothing here."""
        return None

    def warm_up_paths(self) -> dict[str, tuple[Callable[[], None], float]]:
        """The parts of :meth:`warm_up` that compile independently, each with its CPU s on a cold
        cache (together :attr:`COMPILE_S`): :mod:`rockyade.solvers.compile_cache` spreads them
        over its processes. One part, :meth:`warm_up` itself, unless a solver splits it."""
        return {"all": (self.warm_up, self.COMPILE_S)}

    def check_scene(self, scene: Scene) -> None:
        """Refuse, before anything runs, a scene that :meth:`run` would refuse with an
        InputError whatever its motion (e.g. a target the solver cannot reach); nothing here:
        a solver that refuses scenes overrides it."""
        return None

    if TYPE_CHECKING:  # declared for the checker only: every subclass defines both (Solver protocol)

        def run(self, scene: Scene) -> Result:
            """Run ``scene`` (defined by each subclass)."""
            ...

        def estimate_cost(self, scene: Scene) -> CostEstimate:
            """What running ``scene`` will cost (defined by each subclass)."""
            ...


@dataclass(frozen=True)
class StepFactorSolver(SolverBase):
    """An in-process solver whose one option is ``dt_factor``, a factor in [0.001, 1] on the
    largest step of its integrator (:func:`check_dt_factor`; the subclass's docstring says
    which step): the exact solvers (Housner's, the two-block one)."""

    IN_PROCESS = True
    OPTIONS: ClassVar = {"dt_factor": check_dt_factor}

    dt_factor: float = 1.0


class EventTrajectory(Protocol):
    """What an exact (event-driven) solver's trajectory tells its Result's metadata."""

    step_s: float
    status: str
    impacts: np.ndarray
    peaks: np.ndarray
    uplift_times_s: np.ndarray


def exact_meta(
    solver: str,
    method: str,
    scene: Scene,
    traj: EventTrajectory,
    wall: float,
    dt_factor: float,
    before: Mapping[str, object],
    after: Mapping[str, object],
) -> RunMeta:
    """The Result's metadata of an exact solver's run (Housner's, the two-block one): the run's
    identity, status and step, and in ``extra`` the first 200 impacts, peaks and uplifts between
    the solver's own entries; the solver adds the fields it knows (``dataclasses.replace``, which
    the type checker checks).

    Parameters
    ----------
    solver, method
        The solver's name, and its method for the version (e.g. "RK4").
    scene, traj, wall
        The scene run, its trajectory and the integration's wall time, s.
    dt_factor
        The factor on the largest step (:class:`StepFactorSolver`).
    before, after
        The solver's ``extra`` entries before the events' lists (the overturn criterion, the
        counts) and after them.
    """
    return RunMeta(
        solver=solver,
        version=f"rockyade {__version__} ({method}, step {traj.step_s:.3g} s, events by root finding)",
        scene_hash=scene.scene_hash,
        wall_time_s=wall,
        status=as_status(traj.status),
        sample_dt_s=scene.sample_dt_s,
        duration_s=scene.duration_s,
        dt_factor=dt_factor,
        dt_s=traj.step_s,
        extra={
            **before,
            "impacts": traj.impacts[:200].tolist(),
            "peaks": traj.peaks[:200].tolist(),
            "uplift_times_s": traj.uplift_times_s[:200].tolist(),
            **after,
        },
    )
