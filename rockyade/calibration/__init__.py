"""Calibration: the DEM contact parameters of a block from its classical parameters.

``equations`` (the paper's Eqs 5-15: stiffness, equivalent base, damping), ``calibrate``
(the one calibration of a block, whatever the method: paper, matched, explicit, UDEC-style),
``matching`` (the contact damping that makes the reference DEM lose the target energy, found
by running the model builder and the engine on the block alone) and ``model_stage``
(:func:`~rockyade.calibration.model_stage.calibrated_model`, the stage every DEM solver calls:
calibrate every moving block, then build the model). Sits above :mod:`rockyade.dem`, which
runs the joints it is given.
"""
