"""Numbers in messages carry the digits that make them true (issue "What users hit" 8): a
factor or a lower bound printed is rounded up, an upper bound or a limit rounded down, so
that acting on the printed number works."""

from __future__ import annotations

import re

import pytest

from rockyade.cli import main
from rockyade.errors import InputError, at_least, at_most
from rockyade.scene import scene_from_dict

from .conftest import free_scene_dict


@pytest.mark.parametrize(
    ("value", "up", "down"),
    [
        (1.0306, "1.04", "1.03"),
        (1.306, "1.31", "1.3"),
        (1.3, "1.3", "1.3"),
        (2.0, "2", "2"),
        (-1.234, "-1.23", "-1.24"),
    ],
)
def test_directed_rounding(value, up, down):
    assert (at_least(value), at_most(value)) == (up, down)
    assert float(at_least(value)) >= value >= float(at_most(value))


@pytest.mark.parametrize("ring_depth_m", ["0.065", "0.075"])
def test_a_thin_arch_refused_with_a_factor_that_is_enough(tmp_path, capsys, ring_depth_m):
    """A thin arch's joints settle more than 1e-4 of the voussoir height with the default
    jkn: the refusal names a jkn that builds (it said "at least 1 times" for 1.05, and "1.3"
    for 1.306: both too little)."""
    out = tmp_path / "arch.toml"
    args = ["build", "arch", "--ring-depth-m", ring_depth_m, "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    number = r"([0-9.e+-]+)"
    m = re.search(rf"sink {number} m .*\({number} m\).*to at least {number} Pa/m \({number} times\)", err)
    assert m, err
    sink, limit, jkn, factor = (float(g) for g in m.groups())
    assert sink > limit and factor >= sink / limit and factor > 1.0
    assert main([*args, "--jkn-pa-per-m", f"{jkn:g}"]) == 0 and out.is_file()


def test_a_range_printed_is_a_range_that_is_accepted():
    """The inertia range of a block is printed with its lower end rounded up and its upper
    end rounded down: both printed ends are accepted."""
    with pytest.raises(InputError) as err:
        scene_from_dict(free_scene_dict(inertia_kgm2=1e6, p_rad_s=None))
    lo, hi = (float(x) for x in re.search(r"must be in \[([^,]+), ([^\]]+)\]", err.value.message).groups())
    for inertia in (lo, hi):
        scene_from_dict(free_scene_dict(inertia_kgm2=inertia, p_rad_s=None))
