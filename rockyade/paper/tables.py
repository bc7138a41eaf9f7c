"""Reproduction of the paper's Tables 1-6: printed value, ours, difference, consistency flag.

* Tables 1-2: the printed inertia I_0 against that of the printed block (uniform density,
  inertia about a base corner), and the density implied by the printed mass.
* Tables 3-4, T columns: alpha (Eq 2), p (Eq 3), mu (Eq 4) from the geometry of Tables 1-2
  (general polygon forms for the chamfered specimen 4), and the printed % error column
  against (E - T) / T of the printed values.
* Tables 5-6: K (Eq 10, paper units), xi_min (Eqs 12, 13, 15), f_min (Eq 14) and 2 b_eq
  (Eq 11) from the printed classical parameters of Tables 3-4 (T and E columns) and the
  geometry of Tables 1-2, so that each table is checked against its own inputs.

Flag: a value is *consistent* when ours rounds to the printed digits or differs by at most
``CONSISTENCY_TOL_PCT`` (the printed inputs are themselves rounded); otherwise the paper's
number does not follow from its own equations and is flagged.
"""

from __future__ import annotations

import math

import pandas as pd

from rockyade import paper
from rockyade.blocks.classical import classical_parameters
from rockyade.calibration.equations import (
    equivalent_half_base_eq11,
    f_min_eq14,
    generalized_damping_factor_eq12,
    stiffness_damping_eq13,
    stiffness_eq8,
    stiffness_eq10,
    xi_min_eq15,
)
from rockyade.constants import G

CONSISTENCY_TOL_PCT = 1.0

COLUMNS = [
    "table",
    "row",
    "quantity",
    "column",
    "unit",
    "equation",
    "paper",
    "ours",
    "diff",
    "diff_pct",
    "consistent",
    "note",
]


def _row(
    table: int,
    row: str,
    quantity: str,
    col: str,
    unit: str,
    equation: str,
    printed: float,
    ours: float,
    decimals: int,
    note: str = "",
) -> dict[str, object]:
    diff = ours - printed
    pct = 100.0 * diff / printed if printed else math.nan
    rounds = abs(diff) <= 0.5 * 10.0 ** (-decimals) * (1 + 1e-9)
    consistent = bool(rounds or (math.isfinite(pct) and abs(pct) <= CONSISTENCY_TOL_PCT))
    return {
        "table": table,
        "row": row,
        "quantity": quantity,
        "column": col,
        "unit": unit,
        "equation": equation,
        "paper": printed,
        "ours": ours,
        "diff": diff,
        "diff_pct": pct,
        "consistent": consistent,
        "note": note,
    }


def _geometry_rows() -> list[dict[str, object]]:
    rows = []
    for key in paper.ALL_SPECIMENS:
        spec = paper.specimen(key)
        number = 1 if key in paper.SINGLE_SPECIMENS else 2
        block = spec.block()
        cp = classical_parameters(block)
        dec = paper.printed_decimals(number, key, "inertia_I0_kgm2")
        shape = "chamfered polygon" if spec.chamfer_m else "rectangle"
        rows.append(
            _row(
                number,
                spec.label,
                "I_0",
                "-",
                "kg m^2",
                "I_O of the polygon about its pivot (uniform density)"
                if spec.chamfer_m
                else "M (b^2+h^2)/3 + M R^2 (uniform density)",
                spec.inertia_I0_printed_kgm2,
                cp.I_O_kgm2,
                dec,
                f"{shape}, printed mass; implied density {block.density_kg_m3:.0f} kg/m^3",
            )
        )
    return rows


def _classical_rows() -> list[dict[str, object]]:
    rows = []
    for key in paper.ALL_SPECIMENS:
        spec = paper.specimen(key)
        number = 3 if key in paper.SINGLE_SPECIMENS else 4
        cp = classical_parameters(spec.block())
        note = "general polygon forms (Section 3.1 chamfer)" if spec.chamfer_m else ""
        for quantity, unit, eq, ours in (
            ("alpha", "rad", "Eq 2", cp.alpha_rad),
            ("mu", "-", "Eq 4", cp.mu),
            ("p", "1/s", "Eq 3", cp.p_rad_s),
        ):
            col = {"alpha": "alpha_T_rad", "mu": "mu_T", "p": "p_T_rad_s"}[quantity]
            rows.append(
                _row(
                    number,
                    spec.label,
                    quantity,
                    "T",
                    unit,
                    f"{eq}, polygon form" if spec.chamfer_m else eq,
                    spec.theoretical[
                        f"{quantity}_rad" if quantity == "alpha" else ("p_rad_s" if quantity == "p" else "mu")
                    ],
                    ours,
                    paper.printed_decimals(number, key, col),
                    note,
                )
            )
        for quantity in ("alpha", "mu", "p"):
            key_t = {"alpha": "alpha_rad", "mu": "mu", "p": "p_rad_s"}[quantity]
            t, e = spec.theoretical[key_t], spec.experimental[key_t]
            printed_pct = float(paper.table(number).loc[key, f"{quantity}_err_pct"])
            rows.append(
                _row(
                    number,
                    spec.label,
                    f"{quantity} error",
                    "%",
                    "%",
                    "(E - T) / T of printed values",
                    printed_pct,
                    100.0 * (e - t) / t,
                    paper.printed_decimals(number, key, f"{quantity}_err_pct"),
                )
            )
    return rows


def dem_parameters_from_printed(key: str, which: str) -> dict[str, float]:
    """Eqs 10-15 evaluated on the printed classical parameters of one specimen.

    Parameters
    ----------
    key
        Specimen id.
    which
        "theoretical" or "experimental" (Tables 3-4 columns T or E).

    Returns
    -------
    dict
        ``K_paper`` (Eq 10, paper units), ``gamma`` (Eq 12), ``b_s`` (Eq 13), ``xi_min``
        (Eq 15), ``f_min_hz`` (Eq 14), ``base_eq_2b_m`` (2 x Eq 11).
    """
    spec = paper.specimen(key)
    block = spec.block()
    geo = classical_parameters(block)
    params = spec.parameters(which)
    k1 = stiffness_eq8(block.mass_kg, params["p_rad_s"])
    if spec.chamfer_m:
        k2 = stiffness_eq8(block.mass_kg, geo.p_rad_s)
    else:
        from rockyade.calibration.equations import stiffness_eq9

        k2 = stiffness_eq9(block.mass_kg, geo.R_m, G)
    k = stiffness_eq10(k1, k2)
    gamma = generalized_damping_factor_eq12(k, geo.R_m)
    b = stiffness_damping_eq13(gamma, params["mu"])
    f_min = f_min_eq14(params["p_rad_s"])
    return {
        "K_paper": k,
        "gamma": gamma,
        "b_s": b,
        "xi_min": xi_min_eq15(b, f_min),
        "f_min_hz": f_min,
        "base_eq_2b_m": 2.0 * equivalent_half_base_eq11(geo.centroid_height_m, params["alpha_rad"]),
    }


def _dem_rows() -> list[dict[str, object]]:
    rows = []
    for key in paper.SINGLE_SPECIMENS:
        spec = paper.specimen(key)
        for col, which in (("T", "theoretical"), ("E", "experimental")):
            ours = dem_parameters_from_printed(key, which)
            xi_note = "paper's xi was fitted to the tests (Section 6.1); Eq 13 is the regression through them"
            items = (
                ("K", "N/m (paper)", "Eq 10", f"K_{col}_paper_N_per_m", ours["K_paper"], 1.0, ""),
                (
                    "xi_min",
                    "1e-3",
                    "Eqs 12, 13, 15",
                    f"xi_min_{col}_x1e-3",
                    ours["xi_min"] * 1e3,
                    1.0,
                    xi_note,
                ),
                ("f_min", "Hz", "Eq 14", f"f_min_{col}_hz", ours["f_min_hz"], 1.0, ""),
                (
                    "2 b_eq",
                    "m",
                    "Eq 11",
                    f"base_eq_2b_{col}_m",
                    ours["base_eq_2b_m"],
                    1.0,
                    "h = centroid height of the chamfered polygon" if spec.chamfer_m else "",
                ),
            )
            for quantity, unit, eq, csv_col, value, _, note in items:
                printed = float(paper.table(5).loc[key, csv_col])
                rows.append(
                    _row(
                        5,
                        spec.label,
                        quantity,
                        col,
                        unit,
                        eq,
                        printed,
                        value,
                        paper.printed_decimals(5, key, csv_col),
                        note,
                    )
                )
    for key in paper.BIBLOCK_BLOCKS:
        spec = paper.specimen(key)
        ours = dem_parameters_from_printed(key, "experimental")
        for quantity, unit, eq, csv_col, value in (
            ("K", "N/m (paper)", "Eq 10", "K_paper_N_per_m", ours["K_paper"]),
            ("xi_min", "1e-3", "Eqs 12, 13, 15", "xi_min_x1e-3", ours["xi_min"] * 1e3),
            ("f_min", "Hz", "Eq 14", "f_min_hz", ours["f_min_hz"]),
            ("2 b_eq", "m", "Eq 11", "base_eq_2b_m", ours["base_eq_2b_m"]),
        ):
            printed = float(paper.table(6).loc[key, csv_col])
            rows.append(
                _row(
                    6,
                    spec.label,
                    quantity,
                    "E",
                    unit,
                    eq,
                    printed,
                    value,
                    paper.printed_decimals(6, key, csv_col),
                    "Table 4 E parameters (Section 6.3)",
                )
            )
    return rows


def reproduction_report() -> pd.DataFrame:
    """All reproduced values of Tables 1-6 in one long table (see module docstring)."""
    rows = _geometry_rows() + _classical_rows() + _dem_rows()
    return pd.DataFrame(rows, columns=COLUMNS)


def format_report(report: pd.DataFrame) -> str:
    """Printable text of the report, one block per table."""
    titles = {
        1: "Table 1 - single specimens",
        2: "Table 2 - bi-block",
        3: "Table 3 - classical parameters, single blocks (T from geometry)",
        4: "Table 4 - classical parameters, bi-block (T from geometry)",
        5: "Table 5 - DEM parameters, single blocks (from printed Table 3)",
        6: "Table 6 - DEM parameters, bi-block (from printed Table 4, E)",
    }
    out = []
    for number, group in report.groupby("table", sort=True):
        view = group[
            ["row", "quantity", "column", "unit", "equation", "paper", "ours", "diff_pct", "consistent"]
        ].copy()
        view["paper"] = view["paper"].map(lambda v: f"{v:.6g}")
        view["ours"] = view["ours"].map(lambda v: f"{v:.6g}")
        view["diff_pct"] = view["diff_pct"].map(lambda v: f"{v:+.1f}")
        view["consistent"] = view["consistent"].map(lambda v: "ok" if v else "INCONSISTENT")
        n_bad = int((~group["consistent"]).sum())
        out.append(f"{titles[int(number)]}  ({n_bad} of {len(group)} flagged)")
        out.append(view.to_string(index=False))
        out.append("")
    return "\n".join(out)
