"""The calibrated DEM model of a scene: the stage every DEM solver calls.

Every moving block is calibrated by the scene's method
(:func:`rockyade.calibration.calibrate.calibrate`; a matched one runs short DEM models of
the block alone first), then the model is built with those joints
(:func:`rockyade.dem.model_from_scene.build_dem_model`, which knows no calibration).
"""

from __future__ import annotations

from rockyade.calibration.calibrate import calibrate
from rockyade.constants import G
from rockyade.dem.model import DemModel
from rockyade.dem.model_from_scene import build_dem_model
from rockyade.scene import Scene


def supported_masses(scene: Scene) -> list[float]:
    """Mass resting on each block's base joint, kg: in a column the block and those above
    it; in an assembly each block's own mass (the model's statics check the load paths).

    Parameters
    ----------
    scene
        A validated scene (blocks bottom to top).
    """
    masses = [b.block().mass_kg for b in scene.blocks]
    if scene.positioned:
        return masses
    return [sum(masses[i:]) for i in range(len(masses))]


def calibrated_model(scene: Scene, g: float = G, *, rigid_contacts: bool = False) -> DemModel:
    """The scene's DEM model, every moving block's joint calibrated first (module docstring).

    The last scene's model is kept: the model is frozen and only read by the solvers, so the
    cost estimate of ``rockyade run`` and the run itself share it (a 1,000-block wall spends
    seconds here). Only one is kept, so that a study's many scenes do not hold their models.

    Parameters
    ----------
    scene
        A validated scene.
    g
        Gravity, m/s^2.
    rigid_contacts
        For a rigid-contact solver (Siconos): the penalty springs' settlement check is
        skipped (:func:`rockyade.dem.model_from_scene.build_dem_model`).
    """
    global _LAST
    if _LAST is not None and _LAST[0] is scene and _LAST[1] == g and _LAST[3] == rigid_contacts:
        return _LAST[2]
    model = _calibrated_model(scene, g, rigid_contacts)
    _LAST = (scene, g, model, rigid_contacts)  # the scene itself, so that its id is not reused while kept
    return model


#: The last (scene, g, model, rigid_contacts) of :func:`calibrated_model`.
_LAST: tuple[Scene, float, DemModel, bool] | None = None


def _calibrated_model(scene: Scene, g: float, rigid_contacts: bool) -> DemModel:
    supported = supported_masses(scene)
    joints = [
        None
        if spec.fixed
        else calibrate(
            spec.block(),
            scene.contact,
            alpha_rad=spec.alpha_rad,
            p_rad_s=spec.p_rad_s,
            mu=spec.mu,
            supported_mass_kg=supported[i],
            g=g,
        ).joint
        for i, spec in enumerate(scene.blocks)
    ]
    return build_dem_model(scene, joints, g=g, rigid_contacts=rigid_contacts)
