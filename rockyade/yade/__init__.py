"""The YADE backend's translation of a DEM model.

``payload`` and ``contact_plan`` (a model as the JSON data the driver reads, with the per-pair
joints of its vertex spheres) and ``driver`` (the script YADE's own Python runs: it
imports nothing from rockyade).
"""
