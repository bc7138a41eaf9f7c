"""The study file: its grammar, and a :class:`Study` (the base scenes read once, the grid)
whose grid points are made one at a time.

Study file (TOML)::

    name = "harmonic-sweep"
    solvers = ["reference", "housner"]     # each scene runs with each solver
    save_histories = true                  # the time history of every run (else summary only)
    yade_timeout_s = 600                   # optional: YADE's timeout_s, the wall-clock limit of each run, s

    [base]                                 # base scenes: one file, or several
    files = ["examples/specimen1_harmonic.toml", "examples/specimen3_free.toml"]

    [grid]                                 # product of the lists; keys are dotted paths
    "motion.frequency_hz" = [2.0, 3.3]     # into the scene ("blocks.0.mu", "motion", ...)
    "motion.amplitude_mm" = [2.0, 6.0]

A bad file is an :class:`~rockyade.errors.InputError` naming the key (exit 2). The run count
is taken from the grid's sizes, once, when the Study is made, before any scene is built.
"""

from __future__ import annotations

import copy
import itertools
import json
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from rockyade.errors import InputError
from rockyade.io.fields import TableReader
from rockyade.motion.types import RecordMotion
from rockyade.runner.tasks import Cell
from rockyade.scene import Scene
from rockyade.solvers import as_solver, make_solvers, solver_names
from rockyade.solvers.base import Solver

#: Study-file keys that set a solver's option: key -> option.
SOLVER_OPTION_KEYS = {"yade_timeout_s": "timeout_s"}
#: Runs a study may expand into (base scenes x grid points x solvers); ``allow_large``
#: (``--allow-large``) lifts it up to MAX_RUNS_ALLOWED, a ceiling nothing lifts (every run is
#: a validated scene held in memory, about 2 kB, and is validated in about 5 ms).
MAX_RUNS = 100_000
MAX_RUNS_ALLOWED = 1_000_000
#: Largest study file, bytes: a grid is lists of values (1 MiB holds some 200,000 numbers;
#: Python's TOML reader takes about 0.6 s for it); the count check above then refuses more.
MAX_STUDY_BYTES = 1024 * 1024
#: Keys of the scene format that a table takes only alone (its readers refuse both, saying
#: "give exactly one of ..." or "give either ... or ..."): a grid key replaces its
#: alternatives in the table it sets. The base scene is read into its canonical form, which
#: may hold the other key (a pulse given in g holds amplitude_m_s2).
ALTERNATIVES: dict[str, tuple[str, ...]] = {
    # a pulse (motion)
    "amplitude_g": ("amplitude_m_s2",),
    "amplitude_m_s2": ("amplitude_g",),
    # a harmonic motion (motion)
    "cycles": ("duration_s",),
    "duration_s": ("cycles",),
    # a sampled motion (motion)
    "dt_s": ("t_s",),
    "t_s": ("dt_s",),
    # a block (blocks.<i>)
    "mass_kg": ("density_kg_m3",),
    "density_kg_m3": ("mass_kg",),
    "inertia_kgm2": ("p_rad_s",),
    "p_rad_s": ("inertia_kgm2",),
    "vertices_m": ("width_m", "height_m"),
    "width_m": ("vertices_m",),
    "height_m": ("vertices_m",),
}


@dataclass(frozen=True)
class GridPoint:
    """One base scene at one grid point.

    Attributes
    ----------
    labels
        ``base`` (the base scene's name) and the grid's values, as the summary shows them.
    scene
        The validated scene, its record file named by an absolute path.
    """

    labels: dict[str, Cell]
    scene: Scene


@dataclass(frozen=True)
class Study:
    """A study: base scenes (read and validated once, as plain dicts) and a grid over them.

    Making one checks the grid (a key and its alternative both set) and the run count
    (:func:`check_run_count`, from the grid's sizes); no scene is built until
    :meth:`points` is iterated.

    Attributes
    ----------
    name
        The study's name.
    bases
        ``(name, scene dict)`` of each base scene, in the scene format's canonical form.
    grid
        Dotted path into the scene -> its values; the grid is the product of the lists.
    solvers
        Each scene runs with each solver.
    save_histories
        Write every run's time history (else its summary only).
    source
        The study file (errors name it; record files the grid names are found from its folder).
    allow_large
        Allow up to :data:`MAX_RUNS_ALLOWED` runs rather than :data:`MAX_RUNS`.
    """

    name: str
    bases: tuple[tuple[str, dict[str, object]], ...]
    grid: Mapping[str, list[object]]
    solvers: tuple[Solver, ...]
    save_histories: bool = True
    source: str | None = None
    allow_large: bool = field(default=False, compare=False)

    def __post_init__(self) -> None:
        check_run_count(self.run_count, self.allow_large, self.source)
        _check_alternatives(self.grid, self.source)

    @property
    def run_count(self) -> int:
        """Runs the study expands into: base scenes x grid points x solvers."""
        count = len(self.bases) * len(self.solvers)
        for values in self.grid.values():
            count *= len(values)
        return count

    @property
    def solver_names(self) -> tuple[str, ...]:
        """The solvers' names, in order."""
        return tuple(s.name for s in self.solvers)

    def points(self) -> Iterator[GridPoint]:
        """Every base scene x grid point, made as it is asked for (base scenes in order,
        the grid's last key fastest).

        Raises
        ------
        InputError
            A grid key that is not in the base scene, a grid point that is not a valid scene
            (naming the base and the grid point).
        """
        keys = list(self.grid)
        source = self.source
        base_dir = Path(source).resolve().parent if source else None
        motion_only = bool(keys) and all(k == "motion" or k.startswith("motion.") for k in keys)
        for base_name, base in self.bases:
            base_scene = _valid_scene(base, source, base_dir) if motion_only else None
            for values in itertools.product(*(self.grid[k] for k in keys)):
                # a grid over the motion changes only the motion's table: the rest is shared, read-only
                d = {**base, "motion": copy.deepcopy(base["motion"])} if base_scene is not None else copy.deepcopy(base)
                for key, value in zip(keys, values, strict=True):
                    _set_path(d, key, value, source)
                labels = {"base": base_name, **{k: _label(v) for k, v in zip(keys, values, strict=True)}}
                try:
                    scene = _absolute_files(_grid_scene(d, base_scene, source, base_dir))
                except InputError as exc:
                    point = ", ".join(f"{k} = {v}" for k, v in labels.items())
                    raise InputError(exc.field, f"{exc.message} (grid point: {point})", exc.source) from None
                yield GridPoint(labels, scene)


def make_study(
    bases: list[tuple[str, dict[str, object]]],
    grid: Mapping[str, list[object]],
    solvers: Iterable[Solver | str],
    *,
    name: str = "study",
    save_histories: bool = True,
    source: str | None = None,
    allow_large: bool = False,
) -> Study:
    """A :class:`Study` of scene dicts already read (a study built in Python).

    Parameters
    ----------
    bases
        ``(name, scene dict)`` of each base scene.
    grid
        Dotted path -> values (a grid key replaces its alternatives, :data:`ALTERNATIVES`).
    solvers
        Solvers, or their names.
    name, save_histories, source, allow_large
        As :class:`Study` takes them.
    """
    return Study(
        name,
        tuple(bases),
        dict(grid),
        tuple(as_solver(s) for s in solvers),
        save_histories,
        source,
        allow_large,
    )


def load_study(
    path: str | Path,
    options: Mapping[str, object] | None = None,
    fields: Mapping[str, str] | None = None,
    allow_large: bool = False,
) -> Study:
    """Read a study file; its base scenes are read and validated here, once.

    Record files the grid names (``"motion.file" = [...]``, or a file in a grid's motion
    table) are found from the study file's folder, as a scene's from the scene's.

    Parameters
    ----------
    path
        The study file (TOML, or JSON).
    options
        Solver options that replace the file's (e.g. ``{"timeout_s": 90}`` from the command
        line); each goes to the solvers that take it, and one none of them takes is refused.
    fields
        How ``options`` are named in errors (e.g. ``{"timeout_s": "--yade-timeout"}``).
    allow_large
        Allow up to :data:`MAX_RUNS_ALLOWED` runs rather than :data:`MAX_RUNS`.

    Raises
    ------
    InputError
        A bad study file (naming the key), a file above :data:`MAX_STUDY_BYTES`, a grid of
        more runs than the limit (from its sizes, before any scene is built), a bad base scene.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("study", f"file not found: {path}")
    size = path.stat().st_size
    if size > MAX_STUDY_BYTES:
        raise InputError(
            "study",
            f"the file has {size:,} bytes, more than the {MAX_STUDY_BYTES:,} (1 MiB) a study file may have: "
            "a grid of that size expands into more runs than a batch takes; split the study",
            source,
        )
    from rockyade.io.fields import plain_data
    from rockyade.scene.loading import parse_text_file

    data = plain_data(parse_text_file(path, "study"), "study", source)
    r = TableReader(data, "", source)
    name = r.string("name", path.stem)
    names = r.raw("solvers", ["reference"])
    if not isinstance(names, list) or not names or any(s not in solver_names() for s in names):
        raise r.error("solvers", f"must be a list of {', '.join(solver_names())}, got {names!r}")
    save = r.boolean("save_histories", True)
    file_options = {opt: r.raw(key) for key, opt in SOLVER_OPTION_KEYS.items() if r.has(key)}
    file_fields = {opt: key for key, opt in SOLVER_OPTION_KEYS.items()}
    base = r.sub("base")
    files = base.raw("files", None)
    single = base.raw("file", None)
    if (files is None) == (single is None):
        raise base.error("files", "give exactly one of file and files")
    file_list = [single] if single is not None else files
    if not isinstance(file_list, list) or not all(isinstance(f, str) for f in file_list):
        raise base.error("files", "must be a list of scene file paths")
    base.finish()
    grid = r.raw("grid", {})
    if not isinstance(grid, dict):
        raise r.error("grid", "must be a table of dotted paths to lists of values")
    for key, values in grid.items():
        if not isinstance(values, list) or not values:
            raise InputError(f"grid.{key}", "must be a non-empty list of values", source)
    r.finish()
    try:
        solvers = make_solvers(names, {**file_options, **(options or {})}, {**file_fields, **(fields or {})})
    except InputError as exc:  # a key of this file is named with the file
        raise InputError(exc.field, exc.message, source if exc.field in SOLVER_OPTION_KEYS else exc.source) from None
    bases = tuple((Path(f).stem, _scene_dict(path.parent / f)) for f in file_list)
    return Study(name, bases, grid, tuple(solvers), save, source, allow_large)  # checks the run count


def check_run_count(count: int, allow_large: bool = False, source: str | None = None) -> None:
    """Refuse a study of more than :data:`MAX_RUNS` runs (``allow_large``: of more than
    :data:`MAX_RUNS_ALLOWED`), from the grid's sizes, before anything is built.

    Raises
    ------
    InputError
        Field ``grid``, with the count and the limit.
    """
    if count > MAX_RUNS_ALLOWED:
        raise InputError(
            "grid",
            f"the study expands into {count:,} runs, more than the limit of {MAX_RUNS:,} and than the "
            f"{MAX_RUNS_ALLOWED:,} a batch can hold even with --allow-large: split it into several studies",
            source,
        )
    if count > MAX_RUNS and not allow_large:
        raise InputError(
            "grid",
            f"the study expands into {count:,} runs, more than the limit of {MAX_RUNS:,} (each run is a "
            f"validated scene, a row and a file); use a smaller grid, or pass --allow-large (allow_large=True) "
            f"to go up to {MAX_RUNS_ALLOWED:,}",
            source,
        )


def _scene_dict(path: Path) -> dict[str, object]:
    """A base scene file, read and validated, in the scene format's canonical form."""
    from rockyade.scene import load_scene

    return load_scene(path).to_dict()


def _set_path(d: dict[str, object], dotted: str, value: object, source: str | None) -> None:
    """Set ``d``'s value at ``dotted`` (a list's items by number), dropping its alternatives."""
    parts = dotted.split(".")
    target: Any = d
    for i, part in enumerate(parts[:-1]):
        key: Any = int(part) if isinstance(target, list) else part
        try:
            target = target[key]
        except (KeyError, IndexError, ValueError, TypeError):
            raise InputError(f"grid.{dotted}", f"no '{'.'.join(parts[: i + 1])}' in the base scene", source) from None
    last: Any = int(parts[-1]) if isinstance(target, list) else parts[-1]
    if isinstance(target, dict):
        for other in ALTERNATIVES.get(last, ()):
            target.pop(other, None)
    target[last] = copy.deepcopy(value)


def _check_alternatives(keys: Iterable[str], source: str | None) -> None:
    """Refuse a grid that sets a key and its alternative in the same table."""
    seen: dict[tuple[str, str], str] = {}
    for key in keys:
        table, _, leaf = key.rpartition(".")
        for other in ALTERNATIVES.get(leaf, ()):
            if (table, other) in seen:
                raise InputError(
                    f"grid.{key}",
                    f"sets what grid.{seen[(table, other)]} sets (the scene takes one of {leaf} and {other}): "
                    "keep one of the two",
                    source,
                )
        seen[(table, leaf)] = key


def _valid_scene(d: dict[str, object], source: str | None, base_dir: Path | None) -> Scene | None:
    """The scene of ``d``, or None if it is not valid as it is (a grid point may complete it)."""
    from rockyade.scene import scene_from_dict

    try:
        return scene_from_dict(d, source=source, base_dir=base_dir)
    except InputError:
        return None


def _grid_scene(d: dict[str, object], base_scene: Scene | None, source: str | None, base_dir: Path | None) -> Scene:
    """The scene of a grid point ``d``: ``scene_from_dict(d)``. With ``base_scene`` (the valid
    base scene of a grid over the motion only) the same Scene, read at a third of the cost:
    only the motion is read, and checked with the rest (:meth:`rockyade.scene.Scene.with_changes`);
    a motion that does not read is read again with the whole scene, which says what is wrong."""
    from rockyade.io.fields import plain_data
    from rockyade.motion.spec import parse_motion
    from rockyade.scene import scene_from_dict

    if base_scene is not None:
        try:
            motion = parse_motion(plain_data(d["motion"], "motion", source), source, base_dir)
            return base_scene.with_changes(motion=motion)
        except InputError:
            pass
    return scene_from_dict(d, source=source, base_dir=base_dir)


def _absolute_files(scene: Scene) -> Scene:
    """The scene with its record file named by an absolute path (a worker elsewhere reads it)."""
    motion = scene.motion
    if not isinstance(motion, RecordMotion) or Path(motion.file).is_absolute():
        return scene
    return replace(scene, motion=replace(motion, file=str(Path(motion.file).resolve())))


def _label(value: object) -> Cell:
    """A grid value as a summary cell: a table or list as JSON."""
    return value if isinstance(value, (int, float, str, bool)) else json.dumps(value, sort_keys=True)


__all__ = [
    "ALTERNATIVES",
    "MAX_RUNS",
    "MAX_RUNS_ALLOWED",
    "MAX_STUDY_BYTES",
    "GridPoint",
    "Study",
    "check_run_count",
    "load_study",
    "make_study",
]
