"""Siconos as a solver: nonsmooth contact dynamics, the third voice (:mod:`rockyade.siconos.backend`).

The blocks are the DEMs' (contact polygons at the equivalent base b_eq, inertia from p),
but a contact has no stiffness and no dashpot: impacts are instantaneous with a Newton
restitution e (0 by default: the block's geometry gives Housner's restitution) and Coulomb
friction, stepped by Moreau-Jean in Debian's Siconos (``python3-siconos``), in a worker
process kept warm across scenes (no listening socket; a crash or a timeout costs one
scene). The base motion enters as inertial forces -m a_g(t) in the base frame. See
``docs/siconos.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, ClassVar

from rockyade.calibration.model_stage import calibrated_model
from rockyade.dem.model import DemModel
from rockyade.errors import InputError
from rockyade.result import Result
from rockyade.scene import ContactSpec, Scene
from rockyade.siconos.backend import SICONOS, run_model
from rockyade.siconos.calibration import DT_MAX_S, DT_MIN_S, DT_P_FRACTION, check_target_mu, default_dt, steps_for
from rockyade.siconos.payload import INTEGRATORS, Numerics, penetration_bound
from rockyade.siconos.reach import check_landing_reach
from rockyade.solvers.base import WORKER_OPTIONS, SolverBase, check_float, check_folder
from rockyade.solvers.cost_estimate import CostEstimate, stepped_cost

#: Largest time step accepted, s.
DT_LIMIT_S = 0.01


def _check_dt(value: Any, field: str) -> float | None:
    if value is None:
        return None
    return check_float(value, field, 0.0, DT_LIMIT_S, f"a time step in (0, {DT_LIMIT_S:g}] s", lo_open=True)


def _check_tol(value: Any, field: str) -> float:
    return check_float(value, field, 1e-14, 1e-3, "a tolerance in [1e-14, 1e-3]")


def _check_count(low: int, high: int):
    def check(value: Any, field: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise InputError(field, f"must be an integer in [{low}, {high}], got {value!r}")
        return value

    return check


def _check_restitution(value: Any, field: str) -> float:
    return check_float(value, field, 0.0, 1.0, "a number in [0, 1]")


def _check_integrator(value: Any, field: str) -> str:
    if value not in INTEGRATORS:
        raise InputError(field, f"must be one of {', '.join(INTEGRATORS)}, got {value!r}")
    return str(value)


def _check_optional_tol(value: Any, field: str) -> float | None:
    return None if value is None else _check_tol(value, field)


#: The stiffness of the joints of Siconos's DEM model, N/m: the model builder wants one; Siconos's
#: contacts are rigid and never read it.
UNUSED_STIFFNESS_N_PER_M = 1.0


def rigid_scene(scene: Scene) -> Scene:
    """``scene`` with only what Siconos's contacts take from its contact settings: the friction
    angles (``[contact]``'s and those of ``[[joints]]``), and an explicit joint (stiffness
    UNUSED_STIFFNESS_N_PER_M, no damping) for the model builder."""
    c = scene.contact
    contact = ContactSpec(K_N_per_m=UNUSED_STIFFNESS_N_PER_M, beta_s=0.0, friction_angle_deg=c.friction_angle_deg)
    joints = [replace(j, values=tuple((k, v) for k, v in j.values if k == "friction_angle_deg")) for j in scene.joints]
    return replace(scene, contact=contact, joints=tuple(j for j in joints if j.values))


@dataclass(frozen=True)
class SiconosSolver(SolverBase):
    """Siconos as a solver (module docstring).

    Attributes
    ----------
    timeout_s
        Wall-clock limit of each run, s (default 60 s plus 10 ms per body-step, at most
        an hour).
    warm
        Run in a Siconos process kept warm between runs (one per thread; the default), or
        in a process of its own (False): the same result; warm saves the start-up.
    dt_s
        Time step, s (default: :func:`rockyade.siconos.calibration.default_dt`, 3e-3 / p of
        the fastest moving block within [2e-5, 5e-4] s), rounded down to divide the sample
        interval.
    dt_factor
        Multiplies the time step, in [0.001, 1] (1: the step as chosen; 0.5: halved, for
        convergence checks).
    restitution
        Newton restitution e at every contact, in [0, 1] (default 0: the geometry's own
        restitution, Housner's Eq 4).
    integrator
        How each step's one-step problem is built and solved: "numerics" (the default:
        assembled with numpy, solved by Siconos's numerics, Lemke for a few contacts,
        Gauss-Seidel warm-started for more: :mod:`rockyade.siconos.moreau_jean`) or "kernel"
        (Siconos's TimeStepping, the nonsmooth Newton then NSGS and ADMM: the path before).
    solver_tol, solver_max_iter
        Tolerance and iteration cap of the friction-contact solvers (default tolerance:
        DEFAULT_TOL of the integrator; Lemke's pivoting has none; on the kernel path the
        Newton stops at 100 iterations at most).
    newton_max_iter
        Newton iterations per step on the nonlinear kinematics (1: linearised once).
    workdir
        Where the scene data, output and log are kept after every run (default: none; the
        run works in a private temporary folder, removed after a successful or interrupted
        run, kept after a failed one).
    failed_dir, stem
        Set by :meth:`keeping_files` (not options): where a failed run's files go, and their
        stem (default the scene hash and the solver's name); the stem is followed by
        ``_dt<dt_factor>`` so that runs at two steps never share a name.
    """

    name: ClassVar[str] = "siconos"
    OPTIONS: ClassVar = {
        **WORKER_OPTIONS,
        "dt_s": _check_dt,
        "restitution": _check_restitution,
        "integrator": _check_integrator,
        "solver_tol": _check_optional_tol,
        "solver_max_iter": _check_count(1, 100_000),
        "newton_max_iter": _check_count(1, 100),
    }
    #: Siconos's time per step, s: STEP_S + BODY_STEP_S x n for n moving blocks (cost estimate),
    #: the numerics path at its default step and tolerance. Measured with benchmarks/
    #: bench_siconos.py's scenes beside warm YADE on the loaded 2-core machine (load 12-15, where
    #: YADE took 3.0-10.6 times its own estimate), divided by about that factor (4): a block
    #: 0.25 ms a step (30 s record), the bi-block 0.36 ms (25 s record), the 20-voussoir arch
    #: 5.2 ms at rest and 14 ms under a pulse, the 32-block wall 8.3-16.7 ms under a record and
    #: pulses (docs/siconos.md, "Cost beside YADE").
    STEP_S: ClassVar[float] = 3e-5
    BODY_STEP_S: ClassVar[float] = 8.5e-5
    #: The kernel path's (``integrator = "kernel"``): KERNEL_STEP_S x n ** KERNEL_EXPONENT, measured
    #: before (one block 55-75 us a step; the 13-block arch at rest 86 ms; the 20-voussoir arch
    #: collapsing 50 ms; the 33-block wall 98 ms at rest and 1.3 s under a pulse: within a factor
    #: of 4 of each).
    KERNEL_STEP_S: ClassVar[float] = 6e-5
    KERNEL_EXPONENT: ClassVar[float] = 2.5

    timeout_s: float | None = None
    warm: bool = True
    dt_s: float | None = None
    dt_factor: float = 1.0
    #: The friction-contact solvers' default tolerance per integrator (relative; docs/siconos.md,
    #: "The time step and the tolerance": chosen by what halving it changes).
    DEFAULT_TOL: ClassVar[dict[str, float]] = {"numerics": 1e-4, "kernel": 1e-8}

    restitution: float = 0.0
    integrator: str = "numerics"
    solver_tol: float | None = None
    solver_max_iter: int = 1000
    newton_max_iter: int = 1
    workdir: str | None = None
    failed_dir: str | None = None
    stem: str | None = None

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "failed_dir", check_folder(self.failed_dir, "failed_dir"))

    def model(self, scene: Scene) -> DemModel:
        """The scene's blocks, motion, loads and start as the DEMs build them, and its friction
        (:func:`rigid_scene`): none of the DEMs' contact calibration runs (the paper's Eqs 10-15,
        the matched damping search), nor its checks (Eq 13's range, the penalty springs'
        settlement, the DEM time step's stability), since Siconos's contacts are rigid. The
        model keeps the scene's own hash."""
        model = calibrated_model(rigid_scene(scene), rigid_contacts=True)
        return replace(model, scene_hash=scene.scene_hash)

    def numerics(self, model: DemModel) -> tuple[Numerics, dict[str, object]]:
        """The time step and solver settings for ``model``, and how the step was chosen."""
        base = self.dt_s if self.dt_s is not None else default_dt(model)
        dt, steps = steps_for(model.sample_dt_s, base * self.dt_factor)
        numerics = Numerics(
            dt_s=dt,
            steps_per_sample=steps,
            restitution=self.restitution,
            integrator=self.integrator,
            solver_tol=self.solver_tol if self.solver_tol is not None else self.DEFAULT_TOL[self.integrator],
            solver_max_iter=self.solver_max_iter,
            newton_max_iter=self.newton_max_iter,
        )
        how: dict[str, object] = {
            "dt_factor": self.dt_factor,
            "dt_source": "user"
            if self.dt_s is not None
            else f"default ({DT_P_FRACTION:g} / p of the fastest block, in [{DT_MIN_S:g}, {DT_MAX_S:g}] s)",
            "dt_base_s": base,
            "integrator": self.integrator,
            "penetration_bound_m": penetration_bound(model),
        }
        return numerics, how

    def run(self, scene: Scene) -> Result:
        """Run a scene in Siconos (:func:`rockyade.siconos.backend.run_model`).

        Raises
        ------
        InputError
            A target mu the model cannot reach (:func:`rockyade.siconos.calibration.check_target_mu`);
            a block that starts beyond the pairs' reach above the block it would land on
            (:func:`rockyade.siconos.reach.check_landing_reach`).
        """
        check_landing_reach(scene)
        model = self.model(scene)
        mu = check_target_mu(scene, model)
        numerics, how = self.numerics(model)
        return run_model(
            model,
            numerics,
            timeout_s=self.timeout_s,
            accel_lowpass_hz=scene.output.accel_lowpass_hz,
            warm=self.warm,
            workdir=self.workdir,
            failed_dir=self.failed_dir,
            name=f"{self.stem or f'{scene.scene_hash}_{self.name}'}_dt{self.dt_factor:g}",
            extra_meta={**how, **mu},
        )

    def check_scene(self, scene: Scene) -> None:
        """Refuse before any run what :meth:`run` refuses whatever the motion: a block beyond the
        pairs' reach above its support (:func:`rockyade.siconos.reach.check_landing_reach`), a
        target mu the model cannot reach (:func:`rockyade.siconos.calibration.check_target_mu`), a bad
        ``ROCKYADE_SICONOS_PYTHON`` (:meth:`rockyade.dem.worker_backend.WorkerBackend.check_variable`).

        Raises
        ------
        InputError
            As :meth:`run` would.
        """
        check_landing_reach(scene)
        check_target_mu(scene, self.model(scene))
        SICONOS.check_variable()

    def estimate_cost(self, scene: Scene) -> CostEstimate:
        """Steps at the Siconos time step, STEP_S + BODY_STEP_S x n each for n moving blocks
        (the pairs' geometry and the one-step problem's assembly grow with the blocks, and
        Gauss-Seidel's sweeps with the contacts; its iterations, warm-started, stayed at
        11-67 a step on the arch and the wall); on the kernel path KERNEL_STEP_S x
        n ** KERNEL_EXPONENT (its one-step problem, assembled by Siconos's kernel, and the
        nonsmooth Newton's failures on redundant contacts grow faster than n)."""
        model = self.model(scene)
        numerics, _ = self.numerics(model)
        moving = max(1, len(model.moving))
        steps = float(scene.n_samples - 1) * numerics.steps_per_sample
        if self.integrator == "kernel":
            per_step = self.KERNEL_STEP_S * moving**self.KERNEL_EXPONENT
        else:
            per_step = self.STEP_S + self.BODY_STEP_S * moving
        return stepped_cost(scene, self.name, steps * moving, numerics.dt_s, steps * per_step)

    def keeping_files(self, folder: str | Path, stem: str | None = None) -> SiconosSolver:
        """This solver keeping a failed run's files in ``folder``, named ``stem`` (default: by
        scene hash) and the dt_factor; a successful run keeps none (unless ``workdir``)."""
        return replace(self, failed_dir=str(folder), stem=stem)


__all__ = ["SiconosSolver"]
