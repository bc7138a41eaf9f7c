"""A two-block scene as the exact solver's model: geometry, masses, the joints' friction,
and the scenes it refuses (with the reason).

The blocks are the DEMs' (:mod:`rockyade.dem.model_from_scene` builds the same): rectangles
whose base corners sit at the equivalent base x_c +/- b_eq, b_eq = h_c tan(alpha) (paper
Eq 11) when alpha is given, and whose centroidal inertia is set so that I_O = M g R / p^2
(Eq 3) when p is given. The lower block stands on the base; the upper one on the lower's
top, its base (at its own b_eq) within that top. Each joint's friction coefficient is
tan(phi) of its ``[[joints]]`` entry or of ``[contact]``.

Refused (``InputError``, exit 2): not two blocks; a positioned scene; a block that is not a
rectangle; point loads; an upper block whose base (at b_eq) does not lie within the lower
block's top; a p no positive inertia reaches; a friction coefficient at or below the ratio
of horizontal to vertical contact force at the onset of rocking. At rest every part of the
stack moves with the base, so each joint carries T / N = a_h / (g + a_v) until the first
uplift, at a_h / g = lambda_0, the smallest static uplift multiplier of the stack (the
limit analysis's); pure rocking needs mu > lambda_0 at both joints (Shenton 1996, "Criteria
for initiation of slide, rock, and slide-rock rigid-body modes", J. Eng. Mech. 122(7): rocking
without sliding starts when mu > b / h, the block's lambda_0). During the rocking the ratio
is tracked and reported (``meta.extra["friction"]``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rockyade.blocks.classical import inertia_for_frequency
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.scene import BlockSpec, Scene
from rockyade.twoblock import dynamics as dyn

#: Corners within this fraction of the block size of a rectangle's count as one.
RECTANGLE_TOL = 1e-9
#: A seat corner may lie outside the lower block's top by this fraction of its width.
SEAT_TOL = 1e-9


@dataclass(frozen=True)
class TwoBlockModel:
    """Two stacked rectangles on a rigid base (module docstring). Base frame at rest, m.

    Attributes
    ----------
    names
        (lower, upper) block names.
    mass_kg, inertia_c_kgm2
        Masses (kg) and centroidal inertias (kg m^2), lower first.
    centroid_m
        Rest centroids, lower first, m.
    base_corners_x_m
        The lower block's base corners (its pivots on the base, y = 0), m.
    seat_corners_x_m
        The upper block's base corners (its pivots on the lower block's top), m.
    seat_y_m
        Height of the lower block's top, m.
    heights_m, widths_m
        The blocks' heights and (real) widths, m.
    friction
        (base joint, seat joint) friction coefficients tan(phi).
    g
        Gravity, m/s^2.
    notes
        What of the scene the model leaves out or sets, in words.
    """

    names: tuple[str, str]
    mass_kg: tuple[float, float]
    inertia_c_kgm2: tuple[float, float]
    centroid_m: tuple[tuple[float, float], tuple[float, float]]
    base_corners_x_m: tuple[float, float]
    seat_corners_x_m: tuple[float, float]
    seat_y_m: float
    heights_m: tuple[float, float]
    widths_m: tuple[float, float]
    friction: tuple[float, float]
    g: float = G
    notes: tuple[str, ...] = ()

    @property
    def height_m(self) -> float:
        """Height of the stack, m."""
        return self.heights_m[0] + self.heights_m[1]

    @property
    def weight_N(self) -> float:
        """Weight of the stack, N."""
        return (self.mass_kg[0] + self.mass_kg[1]) * self.g

    def uplift_multipliers(self) -> dict[str, float]:
        """Static uplift multipliers lambda = a_h / g of the stack at rest, per mechanism:
        ``stack+``/``stack-`` (the stack as one body about a base corner, a_h towards +x / -x)
        and ``upper+``/``upper-`` (the upper block about a corner of its seat): the resisting
        moment of the weights over the overturning moment of lambda times them."""
        (m1, m2), (g1, g2) = self.mass_kg, self.centroid_m
        xl, xr = self.base_corners_x_m
        sl, sr = self.seat_corners_x_m
        hy = m1 * g1[1] + m2 * g2[1]
        lever = g2[1] - self.seat_y_m
        return {
            "stack+": (m1 * (g1[0] - xl) + m2 * (g2[0] - xl)) / hy,
            "stack-": (m1 * (xr - g1[0]) + m2 * (xr - g2[0])) / hy,
            "upper+": (g2[0] - sl) / lever,
            "upper-": (sr - g2[0]) / lever,
        }

    @property
    def onset_multiplier(self) -> float:
        """lambda_0: the smallest static uplift multiplier (either way, either mechanism)."""
        return min(self.uplift_multipliers().values())

    def own_restitution(self) -> dict[str, float]:
        """Each block's restitution rocking alone on its support with this model's corners and
        inertia (general Eq 4: mu = (I_c + M r_B . r_A) / I_B, the mean of both ways): what
        the impact law gives a block that rocks alone, to set beside a scene's mu."""
        out = {}
        for i, name in enumerate(self.names):
            m, ic = self.mass_kg[i], self.inertia_c_kgm2[i]
            gx, gy = self.centroid_m[i]
            y0 = 0.0 if i == 0 else self.seat_y_m
            xl, xr = self.base_corners_x_m if i == 0 else self.seat_corners_x_m
            a = np.array([gx - xl, gy - y0])
            b = np.array([gx - xr, gy - y0])
            mu_lr = (ic + m * float(a @ b)) / (ic + m * float(b @ b))
            mu_rl = (ic + m * float(a @ b)) / (ic + m * float(a @ a))
            out[name] = math.sqrt(mu_lr * mu_rl)
        return out

    def joint_rocking(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(p^2, alpha) of the stack rocking as one body on the base and of the upper block on
        its seat, the smaller alpha of the two corners (the rest threshold of the integrator)."""
        (m1, m2), (g1, g2) = self.mass_kg, self.centroid_m
        m = m1 + m2
        cx, cy = (m1 * g1[0] + m2 * g2[0]) / m, (m1 * g1[1] + m2 * g2[1]) / m
        out = []
        for corners, y0, parts in (
            (self.base_corners_x_m, 0.0, (0, 1)),
            (self.seat_corners_x_m, self.seat_y_m, (1,)),
        ):
            mass = sum(self.mass_kg[i] for i in parts)
            gx, gy = (cx, cy) if len(parts) == 2 else g2
            best = (math.inf, math.inf)
            for x in corners:
                inertia = sum(
                    self.inertia_c_kgm2[i]
                    + self.mass_kg[i] * ((self.centroid_m[i][0] - x) ** 2 + (self.centroid_m[i][1] - y0) ** 2)
                    for i in parts
                )
                r = math.hypot(gx - x, gy - y0)
                alpha = math.atan2(abs(gx - x), gy - y0)
                if alpha < best[1]:
                    best = (mass * self.g * r / inertia, alpha)
            out.append(best)
        return out[0], out[1]

    def params(self) -> np.ndarray:
        """The parameter vector of :mod:`rockyade.twoblock.dynamics` (its indices)."""
        prm = np.zeros(dyn.N_PARAMS)
        (base, seat) = self.joint_rocking()
        prm[dyn.M1], prm[dyn.M2] = self.mass_kg
        prm[dyn.I1], prm[dyn.I2] = self.inertia_c_kgm2
        prm[dyn.BLX], prm[dyn.BRX] = self.base_corners_x_m
        prm[dyn.SLX], prm[dyn.SRX] = self.seat_corners_x_m
        prm[dyn.HS] = self.seat_y_m
        prm[dyn.G1X], prm[dyn.G1Y] = self.centroid_m[0]
        prm[dyn.G2X], prm[dyn.G2Y] = self.centroid_m[1]
        prm[dyn.GRAV] = self.g
        prm[dyn.WEIGHT] = self.weight_N
        prm[dyn.MOMENT_SCALE] = self.weight_N * self.height_m
        prm[dyn.MU_BASE], prm[dyn.MU_SEAT] = self.friction
        prm[dyn.P2_BASE], prm[dyn.ALPHA_BASE] = base
        prm[dyn.P2_SEAT], prm[dyn.ALPHA_SEAT] = seat
        return prm

    def energy(self, theta_1: float, phi: float, omega_1: float, omega_phi: float) -> float:
        """Kinetic energy plus the weights' potential above rest, J, with the base at rest.

        Parameters
        ----------
        theta_1
            The lower block's rotation, rad (> 0: about its left base corner).
        phi
            The upper block's rotation relative to the lower one, rad (> 0: about the left
            corner of its seat).
        omega_1, omega_phi
            Their rates, rad/s.
        """
        sb = 1 if theta_1 > 0 or (theta_1 == 0 and omega_1 > 0) else -1
        ss = 1 if phi > 0 or (phi == 0 and omega_phi > 0) else -1
        return float(dyn.energy(theta_1, phi, omega_1, omega_phi, sb, ss, self.params()))


def _is_rectangle(spec: BlockSpec) -> bool:
    """A block given by width and height, or by the four corners of an upright rectangle."""
    if spec.vertices_m is None:
        return True
    verts = np.asarray(spec.vertices_m, dtype=float)
    if verts.shape != (4, 2):
        return False
    tol = RECTANGLE_TOL * float(np.ptp(verts, axis=0).max())
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    corners = {(bool(abs(x - lo[0]) <= tol), bool(abs(y - lo[1]) <= tol)) for x, y in verts}
    on_box = all(
        min(abs(x - lo[0]), abs(x - hi[0])) <= tol and min(abs(y - lo[1]), abs(y - hi[1])) <= tol for x, y in verts
    )
    return on_box and len(corners) == 4


def _friction_coefficient(scene: Scene, a: str, b: str) -> tuple[float, str]:
    """tan(phi) of the joint between blocks ``a`` and ``b`` ("base"), and the field it comes from."""
    for k, joint in enumerate(scene.joints):
        angle = joint.get("friction_angle_deg")
        if set(joint.blocks) == {a, b} and angle is not None:
            return math.tan(math.radians(float(angle))), f"joints[{k}].friction_angle_deg"
    return math.tan(math.radians(scene.contact.friction_angle_deg)), "contact.friction_angle_deg"


def _inertia(
    spec: BlockSpec, index: int, b_eq: float, h_c: float, g: float, source: str | None
) -> tuple[float, str | None]:
    """Centroidal inertia, kg m^2: the block's, or the one that gives its p (I_O = M g R / p^2)."""
    block = spec.block()
    if spec.p_rad_s is None:
        return block.inertia_c_kgm2, None
    r = math.hypot(b_eq, h_c)
    inertia = inertia_for_frequency(block.mass_kg, r, spec.p_rad_s, g) - block.mass_kg * r * r
    if inertia <= 0:
        raise InputError(
            f"blocks[{index}].p_rad_s",
            f"p = {spec.p_rad_s:g} 1/s cannot be reached by this block: it needs p^2 < g / R = {g / r:.4g} 1/s^2 "
            "(a positive centroidal inertia)",
            source,
        )
    return inertia, f"{spec.name}: centroidal inertia {inertia:.6g} kg m^2 so that p = {spec.p_rad_s:g} 1/s (Eq 3)"


def two_block_model(scene: Scene, g: float = G) -> TwoBlockModel:
    """The exact solver's model of ``scene`` (module docstring).

    Raises
    ------
    InputError
        A scene the solver cannot treat, naming the field and the reason.
    """
    src = scene.source
    if len(scene.blocks) != 2:
        raise InputError(
            "blocks",
            f"the twoblock solver takes two stacked blocks; this scene has {len(scene.blocks)} "
            "(one block: the housner solver; more: the reference, yade or siconos solver)",
            src,
        )
    if scene.positioned:
        raise InputError(
            "blocks[0].position_m",
            "the twoblock solver takes a column (the upper block on the lower one, placed by x_offset_m), "
            "not blocks placed by position_m",
            src,
        )
    if scene.loads:
        raise InputError("loads", "the twoblock solver takes no point loads (use the reference or yade solver)", src)
    for i, spec in enumerate(scene.blocks):
        if not _is_rectangle(spec):
            raise InputError(
                f"blocks[{i}].vertices_m",
                f"block {spec.name} is not a rectangle: the twoblock solver's modes and impacts are those of two "
                "stacked rectangles (use the reference or yade solver)",
                src,
            )
    lower, upper = scene.blocks
    bl, bu = lower.block(), upper.block()
    h1, h2 = bl.height_m, bu.height_m
    notes: list[str] = []
    x1 = lower.x_offset_m + bl.centroid_m[0]
    x2 = upper.x_offset_m + bu.centroid_m[0]
    hc1, hc2 = bl.centroid_m[1], bu.centroid_m[1]
    b1 = hc1 * math.tan(lower.alpha_rad) if lower.alpha_rad is not None else 0.5 * bl.width_m
    b2 = hc2 * math.tan(upper.alpha_rad) if upper.alpha_rad is not None else 0.5 * bu.width_m
    for spec, b in ((lower, b1), (upper, b2)):
        if spec.alpha_rad is not None:
            notes.append(f"{spec.name}: base corners at the equivalent base b_eq = h tan(alpha) = {b:.6g} m (Eq 11)")
    i1, note1 = _inertia(lower, 0, b1, hc1, g, src)
    i2, note2 = _inertia(upper, 1, b2, hc2, g, src)
    notes += [n for n in (note1, note2) if n]
    top_l, top_r = lower.x_offset_m + bl.level_vertices("top")[0], lower.x_offset_m + bl.level_vertices("top")[1]
    seat = (x2 - b2, x2 + b2)
    tol = SEAT_TOL * bl.width_m
    if seat[0] < top_l - tol or seat[1] > top_r + tol:
        what = "base at its b_eq" if upper.alpha_rad is not None else "base"
        raise InputError(
            "blocks[1].x_offset_m" if upper.x_offset_m else "blocks[1].width_m",
            f"the upper block's {what} spans x = [{seat[0]:.6g}, {seat[1]:.6g}] m, beyond the lower block's top "
            f"[{top_l:.6g}, {top_r:.6g}] m: its pivots must be corners of its own on that top (a wider or overhanging "
            "upper block rocks about the lower block's edge, outside this solver's modes; use the reference solver)",
            src,
        )
    if scene.contact.cohesion_Pa:
        notes.append(f"the scene's cohesion ({scene.contact.cohesion_Pa:g} Pa) is left out: joints carry no tension")
    mu_base, field_base = _friction_coefficient(scene, lower.name, "base")
    mu_seat, field_seat = _friction_coefficient(scene, upper.name, lower.name)
    model = TwoBlockModel(
        names=(lower.name, upper.name),
        mass_kg=(bl.mass_kg, bu.mass_kg),
        inertia_c_kgm2=(i1, i2),
        centroid_m=((x1, hc1), (x2, h1 + hc2)),
        base_corners_x_m=(x1 - b1, x1 + b1),
        seat_corners_x_m=seat,
        seat_y_m=h1,
        heights_m=(h1, h2),
        widths_m=(bl.width_m, bu.width_m),
        friction=(mu_base, mu_seat),
        g=g,
        notes=tuple(notes),
    )
    lam = model.onset_multiplier
    for mu, field in ((mu_base, field_base), (mu_seat, field_seat)):
        if mu <= lam:
            raise InputError(
                field,
                f"a friction coefficient tan(phi) = {mu:.4g} is at or below lambda_0 = {lam:.4g}, the ratio of "
                "horizontal to vertical contact force the joints carry when the stack starts to rock (its static "
                "uplift multiplier): the blocks would slide before they rock (Shenton 1996), outside pure rocking; "
                f"raise it above {math.degrees(math.atan(lam)):.4g} degrees or use the reference solver",
                src,
            )
    return model
