"""``rockyade verify``: the DEMs on assemblies against closed forms, each other and this
version's baseline, as a report (CSV, figures, index.md).

Checks (each a row per solver: measured value, what it is compared with, the difference,
the tolerance, pass or fail):

* ``frame``: a rocking frame (two equal free-standing columns, a free cap beam) rocks like
  one column with p_hat = p sqrt((1 + 2 gamma) / (1 + 3 gamma)), gamma = beam mass /
  columns' mass (Makris & Vassiliou 2013): under a one-sine pulse the first impact within
  2 % and the first peak within 3 % of Housner's column with p_hat;
* ``drums``: a column of 8 equal drums under a slow ramp of base acceleration uplifts as
  one body at g b / (H / 2): the ramp level at which |theta| reaches 1e-3 rad within 2 % of
  a monolithic Housner column's, the top and bottom drums turning together (within 5 %);
* ``pad``: a 0.6 x 0.3 m block above a 0.1 m pad on a lower block, under a pulse: no
  overlap beyond 1 mm (a vertex passing through a block it did not touch at rest);
* ``wall``: a dry running-bond wall of about 1,000 blocks stands under gravity: no block
  moves more than 0.2 mm or turns more than 1e-3 rad (reference DEM);
* ``agreement``: reference DEM against YADE on a slender 5-course wall (0.4 m long, 1 m
  high: it rocks and its top course slides) and on the frame, under a one-sine pulse: peak
  rotation within 5 % and peak displacement within 10 %, or the sum of the two DEMs' own
  changes when their time step is halved if larger (rocking amplifies small differences:
  two DEMs cannot agree better than each converges). The 10 % on displacements is YADE's
  modelling difference, measured and documented (docs/yade.md): its contact spheres round
  the corners, and a flush joint's end that slides apart carries K/2 there (8.8 % measured
  here, against dt/2 changes of 2.7 % and 0.2 %);
* ``baseline``: the paper's single blocks and bi-block (free rocking, harmonic, pulse):
  first five peaks and effective restitution against the values this version's first
  release computed (``data/baseline_0_1.csv``): peaks within 1 %, mu_eff within 0.2 %;
* ``kinematic``: limit analysis and the code's kinematic quantities against closed forms
  (lambda = b/h, e* = 1 and d0* = b of a block, e* of a wall of n courses, the minimum
  thickness of a semicircular arch approaching Milankovitch's t/R = 0.1075);
* ``code``: the NTC 2018 checks of a free-standing wall against the hand calculation of
  docs/limit.md (the wall of docs/howto/is-this-wall-safe.md);
* ``fragility_fit``: the lognormal fit of stripes and its bootstrap band recover the curve
  that synthetic outcomes were drawn from;
* ``loaded_block``: a block 0.4 x 2 m (1000 kg) with a vertical top load N = 8 kN at
  0.05 m from its axis, pushed towards +x (the load at d = 0.15 m from the pivot):
  lambda = (W b + N d) / (W h_c) = 0.32232 from the limit analysis and from Housner's uplift
  multiplier with the load's moment (modified Eq 1), within 1e-6;
* ``loaded_classical``: a 0.45 x 3.2 m tuff wall with 12 kN/m at 0.125 m from its axis, with its
  mass: each direction's alpha, mu and uplift multiplier against the hand calculation (the loaded
  body's centroid and inertia, the angular momentum about the new pivot), and the limit analysis'
  multiplier each way against (W b + N d) / (W h_c + N h_N);
* ``code_friction``: the 8-course wall restrained on the far face of its top course: with the
  restraint's corner contact frictionless both friction rules give the closed form 1.3019; at 35
  degrees the coulomb multiplier (1.6205) lies below the associated one (3.5891) and the code's
  quantities take the lower;
* ``crushing``: the masonry's compressive strength at the hinges: a block's multiplier against
  (B - a) / H, a = W / (0.85 fm t), and as fm tends to infinity the rigid one (a block, 6 courses);
* ``loaded_pushover``: the reference DEM's pushover onset of that block (levels held 0.4 s
  every 1 % of the closed form from 0.98 of it) within 2 % of the closed form, and the last
  level at which it stood at most the closed form;
* ``floor_spectrum``: a mechanism at height by Circolare 2019 C8.7.1 on the floor spectrum of
  C7.2.3 (the tuff wall with its roof at 7 m of a 10 m building, T1 = 0.3 s): the floor's peak,
  the linear demand, a(d_SLV), T_SLV, the nonlinear demand and its C8.7.1.12 floor, and the code's
  capacity against the hand calculation of docs/howto/is-this-wall-safe.md (2e-4);
* ``limit_pushover``: the limit analysis's multiplier against the reference DEM's pushover
  onset (held levels every 1 % of it from 0.98 of it) within 2 %, for a block, a 20-voussoir
  arch, a wall restrained at its top (three hinges) and a running-bond panel that slides on a
  bed joint (a slender panel goes below the limit analysis: docs/assemblies.md);
* ``siconos``: Siconos (nonsmooth contact dynamics) on the DEMs' scenes: free-rocking
  restitution against Housner's Eq 4 (0.5 %), the block's pushover onset against the limit
  analysis (2 %), the rocking frame against Housner's column with p_hat (2 % and 3 %) and a
  tapered 4-block stack at rest (1e-6 rad, 1e-6 m) (:func:`check_siconos`; the arch, the
  restrained wall, the panel and the drums wait on corner-to-corner contacts,
  :data:`rockyade.studies.verify_siconos.SICONOS_PUSHOVERS`).

The checks live by domain: :mod:`rockyade.studies.verify_closed` (no solver),
:mod:`rockyade.studies.verify_dem`, :mod:`rockyade.studies.verify_pushover`,
:mod:`rockyade.studies.verify_siconos`, :mod:`rockyade.studies.verify_floor`; each row holds its tolerance once
(:mod:`rockyade.studies.verify_rows`).

``kinematic``, ``code``, ``fragility_fit``, ``loaded_block``, ``loaded_classical``, ``code_friction``
and ``crushing`` run no solver (the
limit-analysis programme, Housner's model and the fit only).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pandas as pd

from rockyade.io.atomic import atomic_open, write_text
from rockyade.result import Result
from rockyade.studies.verification_checks import CHECKS
from rockyade.studies.verify_assess import check_code_friction, check_crushing, check_loaded_classical
from rockyade.studies.verify_closed import (
    check_code,
    check_fragility_fit,
    check_kinematic,
    check_loaded_block,
    check_loaded_mass,
)
from rockyade.studies.verify_dem import check_agreement, check_baseline, check_drums, check_frame, check_pad, check_wall
from rockyade.studies.verify_floor import check_floor_spectrum
from rockyade.studies.verify_pushover import check_limit_pushover, check_loaded_pushover
from rockyade.studies.verify_rows import Row
from rockyade.studies.verify_siconos import check_siconos

CHECK_FUNCTIONS: dict[str, Callable[[list[str]], tuple[list[Row], dict[str, Result]]]] = {
    "frame": check_frame,
    "drums": check_drums,
    "pad": check_pad,
    "wall": check_wall,
    "agreement": check_agreement,
    "baseline": check_baseline,
    "kinematic": check_kinematic,
    "code": check_code,
    "fragility_fit": check_fragility_fit,
    "loaded_block": check_loaded_block,
    "loaded_mass": check_loaded_mass,
    "loaded_classical": check_loaded_classical,
    "code_friction": check_code_friction,
    "crushing": check_crushing,
    "loaded_pushover": check_loaded_pushover,
    "limit_pushover": check_limit_pushover,
    "floor_spectrum": check_floor_spectrum,
    "siconos": check_siconos,
}


def _figure(check: str, results: dict[str, Result], path: Path) -> None:
    from rockyade.figures.verification_histories import plot_check

    plot_check(check, results, path)


def verify(
    out: str | Path,
    checks: list[str] | None = None,
    solvers: list[str] | None = None,
    progress: Callable[[str], None] | None = None,
) -> pd.DataFrame:
    """Run the checks, write ``verify.csv``, a figure per check and ``index.md``; return the rows."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    solvers = solvers or ["reference", "yade"]
    rows: list[Row] = []
    figures: dict[str, str] = {}
    for check in checks or list(CHECKS):
        if progress:
            progress(check)
        found, results = CHECK_FUNCTIONS[check](solvers)
        rows += found
        if results:
            name = f"verify_{check}.png"
            _figure(check, results, out / name)
            figures[check] = name
    table = pd.DataFrame([r.as_dict() for r in rows])
    with atomic_open(out / "verify.csv") as fh:
        table.to_csv(fh, index=False, float_format="%.8g", lineterminator="\n")
    write_text(out / "index.md", _index(table, figures))
    return table


def _index(table: pd.DataFrame, figures: dict[str, str]) -> str:
    failed = table[~table["passed"]] if len(table) else table
    lines = [
        "# rockyade verification report",
        "",
        f"{len(table)} quantities checked, {len(failed)} failed. Each check is described in "
        "`rockyade.studies.verification` and docs/assemblies.md; `verify.csv` has every row.",
        "",
    ]
    if len(failed):
        lines += [
            "## Failed",
            "",
            "| check | solver | quantity | value | expected | tolerance |",
            "|---|---|---|---|---|---|",
        ]
        for _, r in failed.iterrows():
            lines.append(
                f"| {r.check} | {r.solver} | {r.quantity} | {r.value:.6g} | {r.expected:.6g} | {r.tolerance} |"
            )
        lines.append("")
    for check in dict.fromkeys(table["check"]) if len(table) else []:
        part = table[table["check"] == check]
        lines += [
            f"## {check}",
            "",
            "| solver | quantity | value | expected | from | tolerance | pass |",
            "|---|---|---|---|---|---|---|",
        ]
        for _, r in part.iterrows():
            mark = "yes" if r.passed else "**NO**"
            cells = [r.solver, r.quantity, f"{r.value:.6g}", f"{r.expected:.6g}", r.expected_from, r.tolerance, mark]
            lines.append("| " + " | ".join(cells) + " |")
        if check in figures:
            lines += ["", f"![{check}]({figures[check]})"]
        lines.append("")
    return "\n".join(lines)
