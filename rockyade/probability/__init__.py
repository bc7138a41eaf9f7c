"""Probability: lognormal fragility fits and exceedance probabilities with their bands."""
