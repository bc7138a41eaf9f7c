"""What the backends of the engines that run in another Python (YADE's,
:mod:`rockyade.yade.backend`; Siconos's, :mod:`rockyade.siconos.backend`) decide alike from a
driver's output: reading it, whether it is a result, how the run ended, and the Result's
metadata they share (:class:`rockyade.run_meta.RunMeta` fields).

Each backend adds its own diagnostics (YADE's deep overlaps, Siconos's convergence) and its
own fields to what is here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rockyade.dem.model import DemModel
from rockyade.dem.overturn import CRITERION, body_falls, run_outcome
from rockyade.dem.result_frames import energy_gain
from rockyade.dem.worker_output import WorkerOutput
from rockyade.io.warm_program import error_line

#: The arrays a driver writes beside its metadata (``meta``).
ARRAYS = ("pos", "ang", "angvel", "vpoint", "state", "fn", "ncont", "slip")


def read_output(out_file: Path) -> tuple[WorkerOutput, dict[str, np.ndarray]]:
    """A driver's output file: its metadata and arrays.

    Raises
    ------
    OSError, ValueError, KeyError, zipfile.BadZipFile
        A missing or unreadable file.
    """
    with np.load(out_file, allow_pickle=False) as data:
        meta = WorkerOutput.from_json(str(data["meta"]))
        arrays = {k: data[k] for k in ARRAYS}
    return meta, arrays


def last_error_line(log_file: Path) -> str:
    """The last error line of a worker's log ("" when it has none: a banner is not a reason;
    :func:`rockyade.io.warm_program.error_line`)."""
    try:
        return error_line(log_file.read_text(errors="replace"))
    except OSError:
        return ""


def incomplete_output(model: DemModel, meta: WorkerOutput, arrays: dict[str, np.ndarray], label: str) -> str | None:
    """Why an output is not a whole run (a flush, samples missing, an early stop), or None.

    ``label`` names the engine in the reason ("YADE", "Siconos").
    """
    n = meta.n_filled
    if not meta.complete or arrays["pos"].shape[0] != n:
        return f"partial {label} output"
    if meta.status == "completed" and n != model.n_samples:
        return f"{label} stopped early: {n} of {model.n_samples} samples"
    return None


def unstable(meta: WorkerOutput, arrays: dict[str, np.ndarray]) -> bool:
    """True when the driver said the run failed or its state is not finite."""
    return meta.status == "failed" or not bool(np.all(np.isfinite(arrays["pos"])))


def energy_problem(model: DemModel, arrays: dict[str, np.ndarray], label: str) -> str | None:
    """Why the samples are a blow-up (energy created, :func:`rockyade.dem.result_frames.energy_gain`), or None."""
    gain, t_blowup = energy_gain(model, arrays["pos"], arrays["ang"], arrays["angvel"])
    if t_blowup is None:
        return None
    return f"numerical instability in {label} at t = {t_blowup:.6g} s (energy created: {gain:.3g} x weight x height)"


def shared_run_meta(
    model: DemModel, meta: WorkerOutput, total: float, arrays: dict[str, np.ndarray]
) -> dict[str, object]:
    """The Result's metadata both backends write: how the run ended (overturns per block; for an
    assembly run to its end, the collapse table's rule, :func:`rockyade.dem.overturn.run_outcome`),
    times, samples, bodies and motion.

    Parameters
    ----------
    total
        Wall time of the whole worker call, s (``startup_time_s`` is what the driver did not time).
    """
    names = model.names
    status = meta.status
    overturn_times = {names[int(i)]: t for i, t in meta.overturn_times_s.items()}
    overturn_time = meta.stop_time_s if status == "overturned" else None
    overturned_block = names[meta.stop_body] if status == "overturned" and meta.stop_body is not None else None
    if not model.stop_on_overturn and status == "completed":  # an assembly: the collapse table's rule
        t = np.arange(arrays["ang"].shape[0], dtype=float) * model.sample_dt_s
        falls = body_falls(model.bodies, t, arrays["pos"], arrays["ang"], overturn_times)
        status, overturn_time, overturned_block = run_outcome(overturn_times, names, falls, t)
    return {
        "scene_hash": model.scene_hash,
        "wall_time_s": meta.wall_time_s,
        "startup_time_s": total - meta.wall_time_s if meta.wall_time_s is not None else None,
        "status": status,
        "overturn_time_s": overturn_time,
        "overturned_block": overturned_block,
        "overturn_criterion": CRITERION,
        "overturn_times_s": overturn_times,
        "blocks": names,
        "sample_dt_s": model.sample_dt_s,
        "duration_s": model.duration_s,
        "iterations": meta.steps,
        "bodies": model.body_summary(),
        "motion": model.motion_label,
    }


def failed_partially(out: dict[str, object], reason: str, n: int) -> dict[str, object]:
    """``out`` (a run's metadata) made that of a failed run that keeps its first ``n`` samples:
    status ``failed``, ``partial: true``, no overturn."""
    out.update(
        status="failed",
        failure_reason=reason,
        overturn_time_s=None,
        overturned_block=None,
        partial=True,
        partial_samples=n,
    )
    return out
