"""Identified classical parameters read back (``rockyade identify --out``) and turned into DEM
contact parameters by the one calibration (:func:`rockyade.calibration.calibrate.calibrate`):
the paper's (Eqs 7-15) or the matched one (the damping that makes the reference DEM's
effective mu equal the identified mu).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from rockyade.blocks.classical import check_classical_overrides
from rockyade.blocks.geometry import Block
from rockyade.calibration.calibrate import calibrate
from rockyade.constants import DEFAULT_FRICTION_ANGLE_DEG
from rockyade.errors import InputError
from rockyade.scene import ContactSpec
from rockyade.scene.description import CALIBRATIONS

CLASSICAL_KEYS = ("alpha_rad", "p_rad_s", "mu")
#: Calibration methods offered from identified values (the scene's ``contact.calibration``).
METHODS = CALIBRATIONS


def load_identified(
    source: str | Path | Mapping[str, object], *, field: str = "from", named_in: str | None = None
) -> dict[str, Any]:
    """Identified values from a JSON file (or a mapping): alpha_rad, p_rad_s, mu and their intervals.

    Parameters
    ----------
    source
        The JSON file ``rockyade identify --out`` wrote, or its content.
    field, named_in
        Where the file was named, for the message when it cannot be read: the option or field
        (default ``from``, ``calibrate --from``) and the file that names it (e.g. a study).

    Raises
    ------
    InputError
        When the file is missing or unreadable, a value is missing, unidentified (null or
        listed under ``unidentifiable``) or out of range.
    """
    where = None
    if isinstance(source, Mapping):
        data: Any = dict(source)
    else:
        path = Path(source)
        where = str(path)
        if not path.is_file():
            hint = " (rockyade identify --out writes it; a relative path is read from this file's folder)"
            raise InputError(field, f"file not found: {path}" + (hint if named_in else ""), named_in)
        try:
            data = json.loads(path.read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise InputError(field, f"not a readable JSON file: {exc}", where) from None
    if not isinstance(data, dict):
        raise InputError(field, "must be a JSON object with alpha_rad, p_rad_s and mu", where)
    unidentifiable = data.get("unidentifiable") or {}
    out: dict[str, Any] = {}
    for key in CLASSICAL_KEYS:
        if key in unidentifiable:
            raise InputError(key, f"was not identified ({unidentifiable[key]}): nothing to calibrate with", where)
        value = data.get(key)
        if value is None:
            raise InputError(key, "is missing (null): give alpha_rad, p_rad_s and mu", where)
        out[key] = value
        ci = data.get(f"{key}_ci")
        if ci is not None:
            if not (isinstance(ci, list) and len(ci) == 2 and all(isinstance(c, (int, float)) for c in ci)):
                raise InputError(f"{key}_ci", f"must be [lo, hi], got {ci!r}", where)
            if not ci[0] <= value <= ci[1]:
                raise InputError(f"{key}_ci", f"{ci} does not contain {key} = {value}", where)
            out[f"{key}_ci"] = [float(ci[0]), float(ci[1])]
    try:
        check_classical_overrides(out["alpha_rad"], out["p_rad_s"], out["mu"])
    except InputError as exc:
        raise InputError(exc.field, exc.message, where) from None
    if "covariance_alpha_p_mu" in data:
        out["covariance_alpha_p_mu"] = data["covariance_alpha_p_mu"]
    return out


def calibrate_from_identified(
    block: Block,
    identified: str | Path | Mapping[str, object],
    *,
    method: str = "paper",
    stiffness_scale: float | str | None = None,
    friction_angle_deg: float = DEFAULT_FRICTION_ANGLE_DEG,
) -> dict[str, Any]:
    """DEM contact parameters of ``block`` from identified alpha, p, mu.

    Parameters
    ----------
    block
        The block's geometry and mass (mass enters Eqs 8-10).
    identified
        A JSON file written by ``rockyade identify --out`` or a mapping with the same keys.
    method
        ``"paper"`` (damping from Eq 13) or ``"matched"`` (damping such that the reference
        DEM's effective mu equals the identified mu, :func:`rockyade.calibration.matching.match_beta`).
    stiffness_scale
        Reading of the paper's K (``"N/m"``, ``"kN/m"``, ``"MN/m"`` or a factor; None: MN/m).
    friction_angle_deg
        Joint friction angle, degrees.

    Returns
    -------
    dict
        ``classical`` (the values used and their intervals), the contact parameters
        (``K_N_per_m``, ``Ks_N_per_m``, ``beta_s``, ``beta_eq13_s``, ``xi_min``, ``f_min_hz``,
        ``b_eq_m``, ``dt_s``, ...), and for ``matched`` the reference DEM's ``mu_eff_matched``
        and the reachable range.
    """
    if method not in METHODS:
        raise InputError("method", f"must be one of {', '.join(METHODS)}, got {method!r}")
    values = load_identified(identified)
    params = {k: float(values[k]) for k in CLASSICAL_KEYS}
    contact = ContactSpec(
        calibration=method,
        stiffness_scale="MN/m" if stiffness_scale is None else stiffness_scale,
        friction_angle_deg=friction_angle_deg,
    )
    cal = calibrate(block, contact, **params)
    result: dict[str, Any] = {
        "classical": params,
        "classical_ci": {k: values[f"{k}_ci"] for k in CLASSICAL_KEYS if f"{k}_ci" in values},
        "parameters": "identified",
        "method": method,
        "mass_kg": block.mass_kg,
        **cal.report(),
    }
    if not math.isfinite(result["beta_s"]):
        raise InputError("mu", f"no damping follows from mu = {params['mu']}")
    return result
