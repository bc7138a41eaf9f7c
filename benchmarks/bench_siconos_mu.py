"""Can Siconos reach the paper's experimental mu? What was tried (docs/siconos.md).

Three parts, each printing a table:

1. **Targets**: per specimen (experimental alpha, p, mu; ``examples/*_free.toml``), the
   model's own restitution with e = 0 (general Eq 4, the geometry's: what Siconos runs) and
   what a ``matched`` calibration gets: the one-line refusal with the reachable range.
2. **Moreau-Jean, Newton restitution**: specimen 1's geometry (0.25 x 1.0 m) released at
   alpha/2 through ``SiconosSolver``, e = 0 ... 0.9 at every corner (a pivot has no
   approach velocity, so e at the pivot does nothing: this is also "e at the landing
   corner only"), with friction (30 deg) and frictionless (0.01 deg): the effective mu of
   each of the first impacts from the peaks' potential energy.
3. **LZB multiple impacts** (``MultipleImpactNSL`` + ``MultipleImpact`` + ``LsodarOSI`` +
   ``EventDriven``): ``benchmarks/siconos_lzb_rocking.cpp``, compiled here against Siconos's
   C++ headers (Siconos 4.4's Python has the law but not its one-step problem), on the same
   geometry: the law's energetic restitution e, the corners' stiffness ratio and the
   elasticity exponent eta. Skipped, saying why, without g++ or ``libsiconos-kernel-dev``.
   The executable is compiled once and kept in ``$ROCKYADE_CACHE/siconos_lzb/`` (default
   ``~/.cache/rockyade``), under a key of its source, the compiler and Siconos's files.

Run: ``python benchmarks/bench_siconos_mu.py [--quick]`` (about 3 min; ``--quick`` runs
fewer cases, the LZB ones with a coarser impulse step). Needs python3-siconos (parts 2-3).
"""

from __future__ import annotations

import hashlib
import math
import os
import shutil
import stat
import subprocess
import tempfile
from pathlib import Path

import numpy as np
from quick_option import quick_mode  # type: ignore[import-not-found]

from rockyade.blocks.restitution import find_peaks, restitution_per_impact
from rockyade.errors import InputError
from rockyade.motion.suite_cache import cache_dir
from rockyade.scene import load_scene, scene_from_dict
from rockyade.siconos.calibration import check_target_mu, model_restitution
from rockyade.solvers import make_solver
from rockyade.solvers.siconos import SiconosSolver

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
LZB_SOURCE = ROOT / "benchmarks" / "siconos_lzb_rocking.cpp"
SICONOS_INCLUDE = Path("/usr/include/siconos")
#: Specimen 1's geometry, m (half width, half height) and its critical angle, rad.
B_M, H_M = 0.125, 0.5
ALPHA = math.atan(B_M / H_M)
N_IMPACTS = 4


def targets() -> None:
    """Part 1: the model's own mu against the paper's experimental one, per specimen."""
    print("1. targets (experimental alpha, p, mu): the model's own mu (e = 0) and a matched calibration")
    print(f"{'block':<10} {'target mu':>9} {'model mu':>9} {'gap %':>7}  matched calibration")
    for name in ("specimen1", "specimen2", "specimen3", "specimen4", "biblock"):
        scene = load_scene(EXAMPLES / f"{name}_free.toml")
        matched = scene_from_dict({**scene.to_dict(), "contact": {"calibration": "matched"}}, base_dir=EXAMPLES)
        model = SiconosSolver().model(scene)
        try:
            check_target_mu(matched, model)
            verdict = "accepted"
        except InputError as err:
            verdict = str(err)
        for spec, body in zip(scene.blocks, model.bodies, strict=True):
            if body.fixed:
                continue
            own = model_restitution(body)
            gap = 100 * (spec.mu / own - 1) if spec.mu is not None else math.nan
            print(f"{body.name:<10} {spec.mu!s:>9} {own:9.4f} {gap:7.2f}")
        print(f"  -> {verdict}")


def _free(friction_deg: float):
    return scene_from_dict(
        {
            "duration_s": 3.0,
            "sample_dt_s": 0.002,
            "blocks": [{"name": "b", "width_m": 0.25, "height_m": 1.0, "thickness_m": 0.5, "density_kg_m3": 2000.0}],
            "contact": {"calibration": "paper", "friction_angle_deg": friction_deg},
            "motion": {"type": "free", "theta0_rad": 0.5 * ALPHA},
        }
    )


def _per_impact(t: np.ndarray, theta: np.ndarray) -> np.ndarray:
    return restitution_per_impact(find_peaks(t, theta), ALPHA)[:N_IMPACTS]


def _row(label: str, per: np.ndarray) -> str:
    mean = float(np.prod(per) ** (1 / per.size)) if per.size else math.nan
    return f"{label:<44} {mean:7.4f}   {' '.join(f'{x:.4f}' for x in per)}"


def moreau_jean(quick: bool) -> None:
    """Part 2: Newton restitution e at the corners, with and without friction (quick: e = 0 and 0.9)."""
    housner = 1 - 1.5 * math.sin(ALPHA) ** 2
    print(f"\n2. Moreau-Jean, Newton e (specimen 1's geometry, alpha/2; Housner's mu {housner:.4f})")
    print(f"{'case':<44} {'mean':>7}   first {N_IMPACTS} impacts")
    for friction, restitutions in ((30.0, (0.0, 0.9) if quick else (0.0, 0.3, 0.6, 0.9)), (0.01, (0.0,))):
        for e in restitutions:
            result = make_solver("siconos", restitution=e).run(_free(friction))
            per = _per_impact(result.frame["t_s"].to_numpy(), result.frame["theta_rad"].to_numpy())
            status = "" if result.ok else f" ({result.meta.status})"
            print(_row(f"friction {friction:g} deg, e = {e:g}{status}", per))


def _compile_command(exe: Path) -> list[str]:
    flags = [f"-I{SICONOS_INCLUDE / d}" for d in ("kernel", "numerics", "")]
    return [
        "g++",
        "-O1",
        "-std=c++17",
        *flags,
        "-o",
        str(exe),
        str(LZB_SOURCE),
        "-lsiconos_kernel",
        "-lsiconos_numerics",
    ]


def _lzb_key() -> str:
    """What the probe's executable depends on: its source, the compiler (``g++ --version``), the
    compile command and Siconos's headers and libraries (their sizes and modification times)."""
    digest = hashlib.sha256(LZB_SOURCE.read_bytes())
    version = subprocess.run(["g++", "--version"], capture_output=True, text=True, check=False).stdout
    digest.update(version.encode())
    command = _compile_command(Path("lzb_rocking"))
    digest.update(" ".join(c for c in command if c not in ("lzb_rocking", str(LZB_SOURCE))).encode())
    libraries = sorted(Path("/usr/lib").glob("*/libsiconos_*.so*")) + sorted(Path("/usr/lib").glob("libsiconos_*.so*"))
    for path in (SICONOS_INCLUDE / "SiconosConfig.h", SICONOS_INCLUDE / "kernel" / "MultipleImpact.hpp", *libraries):
        info = path.stat()
        digest.update(f"{path} {info.st_size} {info.st_mtime_ns}".encode())
    return digest.hexdigest()[:20]


def _compile_lzb(workdir: Path) -> Path | str:
    """The LZB probe's executable: compiled once (some 15 s of CPU, nearly all of it in Siconos's
    headers) into ``$ROCKYADE_CACHE/siconos_lzb/<key>/`` (:func:`_lzb_key`) and taken from there
    while nothing it depends on changed; compiled into ``workdir`` when the cache is not writable."""
    if shutil.which("g++") is None:
        return "no g++"
    if not (SICONOS_INCLUDE / "kernel" / "MultipleImpact.hpp").exists():
        return "no Siconos C++ headers (apt-get install libsiconos-kernel-dev)"
    folder = cache_dir() / "siconos_lzb" / _lzb_key()
    cached = folder / "lzb_rocking"
    try:
        info = cached.lstat()
        if stat.S_ISREG(info.st_mode) and info.st_mode & stat.S_IXUSR:  # a file, never a link
            return cached
    except FileNotFoundError:
        pass
    try:
        folder.mkdir(parents=True, exist_ok=True)
        build = Path(tempfile.mkdtemp(dir=folder, prefix=".build-"))
    except OSError:  # a cache that cannot be written: compiled for this run only
        build, cached = workdir, workdir / "lzb_rocking"
    try:
        done = subprocess.run(_compile_command(build / "lzb_rocking"), capture_output=True, text=True, check=False)
        if done.returncode != 0:
            return f"compilation failed: {done.stderr.strip().splitlines()[-1:]}"
        os.replace(build / "lzb_rocking", cached)  # complete or absent: runs at once each rename a whole file
        return cached
    finally:
        if build.parent == folder:
            shutil.rmtree(build, ignore_errors=True)


def _lzb(exe: Path, e: float, k_ratio: float, eta: float, dp: float = 1e-4) -> tuple[float, np.ndarray, int]:
    args = [B_M, H_M, 0.5 * ALPHA, e, 1e8, 1e8 * k_ratio, eta, dp, 1.0]
    out = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, check=True, timeout=600).stdout
    rows = [line.split() for line in out.splitlines()]
    smooth = np.array([[float(x) for x in r[1:3]] for r in rows if r[0] == "S"])
    impacts = [r for r in rows if r[0] == "I"]
    first = float(impacts[0][3]) / float(impacts[0][2])
    return first, _per_impact(smooth[:, 0], smooth[:, 1]), len(impacts)


def lzb(quick: bool) -> None:
    """Part 3: the LZB law's parameters (frictionless: Siconos 4.4's MultipleImpact; quick: three
    cases at a 10 times coarser impulse step dP)."""
    b, h = B_M, H_M
    frictionless = (h * h - 2 * b * b) / (h * h + 4 * b * b)  # e = 0, no friction, impulse at the landing corner
    print(f"\n3. LZB multiple impacts, event-driven (frictionless; e = 0 rigid value {frictionless:.4f})")
    with tempfile.TemporaryDirectory() as tmp:
        exe = _compile_lzb(Path(tmp))
        if isinstance(exe, str):
            print(f"   skipped: {exe}")
            return
        cases = (
            [(e, 1.0, 1.0) for e in (0.0, 0.5, 1.0)]
            if quick
            else [(e, 1.0, 1.0) for e in (0.0, 0.3, 0.5, 0.7, 0.9, 1.0)]
        )
        if not quick:
            cases += [
                (0.0, 1.0, 1.5),
                (0.5, 1.0, 1.5),
                (0.0, 0.1, 1.0),
                (0.0, 10.0, 1.0),
                (0.5, 0.1, 1.0),
                (0.5, 10.0, 1.0),
            ]
        print(f"{'case':<44} {'mean':>7}   first {N_IMPACTS} impacts   (first impact omega+/omega-, impact events)")
        for e, k_ratio, eta in cases:
            first, per, n = _lzb(exe, e, k_ratio, eta, 1e-3 if quick else 1e-4)
            print(_row(f"e = {e:g}, K_right/K_left = {k_ratio:g}, eta = {eta:g}", per) + f"   ({first:.4f}, {n})")


def main() -> None:
    quick = quick_mode(__doc__)
    targets()
    moreau_jean(quick)
    lzb(quick)


if __name__ == "__main__":
    main()
