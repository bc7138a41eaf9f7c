"""Analysis of results: run metrics, collapse of assemblies, bi-block patterns and
cross-solver comparison. It reads Results; it runs no solver.
Peaks and effective restitution live in :mod:`rockyade.blocks.restitution`.
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
