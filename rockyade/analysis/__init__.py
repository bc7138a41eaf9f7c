"""Analysis of results and measurements: run metrics, collapse of assemblies, bi-block
patterns, fragility and exceedance, cross-solver comparison, and the identification of
alpha, p, mu from a measured free-rocking test (which fits Housner's exact solution).

May import everything below it (scene, dem, solvers, result); never figures, studies or
the CLI. Peaks and effective restitution live in :mod:`rockyade.blocks.restitution`.
"""

from rockyade.analysis.metrics import run_metrics
from rockyade.blocks.restitution import (
    Peaks,
    effective_restitution,
    find_peaks,
    restitution_per_impact,
    rocking_potential,
)

__all__ = ["Peaks", "effective_restitution", "find_peaks", "restitution_per_impact", "rocking_potential", "run_metrics"]
