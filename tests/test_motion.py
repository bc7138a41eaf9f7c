"""Base motions: harmonics, pulses, record readers, spectra, EC8, synthetic suites."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from rockyade.constants import STANDARD_GRAVITY as SG
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.motion.analytic import Harmonic, Pulse
from rockyade.motion.ec8 import ElasticSpectrum, damping_correction
from rockyade.motion.processing import bandpass, baseline_correct, integrate, scale_to_pga
from rockyade.motion.records import RecordError, read_at2, read_record, read_single_column, read_two_column
from rockyade.motion.spectra import response_spectrum
from rockyade.motion.suite_cache import suite_record
from rockyade.motion.synthetic import (
    Envelope,
    SuiteSpec,
    compatibility_report,
    generate_record,
    paper_suite,
)
from rockyade.scene import scene_from_dict

from .conftest import EXAMPLES, external_records_dir, free_scene_dict, needs_records
from .oscillator import fine_grid_psa

RECORDS = external_records_dir() or Path()
needs_peer_records = needs_records(
    "RSN6_IMPVALL.I_I-ELC180-hor1.AT2", "RSN6_IMPVALL.I_I-ELC270-hor2.AT2", "RSN77_SFERN_PUL164-hor1.AT2"
)


@pytest.fixture(autouse=True)
def private_cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("ROCKYADE_CACHE", str(tmp_path_factory.getbasetemp() / "rockyade-cache"))


# --------------------------------------------------------------------- harmonic


def test_harmonic_stationary_amplitude_and_rest_at_both_ends():
    h = Harmonic(amplitude_mm=6.0, frequency_hz=3.3, cycles=20, ramp_cycles=2)
    phases = h.phases_s
    t = np.linspace(0, phases["end_s"], 200_001)
    d, v, a = h.kinematics(t)
    stationary = (t > phases["ramp_up_end_s"]) & (t < phases["stationary_end_s"])
    assert np.max(np.abs(a[stationary])) == pytest.approx(6e-3 * (2 * math.pi * 3.3) ** 2, rel=1e-6)
    assert h.accel_amplitude_m_s2 == pytest.approx(6e-3 * (2 * math.pi * 3.3) ** 2)
    for x in (d, v, a):
        assert abs(x[0]) < 1e-12 and abs(x[-1]) < 1e-9
    # the three are consistent: integrating a gives v and d
    vi, di = integrate(t, a)
    assert np.max(np.abs(vi - v)) < 1e-6 and np.max(np.abs(di - d)) < 1e-7
    assert abs(di[-1]) < 1e-7  # the table returns to zero


def test_harmonic_scene_and_free_rocking_tail():
    d = free_scene_dict(duration=12.0)
    d["motion"] = {"type": "harmonic", "amplitude_mm": 6.0, "frequency_hz": 3.3, "duration_s": 5.0}
    scene = scene_from_dict(d)
    assert scene.motion.cycles == round(5.0 * 3.3)
    gm = scene.motion.ground_motion(scene.duration_s)
    assert gm.duration_s < 12.0 and gm.horizontal(11.0) == 0.0  # free rocking after the table stops
    v, disp = gm.velocity_displacement()
    # the analytic table motion ends exactly at rest (test above); the sampled one within
    # the error of linear interpolation at 400 samples per cycle (0.04 % of 6 mm here)
    assert abs(v[-1]) < 1e-6 and abs(disp[-1]) < 1e-5


# --------------------------------------------------------------------- pulses


@pytest.mark.parametrize("shape", ["sine", "cosine", "ricker", "symmetric", "antisymmetric"])
def test_pulses(shape):
    p = Pulse(shape, 3.0, 0.5, cycles=1)
    gm = p.ground_motion()
    assert np.max(np.abs(gm.ah_m_s2)) == pytest.approx(3.0, rel=1e-3)
    v, _ = gm.velocity_displacement()
    if p.kind in ("sine", "cosine"):
        assert abs(v[-1]) < 1e-3  # a whole cycle: the base velocity returns to zero
    if shape == "symmetric":
        assert np.allclose(gm.ah_m_s2, Pulse("sine", 3.0, 0.5).ground_motion().ah_m_s2)


def test_pulse_scene_in_g():
    d = free_scene_dict()
    d["motion"] = {"type": "pulse", "shape": "sine", "amplitude_g": 0.5, "period_s": 0.4}
    assert scene_from_dict(d).motion.amplitude_m_s2 == pytest.approx(0.5 * G)
    d["motion"]["shape"] = "square"
    with pytest.raises(InputError, match=r"motion\.shape"):
        scene_from_dict(d)


# --------------------------------------------------------------------- readers

AT2_DATA = [0.001, -0.002, 0.0035, 0.004, -0.001, 0.0]
AT2_VARIANTS = {
    "peer_new": "NPTS=   6, DT=   .0100 SEC,                          ",
    "no_trailing": "NPTS=  6, DT= .01000 SEC",
    "no_commas": "NPTS= 6 DT= 0.01 SEC",
    "text_after": "NPTS=6, DT=0.01 SEC, some remark here",
    "lowercase": "npts= 6, dt= .01 sec",
    "old_layout": "    6   .0100   NPTS, DT",
    "old_bare": "6 0.01",
}


def _write_at2(
    path, sampling_line, data=AT2_DATA, units_line="ACCELERATION TIME SERIES IN UNITS OF G", crlf=False, extra=()
):
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", "Test event, station, 000", units_line, sampling_line]
    values = list(data) + list(extra)
    for i in range(0, len(values), 5):
        lines.append("".join(f"{v:15.7E}" for v in values[i : i + 5]))
    text = ("\r\n" if crlf else "\n").join(lines) + ("\r\n" if crlf else "\n")
    path.write_bytes(text.encode())
    return path


@pytest.mark.parametrize("variant", sorted(AT2_VARIANTS))
@pytest.mark.parametrize("crlf", [False, True])
def test_at2_header_variants(tmp_path, variant, crlf):
    path = _write_at2(tmp_path / "r.AT2", AT2_VARIANTS[variant], crlf=crlf)
    rec = read_at2(path)
    assert rec.npts == 6 and rec.dt_s == pytest.approx(0.01)
    np.testing.assert_allclose(rec.accel_m_s2, np.array(AT2_DATA) * SG)
    assert rec.units_in_file == "g"
    path = _write_at2(tmp_path / "r.AT2", AT2_VARIANTS[variant], crlf=crlf, extra=[9.9, 9.9])
    with pytest.raises(RecordError, match="NPTS = 6 in the header but the file holds 8 values"):
        read_at2(path)  # values beyond NPTS were once ignored: header and data disagree


@pytest.mark.parametrize(
    ("units_line", "factor", "name"),
    [
        ("ACCELERATION TIME SERIES IN UNITS OF CM/S/S", 0.01, "cm/s2"),
        ("ACCELERATION IN CM/SEC/SEC", 0.01, "cm/s2"),
        ("ACCELERATION (M/S/S)", 1.0, "m/s2"),
        ("ACCELERATION IN GAL", 0.01, "cm/s2"),
    ],
)
def test_at2_units(tmp_path, units_line, factor, name):
    rec = read_at2(_write_at2(tmp_path / "r.at2", AT2_VARIANTS["peer_new"], units_line=units_line))
    assert rec.units_in_file == name
    np.testing.assert_allclose(rec.accel_m_s2, np.array(AT2_DATA) * factor)


@pytest.mark.parametrize(
    ("sampling", "data", "match", "line"),
    [
        ("DT= .01 SEC", AT2_DATA, "no NPTS", 4),
        ("NPTS= 6", AT2_DATA, "no DT", 4),
        ("NPTS= 6, DT= -0.01 SEC", AT2_DATA, "DT must be > 0", 4),
        ("NPTS= 9, DT= 0.01 SEC", AT2_DATA, "NPTS = 9 in the header but the file holds 6", None),
        ("NPTS= x, DT= y", AT2_DATA, "expected 'NPTS=", 4),
        ("NPTS= 6.5, DT= 0.01", AT2_DATA, "integer", 4),
    ],
)
def test_bad_at2_files_name_file_and_line(tmp_path, sampling, data, match, line):
    path = _write_at2(tmp_path / "bad.AT2", sampling, data)
    with pytest.raises(RecordError, match=match) as info:
        read_at2(path)
    assert str(path) in str(info.value)
    if line is not None:
        assert info.value.line == line and f"line {line}" in str(info.value)


def test_bad_at2_value_names_line(tmp_path):
    path = tmp_path / "bad.AT2"
    path.write_text("a\nb\nACCELERATION IN G\nNPTS= 4, DT= 0.01 SEC\n 0.1 0.2\n 0.3 oops\n")
    with pytest.raises(RecordError, match="not a number") as info:
        read_at2(path)
    assert info.value.line == 6


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=2, max_size=40),
    dt=st.sampled_from([0.005, 0.01, 0.02]),
    per_line=st.integers(1, 8),
)
def test_property_at2_round_trip(tmp_path_factory, values, dt, per_line):
    path = tmp_path_factory.mktemp("at2") / "p.AT2"
    lines = ["PEER", "prop", "UNITS OF G", f"NPTS= {len(values)}, DT= {dt} SEC"]
    for i in range(0, len(values), per_line):
        lines.append(" ".join(f"{v:.8E}" for v in values[i : i + per_line]))
    path.write_text("\n".join(lines) + "\n")
    rec = read_at2(path)
    assert rec.npts == len(values) and rec.dt_s == pytest.approx(dt)
    np.testing.assert_allclose(rec.accel_m_s2, np.array(values) * SG, rtol=1e-7, atol=1e-12)


def test_two_column_and_single_column(tmp_path):
    two = tmp_path / "two.csv"
    two.write_text("# test\ntime_s,accel_cm_s2\n0.0,1.0\n0.01,-2.0\n0.02,3.0\n")
    rec = read_two_column(two, "cm/s2")
    np.testing.assert_allclose(rec.accel_m_s2, [0.01, -0.02, 0.03])
    assert rec.dt_s == pytest.approx(0.01)
    ws = tmp_path / "two.txt"
    ws.write_text("0 1\n0.5 2\n1.0 3\n")
    assert read_record(ws, units="g").accel_m_s2[1] == pytest.approx(2 * SG)
    one = tmp_path / "one.txt"
    one.write_text("0.1\n0.2\n-0.3\n")
    rec = read_single_column(one, 0.02, "g")
    assert rec.npts == 3 and rec.duration_s == pytest.approx(0.04)
    bad = tmp_path / "bad.csv"
    bad.write_text("0,1\n0.01,2\n0.02,x\n")
    with pytest.raises(RecordError, match="line 3"):
        read_two_column(bad)
    back = tmp_path / "back.csv"
    back.write_text("0,1\n0.02,2\n0.01,3\n")
    with pytest.raises(RecordError, match="increase"):
        read_two_column(back)
    with pytest.raises(InputError, match="dt_s"):
        read_record(one, "single")


@needs_peer_records
@pytest.mark.parametrize(
    ("name", "npts", "pga_g"),
    [
        ("RSN6_IMPVALL.I_I-ELC180-hor1.AT2", 5372, 0.2807955),
        ("RSN6_IMPVALL.I_I-ELC270-hor2.AT2", 5346, None),
        ("RSN77_SFERN_PUL164-hor1.AT2", 4172, None),
    ],
)
def test_real_peer_records(name, npts, pga_g):
    rec = read_record(RECORDS / name)
    assert rec.npts == npts and rec.dt_s == pytest.approx(0.01) and rec.units_in_file == "g"
    text = (RECORDS / name).read_text().split()
    values = [float(x) for x in text[text.index("SEC,") + 1 :]]
    assert rec.pga_m_s2 == pytest.approx(max(abs(v) for v in values) * SG)
    if pga_g is not None:
        assert rec.pga_m_s2 / SG == pytest.approx(pga_g, rel=1e-7)


# --------------------------------------------------------------------- processing


def test_baseline_correction_zeroes_final_velocity_and_displacement():
    rng = np.random.default_rng(3)
    t = np.arange(0, 20.0, 0.01)
    a = rng.standard_normal(t.size) + 0.05  # with a drift
    corrected = baseline_correct(t, a)
    v, d = integrate(t, corrected)
    assert abs(v[-1]) < 1e-10 and abs(d[-1]) < 1e-10
    # the correction is smooth and small: it leaves the record's content in place
    assert np.corrcoef(a, corrected)[0, 1] > 0.99


def test_bandpass_and_scaling():
    t = np.arange(0, 20, 0.01)
    low = np.sin(2 * math.pi * 0.02 * t)
    mid = np.sin(2 * math.pi * 2.0 * t)
    out = bandpass(low + mid, 0.01, 0.2, 20.0)
    core = slice(500, -500)
    assert np.max(np.abs(out[core] - mid[core])) < 0.05
    scaled, factor = scale_to_pga(mid, 3.0)
    assert np.max(np.abs(scaled)) == pytest.approx(3.0) and factor == pytest.approx(3.0 / np.max(np.abs(mid)))
    with pytest.raises(InputError, match="Nyquist"):
        bandpass(mid, 0.01, 0.1, 60.0)


# --------------------------------------------------------------------- spectra


def test_spectrum_of_a_step_against_closed_form():
    """A constant acceleration a0 from t = 0: max |u| = (a0 / w^2)(1 + exp(-xi pi / sqrt(1 - xi^2)))."""
    a0, xi = 2.0, 0.05
    a = np.full(3000, a0)
    _periods, psa = response_spectrum(a, 0.01, np.array([0.05, 0.3, 1.0, 2.0]), xi)
    expected = a0 * (1 + math.exp(-xi * math.pi / math.sqrt(1 - xi * xi)))
    np.testing.assert_allclose(psa, expected, rtol=1e-3)


def test_spectrum_of_a_sampled_sinusoid_against_steady_state():
    """A long sinusoid of frequency W: PSA(T) = w^2 A / sqrt((w^2 - W^2)^2 + (2 xi w W)^2).

    The amplitude is ramped up smoothly over 15 s, and the phase is that of a cosine: a
    sine acceleration from rest has a mean base velocity A / W, whose build-up would drive
    the long-period oscillators away from their steady state."""
    A, W, xi = 1.0, 2 * math.pi * 1.5, 0.05
    t = np.arange(0, 80.0, 0.005)
    ramp = np.where(t < 15.0, 0.5 * (1 - np.cos(math.pi * t / 15.0)), 1.0)
    a = A * np.cos(W * t) * ramp
    periods = np.array([0.1, 0.3, 0.5, 1.0, 2.5])
    _, psa = response_spectrum(a, 0.005, periods, xi)
    w = 2 * math.pi / periods
    expected = w**2 * A / np.sqrt((w**2 - W**2) ** 2 + (2 * xi * w * W) ** 2)
    np.testing.assert_allclose(psa, expected, rtol=0.005)


@pytest.mark.slow
def test_short_periods_are_substepped():
    """T / dt < 10: the peak between samples is found (against the oscillator's exact response
    on a grid of dt / 100, tests/oscillator.py)."""
    rng = np.random.default_rng(1)
    a = np.convolve(rng.standard_normal(1500), np.ones(3) / 3, "same")
    dt, T, xi = 0.01, 0.04, 0.05
    _, psa = response_spectrum(a, dt, np.array([T]), xi)
    assert psa[0] == pytest.approx(fine_grid_psa(a, dt, T, xi, free_s=0.0), rel=2e-3)


@needs_peer_records
def test_el_centro_spectrum_against_direct_integration():
    """The spectrum of El Centro 1940 (PEER RSN6, 180) at a few periods against an
    independent integration of the oscillator (scipy RK45, tight tolerances)."""
    rec = read_record(RECORDS / "RSN6_IMPVALL.I_I-ELC180-hor1.AT2")
    periods = np.array([0.2, 0.5, 1.0, 2.0])
    _, psa = response_spectrum(rec.accel_m_s2, rec.dt_s, periods, 0.05)
    t = rec.t_s
    for T, value in zip(periods, psa, strict=True):
        w = 2 * math.pi / T

        def rhs(tt, y, w=w):
            return [y[1], -np.interp(tt, t, rec.accel_m_s2) - 0.1 * w * y[1] - w * w * y[0]]

        sol = solve_ivp(rhs, (0, t[-1] + 2 * T), [0, 0], max_step=rec.dt_s / 4, rtol=1e-8, atol=1e-11)
        assert value == pytest.approx(w * w * np.max(np.abs(sol.y[0])), rel=5e-3)
    # plausible for a record of PGA 0.28 g: peak spectral amplification about 2.5-3.5
    assert 2.0 < psa.max() / rec.pga_m_s2 < 4.0


# --------------------------------------------------------------------- EC8


def test_ec8_type2_ground_d_is_the_paper_target():
    s = ElasticSpectrum.ec8(2, "D", ag_s_m_s2=2.8)
    assert (s.S, s.TB_s, s.TC_s, s.TD_s) == (1.8, 0.10, 0.30, 1.2)
    assert s.plateau_m_s2 == pytest.approx(7.0)  # paper Section 3.3
    assert s.psa([0.0])[0] == pytest.approx(2.8)
    T = np.array([0.05, 0.2, 0.6, 2.0])
    ag = 2.8
    np.testing.assert_allclose(
        s.psa(T), [ag * (1 + 0.5 * 1.5), 2.5 * ag, 2.5 * ag * 0.3 / 0.6, 2.5 * ag * 0.3 * 1.2 / 4.0]
    )


@pytest.mark.parametrize("stype", [1, 2])
@pytest.mark.parametrize("ground", list("ABCDE"))
def test_ec8_all_ground_types_continuous(stype, ground):
    s = ElasticSpectrum.ec8(stype, ground, ag_m_s2=2.0)
    for corner in (s.TB_s, s.TC_s, s.TD_s):
        lo, hi = s.psa([corner * (1 - 1e-9), corner * (1 + 1e-9)])
        assert lo == pytest.approx(hi, rel=1e-6)


def test_damping_correction_floor():
    assert damping_correction(0.05) == pytest.approx(1.0)
    assert damping_correction(0.10) == pytest.approx(math.sqrt(10 / 15))
    assert damping_correction(0.5) == 0.55  # the 0.55 floor
    with pytest.raises(InputError):
        ElasticSpectrum(1.0, 1.0, 0.3, 0.2, 2.0)  # TB > TC


# --------------------------------------------------------------------- synthetic


@pytest.fixture(scope="module")
def paper_records():
    import os
    import shutil
    import tempfile

    old = os.environ.get("ROCKYADE_CACHE")
    cache = tempfile.mkdtemp(prefix="rockyade-suite-")
    os.environ["ROCKYADE_CACHE"] = cache
    try:
        spec = paper_suite()
        return spec, [suite_record(spec, i) for i in range(1, 31)]
    finally:
        shutil.rmtree(cache, ignore_errors=True)  # the records are in memory: nothing left in the temporary folder
        if old is None:
            del os.environ["ROCKYADE_CACHE"]
        else:
            os.environ["ROCKYADE_CACHE"] = old


@pytest.mark.slow
def test_paper_suite_is_compatible(paper_records):
    spec, records = paper_records
    report = compatibility_report(records, spec.target, (0.05, 2.0))
    assert report["ratio_min"] >= 0.9 and report["ratio_max"] <= 1.2
    assert report["mean_pga_m_s2"] >= 2.8 and report["mean_pga_m_s2"] <= 1.1 * 2.8
    for row in report["records"]:
        assert abs(row["final_velocity_m_s"]) < 1e-3 and abs(row["final_displacement_m"]) < 1e-3
        assert row["duration_s"] == pytest.approx(20.0)
    assert report["compatible"]


def test_records_reproducible_alone_and_bit_identical(paper_records):
    spec, records = paper_records
    again = generate_record(spec, 21)
    assert np.array_equal(again.accel_m_s2, records[20].accel_m_s2)
    other_suite = SuiteSpec(spec.target, count=40, seed=spec.seed, name="paper")
    assert np.array_equal(generate_record(other_suite, 18).accel_m_s2, records[17].accel_m_s2)
    assert not np.array_equal(records[0].accel_m_s2, records[1].accel_m_s2)
    different_seed = SuiteSpec(spec.target, seed=spec.seed + 1)
    assert not np.array_equal(generate_record(different_seed, 21).accel_m_s2, records[20].accel_m_s2)


def test_records_cached_by_other_generator_code_are_never_reused(monkeypatch):
    """The cache key holds the generator's code: version 2's exact spectra changed every
    record, and a cache written by version 1 (same settings) gave 21 % different peaks."""
    from rockyade.motion import synthetic

    spec = paper_suite()
    assert spec.as_dict()["generator_code"] == synthetic.generator_fingerprint()
    key = spec.key
    monkeypatch.setattr(synthetic, "generator_fingerprint", lambda: "0" * 16)
    assert spec.key != key
    monkeypatch.setattr(synthetic, "GENERATOR_VERSION", synthetic.GENERATOR_VERSION + 1)
    assert len({key, spec.key}) == 2


def test_the_shipped_example_record_is_the_generators_own(paper_records):
    """examples/records/ec8_type2_D_record21.AT2 was written by this generator: the same samples
    (to the file's printed digits) as record 21 of the paper suite generated now."""
    _, records = paper_records
    shipped = read_record(EXAMPLES / "records/ec8_type2_D_record21.AT2")
    n = min(shipped.accel_m_s2.size, records[20].accel_m_s2.size)
    assert np.allclose(shipped.accel_m_s2[:n], records[20].accel_m_s2[:n], rtol=1e-4, atol=1e-6 * 9.80665)


def test_synthetic_scene_uses_the_cached_record(paper_records):
    _spec, records = paper_records
    d = free_scene_dict(duration=25.0)
    d["motion"] = {"type": "synthetic", "record": 21, "load_factor": 0.6}
    gm = scene_from_dict(d).motion.ground_motion(25.0)
    np.testing.assert_allclose(gm.ah_m_s2, 0.6 * records[20].accel_m_s2)
    d["motion"]["record"] = 31
    with pytest.raises(InputError, match=r"motion.record"):
        scene_from_dict(d)


def test_envelope_and_suite_validation():
    env = Envelope("trapezoidal", 1.0, 2.0, 1.0)
    t = np.array([0.0, 0.5, 2.0, 3.5, 4.0])
    np.testing.assert_allclose(env(t), [0.0, 0.5, 1.0, 0.5, 0.0])
    with pytest.raises(InputError, match="envelope"):
        Envelope("boxcar")
    with pytest.raises(InputError, match="seed"):
        SuiteSpec(paper_suite().target, seed=-1)


def test_record_scene_processing(tmp_path):
    rec = tmp_path / "r.csv"
    t = np.arange(0, 5, 0.01)
    rec.write_text("t,a\n" + "\n".join(f"{x},{math.sin(4 * x) + 0.2}" for x in t))
    (tmp_path / "scene.json").write_text(
        json.dumps(
            {
                **free_scene_dict(duration=6.0),
                "motion": {
                    "type": "record",
                    "file": "r.csv",
                    "units": "m/s2",
                    "baseline": True,
                    "target_pga_m_s2": 2.0,
                    "load_factor": 0.5,
                },
            }
        )
    )
    from rockyade.scene import load_scene

    scene = load_scene(tmp_path / "scene.json")
    gm = scene.motion.ground_motion(6.0)
    assert gm.pga_m_s2 == pytest.approx(1.0)
    v, d = gm.velocity_displacement()
    assert abs(v[-1]) < 1e-9 and abs(d[-1]) < 1e-9
    h1 = scene.scene_hash
    assert load_scene(tmp_path / "scene.json").scene_hash == h1
    rec.write_text(rec.read_text() + "\n5.0,0.0\n")  # the file changed (not its name): new hash
    assert load_scene(tmp_path / "scene.json").scene_hash != h1
