"""Compile the in-process solvers' numba code into numba's on-disk cache ahead of any run.

``make setup`` runs ``python -m rockyade.solvers.compile_cache`` after installing, so that no
user and no test waits on numba: without it the first run of each solver in a fresh
installation compiles its kernels (about a minute of CPU each; the run says so,
:func:`rockyade.solvers.base.say_if_compiling`), and every worker process of a study or of
``pytest -n 2`` that finds the cache cold compiles them again.

Each solver that compiles code here loads it through its own ``warm_up``
(:meth:`rockyade.solvers.base.SolverBase.warm_up`): a tiny run of every path it takes, with
the argument types of a real run. The response spectra of ``assess`` are compiled the same way.
numba keys its cache by each kernel's source file, so a solver whose cache is current costs
only the loading (idempotent: run it again after a change of the kernels, or let the first
run compile).
"""

from __future__ import annotations

import argparse
import multiprocessing
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np

from rockyade.solvers import solver_class, solver_names


@dataclass(frozen=True)
class Compiled:
    """What :func:`compile_all` did for one part.

    Attributes
    ----------
    name
        The solver's name (or ``spectra``).
    was_cached
        numba's cache held its code before (only loaded).
    seconds
        CPU time of the loading or compilation, s (this process).
    """

    name: str
    was_cached: bool
    seconds: float


def _spectra_cached() -> bool:
    """Whether numba's cache holds the response spectra's kernel."""
    from rockyade.motion.spectra import _peak_response
    from rockyade.solvers.cost_estimate import numba_cached

    return numba_cached(_peak_response)


def _warm_spectra() -> None:
    """A response spectrum of a 0.1 s record (:func:`rockyade.motion.spectra.response_spectrum`)."""
    from rockyade.motion.spectra import response_spectrum

    response_spectrum(np.array([0.0, 1.0, 0.0, -1.0, 0.0]), 0.025, np.array([0.1, 0.5]))


#: How one part of a solver's compiled code is loaded (compiled), and its CPU s on a cold cache.
WarmPath = tuple[Callable[[], None], float]

#: (name, cached?, its paths by name) of a part with numba code: a solver, or the spectra.
Part = tuple[str, Callable[[], bool], dict[str, WarmPath]]


def parts() -> list[Part]:
    """Every part with numba code: the in-process solvers (the registry's,
    :func:`rockyade.solvers.solver_names`), each with the paths it compiles independently
    (:meth:`rockyade.solvers.base.SolverBase.warm_up_paths`), and the response spectra
    (measured: 1 s)."""
    found: list[Part] = []
    for name in solver_names():
        cls = solver_class(name)
        if not cls.IN_PROCESS:
            continue
        solver = cls()
        found.append((name, _solver_cached(solver), solver.warm_up_paths()))
    found.append(("spectra", _spectra_cached, {"all": (_warm_spectra, 1.0)}))
    return found


def _solver_cached(solver: object) -> Callable[[], bool]:
    """Whether ``solver``'s code is in numba's cache for every path (its ``compiled_cached``
    on a one-block and a two-block scene, when it takes them)."""
    from rockyade.scene.loading import scene_from_dict

    def cached() -> bool:
        probe = getattr(solver, "compiled_cached")  # noqa: B009  # SolverBase's, on every in-process solver
        return all(probe(scene_from_dict(_scene(n))) for n in (1, 2))

    return cached


def _scene(n_blocks: int) -> dict[str, object]:
    """``n_blocks`` of the bi-block stack (``examples/biblock_free.toml``), the top one released
    from 0.01 rad: only its block count matters to the probe."""
    blocks = [
        {"name": "lower", "width_m": 0.2, "height_m": 0.6, "thickness_m": 0.55, "mass_kg": 204},
        {"name": "upper", "width_m": 0.15, "height_m": 0.6, "thickness_m": 0.4, "mass_kg": 91},
    ][:n_blocks]
    return {
        "duration_s": 0.01,
        "sample_dt_s": 0.001,
        "blocks": blocks,
        "motion": {"type": "free", "theta0_rad": 0.01, "block": blocks[-1]["name"]},
    }


def _compile_path(name: str, path: str) -> float:
    """Load (compile) the path ``path`` of the part ``name`` in this process, a worker of
    :func:`compile_all`; its CPU s."""
    start = time.process_time()
    for part, _, paths in parts():
        if part == name:
            paths[path][0]()
    return time.process_time() - start


def _warm_all(paths: dict[str, WarmPath]) -> float:
    """Load (compile) every path in this process; the CPU s."""
    start = time.process_time()
    for warm, _ in paths.values():
        warm()
    return time.process_time() - start


def compile_all(say: Callable[[str], None] = print, missing_only: bool = False, workers: int = 1) -> list[Compiled]:
    """Load every part's numba code, compiling what numba's cache lacks; ``say`` reports each.

    Parameters
    ----------
    missing_only
        Leave alone (unloaded) what the cache holds.
    workers
        Processes compiling side by side, longest path first, when several paths are missing
        (each a fresh interpreter that writes numba's cache; this process then has not loaded
        them): on 2 cores, about the reference DEM's general loop instead of the sum.
    """
    todo = []
    for name, cached, paths in parts():
        was_cached = cached()
        if was_cached and missing_only:
            continue
        if not was_cached:
            cost = sum(s for _, s in paths.values())
            say(f"compiling {name} (numba, once: about {cost:.0f} s of CPU) ...")
        todo.append((name, was_cached, paths))
    cold = sorted(
        ((name, path, s) for name, was_cached, paths in todo if not was_cached for path, (_, s) in paths.items()),
        key=lambda task: -task[2],
    )
    seconds: dict[str, float] = {}
    if workers > 1 and len(cold) > 1:
        from rockyade.solvers import compile_cache  # this module by its name, whatever ran it

        spawn = multiprocessing.get_context("spawn")  # no fork of a process that holds numba's threads
        with ProcessPoolExecutor(max_workers=min(workers, len(cold)), mp_context=spawn) as pool:
            futures = [(name, pool.submit(compile_cache._compile_path, name, path)) for name, path, _ in cold]
            for name, future in futures:
                seconds[name] = seconds.get(name, 0.0) + future.result()
    done = []
    for name, was_cached, paths in todo:
        if name not in seconds:
            seconds[name] = _warm_all(paths)
        done.append(Compiled(name, was_cached, seconds[name]))
        say(f"{name}: {'in the cache, loaded' if was_cached else 'compiled'} in {seconds[name]:.1f} s of CPU")
    return done


def main(argv: list[str] | None = None) -> int:
    """``python -m rockyade.solvers.compile_cache``: compile what the cache lacks (exit 0)."""
    parser = argparse.ArgumentParser(
        prog="python -m rockyade.solvers.compile_cache",
        description="Compile the solvers' numba code into numba's cache (make setup runs it; idempotent).",
    )
    parser.add_argument("-q", "--quiet", action="store_true", help="say only what is compiled")
    parser.add_argument("--workers", type=int, default=1, help="processes compiling side by side (default 1)")
    args = parser.parse_args(argv)

    def say(line: str) -> None:
        if not args.quiet or line.startswith("compiling"):
            print(f"rockyade: {line}", flush=True)

    compile_all(say, workers=max(1, args.workers))
    return 0


if __name__ == "__main__":
    sys.exit(main())
