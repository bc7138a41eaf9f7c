"""Analysis of results: peaks and restitution, run metrics, bi-block patterns, fragility,
cross-solver comparison.

May import ``scene`` and ``result``; never a solver.
"""

from rockyade.analysis.metrics import run_metrics
from rockyade.analysis.peaks import Peaks, effective_restitution, find_peaks, restitution_per_impact, rocking_potential

__all__ = ["Peaks", "effective_restitution", "find_peaks", "restitution_per_impact", "rocking_potential", "run_metrics"]
