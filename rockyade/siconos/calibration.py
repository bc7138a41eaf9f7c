"""The classical parameters carried to nonsmooth contact dynamics (paper's idea, Siconos).

* **alpha** through the equivalent base b_eq (paper Eq 11): the blocks are the DEMs'
  (:mod:`rockyade.dem.model_from_scene`), base corners where the DEMs put them.
* **p** through the inertia: the DEMs' centroidal inertia, set so that
  I_O = M g R / p^2 (:func:`rockyade.blocks.classical.inertia_for_frequency`).
* **mu** is not a parameter of the model: with a Newton restitution e = 0 at the contacts
  (a corner that lands stays down) and an instantaneous impact, angular momentum about the
  landing corner is conserved (the impulse acts there), which is Housner's derivation of
  his restitution: mu = (I_c + M r_B . r_A) / I_B (general Eq 4,
  :func:`rockyade.blocks.classical.restitution`), 1 - 1.5 sin^2 alpha for a rectangle.
  With base corners at +-b_eq = +-R sin(alpha) and I_O = M g R / p^2 this is
  mu = 1 - 2 M b_eq^2 / I_O = 1 - 2 R p^2 sin^2(alpha) / g: alpha, p and the size fix it.
  Measured (docs/siconos.md, ``benchmarks/bench_siconos_mu.py``): a Newton restitution
  e = 0.3-0.6 at the corners still gives that value per cycle (the landing corner's
  rebounds end with it at rest, angular momentum about it conserved: Housner's impact
  again), and Siconos's LZB multiple-impact law (``MultipleImpactNSL``, event-driven;
  frictionless in Siconos 4.4) gives the frictionless rigid value, 0.70 for specimen 1,
  whatever its restitution, stiffness ratio and exponent (the landing impulse lifts the
  pivot, so only one contact takes part). So no calibration reaches a target above the
  model's own; a scene whose calibration asks for a target mu
  (``contact.calibration = "matched"``) is refused unless its target is within MU_RTOL of
  the model's own (:func:`check_target_mu`). Under the other calibrations a
  scene's ``mu`` sets only the DEMs' damping: Siconos runs the geometry's restitution and
  records both in the Result (``mu_model``, ``mu_scene``).
* **The time step** (:func:`default_dt`): DT_P_FRACTION / p of the fastest moving block,
  within [DT_MIN_S, DT_MAX_S], so that one step is the same fraction of the rocking time
  scale 1/p for every block; chosen by measurement (docs/siconos.md, "The time step and the
  tolerance": Moreau-Jean is stable at any step, its impacts fall anywhere within a step):
  halving it changes a pulse's peak, the wall's peak displacement, the arch's collapse time
  and intensity by less than DT_PEAK_RTOL (``tests/test_siconos.py``,
  ``benchmarks/bench_siconos.py convergence``).
"""

from __future__ import annotations

import math

import numpy as np

from rockyade.dem.model import DemBody, DemModel
from rockyade.errors import InputError
from rockyade.scene import Scene

#: A target mu within this relative distance of the model's own counts as reached.
MU_RTOL = 0.01
#: Default time step: this fraction of 1/p of the fastest moving block (1e-3 before the
#: measurements: the wall's blocks, p 7.2 rad/s, got 1.33e-4 s) ...
DT_P_FRACTION = 3.0e-3
#: ... within these bounds, s (at most 5e-4 s: a single block's per-impact restitution
#: scatters by 1.1 % at 1e-3 s, 0.7 % at 5e-4 s, 0.3 % at 2.5e-4 s around Eq 4).
DT_MIN_S = 2.0e-5
DT_MAX_S = 5.0e-4
#: Halving the default step changes peaks by less than this (relative; tested).
DT_PEAK_RTOL = 0.02


def _base_corners(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The left and right base corners of a contact polygon (its lowest vertices)."""
    y0 = float(vertices[:, 1].min())
    size = float(np.ptp(vertices, axis=0).max())
    low = vertices[np.abs(vertices[:, 1] - y0) <= 1e-9 * size]
    return low[np.argmin(low[:, 0])], low[np.argmax(low[:, 0])]


def model_restitution(body: DemBody) -> float:
    """The restitution of a body rocking on its base with e = 0 (general Eq 4, module
    docstring): sqrt(mu_left_to_right x mu_right_to_left), the centroid at the origin of
    the contact polygon's frame and I_c the body's (adjusted) centroidal inertia."""
    if body.fixed:
        return math.nan
    left, right = _base_corners(np.asarray(body.contact_vertices_m, dtype=float))
    m, ic = body.mass_kg, body.inertia_kgm2

    def ratio(a: np.ndarray, b: np.ndarray) -> float:
        # centroid at 0: r_G - r_A = -a, r_G - r_B = -b
        return (ic + m * float(b @ a)) / (ic + m * float(b @ b))

    return math.sqrt(ratio(left, right) * ratio(right, left))


def check_target_mu(scene: Scene, model: DemModel) -> dict[str, object]:
    """The restitution the Siconos model runs against what the scene asks, per moving block.

    Returns
    -------
    dict
        ``mu_model`` (the geometry's, e = 0), ``mu_scene`` (the scene's explicit mu, or
        None) and a ``mu_note`` when they differ.

    Raises
    ------
    InputError
        The scene asks for a target mu (``contact.calibration = "matched"``) more than
        MU_RTOL from the model's own: one line naming every such block with its reachable
        range (the model's own +- MU_RTOL).
    """
    mu_model: dict[str, float] = {}
    mu_scene: dict[str, float | None] = {}
    unreachable: list[str] = []
    for spec, body in zip(scene.blocks, model.bodies, strict=True):
        if body.fixed:
            continue
        own = model_restitution(body)
        mu_model[body.name] = own
        mu_scene[body.name] = spec.mu
        if scene.contact.calibration == "matched" and spec.mu is not None and abs(spec.mu - own) > MU_RTOL * own:
            low, high = own * (1 - MU_RTOL), own * (1 + MU_RTOL)
            unreachable.append(
                f"mu = {spec.mu:.4g} for {body.name} (reachable range [{low:.4g}, {high:.4g}], its own {own:.4g})"
            )
    if unreachable:
        raise InputError(
            "contact.calibration",
            f"the siconos solver cannot reach {', '.join(unreachable)}: with e = 0 a block's impacts give its own "
            "restitution (Eq 4: 1 - 2 R p^2 sin^2(alpha) / g, fixed by alpha, p and the size), and neither a Newton "
            "restitution e > 0 nor the LZB multiple-impact law raises it (docs/siconos.md); "
            "use calibration 'paper' or drop mu",
        )
    out: dict[str, object] = {"mu_model": mu_model, "mu_scene": mu_scene}
    if any(v is not None and abs(v - mu_model[k]) > MU_RTOL * mu_model[k] for k, v in mu_scene.items()):
        out["mu_note"] = (
            "the scene's mu sets the DEMs' damping only; Siconos's impacts give the geometry's restitution (mu_model)"
        )
    return out


def default_dt(model: DemModel) -> float:
    """The default time step, s (module docstring)."""
    p = [b.p_rad_s for b in model.bodies if not b.fixed and math.isfinite(b.p_rad_s) and b.p_rad_s > 0]
    dt = DT_P_FRACTION / max(p) if p else DT_MAX_S
    return min(max(dt, DT_MIN_S), DT_MAX_S)


def steps_for(sample_dt_s: float, dt_s: float) -> tuple[float, int]:
    """The step that divides the sample interval, at most ``dt_s``: (step, steps per sample)."""
    steps = max(1, math.ceil(sample_dt_s / dt_s - 1e-9))
    return sample_dt_s / steps, steps
