"""Whether a run collapsed: the one rule every study applies (``fragility``, ``assess``,
``crosscheck``, the paper's fragility, a batch's ``overturned`` columns).

* a single block falls when its solver says it overturned (its status ``overturned``: Housner's
  |theta| = pi/2, the DEMs' landing on another face, :mod:`rockyade.dem.overturn`);
* a block of several falls by the collapse table's rule (:func:`rockyade.analysis.collapse.
  collapse_report`: it lies on another face, was carried down by more than half its height, or
  is left leaning beyond its tipping angle);
* the run **collapses** when at least ``fallen_blocks`` blocks fell (1 by default).

Beside the verdict: the largest peak |theta| of the blocks (rad) and the largest of each
block's peak |theta| over its own alpha.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from rockyade.constants import G
from rockyade.result import Result
from rockyade.runner.rows import Verdict
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical
from rockyade.solvers.base import GroupRun


def collapse_verdict(
    scene: Scene, result: Result | GroupRun, fallen_blocks: int = 1, report: pd.DataFrame | None = None
) -> Verdict:
    """The verdict of a run that answered (module docstring).

    Parameters
    ----------
    scene
        The scene that was run.
    result
        Its Result, or a run of a group (one block, its sampled rotation).
    fallen_blocks
        Fallen blocks that make a collapse (>= 1).
    report
        The run's :func:`rockyade.analysis.collapse.collapse_report`, when the caller has it
        (several blocks).
    """
    if len(scene.blocks) == 1:
        spec = scene.blocks[0]
        theta = result.theta_rad if isinstance(result, GroupRun) else result.series("theta_rad", spec.name)
        values = np.asarray(theta, dtype=float)
        finite = values[np.isfinite(values)]
        peak = float(np.max(np.abs(finite))) if finite.size else math.nan
        fallen: tuple[str, ...] = (spec.name,) if result.status == "overturned" else ()
        # each side's rotation over that side's alpha, of the body that rocks (its loads' mass in)
        own = loaded_classical(scene, G)[spec.name].theta_over_alpha(values)
        return Verdict(len(fallen) >= fallen_blocks, fallen, peak, own)
    if isinstance(result, GroupRun):
        raise TypeError("a run of a group is of one block")
    if report is None:
        from rockyade.analysis.collapse import collapse_report

        report = collapse_report(scene, result)
    fallen = tuple(str(b) for b in report.loc[report["fell"].astype(bool), "block"])
    ratio = float(np.nanmax(report["max_theta_over_alpha"])) if len(report) else math.nan
    peak = float(np.nanmax(report["max_abs_theta_rad"])) if len(report) else math.nan
    return Verdict(len(fallen) >= fallen_blocks, fallen, peak, ratio)


__all__ = ["Verdict", "collapse_verdict"]
