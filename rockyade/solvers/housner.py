"""Housner's exact solution (:mod:`rockyade.housner`) as a solver: a scene of one block on a
rigid base in, a Result out; runs sharing one model go together (:class:`~rockyade.solvers.base.GroupSolver`)."""

from __future__ import annotations

import dataclasses
import json
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from rockyade.blocks.classical import ClassicalParameters
from rockyade.constants import G
from rockyade.errors import InputError
from rockyade.housner.history import housner_frame
from rockyade.housner.integrator import KERNELS, REST_FRACTION, STEPS_PER_RADIAN, Trajectory, solve, warm_up
from rockyade.housner.sdof import HousnerModel, housner_model
from rockyade.motion.ground import GroundMotion
from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.scene import Scene
from rockyade.scene.carried import loaded_classical
from rockyade.solvers.base import GroupRun, StepFactorSolver, exact_meta, motion_coverage, say_if_compiling
from rockyade.solvers.cost_estimate import CostEstimate, numba_cached, sample_cost


@dataclass(frozen=True)
class HousnerSolver(StepFactorSolver):
    """Housner's exact solution as a solver (single blocks on a rigid base).

    Attributes
    ----------
    dt_factor
        Factor in [0.001, 1] on the largest Runge-Kutta step 1 / (``STEPS_PER_RADIAN`` p), the
        only step of the solution (impacts, uplift and overturning are found by root finding
        to machine precision); recorded in the Result's ``dt_factor`` and ``dt_s``.
    """

    name: ClassVar[str] = "housner"
    COMPILE_S: ClassVar[float] = 9.0

    def compiled_cached(self, scene: Scene) -> bool:
        """Whether numba's cache holds the integrator (:data:`rockyade.housner.integrator.KERNELS`)."""
        return numba_cached(*KERNELS)

    def warm_up(self) -> None:
        """Load (or compile) the integrator (:func:`rockyade.housner.integrator.warm_up`)."""
        warm_up()

    def _step_s(self, model: HousnerModel) -> float:
        """The largest Runge-Kutta step, s: ``dt_factor`` / (``STEPS_PER_RADIAN`` p)."""
        return self.dt_factor / (STEPS_PER_RADIAN * max(model.p_left, model.p_right))

    def _solve(self, scene: Scene, model: HousnerModel, motion: GroundMotion | None) -> Trajectory:
        """The block's response to ``motion`` from the scene's start, sampled as it asks."""
        return solve(
            model,
            motion,
            scene.duration_s,
            scene.motion.initial_theta_rad,
            scene.motion.initial_omega_rad_s,
            scene.sample_dt_s,
            self._step_s(model),
        )

    def check_scene(self, scene: Scene) -> None:
        """Refuse, before any run, a scene of more than one block: the classical theory is for
        one block on a rigid base (studies call this first, so that a cross-check of a wall
        with ``housner`` stops with exit 2 instead of running every other solver's runs and
        failing each of Housner's).

        Raises
        ------
        InputError
            Naming ``blocks``.
        """
        if len(scene.blocks) != 1:
            raise InputError(
                "blocks",
                f"the housner solver takes one block on a rigid base; this scene has {len(scene.blocks)} "
                "(two stacked blocks: the twoblock solver; more: the reference, yade or siconos solver)",
                scene.source,
            )

    def run(self, scene: Scene) -> Result:
        """Solve a single-block scene with Housner's equation and return a Result.

        Raises
        ------
        InputError
            If the scene has more than one block (:meth:`check_scene`).
        """
        self.check_scene(scene)
        spec = scene.blocks[0]
        cp = loaded_classical(scene, G)[spec.name]  # the body that rocks, with the masses its loads carry
        model = housner_model(scene)
        motion = scene.motion.ground_motion(scene.duration_s)
        warm_up()
        start = time.perf_counter()
        traj = self._solve(scene, model, motion)
        wall = time.perf_counter() - start
        frame = housner_frame(scene, spec.block(), model, motion, traj)
        return Result(frame, _meta(scene, cp, motion, traj, wall, self.dt_factor))

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """One step per output sample (:func:`rockyade.solvers.cost_estimate.sample_cost`)."""
        return sample_cost(scene, self.name)

    def group_key(self, scene: Scene) -> str | None:
        """What runs sharing one model have in common (None: this run goes alone).

        Runs of one block whose scenes differ only in their motion of one type (the record,
        the load factor, a pulse's amplitude, the release tilt) share Housner's model, and are
        run together by :meth:`run_group` (the batch reads a group's metrics by its motion's
        type: free rocking or not). A scene of several blocks (which :meth:`run` refuses) goes
        alone.
        """
        if len(scene.blocks) != 1:
            return None
        d = scene.to_dict()
        d["motion"] = scene.motion.type
        return json.dumps(d, sort_keys=True, default=str)

    def run_group(self, scenes: Sequence[Scene], uplift_rad: float, threads: int = 1) -> list[GroupRun]:
        """Run scenes of one :meth:`group_key` together: the model (classical parameters, loads)
        is built once, each run's base motion once (the run and its coverage read the same
        arrays), and no time-history frame is made; each run is integrated as :meth:`run`
        integrates it (the same numbers, bit for bit). The parameters are those of
        :meth:`rockyade.solvers.base.GroupSolver.run_group`; ``threads`` is unused: the runs are
        integrated one after the other in this thread (a batch's workers run one job each).

        Returns
        -------
        list of GroupRun
            In the scenes' order: each run's metadata (as :meth:`run`'s Result, without the
            history; ``wall_time_s`` the run's integration) and its sampled theta.
        """
        say_if_compiling(self, scenes[0])
        start = time.perf_counter()
        first = scenes[0]
        if len(first.blocks) != 1:
            raise InputError("blocks", "run_group: one block per scene only (see group_key)", first.source)
        cp = loaded_classical(first, G)[first.blocks[0].name]
        model = housner_model(first)
        warm_up()
        setup = time.perf_counter() - start
        runs = []
        for scene in scenes:
            motion = scene.motion.ground_motion(scene.duration_s)
            begin = time.perf_counter()
            traj = self._solve(scene, model, motion)
            wall = time.perf_counter() - begin
            meta = _meta(scene, cp, motion, traj, wall, self.dt_factor).with_extra(
                batched={"runs": len(scenes), "setup_time_s": setup}
            )
            meta = dataclasses.replace(meta, motion_coverage=_coverage(scene, motion))
            runs.append(GroupRun(meta, traj.theta_rad, scene.sample_dt_s, _theta_metrics(traj, uplift_rad)))
        return runs


def _coverage(scene: Scene, motion: GroundMotion | None) -> dict:
    """``meta.motion_coverage`` of a run from the base motion it ran
    (:func:`rockyade.solvers.base.motion_coverage` builds that motion again)."""
    from rockyade.motion.coverage import record_coverage

    return record_coverage(motion, scene.duration_s) if motion is not None else motion_coverage(scene)


def _theta_metrics(traj: Trajectory, uplift_rad: float) -> dict[str, float]:
    """``max_abs_theta_rad``, ``residual_theta_rad`` (rad) and ``uplift_time_s`` (s, NaN: never)
    of a trajectory, as :func:`rockyade.analysis.metrics.theta_metrics` computes them from a
    Result (NaN samples ignored)."""
    theta = traj.theta_rad
    finite = theta[np.isfinite(theta)]
    lifted = np.nonzero(np.abs(theta) > uplift_rad)[0]
    return {
        "max_abs_theta_rad": float(np.max(np.abs(finite))) if finite.size else math.nan,
        "residual_theta_rad": float(finite[-1]) if finite.size else math.nan,
        "uplift_time_s": float(traj.t_s[lifted[0]]) if lifted.size else math.nan,
    }


def _meta(
    scene: Scene, cp: ClassicalParameters, motion: GroundMotion | None, traj: Trajectory, wall: float, dt_factor: float
) -> RunMeta:
    """The Result's metadata: status, events (the first 200 of each) and the parameters."""
    name = scene.blocks[0].name
    before = {
        "overturn_criterion": "|theta| reached pi/2",
        "alpha_exceeded_time_s": traj.alpha_exceeded_time_s,
        "n_impacts": traj.n_impacts,
    }
    after = {
        "rest_fraction_of_alpha": REST_FRACTION,
        "motion": motion.label if motion is not None else "free",
        "loads": [q.as_dict() for q in scene.loads],
    }
    return dataclasses.replace(
        exact_meta(HousnerSolver.name, "RK4", scene, traj, wall, dt_factor, before, after),
        overturn_time_s=traj.overturn_time_s,
        overturned_block=name if traj.status == "overturned" else None,
        blocks=(name,),
        classical={name: cp.as_dict()},
    )
