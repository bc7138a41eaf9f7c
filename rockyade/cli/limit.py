"""``rockyade limit``: static collapse of an assembly by limit analysis, and the code's
kinematic quantities (docs/limit.md)."""

from __future__ import annotations

import argparse
import re
from pathlib import Path
from typing import Any

from rockyade.cli.common import check_output_file, json_out, print_wrote
from rockyade.errors import InputError

#: Exit codes: 0 collapse (or no mechanism), 1 unstable under gravity or the coulomb rule's iteration
#: not converged; bad input exits 2.
EXIT_UNSTABLE = 1


def cmd_limit(args: argparse.Namespace) -> int:
    """Solve the scene's limit analysis and print (or --json) the answer."""
    if args.plot is not None:
        check_output_file(args.plot, "--plot", ".png")
    from rockyade.limit import limit_analysis
    from rockyade.limit.analysis import check_friction_rule
    from rockyade.limit.model import check_friction_angle
    from rockyade.limit.report import text_report
    from rockyade.scene import load_scene

    friction = None
    if args.friction_angle_deg is not None:
        friction = check_friction_angle(args.friction_angle_deg, "--friction-angle-deg")
    try:
        from rockyade.limit.kinematic import check_fc

        fc = check_fc(args.fc)
    except InputError as exc:
        raise InputError("--fc", exc.message) from None
    rule = check_friction_rule(args.friction_rule, "--friction-rule")
    if not 1 <= args.max_iterations <= 10000:
        raise InputError("--max-iterations", f"must be an integer in [1, 10000], got {args.max_iterations}")
    scene = load_scene(args.scene)
    result = limit_analysis(
        scene,
        direction=args.direction,
        friction_angle_deg=friction,
        sliding=not args.no_sliding,
        fc=fc,
        friction_rule=rule,
        max_iterations=args.max_iterations,
    )
    if args.json:
        data = result.to_dict()
        data["scene"] = str(args.scene)
        json_out(data)
    else:
        print("\n".join(text_report(result, str(args.scene))))
    if args.plot is not None:
        from rockyade.figures.limit import draw_mechanism

        draw_mechanism(result, args.plot, title=args.scene.name)
        print_wrote(args.plot, args.json)
    return EXIT_UNSTABLE if result.status in ("unstable", "not_converged") else 0


def register(sub: Any) -> None:
    """Add ``rockyade limit``."""
    p = sub.add_parser(
        "limit",
        help="static collapse by limit analysis: load multiplier, mechanism, the code's kinematic quantities",
        description="The horizontal acceleration (in g, on every block's mass) at which an assembly of rigid "
        "blocks with no-tension joints collapses, by the equilibrium linear programme (HiGHS); the mechanism "
        "(hinges, sliding joints) from its dual; and the kinematic method's quantities of NTC 2018 / "
        "Circolare 2019 C8.7.1 (alpha0, M*, e*, a0*, d0*, du*, Ts). Exit 0 on collapse, 1 when the assembly "
        "cannot stand under gravity or the coulomb rule does not converge, 2 on bad input. See docs/limit.md.",
    )
    p.add_argument("scene", type=Path, help="scene file (.toml or .json)")
    p.add_argument(
        "--direction",
        choices=("+x", "-x"),
        default="+x",
        help="sense of the horizontal load lambda m g (default +x)",
    )
    joints = p.add_mutually_exclusive_group()
    joints.add_argument(
        "--friction-angle-deg",
        type=float,
        metavar="DEG",
        help="friction angle of every joint, degrees in [0, 90) (default: each joint's from the scene)",
    )
    joints.add_argument("--no-sliding", action="store_true", help="no joint slides (rocking mechanisms only)")
    p.add_argument(
        "--friction-rule",
        default="associated",
        metavar="RULE",
        help="associated (default: the linear programme, sliding joints dilate) or coulomb (sliding without "
        "dilatancy, by iterated programmes: Gilbert, Casapulla & Ahmed 2006; exit 1 if it does not converge)",
    )
    p.add_argument(
        "--max-iterations",
        type=int,
        default=100,
        metavar="N",
        help="the coulomb rule's programmes at most, in [1, 10000] (default 100)",
    )
    p.add_argument("--fc", type=float, default=1.35, help="the code's confidence factor FC, in [1, 10] (default 1.35)")
    p.add_argument("--json", action="store_true", help="print the answer as JSON")
    p.add_argument("--plot", type=Path, metavar="PNG", help="draw the assembly at rest and along the mechanism")
    # "-x" is a value of --direction, not an option: let the parser read it as it reads "-1"
    p._negative_number_matcher = re.compile(r"^-x$|^-\d+$|^-\d*\.\d+$")
    p.set_defaults(func=cmd_limit)
