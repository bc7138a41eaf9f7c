"""A small study from Python: specimen 1 on a 6 mm table sine, frequency swept.

    python examples/gallery/uplift_sweep.py [OUT_DIR]

Below the uplift acceleration g tan(alpha) the block does not rock at all (theta = 0);
above it, the peak rotation jumps up. Scenes are plain dictionaries; Housner's exact
solver takes a few milliseconds per run.
"""

import math
import sys
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from rockyade.constants import G
from rockyade.scene import scene_from_dict
from rockyade.solvers import run

out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("gallery")
out.mkdir(parents=True, exist_ok=True)

block = {
    "name": "specimen1",
    "width_m": 0.25,
    "height_m": 1.0,
    "thickness_m": 0.754,
    "mass_kg": 503,
    "alpha_rad": 0.235,
    "p_rad_s": 3.84,
    "mu": 0.936,
}
amplitude_mm = 6.0
frequencies = np.linspace(2.0, 5.0, 13)
peaks = []
for f in frequencies:
    motion = {"type": "harmonic", "amplitude_mm": amplitude_mm, "frequency_hz": float(f), "cycles": 10}
    scene = scene_from_dict({"duration_s": 10.0, "sample_dt_s": 0.002, "blocks": [block], "motion": motion})
    result = run(scene, solver="housner")
    peaks.append(np.max(np.abs(result.series("theta_rad"))) / block["alpha_rad"])

uplift_hz = math.sqrt(G * math.tan(block["alpha_rad"]) / (amplitude_mm * 1e-3)) / (2 * math.pi)
fig, ax = plt.subplots(figsize=(7, 4))
ax.plot(frequencies, peaks, "o-", label="Housner (exact)")
ax.axvline(uplift_hz, color="0.4", ls="--", label=f"uplift: A (2 pi f)^2 = g tan alpha at {uplift_hz:.2f} Hz")
ax.set_xlabel("table frequency (Hz)")
ax.set_ylabel("max |theta| / alpha")
ax.set_ylim(0, 1.1)
ax.grid(alpha=0.3)
ax.legend()
ax.set_title(f"Specimen 1, {amplitude_mm:g} mm table sine, 10 cycles")
fig.savefig(out / "uplift_sweep.png", dpi=110, bbox_inches="tight")
print(f"wrote {out / 'uplift_sweep.png'}")
