"""Blocks: geometry and mass properties, Housner's classical parameters, DEM calibration.

``geometry`` (convex polygons, mass and inertia), ``classical`` (alpha, p, mu; paper
Eqs 2-4 and their general polygon forms), ``restitution`` (rocking peaks and the effective
restitution of a history) and ``calibration`` (DEM contact parameters from the classical
ones; paper Eqs 5-15). Imports only ``rockyade.errors`` and
``rockyade.constants``: the first stage of the data flow.
"""
