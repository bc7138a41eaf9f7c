"""The typed metadata of a run: :class:`RunMeta`, what a :class:`rockyade.result.Result`
carries beside its time history.

Every value read by more than one module is a typed attribute (a misspelt one is an error
for mypy, not a silent ``None``); what one solver alone reports goes to :attr:`RunMeta.extra`,
a read-only mapping. A RunMeta is frozen: an update is ``dataclasses.replace(meta, dt_factor=0.5)``
or :meth:`RunMeta.with_extra`.

On disk (a result's JSON, a run's journal record) it is one flat JSON object, the keys the
fields' names and the extra's keys beside them (:meth:`RunMeta.to_dict`), as results were
written before; :meth:`RunMeta.from_dict` reads it back, an unknown key going to ``extra`` and
a missing one taking its default, so that older results load. NaN and infinity are written as
null (:mod:`rockyade.io.strict_json`): a float field written as null reads back as None (not
measured); a value in ``extra`` as None.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any, Generic, Literal, TypeVar, get_args

from rockyade import __version__

#: How a run ended: it ran to its end, a block overturned (a valid outcome), or it failed.
Status = Literal["completed", "overturned", "failed"]
STATUSES: tuple[str, ...] = get_args(Status)


def as_status(value: object) -> Status:
    """``value`` as a :data:`Status`.

    Raises
    ------
    ValueError
        A value that is not one of :data:`STATUSES`.
    """
    if value == "completed":
        return "completed"
    if value == "overturned":
        return "overturned"
    if value == "failed":
        return "failed"
    raise ValueError(f"status must be one of {STATUSES}, got {value!r}")


V = TypeVar("V")


class FrozenMapping(Mapping[str, V], Generic[V]):
    """A read-only mapping (a copy of the one given), picklable (unlike ``MappingProxyType``:
    results come back from worker processes) and equal to any mapping with the same items."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, V] | None = None) -> None:
        self._data: dict[str, V] = dict(data or {})

    def __getitem__(self, key: str) -> V:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return f"FrozenMapping({self._data!r})"

    def __getstate__(self) -> dict[str, V]:
        return self._data

    def __setstate__(self, state: dict[str, V]) -> None:
        self._data = state


def _frozen(value: Mapping[str, V] | None) -> FrozenMapping[V] | None:
    return value if value is None or isinstance(value, FrozenMapping) else FrozenMapping(value)


@dataclass(frozen=True)
class RunMeta:
    """What a run was and how it ended (module docstring). Times in s, lengths in m.

    Attributes
    ----------
    status
        completed | overturned | failed.
    solver
        The solver's name (``housner``, ``reference``, ``yade``, ``siconos``).
    version
        The solver's version and the driver's, in words.
    scene_hash
        The scene's hash (None: unknown).
    rockyade_version
        The toolkit's version that made the result.
    failure_reason
        Why a failed run failed (None otherwise).
    partial
        A failed run that kept the samples it had recorded.
    partial_samples
        How many samples a partial failure kept.
    overturn_time_s
        When the first block overturned (None: none did), s.
    overturned_block
        The first block to overturn (None: none did).
    overturn_times_s
        The DEMs: per block that fell, when it did, s (None: the solver does not say).
    blocks
        The blocks' names, bottom to top.
    sample_dt_s
        Time between output samples, s.
    duration_s
        The run's length, s.
    dt_s
        The time step used, s.
    dt_factor
        The factor on the solver's own time step, in (0, 1].
    wall_time_s
        Wall time of the solver itself, s.
    process_cpu_s
        CPU time of the solver's process, s (a worker's).
    startup_time_s
        Wall time of a worker's start and of moving the data (total less the run), s.
    setup_time_s
        Wall time of building the model (calibration included), s.
    total_time_s
        Wall time of the whole worker call, s.
    timeout_s
        The time limit of a worker's run, s (None: none).
    log_path
        A worker's log file.
    motion_coverage
        How much of the base motion the run covers
        (:func:`rockyade.motion.coverage.record_coverage`).
    bodies
        Per body, the DEMs' model summary (mass, inertia, geometry).
    classical
        Per block, Housner's classical parameters.
    n_steps
        Time steps the solver planned.
    iterations
        Time steps it took.
    unconverged_steps
        Contact solves that ended above the solver's tolerance (None: the solver has none).
    extra
        The solver's own values (read-only).
    """

    status: Status
    solver: str = ""
    version: str = ""
    scene_hash: str | None = None
    rockyade_version: str = __version__
    failure_reason: str | None = None
    partial: bool | None = None
    partial_samples: int | None = None
    overturn_time_s: float | None = None
    overturned_block: str | None = None
    overturn_times_s: Mapping[str, float] | None = None
    blocks: tuple[str, ...] = ()
    sample_dt_s: float | None = None
    duration_s: float | None = None
    dt_s: float | None = None
    dt_factor: float | None = None
    wall_time_s: float | None = None
    process_cpu_s: float | None = None
    startup_time_s: float | None = None
    setup_time_s: float | None = None
    total_time_s: float | None = None
    timeout_s: float | None = None
    log_path: str | None = None
    motion_coverage: Mapping[str, Any] | None = None
    bodies: Mapping[str, Any] | None = None
    classical: Mapping[str, Any] | None = None
    n_steps: int | None = None
    iterations: int | None = None
    unconverged_steps: int | None = None
    extra: Mapping[str, Any] = field(default_factory=lambda: FrozenMapping())

    def __post_init__(self) -> None:
        as_status(self.status)
        object.__setattr__(self, "blocks", tuple(self.blocks))
        for name in ("overturn_times_s", "motion_coverage", "bodies", "classical"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        object.__setattr__(self, "extra", _frozen(self.extra))

    @property
    def ok(self) -> bool:
        """True unless the run failed (an overturn is a valid outcome)."""
        return self.status != "failed"

    def with_extra(self, **values: object) -> RunMeta:
        """This metadata with ``values`` added to (or replacing in) :attr:`extra`."""
        return dataclasses.replace(self, extra={**self.extra, **values})

    def to_dict(self) -> dict[str, object]:
        """The flat JSON-ready form (module docstring): every field (those that are None
        only when :data:`ALWAYS_WRITTEN` names them), then the extra's keys."""
        out: dict[str, object] = {}
        for f in dataclasses.fields(self):
            if f.name == "extra":
                continue
            value = getattr(self, f.name)
            if value is None and f.name not in ALWAYS_WRITTEN:
                continue
            out[f.name] = list(value) if f.name == "blocks" else value
        for key, value in self.extra.items():
            out.setdefault(key, value)
        return out

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> RunMeta:
        """The metadata of a flat mapping (:meth:`to_dict`'s, or an older result's JSON): its
        fields by name, every other key to :attr:`extra`, a missing field its default.

        Raises
        ------
        ValueError
            A status that is not one of :data:`STATUSES`, or none.
        """
        known = {k: v for k, v in data.items() if k in _FIELDS}
        extra = {k: v for k, v in data.items() if k not in _FIELDS}
        for key in ("blocks", "rockyade_version", "solver", "version"):  # fields that are never None
            if known.get(key) is None:
                known.pop(key, None)
        known.setdefault("status", None)  # refused by __post_init__
        return cls(**known, extra=extra)

    @classmethod
    def failed(cls, solver: str, scene_hash: str | None, reason: str, **values: object) -> RunMeta:
        """The metadata of a run that failed with ``reason`` (``values``: more, by field name or extra)."""
        meta = cls.from_dict({"solver": solver, "scene_hash": scene_hash, "status": "failed", **values})
        return dataclasses.replace(meta, failure_reason=reason)


#: Fields written even when None (an older reader finds them as before).
ALWAYS_WRITTEN = frozenset({"solver", "scene_hash", "status", "failure_reason", "overturn_time_s", "overturned_block"})
_FIELDS = frozenset(f.name for f in dataclasses.fields(RunMeta) if f.name != "extra")
