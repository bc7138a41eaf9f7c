"""The DEM core shared by the reference DEM and the YADE backend.

``model`` (the resolved bodies, joints and time step both DEMs run), ``build`` (a scene
resolved into a model), ``matching`` (the matched-damping calibration stage, which runs
short DEM models before the scene's model is built), ``kernel`` and ``engine`` (the
numba rigid-polygon DEM and its driver), ``frames`` (sampled states as a Result frame),
``yade_payload`` (a model as the JSON data the YADE driver reads) and ``yade_driver``
(the script YADE's own Python runs: never imported by rockyade).

May import ``blocks``, ``scene``, ``motion``, ``result``; never ``solvers``.
"""
