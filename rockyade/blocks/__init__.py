"""Blocks: geometry and mass properties and Housner's classical parameters.

``geometry`` (convex polygons, mass and inertia), ``classical`` (alpha, p, mu; paper
Eqs 2-4 and their general polygon forms) and ``restitution`` (rocking peaks and the
effective restitution of a history). Imports only ``rockyade.errors`` and
``rockyade.constants``: the first stage of the data flow.
"""
