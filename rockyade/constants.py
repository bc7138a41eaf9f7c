"""Physical constants and project-wide numerical conventions."""

#: Acceleration of gravity used throughout, m/s^2. The seed paper's printed values
#: (e.g. p = 3.78 1/s for specimen 1 via Eq 3) follow from g = 9.81.
G = 9.81

#: Standard gravity (CGPM 1901), m/s^2: what a record "in g" means (PEER NGA AT2 files and
#: most accelerograph software). Records are converted with it; the paper's classical
#: parameters (p, the uplift acceleration g tan(alpha), amplitudes given in g in scenes)
#: keep :data:`G` = 9.81 as the paper computed them.
STANDARD_GRAVITY = 9.80665

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
