"""The names of ``rockyade verify``'s checks, in the order they run (a module of its own so
that the command's parser lists them without importing the checks themselves)."""

CHECKS = (
    "frame",
    "drums",
    "pad",
    "wall",
    "agreement",
    "baseline",
    "kinematic",
    "code",
    "fragility_fit",
    "loaded_block",
    "loaded_mass",
    "loaded_classical",
    "code_friction",
    "crushing",
    "loaded_pushover",
    "limit_pushover",
    "floor_spectrum",
    "siconos",
)
