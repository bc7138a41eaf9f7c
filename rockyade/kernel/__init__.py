"""The reference DEM's numba kernel: rigid convex polygons with the paper's joint.

Arrays in, arrays out: it knows nothing of scenes or models. ``simulation`` (the time
loop), ``contacts`` (the manifold of a pair of touching polygons) and ``broadphase``
(sort-and-sweep: which pairs can touch).
"""
