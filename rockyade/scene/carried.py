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

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

from rockyade.blocks.classical import ClassicalParameters, rigid_body_classical, with_overrides


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


def carried_on(loads: Sequence[Any], block: str | int, g: float) -> list[tuple[tuple[float, float], float]]:
    """(point, mass) of each load on ``block`` (matched by the load's ``block`` field) with a mass."""
    out = []
    for load in loads:
        if load.block == block:
            m = load_mass_kg(load, g)
            if m > 0.0:
                out.append(((float(load.point_m[0]), float(load.point_m[1])), m))
    return out


def loaded_classical(scene: Any, g: float) -> dict[str, ClassicalParameters]:
    """The classical parameters of every moving block of ``scene`` as it rocks: with the masses of
    the loads it carries merged in and the moments of its loads without mass, by block name.

    A block without loads has its own (``spec.classical()``). A loaded block is one rigid body
    (:func:`loaded_mass_properties`) rocking on the block's two base corners (the equivalent base
    x_c -/+ h_c tan(alpha) where alpha is overridden, paper Eq 11), its own centroidal inertia
    from its left-pivot p (Eq 3: I_O = M g R / p^2, which honours an overridden p), and each
    direction gets its own alpha, R, p, restitution and uplift acceleration
    (:func:`rockyade.blocks.classical.rigid_body_classical`); an overridden mu stays.

    Parameters
    ----------
    scene
        A validated scene (its ``blocks`` and ``loads``).
    g
        Acceleration of gravity, m/s^2.
    """
    out: dict[str, ClassicalParameters] = {}
    loaded = {str(q.block) for q in getattr(scene, "loads", ())}
    placed = None
    for index, spec in enumerate(scene.blocks):
        if spec.fixed:
            continue
        bare = spec.classical()
        if spec.name not in loaded:
            out[spec.name] = bare
            continue
        if placed is None:
            from rockyade.scene.placement import placed_blocks

            placed = placed_blocks(scene)
        out[spec.name] = _loaded_block(spec, placed[index], [q for q in scene.loads if q.block == spec.name], bare, g)
    return out


def _loaded_block(
    spec: Any, placed: Any, loads: Sequence[Any], bare: ClassicalParameters, g: float
) -> ClassicalParameters:
    """:func:`loaded_classical` of one block with its loads (base frame at rest), in its own frame."""
    block = spec.block()
    cx, cy = (float(v) for v in block.centroid_m)
    c, s = math.cos(placed.rotation_rad), math.sin(placed.rotation_rad)

    def own(point: Sequence[float]) -> tuple[float, float]:  # base frame -> block frame
        dx, dy = float(point[0]) - placed.centroid_m[0], float(point[1]) - placed.centroid_m[1]
        return (cx + c * dx + s * dy, cy - s * dx + c * dy)

    pivots = ((cx - cy * math.tan(bare.left.alpha_rad), 0.0), (cx + cy * math.tan(bare.right.alpha_rad), 0.0))
    mass = block.mass_kg
    r_left = math.hypot(cx - pivots[0][0], cy)
    inertia_c = mass * g * r_left / (bare.left.p_rad_s**2) - mass * r_left * r_left
    props = loaded_mass_properties(mass, (cx, cy), inertia_c, [(own(q.point_m), load_mass_kg(q, g)) for q in loads])
    moments = [0.0, 0.0]
    for q in loads:
        fx, fy = residual_force(q, g)
        fx, fy = c * fx + s * fy, -s * fx + c * fy  # the force in the block frame
        px, py = own(q.point_m)
        for k, (x0, y0) in enumerate(pivots):
            moments[k] += (px - x0) * fy - (py - y0) * fx
    cp = rigid_body_classical(
        props.mass_kg,
        props.centroid_m,
        props.inertia_c_kgm2,
        pivots,
        g,
        load_moments_Nm=(moments[0], moments[1]),
        carried_kg=props.carried_kg,
    )
    cp = replace(cp, source={k: v if v == "override" else "geometry and loads" for k, v in bare.source.items()})
    return with_overrides(cp, mu=spec.mu, g=g) if spec.mu is not None else cp
