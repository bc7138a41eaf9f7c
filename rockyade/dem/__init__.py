"""The DEM core shared by the reference DEM and the YADE backend.

``model`` (the resolved bodies, joints and time step both DEMs run), ``build`` (a scene
resolved into a model), ``joints`` (which pair of blocks gets which joint: bed, head,
base, fixed, UDEC-style per-area stiffness, overrides), ``statics`` (the time step's
stability limit and the settlement check of an assembly at rest), ``matching`` (the
matched-damping calibration stage, which runs short DEM models before the scene's model
is built), ``contacts`` (the contact manifold of a pair of touching polygons),
``broadphase`` (sort-and-sweep: which pairs can touch), ``kernel`` and ``engine`` (the
numba rigid-polygon DEM and its driver), ``overturn`` (the landing-angle overturn
criterion both DEMs use), ``frames`` (sampled states as a Result frame),
``yade_payload`` and ``yade_contacts`` (a model as the JSON data the YADE driver reads,
with the per-pair joints of its vertex spheres) and ``yade_driver`` (the script YADE's
own Python runs: never imported by rockyade).

May import ``blocks``, ``scene``, ``motion``, ``result``; never ``solvers``.
"""
