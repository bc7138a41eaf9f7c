"""Studies built on the solvers: the paper reproduced, fragility, patterns, pulses."""
