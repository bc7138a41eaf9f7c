"""The DEM model shared by the reference DEM and the YADE backend.

``model`` (the resolved bodies, joints and time step both DEMs run), ``model_from_scene`` (a scene
resolved into a model), ``joints`` (which pair of blocks gets which joint: bed, head,
base, fixed, UDEC-style per-area stiffness, overrides), ``statics`` (the time step's
stability limit and the settlement check of an assembly at rest), ``engine`` (a model run
by the reference kernel, :mod:`rockyade.kernel`), ``overturn`` (the landing-angle overturn
criterion both DEMs use) and ``result_frames`` (sampled states as a Result frame).
"""
