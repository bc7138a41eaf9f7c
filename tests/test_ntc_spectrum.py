"""The NTC 2018 elastic spectrum (3.2.3.2.1) against spectra computed by hand for two sites,
and the NTC site of ``rockyade assess``."""

from __future__ import annotations

import pytest

from rockyade.assess.site import NtcSite
from rockyade.errors import InputError
from rockyade.motion.ntc2018 import ntc_spectrum, soil_factors, topography_factor


def test_site_one_by_hand():
    """ag = 0.25 g, F0 = 2.4, TC* = 0.3 s, soil B, topography T2 at the top (g = 9.81):

    SS = 1.40 - 0.40 x 2.4 x 0.25 = 1.16 (within [1.00, 1.20]); CC = 1.10 x 0.3^-0.20
    = 1.10 x exp(0.2 ln(1/0.3)) = 1.10 x 1.272260 = 1.399486; ST = 1.2; S = 1.16 x 1.2 = 1.392;
    TC = 1.399486 x 0.3 = 0.419846 s, TB = TC / 3 = 0.139949 s, TD = 4 x 0.25 + 1.6 = 2.6 s;
    ag = 2.4525 m/s^2, ag S = 3.413880, plateau ag S F0 = 8.193312 m/s^2;
    Se(0.07) = 3.413880 + (8.193312 - 3.413880) x 0.07 / 0.139949 = 5.804474;
    Se(1.0) = 8.193312 x 0.419846 / 1.0 = 3.439928; Se(3.0) = 8.193312 x 0.419846 x 2.6 / 9 = 0.993757.
    """
    sp = ntc_spectrum(0.25, 2.4, 0.3, "B", "T2", g=9.81)
    assert pytest.approx(1.392, rel=1e-12) == sp.S
    assert sp.TC_s == pytest.approx(0.419846, rel=1e-6)
    assert sp.TB_s == pytest.approx(0.139949, rel=1e-5)
    assert sp.TD_s == pytest.approx(2.6, rel=1e-12)
    assert sp.plateau_m_s2 == pytest.approx(8.193312, rel=1e-9)
    se = sp.psa([0.0, 0.07, 0.2, 1.0, 3.0])
    assert se == pytest.approx([3.413880, 5.804474, 8.193312, 3.439928, 0.993757], rel=2e-6)


def test_site_two_by_hand():
    """ag = 0.15 g, F0 = 2.5, TC* = 0.5 s, soil D, topography T1 (g = 9.81):

    SS = 2.40 - 1.50 x 2.5 x 0.15 = 1.8375, above the bound: 1.80; CC = 1.25 x 0.5^-0.5 = 1.767767;
    ST = 1; TC = 0.883883 s, TB = 0.294628 s, TD = 4 x 0.15 + 1.6 = 2.2 s; ag = 1.4715 m/s^2,
    ag S = 2.6487, plateau = 6.62175 m/s^2; Se(0.5) = 6.62175 (plateau);
    Se(1.5) = 6.62175 x 0.883883 / 1.5 = 3.901903; Se(4.0) = 6.62175 x 0.883883 x 2.2 / 16 = 0.804768.
    """
    sp = ntc_spectrum(0.15, 2.5, 0.5, "D", "T1", g=9.81)
    assert pytest.approx(1.80, rel=1e-12) == sp.S
    assert sp.TC_s == pytest.approx(0.883883, rel=1e-6)
    assert sp.TD_s == pytest.approx(2.2, rel=1e-12)
    se = sp.psa([0.0, 0.5, 1.5, 4.0])
    assert se == pytest.approx([2.6487, 6.62175, 3.901903, 0.804768], rel=2e-6)


@pytest.mark.parametrize(
    ("soil", "ag", "F0", "ss"),
    [
        ("A", 0.3, 2.5, 1.0),
        ("B", 0.05, 2.4, 1.20),  # 1.40 - 0.048 = 1.352: upper bound 1.20
        ("C", 0.4, 2.6, 1.076),  # 1.70 - 0.624
        ("D", 0.5, 2.6, 0.90),  # 2.40 - 1.95 = 0.45: lower bound 0.90
        ("E", 0.5, 2.5, 1.00),  # 2.00 - 1.375 = 0.625: lower bound 1.00
    ],
)
def test_ss_and_its_bounds(soil, ag, F0, ss):
    assert soil_factors(soil, ag, F0, 0.3)[0] == pytest.approx(ss, rel=1e-12)


def test_topography_falls_to_one_at_the_base():
    assert topography_factor("T4") == pytest.approx(1.4)
    assert topography_factor("T4", 0.5) == pytest.approx(1.2)
    assert topography_factor("T3", 0.0) == 1.0
    assert topography_factor("t1", 1.0) == 1.0


@pytest.mark.parametrize(
    ("args", "field"),
    [
        ((0.25, 2.4, 0.3, "F"), "--soil"),
        ((0.25, 2.4, 0.3, "B", "T5"), "--topography"),
        ((0.25, 9.0, 0.3, "B"), "--f0"),
        ((0.25, 2.4, 0.0, "B"), "--tc-star"),
        ((0.0, 2.4, 0.3, "B"), "--ag"),
        ((0.25, 2.4, 0.3, "B", "T2", 1.5), "--topography-height-ratio"),
    ],
)
def test_a_bad_ntc_site_names_the_option(args, field):
    with pytest.raises(InputError) as info:
        NtcSite(*args)
    assert info.value.field == field


def test_the_ntc_site_gives_the_checks_ag_and_s():
    site = NtcSite(0.25, 2.4, 0.3, "b", "t2")
    assert site.soil == "B" and site.topography == "T2"
    # ag in g is turned into m/s^2 with standard gravity, as a record in g and a0* (docs/conventions.md)
    assert site.ag_m_s2 == pytest.approx(0.25 * 9.80665, rel=1e-12)
    assert ntc_spectrum(0.25, 2.4, 0.3, "B", "T2").plateau_m_s2 == pytest.approx(8.193312 * 9.80665 / 9.81, rel=1e-9)
    assert pytest.approx(1.392) == site.S
    data = site.to_dict()
    assert data["spectrum_code"] == "ntc2018" and data["SS"] == pytest.approx(1.16)
    assert data["spectrum"]["F0"] == 2.4
    assert "NTC 2018" in site.describe() and "ST = 1.2" in site.describe()
