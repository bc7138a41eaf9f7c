"""The CPU cost of one cross-check run per solver on issue 35's masonry scenes (docs/verification.md).

Each solver runs the scene under the paper's synthetic record 1 (``rockyade run``, a process
of its own, YADE's and Siconos's workers its children), at ``--load-factor`` of the record, for
two durations; the CPU time (user + sys of the command and every child it waited for,
``os.wait4``) of the longer run less the shorter one's is the cost of the extra simulated
seconds, which gives the cost of a cross-check run, 25 s of record and 5 s of tail, as
start-up + 30 s x the cost a second. CPU time, not wall time: on a shared machine it moves
far less with the load (the machine's load is printed beside).

Run::

    .venv/bin/python benchmarks/crosscheck_costs.py                       # every scene and solver
    .venv/bin/python benchmarks/crosscheck_costs.py --scenes arch20 --solvers reference,yade
    .venv/bin/python benchmarks/crosscheck_costs.py --quick               # 0.1 and 0.2 s: a check that it runs
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from rockyade.scene import load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[1]
SCENES = {
    "biblock-geometry": (ROOT / "examples" / "biblock_geometry.toml", "twoblock,reference,yade,siconos"),
    "freewall": (ROOT / "examples" / "free_standing_wall_5_courses.toml", "reference,yade,siconos"),
    "arch20": (ROOT / "examples" / "assemblies" / "arch_20_voussoirs.toml", "reference,yade,siconos"),
    "wall32": (ROOT / "examples" / "assemblies" / "wall_5_courses.toml", "reference,yade,siconos"),
}
#: A cross-check run: the paper's 25 s records and 5 s of free motion after them, s.
RUN_S = 30.0


def cpu_seconds(argv: list[str]) -> float:
    """User + sys CPU seconds of a command and the children it waited for."""
    proc = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _pid, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) not in (0, 1):
        err = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
        raise RuntimeError(f"{' '.join(argv)} failed: {err.strip()[-400:]}")
    return usage.ru_utime + usage.ru_stime


def scene_file(path: Path, duration_s: float, load_factor: float, folder: Path) -> Path:
    """The scene under paper record 1 at ``load_factor`` for ``duration_s``, written to ``folder``."""
    data = load_scene(path).to_dict()
    data.update(
        duration_s=duration_s,
        sample_dt_s=0.01,
        motion={"type": "synthetic", "suite": "paper", "record": 1, "load_factor": load_factor},
    )
    scene_from_dict(data)  # checked before any run
    out = folder / f"{path.stem}_{duration_s:g}s.json"
    out.write_text(json.dumps(data))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", default=",".join(SCENES), help=f"comma-separated among {', '.join(SCENES)}")
    parser.add_argument("--solvers", help="comma-separated (default: each scene's solvers)")
    parser.add_argument("--durations", default="2,6", help="the two simulated durations, s (default 2,6)")
    parser.add_argument("--load-factor", type=float, default=0.5, help="on paper record 1 (default 0.5: 0.14 g)")
    parser.add_argument("--quick", action="store_true", help="durations 0.1 and 0.2 s (a check that it runs)")
    args = parser.parse_args()
    unknown = [n.strip() for n in args.scenes.split(",") if n.strip() not in SCENES]
    if unknown:
        parser.error(f"--scenes: {', '.join(unknown)} unknown; choose among {', '.join(SCENES)}")
    short, long_ = (0.1, 0.2) if args.quick else tuple(float(v) for v in args.durations.split(","))
    rockyade = str(Path(sys.executable).with_name("rockyade"))
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
    print("| scene | solver | CPU s, short | CPU s, long | CPU s a simulated s | a 30 s run, CPU s |", flush=True)
    print("| --- | --- | --- | --- | --- | --- |", flush=True)
    with tempfile.TemporaryDirectory() as tmp:
        for name in args.scenes.split(","):
            path, default = SCENES[name.strip()]
            files = [scene_file(path, d, args.load_factor, Path(tmp)) for d in (short, long_)]
            for solver in (args.solvers or default).split(","):
                a, b = (
                    cpu_seconds([rockyade, "run", str(f), "--solver", solver, "--out", str(Path(tmp) / "r.csv")])
                    for f in files
                )
                per_s = (b - a) / (long_ - short)
                run = a - per_s * short + per_s * RUN_S
                print(f"| {name} | {solver} | {a:.1f} | {b:.1f} | {per_s:.2f} | {run:.0f} |", flush=True)
    print(f"load average {os.getloadavg()[0]:.1f}", flush=True)


if __name__ == "__main__":
    main()
