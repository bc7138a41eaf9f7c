"""Physical constants and project-wide numerical conventions."""

#: Acceleration of gravity of the mechanics, m/s^2: the blocks' weights (scenes, limit analysis, DEMs,
#: YADE, Housner) and the paper's classical parameters. The seed paper's printed values (e.g.
#: p = 3.78 1/s for specimen 1 via Eq 3) follow from g = 9.81, so the paper's numbers are reproduced
#: with it (docs/conventions.md, "g").
G = 9.81

#: Standard gravity (CGPM 1901), m/s^2: what a record "in g" means (PEER NGA AT2 files and
#: most accelerograph software). Records are converted with it; the paper's classical
#: parameters (p, the uplift acceleration g tan(alpha), amplitudes given in g in scenes)
#: keep :data:`G` = 9.81 as the paper computed them.
STANDARD_GRAVITY = 9.80665

#: The g of the code check, m/s^2: standard gravity, the same g as records in g. An acceleration
#: given in g (a site's ag, the PGA of a fragility median, a spectrum in g) is turned into m/s^2
#: with it, and so is alpha0 into a0* = alpha0 g / (e* FC) (and alpha into a*): ``assess``,
#: ``fragility``, ``limit`` and ``motion info`` print the same m/s^2 for the same value in g.
CODE_GRAVITY = STANDARD_GRAVITY

#: Units in which accelerations are reported (printed summaries, figure axes), in m/s^2 per
#: unit: "g" is standard gravity, as in the records. Engineers read PGA in g, so the
#: commands about PGA report in g by default, with m/s^2 beside it.
ACCEL_UNITS = {"g": STANDARD_GRAVITY, "m/s2": 1.0}
#: How each unit is written in figure labels (mathtext) and in plain text.
ACCEL_UNIT_LABELS = {"g": "g", "m/s2": "m/s$^2$"}
ACCEL_UNIT_TEXT = {"g": "g", "m/s2": "m/s^2"}

#: A figure axis of load factors: a load factor multiplies the base accelerations as read
#: (a record's samples as in its file; docs/conventions.md).
LOAD_FACTOR_LABEL = "load factor (x the record's accelerations as read)"

#: Stiffness scale applied to the paper's printed K (Tables 5-6 and Eq 10) by default.
#: Read as N/m, Eq 10's K lets specimen 1 sink Mg/K ~ 0.7 m into its base; read as MN/m the
#: static settlement is ~1 micrometre and the DEM rocks as Housner predicts (DESIGN.md).
DEFAULT_STIFFNESS_SCALE = 1.0e6

#: Named readings of the paper's stiffness unit -> factor to N/m.
STIFFNESS_SCALES = {"N/m": 1.0, "kN/m": 1.0e3, "MN/m": 1.0e6}

#: Largest static settlement M g / K accepted, as a fraction of the block height.
MAX_SETTLEMENT_FRACTION = 1.0e-4

#: Default friction angle of the joints (paper Section 6.1, after its ref. [8]), degrees.
DEFAULT_FRICTION_ANGLE_DEG = 30.0

#: Default fraction in the time step of Eq 7.
DEFAULT_TIME_STEP_FRAC = 0.1
