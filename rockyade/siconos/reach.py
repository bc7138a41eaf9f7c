"""A block that starts above its support beyond the reach of Siconos's pairs is refused.

The driver finds its vertex-to-edge pairs once, from the starting geometry
(:func:`rockyade.siconos.driver.contact_pairs`): a vertex pairs with another block's edge when it
lies at most ``PAIR_REACH_FRACTION`` of the smaller block's largest dimension outside it. Every
vertex is paired with the ground, but a block that starts higher than that above the block under
it has no pair with it: it falls through that block, and the collapse rule calls the drop a fall
(measured: a 3-course wall whose top course starts 0.2 m above the second, 0.125 m of reach,
ended ``overturned`` at 0.5 s with its top course 1.2 m down, where the reference DEM and YADE
land it on the second course and the wall stands).
"""

from __future__ import annotations

from rockyade.errors import InputError
from rockyade.scene import Scene
from rockyade.scene.placement import TOUCH_TOL, placed_blocks, scene_rest_contacts
from rockyade.siconos.payload import PAIR_REACH_FRACTION


def check_landing_reach(scene: Scene) -> None:
    """Refuse a moving block that touches nothing at rest and whose nearest block below (one
    that its x-range overlaps and whose top lies at or below its lowest point) is farther than
    the pairs' reach, m (a block that touches the base or another block, as every course of a
    wall and every voussoir of an arch does, is left alone).

    Raises
    ------
    InputError
        Naming ``blocks[i].position_m`` (the higher block), the gap and the reach.
    """
    placed = placed_blocks(scene)
    touching = {i for c in scene_rest_contacts(scene) for i in (c.a, c.b)}
    for a in placed:
        if a.fixed or a.index in touching:
            continue
        low = float(a.vertices_m[:, 1].min())
        left, right = float(a.vertices_m[:, 0].min()), float(a.vertices_m[:, 0].max())
        nearest = None
        for b in placed:
            if b is a:
                continue
            top = float(b.vertices_m[:, 1].max())
            overlap = min(right, float(b.vertices_m[:, 0].max())) - max(left, float(b.vertices_m[:, 0].min()))
            tol = TOUCH_TOL * min(a.size_m, b.size_m)
            if overlap > tol and top <= low + tol and (nearest is None or low - top < nearest[1]):
                nearest = (b, low - top)
        if nearest is None:
            continue
        below, gap = nearest
        reach = PAIR_REACH_FRACTION * min(a.size_m, below.size_m)
        if gap > reach:
            raise InputError(
                f"blocks[{a.index}].position_m",
                f"block {a.name} starts {gap:.4g} m above block {below.name}, beyond the {reach:.4g} m within which "
                f"the siconos solver pairs a block with the one it lands on (its pairs are found once, from the "
                f"start: {a.name} would fall through {below.name}); place it at most {reach:.4g} m above "
                f"{below.name}, or run the reference or yade solver",
                scene.source,
            )
