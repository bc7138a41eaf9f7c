"""The reference DEM: a standalone rigid-polygon DEM (numpy + numba) with the paper's joint.

It reads the same :class:`~rockyade.dem.model.DemModel` as the YADE backend and returns the
common Result schema, plus per block ``n_contacts`` (contact points on the block) and
``slipping`` (one of them slips), for column scenes the contact state per corner
(``<block>_c<i>_state``: open, stick or slip, the worst of the contact points at that
corner; corners numbered counter-clockwise from the bottom left), and energy terms
(``energy_*_J``, ``work_base_J`` and ``energy_balance_error_J``).

Accelerations (``ax_m_s2``, ``ay_m_s2``) are absolute, at the output point, and are the
mean over +/- one sample interval (central difference of the point velocity), which
keeps the impact spikes from aliasing; ``[output] accel_lowpass_hz`` adds a zero-phase
low-pass (paper Section 6.1).

Overturning (:mod:`rockyade.dem.overturn`): a moving block has overturned when it lies on
another face, |theta| within 0.01 rad of the angle at which the face next to its pivot
reaches the ground (pi/2 for a rectangle, a little less with the base corners at b_eq). It
ends a column scene's run (status ``overturned``); in a positioned scene (an assembly) the
run goes on, since a falling block must not end a wall's run, and the run is ``overturned``
at the first block's fall. Either way ``meta.overturn_times_s`` gives, per block that
fell, the first time it did.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any, ClassVar

import numba
import numpy as np
import pandas as pd

from rockyade import __version__
from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.engine import KernelOutput, model_arrays, simulate_model, warm_up
from rockyade.dem.model import DemModel
from rockyade.dem.overturn import CRITERION, body_falls, run_outcome
from rockyade.dem.result_frames import dem_frame, energy_gain, load_work
from rockyade.kernel import simulation as kernel
from rockyade.kernel.runs import simulate_runs
from rockyade.kernel.single import simulate_single, single_body
from rockyade.kernel.state import pack
from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.scene import Scene
from rockyade.solvers.base import (
    GroupRun,
    SolverBase,
    check_dt_factor,
    check_flag,
    classical_meta,
    motion_coverage,
    say_if_compiling,
)
from rockyade.solvers.cost_estimate import CostEstimate, dem_cost, numba_cached

_STATUS_NAMES = {
    kernel.STATUS_COMPLETED: "completed",
    kernel.STATUS_OVERTURNED: "overturned",
    kernel.STATUS_FAILED: "failed",
}


@dataclass(frozen=True)
class ReferenceSolver(SolverBase):
    """The reference DEM as a solver.

    Attributes
    ----------
    record_energy
        Energy terms in the frame (``energy_*_J``, ``work_base_J``, the balance error).
    record_contacts
        ``n_contacts`` and ``slipping`` per block and, for columns, the state of every
        corner.
    dt_factor
        Factor in [0.001, 1] on the model's time step (Eq 7 or the stability limit; 0.5 halves
        it: the convergence check of ``rockyade crosscheck``), recorded in the Result's
        ``dt_factor`` beside the ``dt_s`` used.
    """

    name: ClassVar[str] = "reference"
    IN_PROCESS = True
    OPTIONS: ClassVar = {"record_energy": check_flag, "record_contacts": check_flag, "dt_factor": check_dt_factor}
    #: Kernel time per body-step, s (cost estimate; this project's benchmarks).
    SECONDS_PER_BODY_STEP: ClassVar[float] = 150e-9
    COMPILE_S: ClassVar[float] = 68.0

    record_energy: bool = True
    record_contacts: bool = True
    dt_factor: float = 1.0

    def compiled_cached(self, scene: Scene) -> bool:
        """Whether numba's cache holds the kernels ``scene``'s runs take: for one block the
        grouped and single-body paths, for several the general loop."""
        single = len(scene.blocks) == 1
        return numba_cached(*((simulate_runs, simulate_single) if single else (kernel.simulate,)))

    def warm_up(self) -> None:
        """Load (or compile) the three paths of the kernel: the general loop, the single-body
        path and the runs stepped together (:func:`rockyade.dem.engine.warm_up`)."""
        for warm, _ in self.warm_up_paths().values():
            warm()

    def warm_up_paths(self) -> dict[str, tuple[Callable[[], None], float]]:
        """The kernel's three paths, which compile independently, with their CPU s on a cold cache
        (measured on the 2-core machine, each in a fresh process: the general loop is the most)."""
        return {
            "general loop": (warm_up, 50.0),
            "single body": (functools.partial(warm_up, single=True), 7.0),
            "runs stepped together": (functools.partial(warm_up, runs=True), 11.0),
        }

    def run(self, scene: Scene) -> Result:
        """Run a scene with the reference DEM.

        The returned ``wall_time_s`` is the kernel's; ``setup_time_s`` is the model build
        (including a matched calibration when asked for).
        """
        start = time.perf_counter()
        model = calibrated_model(scene).with_dt_factor(self.dt_factor)
        setup = time.perf_counter() - start
        result = run_model(
            model,
            record_energy=self.record_energy,
            record_contacts=self.record_contacts,
            accel_lowpass_hz=scene.output.accel_lowpass_hz,
            per_corner=not scene.positioned,
        )
        result.meta = dataclasses.replace(result.meta, setup_time_s=setup, dt_factor=self.dt_factor)
        return result

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """Body-steps of the model's time step (:func:`rockyade.solvers.cost_estimate.dem_cost`)."""
        return dem_cost(scene, self.name, self.SECONDS_PER_BODY_STEP, self.dt_factor)

    def group_key(self, scene: Scene) -> str | None:
        """What runs sharing one structure have in common (None: this run goes alone).

        Runs of one free-standing block without energy terms or loads whose scenes differ only
        in their base motion (its samples: the record, the load factor) share the model and are
        run together by :meth:`run_group` (whose kernel has no loads).
        """
        if self.record_energy or scene.positioned or len(scene.blocks) != 1 or scene.blocks[0].fixed or scene.loads:
            return None
        d = scene.to_dict()
        motion = scene.motion
        d["motion"] = [motion.type, motion.initial_theta_rad, motion.initial_omega_rad_s]
        return json.dumps(d, sort_keys=True, default=str)

    def run_group(self, scenes: Sequence[Scene], uplift_rad: float, threads: int = 1) -> list[GroupRun]:
        """Run scenes of one :meth:`group_key` together: the model is built once, its motion
        replaced per run, and the runs stepped in parallel (:func:`rockyade.kernel.runs.simulate_runs`;
        the same per-run results, bit for bit, as :meth:`run`). The parameters are those of
        :meth:`rockyade.solvers.base.GroupSolver.run_group`; ``threads`` are numba's threads
        stepping the runs, in this thread (a batch's workers run one each).

        Returns
        -------
        list of GroupRun
            In the scenes' order: each run's metadata (as :meth:`run`'s Result, without the
            history) and its sampled theta.
        """
        say_if_compiling(self, scenes[0])
        start = time.perf_counter()
        base = calibrated_model(scenes[0]).with_dt_factor(self.dt_factor)
        models = [base] + [
            replace(
                base, motion=s.motion.ground_motion(s.duration_s), scene_hash=s.scene_hash, base_at_rest=s.motion.type
            )
            for s in scenes[1:]
        ]
        records = pack(
            model_arrays(base),
            stop_on_overturn=base.stop_on_overturn,
            record_energy=False,
            record_corners=False,
            coherent=True,
        )
        if not single_body(records[0], records[1], False):
            raise ValueError("run_group: one moving block without energy terms only (see group_key)")
        motions = [model_arrays_motion(m) for m in models]
        starts = np.cumsum([0] + [m[0].size for m in motions])
        mt, mah, mav = (np.concatenate([m[k] for m in motions]) if motions else np.zeros(0) for k in range(3))
        setup = time.perf_counter() - start
        warm_up(runs=True)
        before = numba.get_num_threads()
        most = numba.config.NUMBA_NUM_THREADS  # type: ignore[attr-defined]  # numba.config sets it at import
        numba.set_num_threads(max(1, min(int(threads), most)))
        try:
            start = time.perf_counter()
            out = simulate_runs(
                records[0], records[1], records[3], records[4], mt, mah, mav, starts, uplift_rad, base.sample_dt_s
            )
            wall = (time.perf_counter() - start) / max(1, len(scenes))
        finally:
            numba.set_num_threads(before)
        runs = []
        classical = classical_meta(scenes[0])  # one structure: the same body in every run
        for r, model in enumerate(models):
            n = int(out.n_filled[r])
            one = KernelOutput(
                out.pos[r, :, None, :],
                out.ang[r, :, None],
                out.angvel[r, :, None],
                None,
                None,
                None,
                int(out.status[r]),
                n,
                float(out.t_stop[r]),
                0 if out.status[r] != kernel.STATUS_COMPLETED else -1,
                None,
                None,
                out.overturn_time[r : r + 1],
                1,
                0,
                0,
            )
            meta = RunMeta.from_dict(
                {
                    "solver": self.name,
                    "version": f"rockyade {__version__} reference DEM (numba {numba.__version__})",
                    "scene_hash": model.scene_hash,
                    "wall_time_s": wall,
                    **_outcome(model, one, n, model.stop_on_overturn),
                    "overturn_criterion": CRITERION,
                    "broad_phase": {"rebuilds": 1, "max_candidate_pairs": 0, "separating_axis_tests": 0},
                    **_model_meta(model, wall),
                    "batched": {"runs": len(scenes), "setup_time_s": setup},
                    "setup_time_s": setup / max(1, len(scenes)),
                    "dt_factor": self.dt_factor,
                    "motion_coverage": motion_coverage(scenes[r]),
                    "classical": classical,
                }
            )
            metrics = {
                "max_abs_theta_rad": float(out.max_abs_theta[r]),
                "residual_theta_rad": float(out.residual_theta[r]),
                "uplift_time_s": float(out.uplift_time[r]),
            }
            theta = out.ang[r, :n] - model.bodies[0].rest_angle_rad
            runs.append(GroupRun(meta, theta, model.sample_dt_s, metrics))
        return runs


def model_arrays_motion(model: DemModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The base motion of a model as the kernel reads it: t (s), a_h and a_v (m/s^2)."""
    motion = model.motion
    if motion is None:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    return (
        np.ascontiguousarray(motion.t_s, dtype=float),
        np.ascontiguousarray(motion.ah_m_s2, dtype=float),
        np.ascontiguousarray(motion.av_m_s2, dtype=float),
    )


def run_model(
    model: DemModel,
    *,
    record_energy: bool = True,
    record_contacts: bool = True,
    accel_lowpass_hz: float | None = None,
    per_corner: bool = True,
    stop_on_overturn: bool | None = None,
    stop_angle_rad: np.ndarray | None = None,
) -> Result:
    """Run a DEM model and return a Result (see module docstring).

    Parameters
    ----------
    record_energy
        Energy terms in the frame.
    record_contacts
        ``n_contacts`` and ``slipping`` per block, and with ``per_corner`` the state of
        every corner.
    accel_lowpass_hz
        Optional zero-phase low-pass of the output accelerations, Hz.
    per_corner
        Corner states (``c<i>_state``), one column per vertex: meant for single blocks and
        columns, not for walls of thousands of blocks.
    stop_on_overturn
        End the run when a block reaches its stop angle (default: the model's, True for
        column scenes).
    stop_angle_rad
        (nb,) |theta| at which each block counts as overturned (default: the model's
        landing angles, :func:`rockyade.dem.overturn.stop_angles`).
    """
    if stop_on_overturn is None:
        stop_on_overturn = model.stop_on_overturn
    if stop_angle_rad is None:
        stop_angle_rad = model.stop_angle_rad
    corners = record_contacts and per_corner
    out, wall = simulate_model(
        model, record_energy, record_corners=corners, stop_on_overturn=stop_on_overturn, stop_angle_rad=stop_angle_rad
    )
    n = int(out.n_filled)
    # simulate_model keeps every history (only a batched run's KernelOutput has None)
    assert out.vpoint is not None and out.corner_states is not None and out.energy is not None
    assert out.n_contacts is not None and out.slipping is not None
    frame = dem_frame(
        model,
        out.pos[:n],
        out.ang[:n],
        out.angvel[:n],
        out.vpoint[:n],
        out.corner_states[:n] if corners else None,
        accel_lowpass_hz,
        n_contacts=out.n_contacts[:n] if record_contacts else None,
        slipping=out.slipping[:n] if record_contacts else None,
    )
    meta_energy: dict[str, float] = {}
    if record_energy and n:
        energy, meta_energy = _energy_terms(model, out.energy[:n], out.pos[:n], out.ang[:n])
        frame = pd.concat([frame, energy], axis=1)
    outcome = _outcome(model, out, n, stop_on_overturn)
    meta = {
        "solver": ReferenceSolver.name,
        "version": f"rockyade {__version__} reference DEM (numba {numba.__version__})",
        "scene_hash": model.scene_hash,
        "wall_time_s": wall,
        **outcome,
        "overturn_criterion": CRITERION if model.stop_angle_rad is stop_angle_rad else "|theta| reached its stop angle",
        "broad_phase": {
            "rebuilds": int(out.n_builds),
            "max_candidate_pairs": int(out.max_pairs),
            "separating_axis_tests": int(out.n_tests),
        },
        **_model_meta(model, wall),
        "accel_definition": "absolute, mean over +/- one sample interval"
        + (f", zero-phase low-pass {accel_lowpass_hz:g} Hz" if accel_lowpass_hz else ""),
        **meta_energy,
    }
    return Result(frame, RunMeta.from_dict(meta))


def _energy_terms(
    model: DemModel, e: np.ndarray, pos: np.ndarray, ang: np.ndarray
) -> tuple[pd.DataFrame, dict[str, float]]:
    """The energy columns (potential energy from the rest state) and their summary; with point
    loads, their work (from the samples, :func:`rockyade.dem.result_frames.load_work`) is in the
    balance and in ``work_loads_J``."""
    e_pot_rest = sum(b.mass_kg * model.g * b.rest_centroid_m[1] for b in model.bodies if not b.fixed)
    total = (
        e[:, kernel.E_KIN]
        + e[:, kernel.E_POT]
        + e[:, kernel.E_EL]
        + e[:, kernel.E_DASH]
        + e[:, kernel.E_FRIC]
        - e[:, kernel.W_BASE]
    )
    loads_work = load_work(model, pos, ang)
    total = total - loads_work
    error = total - total[0]
    energy = pd.DataFrame(
        {
            "energy_kinetic_J": e[:, kernel.E_KIN],
            "energy_potential_J": e[:, kernel.E_POT] - e_pot_rest,
            "energy_elastic_J": e[:, kernel.E_EL],
            "energy_dashpot_J": e[:, kernel.E_DASH],
            "energy_friction_J": e[:, kernel.E_FRIC],
            "work_base_J": e[:, kernel.W_BASE],
            **({"work_loads_J": loads_work} if model.load_force_N is not None else {}),
            "energy_balance_error_J": error,
        }
    )
    summary = {
        "energy_balance_max_error_J": float(np.max(np.abs(error))),
        "initial_potential_energy_J": float(e[0, kernel.E_POT] - e_pot_rest),
    }
    return energy, summary


def _outcome(model: DemModel, out: KernelOutput, n: int, stop_on_overturn: bool) -> dict[str, Any]:
    """How the run ended: status, overturn time and block, per-block fall times, a failure's reason."""
    names = model.names
    gain, t_blowup = energy_gain(model, out.pos[:n], out.ang[:n], out.angvel[:n])
    status, t_stop = _STATUS_NAMES[int(out.status)], out.t_stop
    if t_blowup is not None and status != "failed":
        status, t_stop = "failed", t_blowup
    overturn_times = {names[i]: float(t) for i, t in enumerate(out.overturn_time) if np.isfinite(t)}
    overturned_block = names[int(out.stop_body)] if status == "overturned" else None
    if not stop_on_overturn and status == "completed":  # an assembly: the collapse table's rule
        t = np.arange(n, dtype=float) * model.sample_dt_s
        falls = body_falls(model.bodies, t, out.pos[:n], out.ang[:n], overturn_times)
        status, t_first, overturned_block = run_outcome(overturn_times, names, falls, t)
        t_stop = t_first if t_first is not None else t_stop
    return {
        "status": status,
        "overturn_time_s": float(t_stop) if status == "overturned" else None,
        "overturned_block": overturned_block,
        "overturn_times_s": overturn_times,
        "failure_reason": (
            f"numerical instability at t = {t_stop:.6g} s (energy created: {gain:.3g} x weight x height; or a "
            f"non-finite state, speed > {kernel.MAX_SPEED_M_S:g} m/s or spin > {kernel.MAX_SPIN_RAD_S:g} rad/s)"
            if status == "failed"
            else None
        ),
    }


def _model_meta(model: DemModel, wall: float) -> dict[str, Any]:
    """What the Result says about the model: blocks, sampling, time step, joints, bodies."""
    return {
        "blocks": model.names,
        "sample_dt_s": model.sample_dt_s,
        "duration_s": model.duration_s,
        "dt_s": model.dt_s,
        "dt_source": model.dt_source,
        "dt_eq7_s": model.dt_eq7_s,
        "dt_stability_limit_s": model.dt_stable_s,
        "n_steps": model.n_steps,
        "ns_per_step": 1e9 * wall / max(1, model.n_steps),
        "calibration": model.calibration,
        "contact": model.joint_summary(),
        "bodies": model.body_summary(),
        "motion": model.motion_label,
    }
