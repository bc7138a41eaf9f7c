"""Housner's single-degree-of-freedom model of a block rocking on a rigid base: the classical
parameters of both pivots (paper Eqs 2-4) and the point loads of a scene (modified Eq 1; the
equations are in :mod:`rockyade.housner.integrator`'s docstring)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from rockyade.blocks.classical import ClassicalParameters
from rockyade.constants import G
from rockyade.housner.equation import theta_dd
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical, residual_force


@dataclass(frozen=True)
class HousnerModel:
    """The single-degree-of-freedom model: classical parameters of both pivots.

    Attributes
    ----------
    alpha_left, alpha_right
        Critical angles of rocking about the left (theta > 0) and right pivots, rad.
    p_left, p_right
        Frequency parameters, rad/s.
    mu_left_to_right, mu_right_to_left
        Restitution of an impact moving the pivot from left to right (theta going from
        > 0 to < 0) and back.
    g
        Gravity, m/s^2.
    load_a_left, load_b_left, load_a_right, load_b_right
        Point loads about each pivot, a = A / (M R) and b = B / (M R), m/s^2 (module
        docstring, modified Eq 1); 0 without loads.
    """

    alpha_left: float
    alpha_right: float
    p_left: float
    p_right: float
    mu_left_to_right: float
    mu_right_to_left: float
    g: float = G
    load_a_left: float = 0.0
    load_b_left: float = 0.0
    load_a_right: float = 0.0
    load_b_right: float = 0.0

    @classmethod
    def from_classical(cls, cp: ClassicalParameters, g: float = G) -> HousnerModel:
        """Model from classical parameters (geometry or overrides)."""
        return cls(
            cp.left.alpha_rad,
            cp.right.alpha_rad,
            cp.left.p_rad_s,
            cp.right.p_rad_s,
            cp.mu_left_to_right,
            cp.mu_right_to_left,
            g,
        )

    @classmethod
    def symmetric(cls, alpha: float, p: float, mu: float, g: float = G) -> HousnerModel:
        """A symmetric block."""
        return cls(alpha, alpha, p, p, mu, mu, g)

    def acceleration(self, side: int, theta: float, ah: float = 0.0, av: float = 0.0) -> float:
        """theta'' on ``side`` (+1 left pivot, -1 right pivot), rad/s^2."""
        return theta_dd(side, theta, ah, av, self.params())

    def energy(self, side: int, theta: float, omega: float) -> float:
        """Energy in units of M g R of the active side (R its pivot-to-centroid distance):

            omega^2 / (2 p^2) + cos(alpha - |theta|) - cos(alpha) - (a / g) sin(theta) + (b / g) (1 - cos(theta)),

        the kinetic energy, the weight's potential and the point loads' (module docstring). A
        dead load is a constant force F without mass: its potential is -F . u, u the
        displacement of its point, and with the load's moment M_F = A cos(theta) - B sin(theta)
        about the pivot, -integral M_F dtheta = -A sin(theta) + B (1 - cos(theta)); over M g R
        that is the last two terms (a = A / (M R), b = B / (M R)). Conserved between impacts
        when the base does not move.

        Parameters
        ----------
        side
            +1 rocking on the left pivot (theta > 0), -1 on the right one.
        theta
            Rotation, rad (counter-clockwise).
        omega
            Angular velocity, rad/s.
        """
        p = self.p_left if side > 0 else self.p_right
        alpha = self.alpha_left if side > 0 else self.alpha_right
        a = self.load_a_left if side > 0 else self.load_a_right
        b = self.load_b_left if side > 0 else self.load_b_right
        loads = -(a / self.g) * math.sin(theta) + (b / self.g) * (1.0 - math.cos(theta))
        return 0.5 * omega * omega / (p * p) + math.cos(alpha - abs(theta)) - math.cos(alpha) + loads

    def params(self) -> np.ndarray:
        """The model as the array :func:`rockyade.housner.equation.theta_dd` takes (its order:
        :data:`rockyade.housner.equation.PARAMS`)."""
        return np.array(
            [
                self.alpha_left,
                self.alpha_right,
                self.p_left**2 / self.g,
                self.p_right**2 / self.g,
                self.mu_left_to_right,
                self.mu_right_to_left,
                self.g,
                self.p_left,
                self.p_right,
                self.load_a_left,
                self.load_b_left,
                self.load_a_right,
                self.load_b_right,
                float(self.loaded),
            ]
        )

    @property
    def loaded(self) -> bool:
        """True when point loads act on the block."""
        return any((self.load_a_left, self.load_b_left, self.load_a_right, self.load_b_right))

    def uplift_multiplier(self, side: int) -> float:
        """|a_h| / g at which the block at rest lifts about ``side`` (+1 left pivot, -1 right),
        without vertical motion: tan(alpha) -/+ a / (g cos(alpha)) (module docstring)."""
        if side > 0:
            return math.tan(self.alpha_left) - self.load_a_left / (self.g * math.cos(self.alpha_left))
        return math.tan(self.alpha_right) + self.load_a_right / (self.g * math.cos(self.alpha_right))

    def with_loads(self, mass_kg: float, pivots_m, loads) -> HousnerModel:
        """This model with point loads.

        Parameters
        ----------
        mass_kg
            The block's mass, kg.
        pivots_m
            ((x, y) of the left pivot, (x, y) of the right pivot), base frame, m.
        loads
            Each with ``point_m`` (base frame at rest, m) and ``force_N`` (N), e.g.
            :class:`rockyade.scene.LoadSpec`.
        """
        moments = []
        for pivot in pivots_m:
            big_a = big_b = 0.0
            for load in loads:
                rx, ry = load.point_m[0] - pivot[0], load.point_m[1] - pivot[1]
                fx, fy = load.force_N
                big_a += rx * fy - ry * fx  # r_0 x F
                big_b += rx * fx + ry * fy  # r_0 . F
            moments.append((big_a, big_b))
        r_left, r_right = self._radii(pivots_m)
        return replace(
            self,
            load_a_left=moments[0][0] / (mass_kg * r_left),
            load_b_left=moments[0][1] / (mass_kg * r_left),
            load_a_right=moments[1][0] / (mass_kg * r_right),
            load_b_right=moments[1][1] / (mass_kg * r_right),
        )

    def _radii(self, pivots_m) -> tuple[float, float]:
        """R of each side from the pivots' spacing and the alphas: the centroid lies at
        h_c tan(alpha_L) right of the left pivot and h_c tan(alpha_R) left of the right one."""
        span = pivots_m[1][0] - pivots_m[0][0]
        h_c = span / (math.tan(self.alpha_left) + math.tan(self.alpha_right))
        return h_c / math.cos(self.alpha_left), h_c / math.cos(self.alpha_right)


def housner_model(scene: Scene, g: float = G) -> HousnerModel:
    """The single block of ``scene`` as Housner's model, with its point loads (modified Eq 1).

    The classical parameters are those of the block as it rocks, with the masses of the loads it
    carries (:func:`rockyade.scene.carried.loaded_classical`: each direction its own alpha, p and
    restitution); the loads' forces that are not the weights of those masses act as point loads.
    The pivots are the base corners at the equivalent base x_c -/+ h_c tan(alpha) (the real
    corners when alpha comes from the geometry), in the base frame at rest.
    """
    from rockyade.scene.placement import placed_blocks

    spec = scene.blocks[0]
    if not scene.loads:
        return HousnerModel.from_classical(spec.classical(), g)
    bare = spec.classical()
    cx, cy = placed_blocks(scene)[0].centroid_m  # the block's own centroid: its pivots at rest
    pivots = ((cx - cy * math.tan(bare.left.alpha_rad), 0.0), (cx + cy * math.tan(bare.right.alpha_rad), 0.0))
    cp = loaded_classical(scene, g)[spec.name]
    model = HousnerModel.from_classical(cp, g)
    return model.with_loads(cp.mass_kg, pivots, [replace(q, force_N=residual_force(q, g)) for q in scene.loads])
