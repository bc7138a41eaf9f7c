"""The Siconos backend: a scene as data for Siconos's driver, its calibration from the
classical parameters, and the machinery that runs it in Debian's Python.

``payload`` (the scene as the JSON data the driver reads), ``calibration`` (alpha, p and
mu carried to nonsmooth contact dynamics; the default time step), ``backend`` (the run,
parsed back into a Result) and ``driver`` (the script Debian's Python runs: it imports
nothing from rockyade).
"""
