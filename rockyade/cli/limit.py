"""``rockyade limit``: static collapse of an assembly by limit analysis, and the code's
kinematic quantities (docs/limit.md)."""

from __future__ import annotations

import argparse
import math
import re
import sys
from dataclasses import replace
from pathlib import Path

from rockyade.cli.common import (
    Commands,
    add_allow_large,
    add_command,
    add_joint_options,
    check_output_file,
    json_out,
    print_wrote,
)
from rockyade.errors import InputError, RockyadeError

#: The coulomb rule's progress: first after this many seconds, then at most every PROGRESS_EVERY_S.
PROGRESS_AFTER_S = 2.0
PROGRESS_EVERY_S = 5.0
#: Without --time-limit the programmes stop after the larger of TIME_LIMIT_MIN_S and TIME_LIMIT_FACTOR
#: times the estimate (analysis_cost.py): an analysis far slower than its estimate does not run on unseen.
TIME_LIMIT_MIN_S = 300.0
TIME_LIMIT_FACTOR = 4.0
#: Exit codes: 0 collapse (or no mechanism), 1 unstable under gravity or the coulomb rule's iteration
#: not converged; bad input exits 2.
EXIT_UNSTABLE = 1


def cmd_limit(args: argparse.Namespace) -> int:
    """static collapse by limit analysis: load multiplier, mechanism, the code's kinematic quantities

    The horizontal acceleration (in g, on every block's mass) at which an assembly of rigid blocks with no-tension
    joints collapses, by the equilibrium linear programme (HiGHS); the mechanism (hinges, sliding joints) from its
    dual; and the kinematic method's quantities of NTC 2018 / Circolare 2019 C8.7.1 (alpha0, M*, e*, a0*, d0*, du*,
    Ts). Exit 0 on collapse, 1 when the assembly cannot stand under gravity or the coulomb rule does not converge, 2
    on bad input. See docs/limit.md.
    """
    if args.plot is not None:
        check_output_file(args.plot, "--plot", ".png")
    from rockyade.limit import limit_analysis
    from rockyade.limit.analysis import check_friction_rule
    from rockyade.limit.analysis_cost import check_limit_cost, estimate_limit_cost
    from rockyade.limit.coulomb import MAX_ITERATIONS
    from rockyade.limit.crushing import check_fm
    from rockyade.limit.lp import TimeLimitError
    from rockyade.limit.report_text import text_report
    from rockyade.limit.rigid_blocks import check_friction_angle, rigid_block_model
    from rockyade.scene import load_scene

    friction = None
    if args.friction_angle_deg is not None:
        friction = check_friction_angle(args.friction_angle_deg, "--friction-angle-deg")
    try:
        from rockyade.limit.kinematic import check_fc

        fc = check_fc(args.fc)
    except InputError as exc:
        raise InputError("--fc", exc.message) from None
    # no --friction-rule: associated, with a coulomb pass for the code's quantities where the mechanism slides
    # with friction (docs/limit.md); an explicit rule is that rule alone
    coulomb_check = args.friction_rule is None
    rule = check_friction_rule(args.friction_rule or "associated", "--friction-rule")
    if args.max_iterations is not None and rule != "coulomb" and not coulomb_check:
        raise InputError(
            "--max-iterations",
            "counts the coulomb rule's programmes: give it with --friction-rule coulomb (or without --friction-rule)",
        )
    fm = None if args.fm is None else check_fm(args.fm, "--fm")
    max_iterations = MAX_ITERATIONS if args.max_iterations is None else args.max_iterations
    if not 1 <= max_iterations <= 10000:
        raise InputError("--max-iterations", f"must be an integer in [1, 10000], got {max_iterations}")
    time_limit = args.time_limit
    if time_limit is not None and not (math.isfinite(time_limit) and 0.0 < time_limit <= 1.0e6):
        raise InputError("--time-limit", f"must be a time in (0, 1e6] s, got {time_limit:g}")
    scene = load_scene(args.scene)
    model = rigid_block_model(scene, friction_angle_deg=friction, sliding=not args.no_sliding)
    cost = estimate_limit_cost(model, rule, max_iterations)
    extra = ""
    if coulomb_check and any(itf.friction_angle_deg for itf in model.interfaces):
        programmes = estimate_limit_cost(model, "coulomb", max_iterations).describe().split("; ")[-2]
        extra = f"; and a coulomb pass ({programmes}) if the mechanism slides with friction"
        extra += " (--friction-rule associated skips it)"
    if fm is not None:
        extra += "; the hinges moved by crushing: a programme per iteration to a fixed point (a few)"
    _say(f"cost: {cost.describe()}{extra}")
    if coulomb_check and any(itf.friction_angle_deg for itf in model.interfaces):
        # the coulomb pass runs where the mechanism slides with friction, as on every running-bond wall
        # measured: the check counts it (an analysis refused up front rather than stopped at its time limit)
        cost = replace(
            cost, programmes=cost.programmes + estimate_limit_cost(model, "coulomb", max_iterations).programmes
        )
    check_limit_cost(cost, allow_large=args.allow_large, time_limit_s=time_limit)
    expected = cost.expected_time_s
    if time_limit is None:
        time_limit = min(max(TIME_LIMIT_MIN_S, TIME_LIMIT_FACTOR * expected), 1.0e6)
        bound = (
            f"time limit {time_limit:.0f} s (the larger of {TIME_LIMIT_MIN_S:.0f} s and {TIME_LIMIT_FACTOR:g} times "
            "the estimate; --time-limit S to change it)"
        )
    else:
        bound = f"time limit {time_limit:g} s (--time-limit)"
    _say(f"solving: {bound}; Ctrl-C stops it")
    progress = _Progress(max_iterations) if rule == "coulomb" or coulomb_check else None
    try:
        result = limit_analysis(
            model,
            direction=args.direction,
            fc=fc,
            friction_rule=rule,
            max_iterations=max_iterations,
            time_limit_s=time_limit,
            on_iteration=progress,
            coulomb_check=coulomb_check,
            fm_MPa=fm,
            on_progress=_solving(expected),
        )
    except TimeLimitError as exc:
        given = "--time-limit" if args.time_limit is not None else "the default time limit; --time-limit S for more"
        raise LimitTimeLimitError(f"error: {exc} ({given}): no answer") from None
    if args.json:
        data = result.to_dict()
        data["scene"] = str(args.scene)
        data["cost"] = cost.to_dict()
        json_out(data)
    else:
        print("\n".join(text_report(result, str(args.scene))))
    if args.plot is not None:
        from rockyade.figures.collapse_mechanism import draw_mechanism

        draw_mechanism(result, args.plot, title=args.scene.name)
        print_wrote(args.plot, args.json)
    return EXIT_UNSTABLE if result.status in ("unstable", "not_converged") else 0


class LimitTimeLimitError(RockyadeError):
    """The programme stopped at ``--time-limit`` (exit 1)."""


def _say(message: str) -> None:
    """A line on stderr (stdout keeps the answer, and --json's JSON clean)."""
    print(f"rockyade limit: {message}", file=sys.stderr, flush=True)


def _solving(expected_s: float):
    """Progress within a large programme (every 10 s, :mod:`rockyade.limit.highs_child`) on stderr."""

    def say(seconds: float, iteration: str) -> None:
        where = f", {iteration}" if iteration else ""
        _say(f"solving: {seconds:.0f} s{where} (expected about {max(expected_s, 1.0):.0f} s)")

    return say


class _Progress:
    """The coulomb rule's iterations on stderr: after PROGRESS_AFTER_S, every PROGRESS_EVERY_S."""

    def __init__(self, max_iterations: int) -> None:
        self.max_iterations = max_iterations
        self.last = -math.inf

    def __call__(self, iteration: int, multiplier: float, seconds: float) -> None:
        if seconds >= PROGRESS_AFTER_S and seconds - self.last >= PROGRESS_EVERY_S:
            self.last = seconds
            _say(f"coulomb iteration {iteration}/{self.max_iterations}: lambda = {multiplier:.6g}, {seconds:.0f} s")


def register(sub: Commands) -> None:
    """Add ``rockyade limit``."""
    p = add_command(sub, cmd_limit)
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument(
        "--direction",
        choices=("+x", "-x"),
        default="+x",
        help="sense of the horizontal load lambda m g (default +x)",
    )
    add_joint_options(
        p,
        "friction angle of every joint, degrees in [0, 89.9] (default: each joint's from the scene)",
        "associated (the linear programme alone, sliding joints dilate) or coulomb (sliding without "
        "dilatancy, by iterated programmes: Gilbert, Casapulla & Ahmed 2006; exit 1 if it does not converge); "
        "default: associated, and where its mechanism slides with friction a coulomb pass too, the code's "
        "quantities taking the lower multiplier (both printed)",
        "the masonry's compressive strength fm, MPa (> 0): each hinge moves into its joint by the stress "
        "block's resultant, a / 2 with a = N / (0.85 fm t) (NTC 2018 7.8.2.2.1), iterated with the programme's "
        "normal forces; default: rigid blocks (hinges at the joints' edges)",
    )
    p.add_argument(
        "--max-iterations",
        type=int,
        metavar="N",
        help="the coulomb rule's programmes at most, in [1, 10000] (default 100; not with --friction-rule associated)",
    )
    p.add_argument(
        "--time-limit",
        type=float,
        metavar="S",
        help="stop the programmes after S seconds of wall time (HiGHS's time limit; exit 1 without an answer, "
        "or the coulomb rule not converged), in (0, 1e6]; it bounds the expected time checked against the limits "
        f"too; default: the larger of {TIME_LIMIT_MIN_S:.0f} s and {TIME_LIMIT_FACTOR:g} times the estimate",
    )
    add_allow_large(p)
    p.add_argument("--fc", type=float, default=1.35, help="the code's confidence factor FC, in [1, 10] (default 1.35)")
    p.add_argument("--json", action="store_true", help="print the answer as JSON")
    p.add_argument("--plot", type=Path, metavar="PNG", help="draw the assembly at rest and along the mechanism")
    # "-x" is a value of --direction, not an option: let the parser read it as it reads "-1"
    p._negative_number_matcher = re.compile(r"^-x$|^-\d+$|^-\d*\.\d+$")
