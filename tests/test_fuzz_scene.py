"""Fuzzing scene loading: mutated example scenes (as dictionaries, JSON and raw TOML bytes)
load or fail with an InputError; never a traceback, never a hang. Accepted scenes get a
cost estimate, which must not fail either."""

from __future__ import annotations

import copy
import json
import math
import tempfile
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rockyade.runner.cost_limits import estimate_cost
from rockyade.scene import load_scene, scene_from_dict

from .conftest import EXAMPLES
from .fuzzing import fuzz_settings, outcome, report

BASES = [tomllib.loads(p.read_text()) for p in sorted(EXAMPLES.glob("*.toml"))]
TEXTS = [p.read_bytes() for p in sorted(EXAMPLES.glob("*.toml"))]

NUMBERS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([5e-324, 1e-300, -0.0, 1e300, 1e-12, 1e30, 0.0, -1.0, 1e5, 1e-9, math.pi / 2]),
    st.integers(min_value=-(10**400), max_value=10**400),
    st.integers(min_value=-3, max_value=10),
)
SCALARS = st.one_of(NUMBERS, st.text(max_size=12), st.booleans(), st.none())


def _deep(depth: int) -> Any:
    value: Any = 1.0
    for _ in range(depth):
        value = [value]
    return value


LEAVES = st.one_of(
    SCALARS,
    st.lists(NUMBERS, max_size=5),
    st.lists(st.lists(NUMBERS, min_size=2, max_size=2), max_size=6),
    st.dictionaries(st.text(max_size=6), SCALARS, max_size=3),
    st.integers(min_value=10, max_value=1500).map(_deep),
    NUMBERS.filter(lambda v: isinstance(v, float)).map(np.float64),
    st.lists(st.floats(-2, 2), min_size=3, max_size=6).map(lambda v: np.array(v).reshape(-1, 1).repeat(2, axis=1)),
)


def _paths(value: Any, prefix: tuple = ()) -> list[tuple]:
    out = [prefix]
    if isinstance(value, dict):
        for k, v in value.items():
            out += _paths(v, (*prefix, k))
    elif isinstance(value, list):
        for i, v in enumerate(value):
            out += _paths(v, (*prefix, i))
    return out


@st.composite
def mutated_scenes(draw: st.DrawFn) -> dict:
    d = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 3))):
        paths = _paths(d)[1:]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = d
        for key in path[:-1]:
            parent = parent[key]
        op = draw(st.sampled_from(["replace", "replace", "delete", "add", "rename"]))
        if op == "replace":
            parent[path[-1]] = draw(LEAVES)
        elif op == "delete":
            del parent[path[-1]]
        elif op == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=10))] = draw(LEAVES)
        elif op == "rename" and isinstance(parent, dict):
            parent[f"{path[-1]}{draw(st.sampled_from(['m', '_x', 's', '']))}x"] = parent.pop(path[-1])
    return d


def _load_and_estimate(d: dict) -> None:
    scene = scene_from_dict(d, source="fuzz.toml")
    estimate_cost(scene, "housner")
    estimate_cost(scene, "reference")


@fuzz_settings(400)
@given(mutated_scenes())
@pytest.mark.slow
def test_fuzz_scene_dictionaries(d):
    outcome("scene dict", lambda: _load_and_estimate(d))


@fuzz_settings(150)
@given(mutated_scenes())
def test_fuzz_scene_json_files(d):
    def load() -> None:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "s.json"
            try:
                text = json.dumps(d, default=lambda o: o.tolist() if hasattr(o, "tolist") else str(o))
            except (ValueError, RecursionError):
                text = "{" * 2000
            path.write_text(text)
            load_scene(path)

    outcome("scene JSON", load)


BYTES = st.one_of(
    st.binary(max_size=8),
    st.sampled_from(
        [
            b"\xff",
            b"\xe9",
            b"\x00",
            b"\xef\xbb\xbf",
            b"1_0",
            b"1e400",
            b"nan",
            b"inf",
            b"[[[[[[",
            b"]",
            b"\n[[blocks]]\n",
            b" = ",
            b'"',
            b"'",
            b"9" * 400,
            b"\xd9\xa1",
            b"\r\n",
            b"#",
            b"0x1F",
        ]
    ),
)


@st.composite
def mutated_toml(draw: st.DrawFn) -> bytes:
    text = bytearray(draw(st.sampled_from(TEXTS)))
    for _ in range(draw(st.integers(1, 4))):
        pos = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "truncate", "overwrite"]))
        if op == "insert":
            text[pos:pos] = draw(BYTES)
        elif op == "delete":
            del text[pos : pos + draw(st.integers(1, 20))]
        elif op == "truncate":
            del text[pos:]
        else:
            chunk = draw(BYTES)
            text[pos : pos + len(chunk)] = chunk
    return bytes(text)


@fuzz_settings(400)
@given(mutated_toml())
@pytest.mark.slow
def test_fuzz_scene_toml_bytes(data):
    def load() -> None:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "s.toml"
            path.write_bytes(data)
            scene = load_scene(path)
            estimate_cost(scene, "reference")

    outcome("scene TOML bytes", load)


def _json_text(toml: bytes) -> bytes:
    import tomllib

    return json.dumps(tomllib.loads(toml.decode()), indent=1).encode()


JSON_TEXTS = [_json_text(t) for t in TEXTS]
#: Pieces that make JSON objects hold a key twice, among the usual damage.
JSON_BYTES = st.one_of(
    BYTES, st.sampled_from([b'"duration_s": 1.0, ', b'"type": "free", ', b'"name": "x", ', b"{", b"}"])
)


@fuzz_settings(300)
@given(data=st.data())
def test_fuzz_scene_json_bytes(data):
    """Mutated JSON text (keys spliced in twice, bytes inserted or cut): a scene or one clean
    error (a key given twice is one), never a traceback."""
    text = bytearray(data.draw(st.sampled_from(JSON_TEXTS)))
    for _ in range(data.draw(st.integers(1, 3))):
        pos = data.draw(st.integers(0, len(text)))
        if data.draw(st.booleans()):
            text[pos:pos] = data.draw(JSON_BYTES)
        else:
            del text[pos : pos + data.draw(st.integers(1, 20))]

    def load() -> None:
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "s.json"
            path.write_bytes(bytes(text))
            load_scene(path)

    outcome("scene JSON bytes", load)


@pytest.fixture(scope="module", autouse=True)
def _print_counts():
    yield
    for suite in ("scene dict", "scene JSON", "scene TOML bytes", "scene JSON bytes", "scene runs"):
        print("\n" + report(suite))


@st.composite
def perturbed_scenes(draw: st.DrawFn) -> dict:
    """A base scene with numbers scaled by up to 1000x either way: mostly valid, often odd."""
    d = copy.deepcopy(draw(st.sampled_from(BASES)))
    numeric = [p for p in _paths(d)[1:] if _is_number(_get(d, p))]
    for path in draw(st.lists(st.sampled_from(numeric), min_size=1, max_size=3, unique=True)):
        parent = _get(d, path[:-1])
        value = parent[path[-1]]
        factor = 10.0 ** draw(st.floats(-3, 3))
        parent[path[-1]] = int(value * factor) if isinstance(value, int) else value * factor
    d["duration_s"] = min(float(d["duration_s"]), 2.0)
    d["sample_dt_s"] = min(max(float(d["sample_dt_s"]), 1e-3), d["duration_s"])
    return d


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _get(d: Any, path: tuple) -> Any:
    for key in path:
        d = d[key]
    return d


def _run(d: dict) -> None:
    from rockyade.runner.cost_limits import check_cost
    from rockyade.solvers import make_solver

    scene = scene_from_dict(d, source="fuzz.toml")
    for solver in ("housner", "reference"):
        check_cost(scene, solver)
        result = make_solver(solver).run(scene)
        assert result.status in ("completed", "overturned", "failed")


@fuzz_settings(40)
@given(perturbed_scenes())
@pytest.mark.slow
def test_fuzz_runs_of_perturbed_scenes(d):
    outcome("scene runs", lambda: _run(d), compiles=True)
