"""Loads with their mass: the mass properties of a block and the loads it carries.

A ``[[loads]]`` entry is a force at a material point of a block. Its mass (``mass_kg``)
moves rigidly with the block: the block and its carried masses are one rigid body whose

* mass is M = m + sum m_j;
* centroid is c = (m c_b + sum m_j p_j) / M (c_b the block's own centroid, p_j the loads'
  points);
* inertia about c is I_c = I_b + m |c_b - c|^2 + sum m_j |p_j - c|^2 (the carried masses as
  point masses, parallel-axis theorem).

The load's weight is its ``force_N``; the part of it that is the weight of its mass,
(0, -m_j g), acts through the merged body's weight, and only the rest,
force_N + (0, m_j g) (zero for a vertical load whose mass is its weight over g), is left as
a force without mass (:func:`residual_force`).

Default (``mass_kg`` not given): the mass of the load's weight, m = -F_y / g for a downward
load (0 for a load that does not push down). The kinematic method of NTC 2018 counts among the
forces P_i that the horizontal acceleration acts on the blocks' weights *and the vertical
loads they carry* (Circolare 2019 C8.7.1), unless the load's horizontal force is taken
elsewhere: a massless load (``mass_kg = 0``) is the exception the engineer states.

Every solver and check (both DEMs, YADE through the DEM model, Housner, the limit analysis
and the kinematic quantities) takes the loaded block's mass properties from
:func:`loaded_mass_properties`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class MassProperties:
    """A rigid body's mass, centroid and centroidal inertia.

    Attributes
    ----------
    mass_kg
        Mass, kg.
    centroid_m
        Centroid (x, y), m, in the frame the inputs were given in.
    inertia_c_kgm2
        Inertia about the centroid (z axis), kg m^2.
    carried_kg
        The part of ``mass_kg`` carried as loads, kg.
    """

    mass_kg: float
    centroid_m: tuple[float, float]
    inertia_c_kgm2: float
    carried_kg: float = 0.0

    def inertia_about(self, point_m: Sequence[float]) -> float:
        """Inertia about ``point_m`` (e.g. a pivot, I_O), kg m^2 (parallel-axis theorem)."""
        dx, dy = self.centroid_m[0] - point_m[0], self.centroid_m[1] - point_m[1]
        return self.inertia_c_kgm2 + self.mass_kg * (dx * dx + dy * dy)


def load_mass_kg(load: Any, g: float) -> float:
    """The mass of a load that moves with its block, kg (module docstring).

    Parameters
    ----------
    load
        Anything with ``force_N`` (fx, fy), N, and ``mass_kg`` (kg, or None for the default).
    g
        Acceleration of gravity, m/s^2 (the default mass is the weight over g).
    """
    mass = getattr(load, "mass_kg", None)
    if mass is not None:
        return float(mass)
    return max(-float(load.force_N[1]), 0.0) / g


def residual_force(load: Any, g: float) -> tuple[float, float]:
    """The part of the load's force that is not the weight of its mass, N: F + (0, m g)."""
    m = load_mass_kg(load, g)
    fx, fy = float(load.force_N[0]), float(load.force_N[1])
    fy_rest = fy + m * g
    if abs(fy_rest) <= 1e-12 * max(abs(fy), m * g, 1.0):
        fy_rest = 0.0  # the default mass: exactly its weight
    return (fx, fy_rest)


def loaded_mass_properties(
    mass_kg: float,
    centroid_m: Sequence[float],
    inertia_c_kgm2: float,
    carried: Sequence[tuple[Sequence[float], float]],
) -> MassProperties:
    """The mass properties of a block with the masses it carries (module docstring).

    Parameters
    ----------
    mass_kg
        The block's own mass, kg.
    centroid_m
        The block's own centroid (x, y), m.
    inertia_c_kgm2
        The block's own inertia about its centroid, kg m^2.
    carried
        (point (x, y) in the same frame, m; mass, kg) of each load on the block; masses of
        0 are allowed (and change nothing).

    Returns
    -------
    MassProperties
        Of the block and its carried masses as one rigid body.
    """
    total = float(mass_kg)
    sx, sy = mass_kg * float(centroid_m[0]), mass_kg * float(centroid_m[1])
    extra = 0.0
    for point, m in carried:
        if m < 0.0:
            raise ValueError(f"a carried mass must be >= 0 kg, got {m!r}")
        total += m
        extra += m
        sx += m * float(point[0])
        sy += m * float(point[1])
    if extra == 0.0:
        return MassProperties(float(mass_kg), (float(centroid_m[0]), float(centroid_m[1])), float(inertia_c_kgm2))
    cx, cy = sx / total, sy / total
    inertia = inertia_c_kgm2 + mass_kg * ((centroid_m[0] - cx) ** 2 + (centroid_m[1] - cy) ** 2)
    for point, m in carried:
        inertia += m * ((point[0] - cx) ** 2 + (point[1] - cy) ** 2)
    return MassProperties(total, (cx, cy), float(inertia), extra)


def pivot_restitution(props: MassProperties, pivot_from: Sequence[float], pivot_to: Sequence[float]) -> float:
    """omega after / omega before when the pivot moves from ``pivot_from`` to ``pivot_to``
    (angular momentum about the new pivot conserved, Housner 1963 generalised to any centroid):

        mu = (I_c + M r_from . r_to) / (I_c + M |r_to|^2),   r = c - pivot.

    For a rectangle with its centroid on its axis this is 1 - 1.5 sin^2(alpha).
    """
    c = props.centroid_m
    rf = (c[0] - pivot_from[0], c[1] - pivot_from[1])
    rt = (c[0] - pivot_to[0], c[1] - pivot_to[1])
    m, i_c = props.mass_kg, props.inertia_c_kgm2
    return (i_c + m * (rf[0] * rt[0] + rf[1] * rt[1])) / (i_c + m * (rt[0] * rt[0] + rt[1] * rt[1]))


def carried_on(loads: Sequence[Any], block: str | int, g: float) -> list[tuple[tuple[float, float], float]]:
    """(point, mass) of each load on ``block`` (matched by the load's ``block`` field) with a mass."""
    out = []
    for load in loads:
        if load.block == block:
            m = load_mass_kg(load, g)
            if m > 0.0:
                out.append(((float(load.point_m[0]), float(load.point_m[1])), m))
    return out


def loaded_rocking_parameters(
    mass_kg: float,
    centroid_m: Sequence[float],
    pivots_m: Sequence[Sequence[float]],
    p_left: float,
    g: float,
    carried: Sequence[tuple[Sequence[float], float]],
) -> tuple[MassProperties, dict[str, float]]:
    """Housner's parameters of a single block with the masses it carries.

    The block's own centroidal inertia comes from its left-pivot p (Eq 3: I_O = M g R / p^2,
    which also honours an overridden p); the loaded block's alpha, p (Eq 3 again) and pivot
    restitution (:func:`pivot_restitution`) follow from :func:`loaded_mass_properties`.

    Parameters
    ----------
    mass_kg, centroid_m
        The block's own mass, kg, and centroid at rest (base frame), m.
    pivots_m
        (left pivot, right pivot), base frame, m.
    p_left
        The block's own frequency parameter about its left pivot, rad/s.
    g
        Acceleration of gravity, m/s^2.
    carried
        (point, mass) of each carried load, base frame, m and kg.

    Returns
    -------
    MassProperties, dict
        The loaded block, and ``alpha_left``, ``alpha_right``, ``p_left``, ``p_right``,
        ``mu_left_to_right``, ``mu_right_to_left`` (rad, rad/s, dimensionless).
    """
    import math

    left, right = pivots_m[0], pivots_m[1]
    r_left = math.hypot(centroid_m[0] - left[0], centroid_m[1] - left[1])
    inertia_c = mass_kg * g * r_left / (p_left * p_left) - mass_kg * r_left * r_left
    props = loaded_mass_properties(mass_kg, centroid_m, inertia_c, carried)
    cx, cy = props.centroid_m
    m = props.mass_kg

    def p_about(pivot: Sequence[float]) -> float:
        return math.sqrt(m * g * math.hypot(cx - pivot[0], cy - pivot[1]) / props.inertia_about(pivot))

    return props, {
        "alpha_left": math.atan2(cx - left[0], cy),
        "alpha_right": math.atan2(right[0] - cx, cy),
        "p_left": p_about(left),
        "p_right": p_about(right),
        "mu_left_to_right": pivot_restitution(props, left, right),
        "mu_right_to_left": pivot_restitution(props, right, left),
    }
