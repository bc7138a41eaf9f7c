"""Reading scene files (TOML or JSON) and validating them field by field.

Every bad or missing value raises :class:`~rockyade.errors.InputError` naming the file,
the dotted field and the allowed range.
"""

from __future__ import annotations

import json
import math
import os
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from rockyade.blocks.geometry import MAX_POLYGON_VERTICES
from rockyade.constants import DEFAULT_FRICTION_ANGLE_DEG, DEFAULT_TIME_STEP_FRAC, STIFFNESS_SCALES
from rockyade.errors import InputError
from rockyade.io.fields import TableReader, plain_data
from rockyade.motion.spec import parse_motion
from rockyade.scene.bounds import BOUNDS, check_block_ranges
from rockyade.scene.description import (
    CALIBRATIONS,
    JOINT_OVERRIDE_KEYS,
    MAX_DURATION_S,
    MAX_LENGTH_M,
    MAX_LOAD_N,
    MAX_SAMPLES,
    NAME_PATTERN,
    BlockSpec,
    ContactSpec,
    JointOverride,
    LoadSpec,
    OutputSpec,
    Scene,
    _check_scene,
)

#: Largest scene (or study) file read, bytes. A scene is a small text file: 16 MiB hold about
#: 1.5 million inline base-motion samples, which Python's TOML reader takes about 10 s to
#: parse; a longer motion belongs in a record file (up to 512 MiB).
MAX_SCENE_BYTES = 16 * 1024 * 1024


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file (``.toml`` or ``.json``).

    Raises
    ------
    InputError
        Naming the file, the field and the allowed range, for any bad or missing value.
    """
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("scene", f"file not found: {path}")
    suffix = path.suffix.lower()
    if suffix not in (".toml", ".json"):
        raise InputError("scene", f"unknown file type {suffix!r}: use .toml or .json", source)
    data = parse_text_file(path, "scene")
    return scene_from_dict(data, source=source, base_dir=path.parent)


def parse_text_file(path: Path, field: str) -> Any:
    """The table in a UTF-8 TOML or JSON file (by suffix); InputError naming the file otherwise.

    Files larger than :data:`MAX_SCENE_BYTES` are refused before they are read; a JSON
    object with the same key twice is refused (JSON readers keep the last value silently,
    TOML refuses it).
    """
    source = str(path)
    try:
        data = _read_capped(path, field)
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        byte = exc.object[exc.start]
        raise InputError(field, f"not UTF-8 text (byte {byte:#04x} at offset {exc.start})", source) from None
    except OSError as exc:
        raise InputError(field, f"cannot read the file: {exc.strerror or exc}", source) from None
    kind = "JSON" if path.suffix.lower() == ".json" else "TOML"
    try:
        return json.loads(text, object_pairs_hook=_unique_keys) if kind == "JSON" else tomllib.loads(text)
    except DuplicateKeyError as exc:
        raise InputError(field, f"not valid JSON: {exc}", source) from None
    except (tomllib.TOMLDecodeError, json.JSONDecodeError) as exc:
        raise InputError(field, f"not valid {kind}: {exc}", source) from None
    except RecursionError:
        raise InputError(field, f"not valid {kind}: nested too deeply", source) from None
    except ValueError as exc:  # e.g. an integer literal too long to convert
        raise InputError(field, f"not valid {kind}: {exc}", source) from None


def _read_capped(path: Path, field: str) -> bytes:
    """The bytes of ``path``, refused at once (from its size, before reading) above the cap."""
    with path.open("rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        if size > MAX_SCENE_BYTES:
            raise _too_large(path, field, size)
        data = fh.read(MAX_SCENE_BYTES + 1)  # a file that grows while being read is cut here
    if len(data) > MAX_SCENE_BYTES:
        raise _too_large(path, field, len(data))
    return data


def _too_large(path: Path, field: str, size: int) -> InputError:
    return InputError(
        field,
        f"the file has {size:,} bytes, more than the {MAX_SCENE_BYTES:,} ({MAX_SCENE_BYTES // 2**20} MiB) a "
        'scene file may have: put a long base motion in a record file ([motion] type = "record")',
        str(path),
    )


class DuplicateKeyError(ValueError):
    """A JSON object that holds a key twice."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """``object_pairs_hook`` of :func:`json.loads`: a dict, or DuplicateKeyError naming the key."""
    table: dict[str, Any] = {}
    for key, value in pairs:
        if key in table:
            others = ", ".join(repr(k) for k in table if k != key)
            raise DuplicateKeyError(
                f"the key {key!r} appears twice in one object (beside {others or 'no other key'}): "
                "JSON readers would keep the last value silently; keep one"
            )
        table[key] = value
    return table


def scene_from_dict(data: Any, source: str | None = None, base_dir: Path | None = None) -> Scene:
    """Validate a scene given as a dictionary (as read from TOML or JSON).

    numpy arrays and scalars are accepted wherever lists and numbers are.
    """
    data = plain_data(data, "scene", source)
    top = TableReader(data, "", source)
    duration = top.number("duration_s", lo=0.0, hi=MAX_DURATION_S, lo_open=True, unit="s")
    sample_dt = top.number("sample_dt_s", **BOUNDS["sample_dt_s"].kwargs())
    if sample_dt > duration:
        raise top.error("sample_dt_s", f"must be <= duration_s ({duration:g} s), got {sample_dt:g}")
    if duration / sample_dt > MAX_SAMPLES:
        raise top.error("sample_dt_s", f"gives more than {MAX_SAMPLES} samples; use a larger interval")
    raw_blocks = top.raw("blocks")
    if not isinstance(raw_blocks, list) or not raw_blocks:
        raise top.error("blocks", "must be a non-empty list of block tables ([[blocks]])")
    blocks = tuple(_parse_block(b, i, source) for i, b in enumerate(raw_blocks))
    contact = _parse_contact(top.sub("contact", {}))
    motion = parse_motion(top.raw("motion"), source, base_dir)
    output = _parse_output(top.sub("output", {}))
    if output.accel_lowpass_hz is not None and output.accel_lowpass_hz >= 0.5 / sample_dt:
        raise InputError(
            "output.accel_lowpass_hz",
            f"must be below the Nyquist frequency 1 / (2 sample_dt_s) = {0.5 / sample_dt:g} Hz, "
            f"got {output.accel_lowpass_hz:g}",
            source,
        )
    joints = _parse_joints(top.raw("joints", []), source)
    loads = _parse_loads(top.raw("loads", []), source)
    top.finish()
    scene = Scene(duration, sample_dt, blocks, contact, motion, output, source, joints, loads)
    _check_scene(scene)
    return scene


def _parse_block(table: Any, index: int, source: str | None) -> BlockSpec:
    r = TableReader(table, f"blocks[{index}]", source)
    name = r.string("name", f"block{index}")
    if not NAME_PATTERN.match(name):
        raise r.error("name", "must start with a letter and contain only letters, digits and _ (max 64)")
    thickness = _length(r, "thickness_m")
    vertices = None
    width = height = None
    if r.has("vertices_m"):
        raw = r.raw("vertices_m")
        if not isinstance(raw, list) or len(raw) < 3 or not all(isinstance(v, list) and len(v) == 2 for v in raw):
            raise r.error("vertices_m", "must be a list of at least 3 [x, y] pairs in metres")
        if len(raw) > MAX_POLYGON_VERTICES:  # refused before each vertex is checked
            raise r.error(
                "vertices_m", f"has {len(raw)} vertices, more than the {MAX_POLYGON_VERTICES} a block may have"
            )
        sub = TableReader({f"v{i}": v for i, v in enumerate(raw)}, r.field("vertices_m"), source)
        vertices = tuple(tuple(sub.number_list(f"v{i}", min_len=2, unit="m")) for i in range(len(raw)))
        if max(abs(c) for v in vertices for c in v) > MAX_LENGTH_M:
            raise r.error("vertices_m", f"coordinates must be within +/-{MAX_LENGTH_M:g} m")
        for key in ("width_m", "height_m"):
            if r.has(key):
                raise r.error(key, "give either vertices_m or width_m/height_m, not both")
            r.raw(key, None)
    else:
        width = _length(r, "width_m")
        height = _length(r, "height_m")
    mass = r.number("mass_kg", None, **BOUNDS["mass_kg"].kwargs())
    density = r.number("density_kg_m3", None, **BOUNDS["density_kg_m3"].kwargs())
    if (mass is None) == (density is None):
        raise r.error("mass_kg", "give exactly one of mass_kg and density_kg_m3")
    inertia = r.positive("inertia_kgm2", None, unit="kg m^2")
    x_offset = r.number("x_offset_m", 0.0, lo=-MAX_LENGTH_M, hi=MAX_LENGTH_M, unit="m")
    position = r.number_list("position_m", None, min_len=2, unit="m")
    if position is not None:
        if len(position) != 2:
            raise r.error("position_m", "must be [x, y] in metres")
        if max(abs(c) for c in position) > MAX_LENGTH_M:
            raise r.error("position_m", f"coordinates must be within +/-{MAX_LENGTH_M:g} m")
    rotation = r.number("rotation_rad", 0.0, lo=-2 * math.pi, hi=2 * math.pi, unit="rad")
    if rotation != 0.0 and position is None:
        raise r.error("rotation_rad", "needs position_m (an assembly scene)")
    fixed = r.boolean("fixed", False)
    alpha = r.number("alpha_rad", None, **BOUNDS["alpha_rad"].kwargs())
    p = r.positive("p_rad_s", None, unit="rad/s")
    mu = r.number("mu", None, **BOUNDS["mu"].kwargs())
    if inertia is not None and p is not None:
        raise r.error("p_rad_s", "give either inertia_kgm2 or p_rad_s (p sets the DEM inertia), not both")
    r.finish()
    spec = BlockSpec(
        name=name,
        thickness_m=thickness,
        width_m=width,
        height_m=height,
        vertices_m=vertices,
        mass_kg=mass,
        density_kg_m3=density,
        inertia_kgm2=inertia,
        x_offset_m=x_offset,
        alpha_rad=None if alpha is None else float(alpha),
        p_rad_s=None if p is None else float(p),
        mu=None if mu is None else float(mu),
        position_m=None if position is None else (position[0], position[1]),
        rotation_rad=rotation,
        fixed=fixed,
    )
    try:
        block = spec.block()
    except InputError as exc:
        raise InputError(f"blocks[{index}].{exc.field}", exc.message, source) from None
    check_block_ranges(block, spec, f"blocks[{index}].", source)
    return spec


def _length(r: TableReader, key: str) -> float:
    """A length in the documented range (:data:`rockyade.scene.bounds.BOUNDS`), metres."""
    return r.number(key, **BOUNDS["length_m"].kwargs())


def _bounded(r: TableReader, key: str, default: Any = None) -> Any:
    """A ``[contact]`` (or ``[[joints]]``) number in its documented range."""
    return r.number(key, default, **BOUNDS[f"contact.{key}"].kwargs())


def _parse_contact(r: TableReader) -> ContactSpec:
    calibration = r.string("calibration", "paper", choices=CALIBRATIONS)
    scale = r.raw("stiffness_scale", "MN/m")
    if isinstance(scale, str):
        if scale not in STIFFNESS_SCALES:
            raise r.error(
                "stiffness_scale", f"must be one of {sorted(STIFFNESS_SCALES)} or a number > 0, got {scale!r}"
            )
    else:
        scale = r.number("stiffness_scale", **BOUNDS["contact.stiffness_scale"].kwargs())
    spec = ContactSpec(
        calibration=calibration,
        stiffness_scale=scale,
        K_N_per_m=_bounded(r, "K_N_per_m"),
        Ks_N_per_m=_bounded(r, "Ks_N_per_m"),
        friction_angle_deg=r.number(
            "friction_angle_deg", DEFAULT_FRICTION_ANGLE_DEG, lo=0.0, hi=90.0, hi_open=True, unit="deg"
        ),
        cohesion_Pa=r.number("cohesion_Pa", 0.0, lo=0.0, unit="Pa"),
        beta_s=_bounded(r, "beta_s"),
        dt_s=_bounded(r, "dt_s"),
        time_step_frac=_bounded(r, "time_step_frac", DEFAULT_TIME_STEP_FRAC),
        mass_damping_1_s=_bounded(r, "mass_damping_1_s", 0.0),
        jkn_Pa_per_m=_bounded(r, "jkn_Pa_per_m"),
        jks_Pa_per_m=_bounded(r, "jks_Pa_per_m"),
    )
    if spec.K_N_per_m is not None and spec.jkn_Pa_per_m is not None:
        raise r.error("jkn_Pa_per_m", "give K_N_per_m (per contact point) or jkn_Pa_per_m (per unit area), not both")
    if spec.jks_Pa_per_m is not None and spec.jkn_Pa_per_m is None:
        raise r.error("jks_Pa_per_m", "needs jkn_Pa_per_m (UDEC-style stiffness per unit area)")
    if spec.jkn_Pa_per_m is not None and spec.beta_s is None:
        raise r.error(
            "beta_s",
            "is required with jkn_Pa_per_m: the paper's Eq 13 damping is fitted to its own K (Eq 10), "
            "not to a stiffness per unit area",
        )
    if spec.cohesion_Pa != 0.0:
        raise r.error(
            "cohesion_Pa",
            "must be 0: the paper's dry joints have no cohesion and YADE's ViscElPhys law "
            "(the same law in both DEMs) has none",
        )
    r.finish()
    return spec


def _parse_output(r: TableReader) -> OutputSpec:
    point = r.raw("accel_point", "top_centre")
    if isinstance(point, str):
        if point != "top_centre":
            raise r.error("accel_point", f"must be 'top_centre' or [x, y] in metres, got {point!r}")
    else:
        point = tuple(r.number_list("accel_point", min_len=2, unit="m"))
        if len(point) != 2:
            raise r.error("accel_point", "must be 'top_centre' or [x, y] in metres")
        limit = BOUNDS["output.accel_point"]
        if not all(limit.lo <= c <= limit.hi for c in point):
            rng = f"[{limit.lo:g}, {limit.hi:g}] m"
            raise r.error("accel_point", f"coordinates must be within {rng}, got {list(point)}")
    lowpass = r.number("accel_lowpass_hz", None, **BOUNDS["output.accel_lowpass_hz"].kwargs())
    r.finish()
    return OutputSpec(point, lowpass)


def _list_readers(raw: Any, key: str, source: str | None) -> Iterator[TableReader]:
    """A reader of each table of the list ``[[key]]`` in turn (named ``key[k]`` in errors)."""
    if not isinstance(raw, list):
        raise InputError(key, f"must be a list of tables ([[{key}]])", source)
    for k, table in enumerate(raw):
        yield TableReader(table, f"{key}[{k}]", source)


def _parse_joints(raw: Any, source: str | None) -> tuple[JointOverride, ...]:
    """The ``[[joints]]`` list: per-pair overrides by block names (see scene.description.JointOverride)."""
    out = []
    for r in _list_readers(raw, "joints", source):
        names = r.raw("blocks")
        if not isinstance(names, list) or len(names) != 2 or not all(isinstance(n, str) for n in names):
            raise r.error("blocks", 'must be two block names, e.g. ["b1", "b2"] or ["b1", "base"]')
        values = []
        for key in JOINT_OVERRIDE_KEYS:
            if key == "friction_angle_deg":
                value = r.number(key, None, lo=0.0, hi=90.0, hi_open=True, unit="deg")
            else:
                value = _bounded(r, key)
            if value is not None:
                values.append((key, float(value)))
        if not values:
            raise r.error("blocks", f"the joint overrides nothing: give one of {', '.join(JOINT_OVERRIDE_KEYS)}")
        r.finish()
        out.append(JointOverride((names[0], names[1]), tuple(values)))
    return tuple(out)


def _parse_loads(raw: Any, source: str | None) -> tuple[LoadSpec, ...]:
    """The ``[[loads]]`` list (see scene.description.LoadSpec); the cross-checks are in ``_check_scene``."""
    out = []
    for r in _list_readers(raw, "loads", source):
        block = r.string("block")
        point = r.number_list("point_m", min_len=2, unit="m")
        force = r.number_list("force_N", min_len=2, unit="N")
        if len(point) != 2:
            raise r.error("point_m", "must be [x, y] in metres (base frame at rest)")
        if len(force) != 2:
            raise r.error("force_N", "must be [fx, fy] in newtons")
        if max(abs(c) for c in point) > MAX_LENGTH_M:
            raise r.error("point_m", f"coordinates must be within +/-{MAX_LENGTH_M:g} m")
        if max(abs(c) for c in force) > MAX_LOAD_N:
            raise r.error("force_N", f"components must be within +/-{MAX_LOAD_N:g} N, got {force}")
        mass = r.number("mass_kg", None, **BOUNDS["loads.mass_kg"].kwargs())
        r.finish()
        out.append(
            LoadSpec(
                block,
                (float(point[0]), float(point[1])),
                (float(force[0]), float(force[1])),
                None if mass is None else float(mass),
            )
        )
    return tuple(out)
