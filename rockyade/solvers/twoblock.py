"""The exact solution of two stacked blocks (:mod:`rockyade.twoblock`) as a solver: a scene of
two rectangles, the upper on the lower, in; a Result with the DEMs' columns for a two-block
scene out. Its modes, impacts and refusals are in ``docs/twoblock.md``."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import ClassVar

from rockyade.errors import InputError
from rockyade.motion.ground import GroundMotion
from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.scene import Scene
from rockyade.solvers.base import StepFactorSolver, exact_meta
from rockyade.solvers.cost_estimate import CostEstimate, numba_cached, sample_cost
from rockyade.twoblock import TwoBlockModel, TwoBlockTrajectory, solve, two_block_model, warm_up
from rockyade.twoblock.event_driven import REST_FRACTION, integrate
from rockyade.twoblock.time_history import two_block_frame
from rockyade.twoblock.trajectory import max_step

#: A scene's mu within this relative distance of the model's own counts as reached.
MU_RTOL = 0.01
#: Wall time per Runge-Kutta step, s, events included (cost estimate): the bi-block under a
#: 25 s record, 445-829 impacts, 4.7 us a step on the loaded 2-core machine
#: (``benchmarks/bench_twoblock.py``).
SECONDS_PER_STEP = 5e-6
#: How the run decides an overturn (the Result's ``overturn_criterion``).
OVERTURN_CRITERION = (
    "|theta| of either block or the upper block's rotation on its seat reached pi/2 (the run stops there, "
    "as a column scene's DEM run does)"
)


@dataclass(frozen=True)
class TwoBlockSolver(StepFactorSolver):
    """The two-block exact solver (module docstring).

    Attributes
    ----------
    dt_factor
        Factor in [0.001, 1] on the largest Runge-Kutta step 1 / (400 p), p the larger of the
        stack's and the upper block's (impacts, uplifts and overturns are found by root
        finding to machine precision); recorded in the Result's ``dt_factor`` and ``dt_s``.
    """

    name: ClassVar[str] = "twoblock"
    COMPILE_S: ClassVar[float] = 24.0

    def compiled_cached(self, scene: Scene) -> bool:
        """Whether numba's cache holds the event-driven integrator."""
        return numba_cached(integrate)

    def warm_up(self) -> None:
        """Load (or compile) the integrator (:func:`rockyade.twoblock.warm_up`)."""
        warm_up()

    def model(self, scene: Scene) -> TwoBlockModel:
        """The scene's stack (:func:`rockyade.twoblock.two_block_model`), with the scene's mu
        checked against the impact law's (:meth:`check_scene`).

        Raises
        ------
        InputError
            A scene the solver cannot treat.
        """
        model = two_block_model(scene)
        _check_mu(scene, model)
        return model

    def check_scene(self, scene: Scene) -> None:
        """Refuse before any run what :meth:`run` refuses whatever the motion.

        Raises
        ------
        InputError
            As :meth:`run` would.
        """
        self.model(scene)

    def run(self, scene: Scene) -> Result:
        """Solve a two-block scene exactly and return a Result.

        Raises
        ------
        InputError
            A scene the solver cannot treat (module docstring of :mod:`rockyade.twoblock.stack`).
        """
        model = self.model(scene)
        motion = scene.motion.ground_motion(scene.duration_s)
        released = scene.released_index
        warm_up()
        start = time.perf_counter()
        traj = solve(
            model,
            motion,
            scene.duration_s,
            released,
            scene.motion.initial_theta_rad,
            scene.motion.initial_omega_rad_s,
            scene.sample_dt_s,
            max_step(model, self.dt_factor),
        )
        wall = time.perf_counter() - start
        frame = two_block_frame(scene, model, motion, traj)
        return Result(frame, _meta(scene, model, motion, traj, wall, self.dt_factor))

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """The output of :func:`rockyade.solvers.cost_estimate.sample_cost` (the time history of
        both blocks), and the Runge-Kutta steps at the largest step, SECONDS_PER_STEP each.

        Raises
        ------
        InputError
            A scene the solver cannot treat.
        """
        step = max_step(self.model(scene), self.dt_factor)
        steps = scene.duration_s / step
        cost = sample_cost(scene, self.name)
        return replace(
            cost, integration_steps=steps, time_step_s=step, wall_time_s=cost.wall_time_s + steps * SECONDS_PER_STEP
        )


def _check_mu(scene: Scene, model: TwoBlockModel) -> dict[str, object]:
    """The restitution the impact law gives each block against the scene's mu.

    Under ``contact.calibration = "matched"`` a scene asks for its mu; the impact law (angular
    momentum about the new pivots) has no parameter, so a mu more than MU_RTOL from the
    block's own is refused. Under the other calibrations the scene's mu sets the DEMs' damping
    only, and the Result says both.

    Raises
    ------
    InputError
        A matched calibration whose mu the model cannot reach.
    """
    own = model.own_restitution()
    asked = {spec.name: spec.mu for spec in scene.blocks}
    far = [n for n, mu in asked.items() if mu is not None and abs(mu - own[n]) > MU_RTOL * own[n]]
    if far and scene.contact.calibration == "matched":
        shown = ", ".join(f"mu = {asked[n]:.4g} for {n} (its own {own[n]:.4g})" for n in far)
        raise InputError(
            "contact.calibration",
            f"the twoblock solver cannot reach {shown}: its impacts conserve angular momentum about the new pivots, "
            "which fixes each block's restitution by its corners and inertia (Eq 4); use calibration 'paper' or "
            "drop mu",
            scene.source,
        )
    out: dict[str, object] = {"mu_model": own, "mu_scene": asked}
    if far:
        out["mu_note"] = (
            "the scene's mu sets the DEMs' damping only; the exact solver's impacts give each block the restitution "
            "of its corners and inertia (mu_model)"
        )
    return out


def _meta(
    scene: Scene,
    model: TwoBlockModel,
    motion: GroundMotion | None,
    traj: TwoBlockTrajectory,
    wall: float,
    dt_factor: float,
) -> RunMeta:
    """The Result's metadata: status, events (the first 200 of each) and the parameters."""
    names = model.names
    overturned = names[traj.overturned_block] if traj.overturned_block is not None else None
    failed = traj.status == "failed"
    classical = {spec.name: spec.classical().as_dict() for spec in scene.blocks}
    before = {
        "overturn_criterion": OVERTURN_CRITERION,
        "failure_time_s": traj.end_time_s if failed else None,
        "n_impacts": traj.counts["impacts"],
    }
    after = {
        "mode_changes": traj.mode_changes[:200].tolist(),
        "event_counts": traj.counts,
        "friction": {
            "coefficient": dict(zip(("base", "seat"), model.friction, strict=True)),
            "max_ratio": dict(zip(("base", "seat"), traj.friction_max, strict=True)),
            "exceeded_time_s": dict(zip(("base", "seat"), traj.friction_exceeded_s, strict=True)),
            "max_impulse_ratio": dict(zip(("base", "seat"), traj.impulse_ratio_max, strict=True)),
        },
        "pivot_tension_time_s": dict(zip(("base", "seat"), traj.pivot_tension_s, strict=True)),
        "onset_multiplier": model.onset_multiplier,
        "uplift_multipliers": model.uplift_multipliers(),
        "model_notes": list(model.notes),
        "rest_fraction_of_alpha": REST_FRACTION,
        "motion": motion.label if motion is not None else "free",
        **_check_mu(scene, model),
    }
    return replace(
        exact_meta(TwoBlockSolver.name, "two-block modes, RK4", scene, traj, wall, dt_factor, before, after),
        failure_reason=traj.failure_reason,
        partial=True if failed else None,
        partial_samples=len(traj.t_s) if failed else None,
        overturn_time_s=traj.end_time_s if overturned else None,
        overturned_block=overturned,
        overturn_times_s={overturned: traj.end_time_s} if overturned and traj.end_time_s is not None else {},
        blocks=names,
        classical=classical,
    )


__all__ = ["TwoBlockSolver"]
