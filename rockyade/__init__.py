"""rockyade: seismic rocking of rigid blocks.

Housner's classical rocking theory, an exact Housner solver, DEM contact parameters
derived from the classical parameters (the seed paper's Eqs 5-15), a reference DEM and a
YADE backend reading the same scene files, base motions, analysis, reports and batches.

Data flow (one direction): block geometry -> classical parameters -> contact calibration
-> scene -> solver -> result -> analysis -> report.
"""

__version__ = "0.1.0"
