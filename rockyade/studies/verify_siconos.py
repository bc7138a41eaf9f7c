"""``rockyade verify``'s Siconos rows (``siconos``): Siconos (nonsmooth contact dynamics)
against closed forms and the limit analysis, on the scenes the DEMs' checks use."""

from __future__ import annotations

import math

import numpy as np

from rockyade.blocks.restitution import find_peaks
from rockyade.result import Result
from rockyade.scene import scene_from_dict
from rockyade.solvers import run
from rockyade.studies.verify_pushover import _short_pushover, limit_pushover_scenes
from rockyade.studies.verify_rows import Row, known, relative


def check_siconos(solvers: list[str]) -> tuple[list[Row], dict[str, Result]]:
    """Siconos (nonsmooth contact dynamics) against closed forms, whatever ``solvers`` says:

    * free rocking of specimen 1's geometry (0.25 x 1.0 m, released at alpha / 2, e = 0): the
      mean restitution of the first four impacts within 0.5 % of Housner's Eq 4,
      1 - 1.5 sin^2 alpha (nothing tuned: the model's own);
    * the pushover onset of the 0.4 x 2 m block of ``limit_pushover`` within 2 % of the limit
      analysis (b / h = 0.2).

    The frame, the drums, the arch, the restrained wall and the panel are not here: Siconos's
    friction solver (NSGS) does not converge on stacks of more than two blocks within its
    iterations (measured, docs/siconos.md)."""
    from rockyade.analysis.capacity import capacity_curve, pushover_onset
    from rockyade.blocks.restitution import restitution_per_impact
    from rockyade.limit import limit_analysis
    from rockyade.motion.quasistatic import Pushover
    from rockyade.motion.spec import parse_motion

    rows = []
    alpha = math.atan(0.25)
    free = scene_from_dict(
        {
            "duration_s": 3.0,
            "sample_dt_s": 0.002,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.754, "mass_kg": 503.0}],
            "motion": {"type": "free", "theta0_rad": alpha / 2.0},
        }
    )
    result = run(free, "siconos")
    eq4 = 1.0 - 1.5 * math.sin(alpha) ** 2
    per_impact = restitution_per_impact(
        find_peaks(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy()), alpha
    )[:4]
    mu = float(np.mean(per_impact)) if result.ok and len(per_impact) else math.nan
    rows.append(
        Row(
            "siconos",
            "siconos",
            "specimen 1 free rocking: mean restitution of 4 impacts (e = 0)",
            mu,
            eq4,
            "Housner Eq 4, 1 - 1.5 sin^2 alpha",
            relative(0.005),
        )
    )
    data, _ = limit_pushover_scenes()["block"]
    expected = known(limit_analysis(scene_from_dict(data), direction="+x").load_multiplier, "load multiplier")
    motion = parse_motion(_short_pushover(expected))
    assert isinstance(motion, Pushover)
    t_path, _ = motion.lambda_path(0.0)
    scene = scene_from_dict(data).with_changes(motion=motion, duration_s=float(t_path[-1]) + 0.5)
    pushed = run(scene, "siconos")
    onset = pushover_onset(capacity_curve(pushed, scene), scene).multiplier if pushed.ok else math.nan
    rows.append(
        Row(
            "siconos",
            "siconos",
            "block 0.4 x 2 m: pushover onset (first held level it did not stand)",
            onset,
            expected,
            "limit analysis",
            relative(0.02),
        )
    )
    return rows, {}
