"""Scenes for the limit-analysis tests, made with the project's generators or by hand."""

from __future__ import annotations

from rockyade.scene import scene_from_dict
from rockyade.scene.generators import arch, rest_motion, stack, wall


def block_scene(width: float, height: float, friction_deg: float = 30.0, density: float = 2400.0):
    """One rectangular block on the base, centred on x = 0."""
    contact = {"calibration": "paper", "friction_angle_deg": friction_deg}
    return scene_from_dict(stack(widths_m=[width], heights_m=height, density_kg_m3=density, contact=contact))


def stack_scene(widths: list[float], heights: list[float], friction_deg: float = 30.0):
    """Blocks of the given sizes stacked bottom to top, centred on x = 0."""
    contact = {"calibration": "paper", "friction_angle_deg": friction_deg}
    return scene_from_dict(stack(widths_m=widths, heights_m=heights, contact=contact))


def arch_scene(t_over_r: float, voussoirs: int, radius: float = 1.0):
    """A semicircular arch of mean radius ``radius`` and ring depth t = t_over_r R on fixed piers
    (``rockyade build arch --piers fixed``)."""
    t = t_over_r * radius
    data = arch(
        span_m=2.0 * (radius - t / 2.0),
        ring_depth_m=t,
        voussoirs=voussoirs,
        pier_width_m=2.0 * t,
        pier_height_m=0.5,
        piers="fixed",
        motion=rest_motion(),
    )
    return scene_from_dict(data)


def course_wall_scene(courses: int, unit_length: float = 0.4, unit_height: float = 0.5):
    """A wall of ``courses`` equal courses of one unit each (``rockyade build wall
    --units-per-course 1 --bond stack``)."""
    return scene_from_dict(
        wall(courses=courses, units_per_course=1, bond="stack", unit_length_m=unit_length, unit_height_m=unit_height)
    )


def positioned_scene(blocks: list[dict], friction_deg: float = 30.0, joints: list[dict] | None = None):
    """A scene of hand-placed rectangles: dicts with name, width_m, height_m, position_m (and fixed)."""
    table = []
    for b in blocks:
        entry = {"thickness_m": 0.2, "density_kg_m3": 2000.0, **b}
        table.append(entry)
    data = {
        "duration_s": 1.0,
        "sample_dt_s": 0.01,
        "blocks": table,
        "contact": {"calibration": "paper", "friction_angle_deg": friction_deg},
        "motion": rest_motion(),
    }
    if joints:
        data["joints"] = joints
    return scene_from_dict(data)


def corner_friction_wall(corner_friction_deg: float = 35.0):
    """The 8-course tuff wall restrained on the far face of its top course, its roof without mass and the
    restraint's contact with the top corner of the course below at ``corner_friction_deg``
    (:func:`rockyade.studies.verify_assess.corner_friction_wall`)."""
    from rockyade.studies.verify_assess import corner_friction_wall as scene

    return scene(corner_friction_deg)
