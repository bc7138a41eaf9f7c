"""Calibration: the DEM contact parameters of a block from its classical parameters.

``equations`` (the paper's Eqs 5-15: stiffness, equivalent base, damping, time step) and
``matched`` (the contact damping that makes the reference DEM lose the target energy,
found by running the kernel on the block alone).
"""
