"""Record the single-block and bi-block results of this version as the baseline of ``rockyade verify``.

Run once per release from the repository root (it takes about a minute with YADE):

    .venv/bin/python tools/make_verify_baseline.py rockyade/studies/data/baseline_0_1.csv

It also writes the scenes themselves (``baseline_scenes.json`` beside it), so that the
check runs from an installed wheel. The verification report compares the current DEMs with
this file: the paper study's single-block and bi-block results must not change when the
contact code changes.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from rockyade import __version__
from rockyade.blocks.restitution import effective_restitution, find_peaks
from rockyade.scene import load_scene
from rockyade.solvers import run

ROOT = Path(__file__).resolve().parent.parent
CASES = [
    ("specimen1_free", "paper"),
    ("specimen1_free", "matched"),
    ("specimen3_free", "matched"),
    ("specimen4_free", "matched"),
    ("biblock_free", "paper"),
    ("specimen1_harmonic", "paper"),
    ("specimen1_pulse", "paper"),
]


def main(out: str) -> None:
    rows = []
    for example, calibration in CASES:
        scene = load_scene(ROOT / "examples" / f"{example}.toml")
        d = scene.to_dict()
        d["contact"]["calibration"] = calibration
        from rockyade.scene import scene_from_dict

        scene = scene_from_dict(d)
        for solver in ("reference", "yade"):
            result = run(scene, solver)
            for spec in scene.blocks:
                alpha = spec.classical().alpha_rad
                theta = result.series("theta_rad", spec.name)
                peaks = find_peaks(result.t, theta, 1e-3 * alpha)
                row = {
                    "case": example,
                    "calibration": calibration,
                    "solver": solver,
                    "block": spec.name,
                    "status": result.status,
                    "max_abs_theta_rad": float(np.nanmax(np.abs(theta))),
                    "mu_eff": effective_restitution(peaks, alpha, 5) if scene.motion.type == "free" else np.nan,
                    "overturn_time_s": result.meta.get("overturn_time_s") or np.nan,
                }
                for k in range(5):
                    row[f"peak{k + 1}_rad"] = float(peaks.amplitude_rad[k]) if len(peaks) > k else np.nan
                    row[f"peak{k + 1}_time_s"] = float(peaks.t_s[k]) if len(peaks) > k else np.nan
                rows.append(row)
                print(example, calibration, solver, spec.name, result.status, row["peak1_rad"], row["mu_eff"])
    scenes = {example: load_scene(ROOT / "examples" / f"{example}.toml").to_dict() for example, _ in CASES}
    (Path(out).parent / "baseline_scenes.json").write_text(json.dumps(scenes, indent=1, sort_keys=True) + "\n")
    frame = pd.DataFrame(rows)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w") as fh:
        fh.write(f"# rockyade {__version__} single-block and bi-block results (tools/make_verify_baseline.py)\n")
        frame.to_csv(fh, index=False, float_format="%.10g", lineterminator="\n")


if __name__ == "__main__":
    main(sys.argv[1])
