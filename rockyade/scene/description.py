"""Scenes: the one description of a simulation that every solver reads (TOML or JSON).

A scene is data, never code. Layout::

    duration_s = 4.0          # simulated time, s
    sample_dt_s = 0.001       # output sampling interval, s

    [[blocks]]                # listed bottom to top
    name = "specimen1"
    width_m = 0.25            # or vertices_m = [[x, y], ...] (convex, base on y = 0)
    height_m = 1.0
    thickness_m = 0.754
    mass_kg = 503             # or density_kg_m3
    # inertia_kgm2 = ...      # optional, about the centroid
    # x_offset_m = 0.0        # optional horizontal offset of the block frame
    alpha_rad = 0.235         # optional classical overrides (e.g. experimental values)
    p_rad_s = 3.84
    mu = 0.936

    [contact]                 # DEM joints (ignored by the Housner solver)
    calibration = "paper"     # "paper" (Eqs 10-15) or "matched" (beta matched to mu)
    # stiffness_scale = "MN/m"; K_N_per_m, Ks_N_per_m, friction_angle_deg, cohesion_Pa,
    # beta_s, dt_s, time_step_frac, mass_damping_1_s

    [motion]
    type = "free"
    theta0_rad = 0.1175

    [output]                  # optional
    # accel_point = "top_centre" | [x, y] (block frame, m); accel_lowpass_hz = 20.0

    [[loads]]                 # optional: loads carried by named blocks
    block = "specimen1"
    point_m = [0.125, 1.0]    # point of application, base frame at rest, m (on the block)
    force_N = [0.0, -2000.0]  # (fx, fy), N: a dead load (keeps its direction)
    # mass_kg = 0.0           # its mass moving with the block, kg; default -fy / g

A load's mass (``mass_kg``) moves rigidly with the block it bears on; by default it is the
mass of the load's weight, -fy / g (the code counts the vertical loads a wall carries among
the forces the horizontal acceleration acts on, Circolare 2019 C8.7.1). ``mass_kg = 0`` gives a
force without mass, on which the horizontal base acceleration does not act (a load whose
horizontal force goes elsewhere). :mod:`rockyade.scene.carried` merges the masses into their
blocks for every solver. The force is a weight carried by the block: it follows
the apparent gravity, scaled by (g + a_v) / g, so that it ramps in with gravity under
``gravity-ramp`` and ``pushover`` (a_v = -g at t = 0) and is constant under a horizontal motion.
Its point is a material point of the block: it moves and turns with the block.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import re
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, NotRequired, TypedDict

from rockyade.blocks.classical import ClassicalParameters, classical_parameters
from rockyade.blocks.geometry import Block
from rockyade.constants import DEFAULT_FRICTION_ANGLE_DEG, DEFAULT_TIME_STEP_FRAC, G
from rockyade.errors import InputError
from rockyade.scene.frozen_cache import computed_once, without_caches

if TYPE_CHECKING:  # a name only: the dataclasses load without the motion types (scipy, numba)
    from rockyade.motion.spec import MotionSpec

#: Upper bounds that keep inputs physical (and the arithmetic finite).
MAX_LENGTH_M = 1000.0
MAX_DURATION_S = 1.0e5

#: Largest load component, N (a million tonnes-force: keeps the arithmetic finite).
MAX_LOAD_N = 1.0e10
#: Largest load, as a multiple of the weight of the scene's moving blocks.
MAX_LOAD_TO_WEIGHT = 1.0e4
#: A load's point may lie outside its block by this fraction of the block's size.
LOAD_POINT_TOL = 1e-6

NAME_PATTERN = re.compile(r"^[A-Za-z][A-Za-z0-9_]{0,63}$")
CALIBRATIONS = ("paper", "matched")
MAX_SAMPLES = 50_000_000


@dataclass(frozen=True)
class BlockSpec:
    """One ``[[blocks]]`` entry, validated. See the module docstring for the keys."""

    name: str
    thickness_m: float
    width_m: float | None = None
    height_m: float | None = None
    vertices_m: tuple[tuple[float, float], ...] | None = None
    mass_kg: float | None = None
    density_kg_m3: float | None = None
    inertia_kgm2: float | None = None
    x_offset_m: float = 0.0
    alpha_rad: float | None = None
    p_rad_s: float | None = None
    mu: float | None = None
    position_m: tuple[float, float] | None = None
    rotation_rad: float = 0.0
    fixed: bool = False

    def __getstate__(self) -> dict[str, object]:
        return without_caches(self)

    def block(self) -> Block:
        """The rigid block (geometry, mass, inertia); built once (both are frozen)."""
        return computed_once(self, "_block", self._new_block)

    def _new_block(self) -> Block:
        if self.vertices_m is not None:
            shape = functools.partial(Block.polygon, self.vertices_m)
        else:
            assert self.width_m is not None and self.height_m is not None  # loading requires them without vertices
            shape = functools.partial(Block.rectangle, self.width_m, self.height_m)
        return shape(
            self.thickness_m,
            mass_kg=self.mass_kg,
            density_kg_m3=self.density_kg_m3,
            inertia_kgm2=self.inertia_kgm2,
            name=self.name,
        )

    def classical(self) -> ClassicalParameters:
        """Classical parameters: the geometry's, with this block's overrides applied."""
        return classical_parameters(self.block(), alpha_rad=self.alpha_rad, p_rad_s=self.p_rad_s, mu=self.mu)


@dataclass(frozen=True)
class ContactSpec:
    """The ``[contact]`` table: calibration method and explicit overrides.

    Explicit values (K_N_per_m, Ks_N_per_m, beta_s) replace the calibrated ones for every
    joint; the others come from the calibration of the block above each joint.
    """

    calibration: str = "paper"
    stiffness_scale: str | float = "MN/m"
    K_N_per_m: float | None = None
    Ks_N_per_m: float | None = None
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG
    cohesion_Pa: float = 0.0
    beta_s: float | None = None
    dt_s: float | None = None
    time_step_frac: float = DEFAULT_TIME_STEP_FRAC
    mass_damping_1_s: float = 0.0
    jkn_Pa_per_m: float | None = None
    jks_Pa_per_m: float | None = None

    @property
    def explicit_stiffness(self) -> bool:
        """True when the stiffness is given (K or jkn) rather than calibrated."""
        return self.K_N_per_m is not None or self.jkn_Pa_per_m is not None


#: The contact values a ``[[joints]]`` entry may override.
JOINT_OVERRIDE_KEYS = ("K_N_per_m", "Ks_N_per_m", "beta_s", "friction_angle_deg", "jkn_Pa_per_m", "jks_Pa_per_m")


@dataclass(frozen=True)
class JointOverride:
    """One ``[[joints]]`` entry: contact values for one pair of blocks (or a block and the base).

    Attributes
    ----------
    blocks
        The two block names; the second may be ``"base"``.
    values
        Overridden values, keys among :data:`JOINT_OVERRIDE_KEYS` (N/m, s, degrees, Pa/m).
    """

    blocks: tuple[str, str]
    values: tuple[tuple[str, float], ...]

    def get(self, key: str) -> float | None:
        """The overridden value of ``key``, or None."""
        return dict(self.values).get(key)


class LoadTable(TypedDict):
    """A ``[[loads]]`` table: a force, N, at a point of a block, m (base frame at rest), with
    the mass it carries, kg (:class:`LoadSpec`)."""

    block: str
    point_m: list[float]
    force_N: list[float]
    mass_kg: NotRequired[float]


@dataclass(frozen=True)
class LoadSpec:
    """One ``[[loads]]`` entry: a constant force on a block, with its mass (module docstring).

    Attributes
    ----------
    block
        The block's name.
    point_m
        Point of application at rest, base frame, m; a material point of the block.
    force_N
        (fx, fy), N; it keeps its direction when the block turns (a dead load).
    mass_kg
        Its mass moving with the block, kg; None: the default, the mass of its weight -fy / g
        (:func:`rockyade.scene.carried.load_mass_kg`).
    """

    block: str
    point_m: tuple[float, float]
    force_N: tuple[float, float]
    mass_kg: float | None = None

    def as_dict(self) -> LoadTable:
        """The ``[[loads]]`` table (``mass_kg`` only when given)."""
        out: LoadTable = {"block": self.block, "point_m": list(self.point_m), "force_N": list(self.force_N)}
        if self.mass_kg is not None:
            out["mass_kg"] = self.mass_kg
        return out


@dataclass(frozen=True)
class OutputSpec:
    """The ``[output]`` table.

    Attributes
    ----------
    accel_point
        Where absolute accelerations are reported: "top_centre" (the paper's
        accelerometers) or [x, y] in the block frame, m.
    accel_lowpass_hz
        Optional zero-phase low-pass cut-off for those accelerations, Hz (paper Section 6.1
        on impact spikes).
    """

    accel_point: str | tuple[float, float] = "top_centre"
    accel_lowpass_hz: float | None = None


@dataclass(frozen=True)
class Scene:
    """A validated scene."""

    duration_s: float
    sample_dt_s: float
    blocks: tuple[BlockSpec, ...]
    contact: ContactSpec
    motion: MotionSpec
    output: OutputSpec = field(default_factory=OutputSpec)
    source: str | None = field(default=None, compare=False)
    joints: tuple[JointOverride, ...] = ()
    loads: tuple[LoadSpec, ...] = ()

    def __getstate__(self) -> dict[str, object]:
        return without_caches(self)

    # ------------------------------------------------------------------ queries
    @property
    def n_samples(self) -> int:
        """Number of output rows (t = 0, dt, ..., duration)."""
        return math.floor(self.duration_s / self.sample_dt_s + 1e-9) + 1

    def block_index(self, name: str) -> int:
        """Index of the block called ``name``."""
        for i, spec in enumerate(self.blocks):
            if spec.name == name:
                return i
        raise InputError("motion.block", f"no block named {name!r}; blocks: {[b.name for b in self.blocks]}")

    @property
    def positioned(self) -> bool:
        """True for an assembly (blocks placed by ``position_m``), False for a column."""
        return self.blocks[0].position_m is not None

    @property
    def released_index(self) -> int:
        """Index of the block given the initial tilt (free rocking): named, else the top."""
        name = self.motion.released_block
        return len(self.blocks) - 1 if name is None else self.block_index(name)

    def to_dict(self) -> dict[str, Any]:
        """Canonical dictionary of the scene, defaults filled in (JSON-ready)."""
        blocks = []
        for b in self.blocks:
            d = asdict(b)
            if d["vertices_m"] is not None:
                d["vertices_m"] = [list(v) for v in d["vertices_m"]]
            if d["position_m"] is not None:
                d["position_m"] = list(d["position_m"])
                d.pop("x_offset_m")
            else:
                d.pop("rotation_rad")
            if not d["fixed"]:
                d.pop("fixed")
            blocks.append(d)
        out = asdict(self.output)
        if isinstance(out["accel_point"], tuple):
            out["accel_point"] = list(out["accel_point"])
        data = {
            "duration_s": self.duration_s,
            "sample_dt_s": self.sample_dt_s,
            "blocks": blocks,
            "contact": asdict(self.contact),
            "motion": self.motion.to_dict(),
            "output": out,
        }
        if self.joints:
            data["joints"] = [{"blocks": list(j.blocks), **dict(j.values)} for j in self.joints]
        if self.loads:
            data["loads"] = [q.as_dict() for q in self.loads]
        return _drop_none(data)

    @functools.cached_property
    def scene_hash(self) -> str:
        """SHA-256 of the canonical scene (first 16 hex digits): same physics, same hash."""
        material = self.to_dict()
        material["motion"] = self.motion.hash_material()
        if any(q.mass_kg is None for q in self.loads):
            material["load_mass_default"] = "weight/g"  # loads carried massless before: not the same physics
        text = json.dumps(material, sort_keys=True, separators=(",", ":"), default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def with_changes(self, **changes: Any) -> Scene:
        """A copy with top-level fields replaced (e.g. ``motion=...``), re-validated."""
        scene = replace(self, **changes)
        _check_scene(scene)
        return scene

    def write_json(self, path: str | Path) -> None:
        """Write the canonical scene as JSON (atomically)."""
        from rockyade.io.atomic import write_json

        write_json(path, self.to_dict())


def _drop_none(value: Any) -> Any:
    """Remove None-valued keys recursively (optional fields left out of canonical files)."""
    if isinstance(value, dict):
        return {k: _drop_none(v) for k, v in value.items() if v is not None}
    if isinstance(value, list):
        return [_drop_none(v) for v in value]
    return value


def _check_scene(scene: Scene) -> None:
    """Cross-field checks: unique names, placement (stacking or positions), joints, motion."""
    names = [b.name for b in scene.blocks]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise InputError(f"blocks[{i}].name", f"duplicate block name {name!r}", scene.source)
        if name == "base":
            raise InputError(f"blocks[{i}].name", "'base' is reserved for the base (name the block otherwise)")
    if scene.motion.released_block is not None and scene.motion.released_block not in names:
        raise InputError(
            "motion.block", f"no block named {scene.motion.released_block!r}; blocks: {names}", scene.source
        )
    if scene.positioned:
        _check_positioned(scene)
    else:
        _check_column(scene)
    _check_joints(scene, names)
    _check_loads(scene, names)


def _check_column(scene: Scene) -> None:
    """A column scene: blocks listed bottom to top, each resting on the one below."""
    lower: Block | None = None
    lower_offset = 0.0
    for i, spec in enumerate(scene.blocks):
        if spec.position_m is not None:
            raise InputError(
                f"blocks[{i}].position_m",
                "give position_m on every block (assembly) or on none (column); blocks[0] has none",
                scene.source,
            )
        if spec.fixed:
            raise InputError(f"blocks[{i}].fixed", "fixed blocks need position_m (an assembly scene)", scene.source)
        block = spec.block()
        if lower is not None:
            lo_l, lo_r = lower.level_vertices("top")
            up_l, up_r = block.level_vertices("base")
            overlap = min(lo_r + lower_offset, up_r + spec.x_offset_m) - max(
                lo_l + lower_offset, up_l + spec.x_offset_m
            )
            if lo_r - lo_l <= 0:
                raise InputError(
                    f"blocks[{i - 1}].vertices_m",
                    "a block that carries another needs a flat top",
                    scene.source,
                )
            if overlap <= 0:
                raise InputError(
                    f"blocks[{i}].x_offset_m",
                    "block does not rest on the block below it (no overlap); to place blocks side by side "
                    "give every block position_m = [x, y]",
                    scene.source,
                )
        lower, lower_offset = block, spec.x_offset_m


def _check_positioned(scene: Scene) -> None:
    """An assembly: every block placed, none below the base, none overlapping another."""
    from rockyade.scene.placement import OVERLAP_TOL, overlapping_pairs, placed_blocks

    for i, spec in enumerate(scene.blocks):
        if spec.position_m is None:
            raise InputError(
                f"blocks[{i}].position_m",
                f"is required: blocks[0] ({scene.blocks[0].name}) has position_m, so every block needs one",
                scene.source,
            )
        if spec.x_offset_m != 0.0:
            raise InputError(f"blocks[{i}].x_offset_m", "use position_m alone in an assembly scene", scene.source)
        if spec.fixed and any(v is not None for v in (spec.alpha_rad, spec.p_rad_s, spec.mu)):
            raise InputError(
                f"blocks[{i}].fixed", "a fixed block moves with the base: it takes no alpha_rad, p_rad_s or mu"
            )
    placed = placed_blocks(scene)
    if all(b.fixed for b in placed):
        raise InputError("blocks", "every block is fixed: nothing can move", scene.source)
    for b in placed:
        low = float(b.vertices_m[:, 1].min())
        if low < -OVERLAP_TOL * b.size_m:
            raise InputError(
                f"blocks[{b.index}].position_m",
                f"block {b.name} reaches y = {low:.6g} m, below the base (y = 0)",
                scene.source,
            )
    clashes = overlapping_pairs(placed)
    if clashes:
        i, j, depth = clashes[0]
        more = f" (and {len(clashes) - 1} more pairs)" if len(clashes) > 1 else ""
        raise InputError(
            f"blocks[{j}].position_m",
            f"blocks {placed[i].name} and {placed[j].name} overlap at rest by {depth:.3g} m{more}",
            scene.source,
        )
    motion = scene.motion
    if (motion.initial_theta_rad or motion.initial_omega_rad_s) and motion.released_block is None:
        raise InputError(
            "motion.block", "is required for free rocking in an assembly: the name of the block to tilt", scene.source
        )
    if motion.released_block is not None and scene.blocks[scene.block_index(motion.released_block)].fixed:
        raise InputError("motion.block", f"{motion.released_block} is fixed: tilt a block that can move", scene.source)


def _check_joints(scene: Scene, names: list[str]) -> None:
    """[[joints]] name existing blocks, each pair once; stiffness given one way."""
    seen: set[frozenset[str]] = set()
    for k, joint in enumerate(scene.joints):
        a, b = joint.blocks
        for name in (a, b):
            if name != "base" and name not in names:
                raise InputError(f"joints[{k}].blocks", f"no block named {name!r}; blocks: {names[:20]}", scene.source)
        if a == b:
            raise InputError(f"joints[{k}].blocks", f"needs two different blocks, got {a!r} twice", scene.source)
        if a == "base":
            raise InputError(f"joints[{k}].blocks", "name the block first and 'base' second", scene.source)
        key = frozenset((a, b))
        if key in seen:
            raise InputError(f"joints[{k}].blocks", f"the pair {a}-{b} is given twice", scene.source)
        seen.add(key)
        if joint.get("K_N_per_m") is not None and joint.get("jkn_Pa_per_m") is not None:
            raise InputError(f"joints[{k}].jkn_Pa_per_m", "give K_N_per_m or jkn_Pa_per_m, not both", scene.source)


def _check_loads(scene: Scene, names: list[str]) -> None:
    """[[loads]] act on existing moving blocks, at a point on the block, with a bounded force."""
    if not scene.loads:
        return
    import difflib

    from rockyade.scene.placement import placed_blocks

    placed = placed_blocks(scene)
    weight = sum(spec.block().mass_kg for spec in scene.blocks if not spec.fixed) * G
    for k, load in enumerate(scene.loads):
        field_name = f"loads[{k}]"
        if load.block not in names:
            close = difflib.get_close_matches(load.block, names, n=3, cutoff=0.6)
            hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
            shown = ", ".join(names[:10]) + (" ..." if len(names) > 10 else "")
            raise InputError(
                f"{field_name}.block", f"no block named {load.block!r}{hint} (blocks: {shown})", scene.source
            )
        index = names.index(load.block)
        if scene.blocks[index].fixed:
            raise InputError(
                f"{field_name}.block",
                f"{load.block} is fixed: a load on a fixed block goes straight to the base; load a block that moves",
                scene.source,
            )
        magnitude = math.hypot(*load.force_N)
        if magnitude > MAX_LOAD_TO_WEIGHT * weight:
            raise InputError(
                f"{field_name}.force_N",
                f"|F| = {magnitude:.4g} N is more than {MAX_LOAD_TO_WEIGHT:g} times the weight of the moving blocks "
                f"({weight:.4g} N): check the units (N, not kN per metre)",
                scene.source,
            )
        if load.mass_kg is not None and load.mass_kg * G > MAX_LOAD_TO_WEIGHT * weight:
            raise InputError(
                f"{field_name}.mass_kg",
                f"{load.mass_kg:.4g} kg weighs more than {MAX_LOAD_TO_WEIGHT:g} times the moving blocks "
                f"({weight / G:.4g} kg): check the units (kg)",
                scene.source,
            )
        _note_mass_apart_from_weight(load, field_name, scene.source)
        block = placed[index]
        outside = _outside(block.vertices_m, load.point_m)
        if outside > LOAD_POINT_TOL * block.size_m:
            raise InputError(
                f"{field_name}.point_m",
                f"({load.point_m[0]:g}, {load.point_m[1]:g}) m lies {outside:.4g} m outside block {load.block} "
                f"(allowed: {LOAD_POINT_TOL:g} of its size); the point is in the base frame at rest",
                scene.source,
            )


#: A load's mass above this many times its weight / g is accepted with a note.
LOAD_MASS_NOTE_RATIO = 2.0


def _note_mass_apart_from_weight(load: LoadSpec, field_name: str, source: str | None) -> None:
    """Say so (an :class:`~rockyade.errors.InputNote`) when a load's ``mass_kg`` is more than
    :data:`LOAD_MASS_NOTE_RATIO` times its weight / g (``-fy / g``, the default): its mass moves
    with the block (Circolare 2019 C8.7.1: the masses the horizontal acceleration acts on) while
    only ``fy`` bears on it, which is possible (a floor carried elsewhere) but more often a unit
    slip (a weight in kN given as a mass in kg, or a mass in kg per metre of a longer wall)."""
    if load.mass_kg is None or load.mass_kg <= 0.0:
        return
    weight_mass = max(-load.force_N[1], 0.0) / G
    if load.mass_kg > LOAD_MASS_NOTE_RATIO * weight_mass:
        import warnings

        from rockyade.errors import InputNote

        against = (
            f"is {load.mass_kg / weight_mass:.3g} times the load's weight / g ({weight_mass:.4g} kg, its -fy / g)"
            if weight_mass > 0.0
            else "moves with a load that does not weigh on the block (fy >= 0)"
        )
        warnings.warn(
            InputNote(
                f"{field_name}.mass_kg",
                f"{load.mass_kg:.4g} kg {against}: the mass moves with the block while only fy bears on it; "
                "accepted as given (by default mass_kg = -fy / g: check the units)",
                source,
            ),
            stacklevel=2,
        )


def _outside(poly: Any, point: tuple[float, float]) -> float:
    """How far ``point`` lies outside the counter-clockwise convex polygon ``poly`` (<= 0: inside), m."""
    import numpy as np

    p = np.asarray(poly, dtype=float)
    edges = np.roll(p, -1, axis=0) - p
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals /= np.hypot(normals[:, 0], normals[:, 1])[:, None]
    return float(np.max(np.einsum("ij,ij->i", np.asarray(point, dtype=float) - p, normals)))
