"""Identification: alpha, p and mu of a block from a measured free-rocking history.

An inverse problem that runs Housner's solver: ``measurement`` (the measured history),
``forward_model`` (the free-rocking model fitted), ``start`` (start values), ``fit`` (the
error-surface fit with its intervals) and ``identified`` (the identified-parameter file
and the DEM parameters calibrated from it).
"""
