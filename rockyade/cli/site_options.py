"""The site's options, shared by ``rockyade assess`` and ``rockyade motion select``: the site's
elastic spectrum (NTC 2018 3.2.3.2.1 by default, or EN 1998-1 3.2.2.2) and the building's period
T1. Declared once here so that both commands take the same options with the same checks
(standard library only at import: the parser stays fast)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from rockyade.errors import InputError

if TYPE_CHECKING:  # imported when a command runs
    from rockyade.assess.site import AnySite


def add_site_options(p: argparse.ArgumentParser) -> None:
    """``--ag`` (required), ``--spectrum``, the NTC 2018 site (``--f0``, ``--tc-star``, ``--soil``,
    ``--topography``, ``--topography-height-ratio``) and the EC8 site (``--spectrum-type``,
    ``--ground``, ``--importance``).

    Parameters
    ----------
    p
        The command's parser.
    """
    p.add_argument(
        "--ag",
        required=True,
        help="the site's peak ground acceleration on type A ground, with its unit: 0.25g or 2.45m/s2 "
        "(g: standard gravity, 9.80665 m/s^2, as for records in g and in a0* = alpha0 g / (e* FC)); "
        "NTC 2018: ag of Allegato A for the limit "
        "state's return period; EC8: agR",
    )
    p.add_argument(
        "--spectrum",
        choices=("ntc2018", "ec8"),
        help="whose elastic spectrum: ntc2018 (the default with --code ntc2018, NTC 2018 3.2.3.2.1) or ec8 "
        "(EN 1998-1 3.2.2.2; also chosen by giving --spectrum-type and --ground)",
    )
    ntc = p.add_argument_group("the NTC 2018 site (3.2.3.2.1; ag, F0, TC* from Allegato A)")
    ntc.add_argument("--f0", type=float, help="F0, the spectrum's maximum amplification")
    ntc.add_argument("--tc-star", type=float, metavar="S", help="TC*, s")
    ntc.add_argument("--soil", help="subsoil category A, B, C, D or E (Tab. 3.2.II; SS and CC of Tab. 3.2.IV)")
    ntc.add_argument(
        "--topography", help="topographic category T1, T2, T3 or T4 (Tab. 3.2.III; ST of Tab. 3.2.V; default T1)"
    )
    ntc.add_argument(
        "--topography-height-ratio",
        type=float,
        metavar="R",
        help="the site's height above the base of the relief over the relief's height, in [0, 1]: ST falls "
        "linearly from Tab. 3.2.V's value at the top (1, the default) to 1 at the base",
    )
    ec8 = p.add_argument_group("the EC8 site (EN 1998-1 3.2.2.2)")
    ec8.add_argument("--spectrum-type", type=int, help="EC8 elastic spectrum type: 1 or 2")
    ec8.add_argument("--ground", help="EC8 ground type: A, B, C, D or E")
    ec8.add_argument("--importance", type=float, help="importance factor gamma_I, in [0.5, 2] (default 1)")


def add_period_option(group: argparse._ActionsContainer, use: str) -> None:
    """``--t1``: the building's fundamental period, s, in (0, 4] (checked where it is used).

    Parameters
    ----------
    group
        The parser or argument group that takes it.
    use
        What the command does with it (the end of the help).
    """
    group.add_argument("--t1", type=float, metavar="S", help=f"fundamental period T1 of the building, s: {use}")


def site_from(args: argparse.Namespace) -> AnySite:
    """The site: NTC 2018's spectrum unless EC8's is asked for (``--spectrum ec8``, or its own
    options ``--spectrum-type`` and ``--ground``)."""
    from rockyade.assess import Site, parse_acceleration
    from rockyade.assess.site import NtcSite
    from rockyade.constants import CODE_GRAVITY as G

    ec8_given = [o for o in ("spectrum_type", "ground", "importance") if getattr(args, o) is not None]
    ntc_given = [
        o for o in ("f0", "tc_star", "soil", "topography", "topography_height_ratio") if getattr(args, o) is not None
    ]
    if args.spectrum is None and ec8_given and ntc_given:
        raise InputError(
            "--" + ntc_given[0].replace("_", "-"),
            f"mixes the NTC 2018 site (--{ntc_given[0].replace('_', '-')}) with an EC8 option "
            f"(--{ec8_given[0].replace('_', '-')}): give one site, or --spectrum to say which",
        )
    spectrum = args.spectrum or ("ec8" if ec8_given else "ntc2018")
    ag = parse_acceleration(args.ag, "--ag")
    if spectrum == "ec8":
        if ntc_given:
            raise InputError(
                "--" + ntc_given[0].replace("_", "-"), "is an NTC 2018 site parameter, not with the EC8 spectrum"
            )
        for option in ("spectrum_type", "ground"):
            if getattr(args, option) is None:
                raise InputError("--" + option.replace("_", "-"), "is required with the EC8 spectrum")
        return Site(args.spectrum_type, args.ground, ag, 1.0 if args.importance is None else args.importance)
    if ec8_given:
        raise InputError(
            "--" + ec8_given[0].replace("_", "-"),
            "is an EC8 option, not with the NTC 2018 spectrum (give --spectrum ec8 for EC8's)",
        )
    for option in ("f0", "tc_star", "soil"):
        if getattr(args, option) is None:
            raise InputError(
                "--" + option.replace("_", "-"),
                "is required with the NTC 2018 spectrum (the default with --code ntc2018): the site's ag, F0 and TC* "
                "(NTC 2018 Allegato A) and its soil category; or give --spectrum ec8 with --spectrum-type and --ground",
            )
    return NtcSite(
        ag / G,
        args.f0,
        args.tc_star,
        args.soil,
        args.topography or "T1",
        1.0 if args.topography_height_ratio is None else args.topography_height_ratio,
    )


__all__ = ["add_period_option", "add_site_options", "site_from"]
