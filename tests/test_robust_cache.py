"""The synthetic-record cache: a damaged entry is regenerated (or a cache that cannot be written
is worked around), never used, never a traceback. Each case of the issue: truncated, emptied,
not a zip, wrong dtype or shape, NaN, rescaled, one huge sample, a link in place of the file,
a cache folder that is a file, a cache that cannot be written, two processes at once."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.record_text import MAX_ABS_ACCEL_M_S2
from rockyade.motion.suite_cache import (
    CacheDamagedError,
    _digest,
    cache_path,
    load_cached_record,
    suite_record,
)
from rockyade.motion.synthetic import Envelope, SuiteSpec, generate_record

#: A quick suite: 2.5 s records, two spectral corrections at most.
SPEC = SuiteSpec(
    ElasticSpectrum.ec8(2, "D", ag_s_m_s2=2.8),
    count=2,
    seed=5,
    envelope=Envelope("jennings", 0.5, 1.0, 1.0),
    max_iterations=2,
    name="c",
)


@pytest.fixture(scope="module")
def generated():
    return generate_record(SPEC, 1)


@pytest.fixture
def cache(tmp_path, monkeypatch, generated):
    """A private cache holding records 1 and 2 as written; yields record 1's file."""
    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path / "cache"))
    suite_record(SPEC, 1)
    suite_record(SPEC, 2)
    path = cache_path(SPEC, 1)
    assert path.is_file()
    return path


def _arrays(path):
    with np.load(path, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}


def _npz(**arrays) -> bytes:
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _resaved(path, **changes) -> bytes:
    return _npz(**{**_arrays(path), **changes})


def _with_sample(a, value):
    a = a.copy()
    a[7] = value
    return a


DAMAGE = {
    "truncated": lambda p: p.read_bytes()[: p.stat().st_size // 2],
    "last bytes cut": lambda p: p.read_bytes()[:-10],
    "zero bytes": lambda p: b"",
    "not a zip": lambda p: b"not a zip file\n" * 50,
    "float32": lambda p: _resaved(p, accel_m_s2=_arrays(p)["accel_m_s2"].astype(np.float32)),
    "integers": lambda p: _resaved(p, accel_m_s2=(1000 * _arrays(p)["accel_m_s2"]).astype(np.int64)),
    "strings": lambda p: _resaved(p, accel_m_s2=np.array(["a", "b"])),
    "shorter": lambda p: _resaved(p, accel_m_s2=_arrays(p)["accel_m_s2"][:-5]),
    "two columns": lambda p: _resaved(p, accel_m_s2=np.c_[_arrays(p)["accel_m_s2"], _arrays(p)["accel_m_s2"]]),
    "NaN": lambda p: _resaved(p, accel_m_s2=_with_sample(_arrays(p)["accel_m_s2"], np.nan)),
    "scaled by 0.01": lambda p: _resaved(p, accel_m_s2=0.01 * _arrays(p)["accel_m_s2"]),
    "one sample 1e6": lambda p: _resaved(p, accel_m_s2=_with_sample(_arrays(p)["accel_m_s2"], 1e6)),
    "times doubled": lambda p: _resaved(p, t_s=2 * _arrays(p)["t_s"]),
    "no checksum": lambda p: _npz(**{k: v for k, v in _arrays(p).items() if k != "sha256"}),
    "an extra array": lambda p: _resaved(p, extra=np.zeros(3)),
    "pickled object": lambda p: _resaved(p, meta=np.array([{"a": 1}], dtype=object)),
    "another record": lambda p: cache_path(SPEC, 2).read_bytes(),
}


@pytest.mark.parametrize("damage", sorted(DAMAGE))
def test_a_damaged_cache_file_is_regenerated_never_used(cache, generated, damage, capsys):
    cache.write_bytes(DAMAGE[damage](cache))
    with pytest.raises(CacheDamagedError):
        load_cached_record(cache, SPEC, 1)
    rec = suite_record(SPEC, 1)
    np.testing.assert_array_equal(rec.accel_m_s2, generated.accel_m_s2)
    np.testing.assert_array_equal(rec.t_s, generated.t_s)
    err = capsys.readouterr().err
    assert f"rockyade: note: {cache}: " in err and err.strip().endswith("regenerated") and "Traceback" not in err
    np.testing.assert_array_equal(load_cached_record(cache, SPEC, 1).accel_m_s2, generated.accel_m_s2)


def test_a_consistent_entry_beyond_the_record_bounds_is_regenerated(cache, generated, capsys):
    """A cached record passes the bounds a read one does, even with a matching checksum."""
    arrays = _arrays(cache)
    huge = _with_sample(arrays["accel_m_s2"], 2 * MAX_ABS_ACCEL_M_S2)
    meta = str(arrays["meta"][()])
    cache.write_bytes(
        _npz(
            t_s=arrays["t_s"], accel_m_s2=huge, meta=arrays["meta"], sha256=np.array(_digest(arrays["t_s"], huge, meta))
        )
    )
    with pytest.raises(CacheDamagedError, match="beyond"):
        load_cached_record(cache, SPEC, 1)
    np.testing.assert_array_equal(suite_record(SPEC, 1).accel_m_s2, generated.accel_m_s2)
    assert "beyond +/-1000 m/s^2: regenerated" in capsys.readouterr().err


def test_a_symlink_in_place_of_the_file_is_replaced_not_followed(cache, generated, tmp_path):
    victim = tmp_path / "precious.npz"
    victim.write_bytes(cache.read_bytes())  # even a valid record elsewhere is not read through a link
    before = victim.read_bytes()
    cache.unlink()
    cache.symlink_to(victim)
    with pytest.raises(CacheDamagedError, match="symbolic link"):
        load_cached_record(cache, SPEC, 1)
    np.testing.assert_array_equal(suite_record(SPEC, 1).accel_m_s2, generated.accel_m_s2)
    assert not cache.is_symlink() and cache.is_file() and victim.read_bytes() == before


@pytest.mark.parametrize("which", ["suite folder", "cache root"])
def test_a_cache_folder_that_is_a_file_gives_the_record_and_one_warning(cache, generated, which, monkeypatch, capsys):
    from rockyade.motion import suite_cache

    monkeypatch.setattr(suite_cache, "_WARNED", set())
    blocked = cache.parent if which == "suite folder" else cache.parent.parent.parent
    shutil.rmtree(blocked)
    blocked.write_text("a file where a folder should be")
    for index in (1, 2, 1):
        rec = suite_record(SPEC, index)
    np.testing.assert_array_equal(rec.accel_m_s2, generated.accel_m_s2)
    err = capsys.readouterr().err
    assert err.count("rockyade: warning: cannot write the synthetic-record cache") == 1, err
    assert "Traceback" not in err and blocked.read_text() == "a file where a folder should be"


def test_a_folder_in_place_of_a_cache_file_is_named_and_the_record_generated(cache, generated, monkeypatch, capsys):
    """A folder where a record's cache file should be: the record is generated, one note
    names the file (it used to end with 'rockyade: error: 14: Is a directory', naming a file
    descriptor), one warning says the cache cannot be written there, whatever the reads."""
    from rockyade.motion import suite_cache

    monkeypatch.setattr(suite_cache, "_WARNED", set())
    monkeypatch.setattr(suite_cache, "_NOTED", set())
    monkeypatch.setattr(suite_cache, "_HELD", type(suite_cache._HELD)())
    cache.unlink()
    cache.mkdir()
    for _ in range(3):
        rec = suite_record(SPEC, 1)
    np.testing.assert_array_equal(rec.accel_m_s2, generated.accel_m_s2)
    err = capsys.readouterr().err
    assert err.count(f"rockyade: note: {cache}: a folder, not a cache file: regenerated") == 1, err
    assert err.count("rockyade: warning: cannot write the synthetic-record cache") == 1, err
    assert cache.is_dir() and "Traceback" not in err


@pytest.mark.slow
def test_an_unwritable_cache_gives_the_record_and_a_warning(tmp_path, generated):
    """A read-only cache folder (a read-only file system: root writes through permissions)."""
    folder = tmp_path / "ro"
    folder.mkdir()
    code = textwrap.dedent(
        """
        from rockyade.motion.suite_cache import suite_record
        from tests.test_robust_cache import SPEC
        print(repr(float(suite_record(SPEC, 1).accel_m_s2.sum())))
        """
    )
    env = {**os.environ, "ROCKYADE_CACHE": str(folder)}
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if os.geteuid() == 0:
        probe = subprocess.run(["unshare", "-Urm", "true"], capture_output=True)
        if probe.returncode != 0:
            pytest.skip("needs unshare -Urm (a user namespace) to make a read-only file system as root")
        argv = [
            "unshare",
            "-Urm",
            "sh",
            "-c",
            f'mount -t tmpfs -o ro tmpfs "{folder}" && exec "$0" -c "$1"',
            sys.executable,
            code,
        ]
    else:
        folder.chmod(0o500)
        argv = [sys.executable, "-c", code]
    proc = subprocess.run(argv, capture_output=True, text=True, env=env, cwd=root, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert float(proc.stdout) == generated.accel_m_s2.sum()
    assert "rockyade: warning: cannot write the synthetic-record cache" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.slow
def test_two_processes_regenerating_at_once_both_get_the_record(cache, generated):
    cache.write_bytes(b"")  # damaged: both processes regenerate it and rename a file into place
    code = textwrap.dedent(
        """
        from rockyade.motion.suite_cache import suite_record
        from tests.test_robust_cache import SPEC
        print(suite_record(SPEC, 1).accel_m_s2.tobytes().hex()[:64])
        """
    )
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", code],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=root,
            env=dict(os.environ),
        )
        for _ in range(2)
    ]
    outs = [p.communicate(timeout=300) for p in procs]
    assert all(p.returncode == 0 for p in procs), outs
    assert {out for out, _ in outs} == {generated.accel_m_s2.tobytes().hex()[:64] + "\n"}
    np.testing.assert_array_equal(load_cached_record(cache, SPEC, 1).accel_m_s2, generated.accel_m_s2)
    assert not [p for p in cache.parent.iterdir() if p.name.endswith(".tmp")]


def test_a_run_of_a_synthetic_scene_regenerates_a_damaged_entry(tmp_path, monkeypatch, capsys):
    """A batch run failed with BadZipFile instead of regenerating."""
    from rockyade.cli import main

    from .conftest import free_scene_dict

    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path / "cache"))
    d = free_scene_dict(duration=2.0)
    d["motion"] = {
        "type": "synthetic",
        "suite": "c",
        "spectrum_type": 2,
        "ground": "D",
        "ag_s_m_s2": 2.8,
        "seed": 9,
        "count": 1,
        "record": 1,
        "load_factor": 0.2,
    }
    scene = tmp_path / "s.json"
    scene.write_text(json.dumps(d))
    assert main(["run", str(scene)]) == 0
    entry = next((tmp_path / "cache" / "suites").rglob("record_01.npz"))
    entry.write_bytes(entry.read_bytes()[:100])
    capsys.readouterr()
    assert main(["run", str(scene)]) == 0
    err = capsys.readouterr().err
    assert "not a readable .npz (BadZipFile" in err and "regenerated" in err


def test_random_and_mutated_bytes_in_a_cache_file_are_damage_never_a_traceback(cache, generated):
    """Hypothesis: any bytes in place of a cache file give CacheDamagedError (then a
    regeneration), or, if they happen to be the file as written, the record itself."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    pristine = cache.read_bytes()

    @settings(max_examples=200, deadline=None, derandomize=True, database=None)
    @given(
        data=st.one_of(
            st.binary(max_size=300),
            st.builds(
                lambda pos, chunk, cut: pristine[:pos] + chunk + pristine[pos + cut :],
                st.integers(0, len(pristine)),
                st.binary(max_size=8),
                st.integers(0, 16),
            ),
        )
    )
    def check(data):
        cache.write_bytes(data)
        try:
            rec = load_cached_record(cache, SPEC, 1)
        except CacheDamagedError:
            return
        np.testing.assert_array_equal(rec.accel_m_s2, generated.accel_m_s2)

    check()
