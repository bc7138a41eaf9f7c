"""The rigid-block model of a scene for limit analysis: blocks, interfaces, friction, loads.

Every block of the scene is a rigid convex polygon placed as :func:`~rockyade.scene.placement.placed_blocks`
places it; its weight m g acts at its centroid. Fixed blocks and the base are supports. Every
interface at rest (:func:`~rockyade.scene.placement.rest_contacts`: two bodies sharing a segment)
carries a contact force at each of its two ends: a normal force n >= 0 (no tension, no
cohesion) and a tangential force t with |t| <= tan(phi) n (Coulomb), or any t at all when
sliding is excluded. The resultant of the two end forces can lie anywhere on the interface,
which is exactly what a no-tension joint of a rigid block can carry.

External loads (:class:`PointLoad`): a floor's reaction, an overburden, each with the mass
that moves with its block (by default the mass of its weight, -F_y / g: the code counts the
vertical loads a wall carries among the forces P_i the horizontal acceleration acts on,
Circolare 2019 C8.7.1; :mod:`rockyade.scene.carried`). A load's mass is merged into its block
(:func:`rockyade.scene.carried.loaded_mass_properties`): ``masses_kg`` and ``centroids_m`` are
those of the loaded blocks, so the weight m g and the horizontal force lambda m g of the load
act at its point; ``loads`` keeps only what is not the weight of a mass
(:func:`rockyade.scene.carried.residual_force`: all of a massless load). ``given_loads`` are
the loads as given, their masses resolved, for the report and the code's P_i.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TypedDict

import numpy as np
from numpy.typing import NDArray

from rockyade.blocks.geometry import polygon_section
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.limit.point_contacts import PointContact, point_contacts
from rockyade.scene.carried import carried_on, load_mass_kg, loaded_mass_properties, residual_force
from rockyade.scene.placement import TOUCH_TOL, placed_blocks, rest_contacts

#: The base's name in interfaces, hinges and output.
BASE = "base"
#: Largest load accepted, N (keeps the arithmetic finite; 1e12 N is a million tonnes-force).
MAX_LOAD_N = 1.0e12


@dataclass(frozen=True)
class PointLoad:
    """A force applied to a block, with its mass (a floor's reaction, an overburden).

    Attributes
    ----------
    block
        The block it acts on: its index in the scene's block list, or its name.
    point_m
        Point of application at rest, base frame, m (on or inside the block); it moves with
        the block when the mechanism is followed at finite displacement.
    force_N
        Force vector (Fx, Fy), N (e.g. (0, -N) for a vertical load N). Its direction stays
        the same when the block moves (a dead load).
    mass_kg
        Its mass moving with the block, kg; None: the mass of its weight, -F_y / g (module
        docstring); 0: a force without mass.
    """

    block: int | str
    point_m: tuple[float, float]
    force_N: tuple[float, float]
    mass_kg: float | None = None


class LoadRow(TypedDict):
    """A given load as plain data (:meth:`RigidBlockModel.loads_table`, the JSON's ``loads``)."""

    block: str
    point_m: list[float]
    force_N: list[float]
    mass_kg: float
    mass_takes_part: bool
    why: str


@dataclass(frozen=True)
class Interface:
    """A joint at rest between body ``a`` (moving) and body ``b`` (another block, or the base).

    Attributes
    ----------
    a, b
        Body indices; ``b = -1`` is the base. The normal points from ``b`` into ``a``; ``a``
        is the moving body of a joint with a fixed one, else the upper body of a bed joint.
    ends_m
        (2, 2) the two ends of the shared segment, base frame, m.
    normal
        Unit normal from ``b`` into ``a``.
    friction_angle_deg
        Friction angle of the joint, degrees; None when sliding is excluded.
    kind
        "bed" or "head" (see :mod:`rockyade.scene.placement`).
    """

    a: int
    b: int
    ends_m: NDArray[np.float64]
    normal: NDArray[np.float64]
    friction_angle_deg: float | None
    kind: str

    @property
    def tangent(self) -> NDArray[np.float64]:
        """Unit tangent, the normal turned 90 degrees counter-clockwise."""
        return np.array([-self.normal[1], self.normal[0]])

    @property
    def length_m(self) -> float:
        """Length of the interface, m."""
        return float(np.hypot(*(self.ends_m[1] - self.ends_m[0])))


@dataclass(frozen=True)
class Corner:
    """A point contact with several ways to hold (:mod:`rockyade.limit.point_contacts`).

    Attributes
    ----------
    a, b
        Body indices (``b = -1``: the base); ``a`` moves.
    point_m
        The point at rest, base frame, m.
    ways
        Each way as the interfaces (zero length, at the point) that make it.
    """

    a: int
    b: int
    point_m: tuple[float, float]
    ways: tuple[tuple[Interface, ...], ...]


@dataclass(frozen=True)
class RigidBlockModel:
    """A scene as rigid blocks, interfaces and loads (module docstring).

    Attributes
    ----------
    names
        Block names, in the scene's order.
    masses_kg
        (nb,) masses of the loaded blocks (each with the masses it carries), kg.
    centroids_m
        (nb, 2) centroids of the loaded blocks at rest, base frame, m.
    polygons_m
        Block polygons at rest, base frame, m (counter-clockwise).
    fixed
        (nb,) True for blocks that move with the base.
    interfaces
        The joints at rest.
    loads
        The forces beyond the carried masses' weights, ``block`` resolved to an index.
    g
        Acceleration of gravity, m/s^2.
    notes
        What of the scene the model leaves out (cohesion, classical overrides), said once each.
    given_loads
        The loads as given, ``block`` an index and ``mass_kg`` resolved to kg (module docstring).
    block_masses_kg, block_centroids_m
        The blocks' own masses, kg, and centroids, m (None: as ``masses_kg``, ``centroids_m``).
    corners
        Point contacts that can hold in more than one way (two corners meeting, one of them on a
        fixed block or the base: :mod:`rockyade.limit.point_contacts`), each with its ways as
        interfaces of zero length; :func:`rockyade.limit.admissible.solve_admissible` chooses.
        Point contacts with one way are among ``interfaces`` (kind "corner").
    depths_m
        (nb,) the blocks' depth out of the section (the scene's ``thickness_m``: a wall's length), m;
        the joints' depth where the masonry's compressive strength counts (:mod:`rockyade.limit.crushing`).
    """

    names: tuple[str, ...]
    masses_kg: NDArray[np.float64]
    centroids_m: NDArray[np.float64]
    polygons_m: tuple[NDArray[np.float64], ...]
    fixed: NDArray[np.bool_]
    interfaces: tuple[Interface, ...]
    loads: tuple[PointLoad, ...] = ()
    g: float = G
    notes: tuple[str, ...] = ()
    corners: tuple[Corner, ...] = ()
    given_loads: tuple[PointLoad, ...] = ()
    block_masses_kg: NDArray[np.float64] | None = None
    block_centroids_m: NDArray[np.float64] | None = None
    depths_m: NDArray[np.float64] | None = None

    def weight_points(self) -> list[tuple[int, NDArray[np.float64], float]]:
        """(block, point at rest, mass kg) of every mass the horizontal acceleration acts on: each
        moving block's own at its centroid and each carried load's at its point (the code's P_i)."""
        own_m = self.masses_kg if self.block_masses_kg is None else self.block_masses_kg
        own_c = self.centroids_m if self.block_centroids_m is None else self.block_centroids_m
        out = [(int(i), np.asarray(own_c[i], dtype=float), float(own_m[i])) for i in self.moving]
        for load in self.given_loads:
            i = int(load.block)
            if not self.fixed[i] and load.mass_kg:
                out.append((i, np.asarray(load.point_m, dtype=float), float(load.mass_kg)))
        return out

    def loads_table(self) -> list[LoadRow]:
        """Each given load as plain data: its block, point, force, mass and whether the mass
        takes part in the horizontal acceleration (and so in the code's P_i)."""
        out: list[LoadRow] = []
        for q in self.given_loads:
            i = int(q.block)
            mass = float(q.mass_kg or 0.0)
            if self.fixed[i]:
                why = "on a fixed block: it goes straight to the base"
            elif mass > 0.0:
                why = "its mass shakes with its block (a P_i of the kinematic method, Circolare 2019 C8.7.1)"
            else:
                why = "given without mass (mass_kg = 0): its horizontal force is taken elsewhere"
            out.append(
                LoadRow(
                    block=self.names[i],
                    point_m=list(q.point_m),
                    force_N=list(q.force_N),
                    mass_kg=mass,
                    mass_takes_part=bool(mass > 0.0 and not self.fixed[i]),
                    why=why,
                )
            )
        return out

    def load_lines(self) -> list[str]:
        """One line per load for the text reports: force, point and whether its mass takes part."""
        lines = []
        for k, q in enumerate(self.loads_table()):
            fx, fy = q["force_N"]
            mass = f"with its mass {q['mass_kg']:.4g} kg" if q["mass_takes_part"] else "without mass"
            lines.append(
                f"load {k}: ({fx:.4g}, {fy:.4g}) N on {q['block']} at "
                f"({q['point_m'][0]:.4g}, {q['point_m'][1]:.4g}) m, "
                f"{mass}: {q['why']}"
            )
        return lines

    @property
    def n_blocks(self) -> int:
        """Number of blocks (fixed ones included)."""
        return len(self.names)

    @property
    def moving(self) -> NDArray[np.int64]:
        """Indices of the blocks that are not fixed."""
        return np.flatnonzero(~self.fixed)

    @functools.cached_property
    def size_m(self) -> float:
        """Largest extent of the assembly, m (the length scale of tolerances)."""
        pts = np.vstack(self.polygons_m)
        return float(np.max(np.ptp(pts, axis=0)))

    def body_name(self, index: int) -> str:
        """Name of body ``index`` (``"base"`` for -1)."""
        return BASE if index < 0 else self.names[index]


def _mass(spec, polygon: NDArray[np.float64]) -> float:
    """A block's mass, kg: its ``mass_kg``, else density x section area x thickness (as
    :meth:`rockyade.blocks.geometry.Block.polygon` computes it)."""
    if spec.mass_kg is not None:
        return float(spec.mass_kg)
    return float(spec.density_kg_m3) * polygon_section(polygon).area_m2 * float(spec.thickness_m)


def _friction_of(scene, a: int, b: int, default_deg: float) -> float:
    """The scene's friction angle of the joint between blocks ``a`` and ``b`` (-1: base), degrees:
    a ``[[joints]]`` entry naming the pair, else ``default_deg``."""
    na = scene.blocks[a].name
    nb = BASE if b < 0 else scene.blocks[b].name
    for joint in scene.joints:
        if set(joint.blocks) == {na, nb}:
            value = joint.get("friction_angle_deg")
            if value is not None:
                return float(value)
    return default_deg


def _left_out(scene) -> tuple[str, ...]:
    """Notes on what of the scene the rigid-block model does not use."""
    notes = []
    if scene.contact.cohesion_Pa:
        notes.append(f"the scene's cohesion ({scene.contact.cohesion_Pa:g} Pa) is left out: joints carry no tension")
    overridden = [b.name for b in scene.blocks if b.alpha_rad is not None]
    if overridden:
        shown = ", ".join(overridden[:5]) + (" ..." if len(overridden) > 5 else "")
        notes.append(
            f"alpha_rad given for {shown} is not used: limit analysis takes the blocks' geometry "
            "(the corners are the pivots)"
        )
    return tuple(notes)


#: The largest friction angle of the programme, degrees. Its cone columns are n +- tan(phi) t
#: (:mod:`rockyade.limit.lp`): they lose digits as tan(phi)^2 (HiGHS's answer on the 5-course example
#: wall: the mechanism's closing residual 1.8e-11 at 89.9 deg, 7.5e-9 at 89.99, 4.6e-7 at 89.999, near
#: the mechanism's tolerance 1e-6; at 89.9999 lambda is off by 1.5e-6 and HiPO fails). tan(89.9 deg) = 573
#: is friction no joint has; a joint that does not slide is --no-sliding (sliding=False).
MAX_FRICTION_ANGLE_DEG = 89.9
_WHY_MAX = (
    "the programme's cone columns n +- tan(phi) t lose digits as tan(phi)^2 above it (tan(89.9 deg) = 573); "
    "for joints that do not slide, --no-sliding"
)


def check_friction_angle(value: float, field: str = "friction_angle_deg") -> float:
    """A friction angle in [0, :data:`MAX_FRICTION_ANGLE_DEG`] degrees, else InputError naming ``field``."""
    top = f"{MAX_FRICTION_ANGLE_DEG:g}"
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise InputError(field, f"must be a number of degrees in [0, {top}], got {value!r}")
    if not 0.0 <= value <= MAX_FRICTION_ANGLE_DEG:
        raise InputError(field, f"must be in [0, {top}] degrees, got {value:g}: {_WHY_MAX}")
    return float(value)


def _resolve_loads(loads: Sequence[PointLoad], names: tuple[str, ...], polygons) -> tuple[PointLoad, ...]:
    """Loads with their block as an index, checked: the block exists, the numbers are finite,
    the point lies on or inside the block."""
    out = []
    for k, load in enumerate(loads):
        field = f"loads[{k}]"
        if not isinstance(load, PointLoad):
            raise InputError(field, f"must be a PointLoad(block, point_m, force_N), got {type(load).__name__}")
        block = load.block
        if isinstance(block, str):
            if block not in names:
                shown = ", ".join(names[:10]) + (" ..." if len(names) > 10 else "")
                raise InputError(f"{field}.block", f"no block named {block!r}; blocks: {shown}")
            index = names.index(block)
        elif isinstance(block, (int, np.integer)) and not isinstance(block, bool) and 0 <= block < len(names):
            index = int(block)
        else:
            raise InputError(
                f"{field}.block", f"must be a block name or an index in [0, {len(names) - 1}], got {block!r}"
            )
        point = _pair(load.point_m, f"{field}.point_m", "m", 1.0e3)
        force = _pair(load.force_N, f"{field}.force_N", "N", MAX_LOAD_N)
        poly = polygons[index]
        size = float(np.max(np.ptp(poly, axis=0)))
        if _outside(poly, np.asarray(point)) > 1e-9 * size:
            raise InputError(
                f"{field}.point_m",
                f"({point[0]:g}, {point[1]:g}) m is not on block {names[index]} (a load acts on its block)",
            )
        mass = load.mass_kg
        if mass is not None:
            mass = float(mass)
            if not (math.isfinite(mass) and 0.0 <= mass <= MAX_LOAD_N):
                raise InputError(f"{field}.mass_kg", f"must be a finite mass in [0, {MAX_LOAD_N:g}] kg, got {mass!r}")
        out.append(PointLoad(index, point, force, mass))
    return tuple(out)


def _carry(
    masses: NDArray[np.float64], centroids: NDArray[np.float64], fixed, loads: Sequence[PointLoad], g: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], tuple[PointLoad, ...], tuple[PointLoad, ...]]:
    """The loaded blocks' masses and centroids, the loads with their masses resolved, and the
    forces left beyond the carried weights (module docstring)."""
    given = tuple(
        PointLoad(q.block, q.point_m, q.force_N, load_mass_kg(q, g) if not fixed[int(q.block)] else 0.0) for q in loads
    )
    masses, centroids = masses.copy(), centroids.copy()
    for i in sorted({int(q.block) for q in given if q.mass_kg}):
        props = loaded_mass_properties(masses[i], centroids[i], 0.0, carried_on(given, i, g))
        masses[i], centroids[i] = props.mass_kg, props.centroid_m
    rest = []
    for q in given:
        f = residual_force(q, g)
        if f != (0.0, 0.0):
            rest.append(PointLoad(q.block, q.point_m, f, 0.0))
    return masses, centroids, given, tuple(rest)


def _pair(value, field: str, unit: str, bound: float) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(field, f"must be two numbers ({unit}), got {value!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)) or max(abs(x), abs(y)) > bound:
        raise InputError(field, f"must be two finite numbers within [-{bound:g}, {bound:g}] {unit}, got {value!r}")
    return (x, y)


def _outside(poly: NDArray[np.float64], point: NDArray[np.float64]) -> float:
    """How far ``point`` lies outside the counter-clockwise convex polygon (<= 0: inside), m."""
    edges = np.roll(poly, -1, axis=0) - poly
    normals = np.column_stack([edges[:, 1], -edges[:, 0]])
    normals /= np.hypot(normals[:, 0], normals[:, 1])[:, None]
    return float(np.max(np.einsum("ij,ij->i", point - poly, normals)))


def _point_contacts(placed, polygons, fixed, rest) -> list[PointContact]:
    """The point contacts of the placed blocks where no joint of ``rest`` passes
    (:func:`rockyade.limit.point_contacts.point_contacts`)."""
    tol = TOUCH_TOL * max((b.size_m for b in placed), default=1.0)
    segments: dict[tuple[int, int], list[NDArray[np.float64]]] = {}
    for c in rest:
        segments.setdefault((min(c.a, c.b), max(c.a, c.b)), []).append(np.asarray(c.ends_m, dtype=float))

    def covered(i: int, j: int, p: NDArray[np.float64]) -> bool:
        for e0, e1 in segments.get((min(i, j), max(i, j)), ()):
            d = e1 - e0
            s = float(np.clip((p - e0) @ d / max(float(d @ d), 1e-300), 0.0, 1.0))
            if np.hypot(*(e0 + s * d - p)) <= tol:
                return True
        return False

    return point_contacts(polygons, fixed, covered, tol)


def scene_loads(scene) -> tuple[PointLoad, ...]:
    """The scene's ``[[loads]]`` as :class:`PointLoad` (block by name, point and force as given)."""
    return tuple(
        PointLoad(q.block, tuple(q.point_m), tuple(q.force_N), getattr(q, "mass_kg", None))
        for q in getattr(scene, "loads", ())
    )


def rigid_block_model(
    scene,
    loads: Sequence[PointLoad] = (),
    friction_angle_deg: float | None = None,
    sliding: bool = True,
    g: float = G,
) -> RigidBlockModel:
    """The rigid-block model of a scene (module docstring).

    Parameters
    ----------
    scene
        A validated :class:`~rockyade.scene.Scene` (an assembly or a column).
    loads
        External loads (:class:`PointLoad`, with their mass: by default that of their
        weight), added to the scene's own ``[[loads]]`` (which always act).
    friction_angle_deg
        Friction angle of every joint, degrees in [0, 90). None: each joint's own from the
        scene (a ``[[joints]]`` entry for the pair, else ``[contact] friction_angle_deg``).
    sliding
        False: no joint slides (the tangential force is unbounded), whatever the friction.
    g
        Acceleration of gravity, m/s^2.

    Returns
    -------
    RigidBlockModel
    """
    if friction_angle_deg is not None:
        friction_angle_deg = check_friction_angle(friction_angle_deg)
    placed = placed_blocks(scene)
    names = tuple(b.name for b in placed)
    polygons = tuple(np.asarray(b.vertices_m, dtype=float) for b in placed)
    masses = np.array([_mass(spec, poly) for spec, poly in zip(scene.blocks, polygons, strict=True)])
    centroids = np.array([b.centroid_m for b in placed], dtype=float)
    fixed = np.array([b.fixed for b in placed], dtype=bool)
    default = float(scene.contact.friction_angle_deg) if friction_angle_deg is None else friction_angle_deg
    interfaces = []
    rest = rest_contacts(placed)
    for c in rest:
        a, b = c.a, c.b
        normal = np.asarray(c.normal, dtype=float)
        # the moving body first, else the upper body of a bed joint (the normal points into a)
        if b >= 0 and (fixed[a] or (not fixed[b] and c.kind == "bed" and c.upper == b)):
            a, b, normal = b, a, -normal
        if friction_angle_deg is not None or not sliding:
            phi = friction_angle_deg
        else:
            phi = _friction_of(scene, a, b, default)
        if sliding and phi is not None and phi > MAX_FRICTION_ANGLE_DEG:
            field = f"the joint {names[a]}-{BASE if b < 0 else names[b]}'s friction_angle_deg (scene)"
            check_friction_angle(phi, field)
        interfaces.append(Interface(a, b, np.asarray(c.ends_m, dtype=float), normal, phi if sliding else None, c.kind))
    corners = []
    for pc in _point_contacts(placed, polygons, fixed, rest):
        if friction_angle_deg is not None or not sliding:
            phi = friction_angle_deg
        else:
            phi = _friction_of(scene, pc.a, pc.b, default)
        ends = np.array([pc.point_m, pc.point_m])
        ways = tuple(
            tuple(Interface(pc.a, pc.b, ends, np.asarray(n), phi if sliding else None, "corner") for n in way)
            for way in pc.ways
        )
        if len(ways) == 1:
            interfaces.extend(ways[0])
        elif ways and (fixed[pc.a] or pc.b < 0 or fixed[pc.b]):
            corners.append(Corner(pc.a, pc.b, pc.point_m, ways))
    touching = {b for itf in interfaces for b in (itf.a, itf.b)} | {b for c in corners for b in (c.a, c.b)}
    idle = [names[i] for i in np.flatnonzero(fixed) if i not in touching]
    notes = _left_out(scene)
    if idle:
        shown = ", ".join(idle[:5]) + (" ..." if len(idle) > 5 else "")
        notes += (
            f"fixed block(s) {shown} touch no moving block at rest: they take no part in the limit analysis "
            "(a gap left on purpose, or a block not placed as meant)",
        )
    resolved = _resolve_loads(scene_loads(scene) + tuple(loads), names, polygons)
    loaded_m, loaded_c, given, residual = _carry(masses, centroids, fixed, resolved, float(g))
    return RigidBlockModel(
        corners=tuple(corners),
        notes=notes,
        names=names,
        masses_kg=loaded_m,
        centroids_m=loaded_c,
        polygons_m=polygons,
        fixed=fixed,
        interfaces=tuple(interfaces),
        loads=residual,
        g=float(g),
        given_loads=given,
        block_masses_kg=masses,
        block_centroids_m=centroids,
        depths_m=np.array([float(spec.thickness_m) for spec in scene.blocks]),
    )
