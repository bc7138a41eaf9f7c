"""The reference DEM's numba kernel: rigid convex polygons with the paper's joint.

Arrays in, arrays out: it knows nothing of scenes or models. One module per part:

* ``state``: the inputs as five records (``Bodies``, ``Joints``, ``BaseMotion``, ``Settings``,
  ``Initial``) and ``pack``, which makes them from :func:`rockyade.dem.engine.model_arrays`;
* ``simulation``: the time loop, ``simulate`` (set-up, broad-phase rebuilds, the ``Output``
  record) and ``advance`` (the steps between two rebuilds, as a short sequence of the parts);
* ``world``: the polygons in the base frame;
* ``contact_law``: the joint at one contact point (no-tension spring and dashpot,
  incremental Coulomb-capped shear spring, shear dashpot while sticking), written once;
* ``base_contacts`` and ``pair_contacts``: where the law applies (vertices below the base;
  the manifold of each touching pair, from ``narrowphase``: separating-axis test and clipping);
* ``broadphase`` and ``pairs``: sort and sweep over grown boxes, and what each candidate
  pair keeps between steps;
* ``integration``: the leap-frog kick and drift, overturn and blow-up checks;
* ``energy`` and ``recording``: energy terms and sampled outputs.

The base acceleration is looked up by :func:`rockyade.motion.ground.ground_acceleration`,
shared with Housner's solver.

The parts that run every step are ``inline="always"``: numba compiles them into ``advance``,
which is compiled without reference counting (``_nrt=False``). A part that allocates arrays
must therefore run outside ``advance`` (set-up and rebuilds, in ``simulate``).
"""
