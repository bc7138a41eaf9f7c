"""Write ``specimen1_free_rocking.csv``: a measured-like free-rocking test made by rockyade.

Specimen 1 of the paper with its experimental parameters (alpha = 0.235 rad, p = 3.84 1/s,
mu = 0.936), held at 0.12 rad for 0.8 s, then released; sampled at 200 Hz for 8 s.
Columns: ``t_s``; ``theta_rad``, an inclinometer with a 0.002 rad offset and Gaussian noise
of 1.2e-3 rad (0.5 % of alpha); ``led1_y_m`` and ``led2_y_m``, the vertical displacements of
two targets 0.20 m apart at 0.80 m height (x = -0.10 and +0.10 m from the axis), zeroed at
the start of the recording (while the block is held tilted), with 0.1 mm noise.

    .venv/bin/python examples/measured/make_free_rocking_measurement.py
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from rockyade.identification.fit import FreeRockingFit, model_history
from rockyade.io.atomic import atomic_open

SEED = 12
RATE_HZ = 200.0
DURATION_S = 8.0
ALPHA, P, MU = 0.235, 3.84, 0.936
THETA0, HOLD_S = 0.12, 0.8031
OFFSET_RAD, NOISE_RAD, LED_NOISE_M = 0.002, 1.2e-3, 1.0e-4
HALF_WIDTH, LED_X, LED_HEIGHT = 0.125, 0.10, 0.80


def main() -> Path:
    rng = np.random.default_rng(SEED)
    n = round(DURATION_S * RATE_HZ) + 1
    t = np.arange(n) / RATE_HZ
    truth = FreeRockingFit(ALPHA, P, MU, HOLD_S, 0.0, THETA0 / ALPHA, 1)
    theta = model_history(truth, 0.0, 1.0 / RATE_HZ, n)[0]
    b_eq = 0.5 * math.tan(ALPHA)  # pivots at the equivalent half base (paper Eq 11)
    pivot_x = np.where(theta >= 0, -b_eq, b_eq)
    ys = []
    for x in (-LED_X, LED_X):
        rx = x - pivot_x
        y = rx * np.sin(theta) + LED_HEIGHT * (np.cos(theta) - 1.0)
        ys.append(y - y[0] + LED_NOISE_M * rng.standard_normal(n))
    frame = pd.DataFrame(
        {
            "t_s": t,
            "theta_rad": theta + OFFSET_RAD + NOISE_RAD * rng.standard_normal(n),
            "led1_y_m": ys[0],
            "led2_y_m": ys[1],
        }
    )
    path = Path(__file__).resolve().parent / "specimen1_free_rocking.csv"
    with atomic_open(path) as fh:
        fh.write(f"# free rocking of specimen 1 made by rockyade (seed {SEED}); see {Path(__file__).name}\n")
        frame.to_csv(fh, index=False, float_format="%.7g", lineterminator="\n")
    return path


if __name__ == "__main__":
    print(f"wrote {main()}")
